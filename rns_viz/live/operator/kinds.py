"""The one choice of what the operator drives on a model, made when the model loads.

A task arm with compensating arms (``[arms]`` in the parameter file) is driven by its target; otherwise the
reaction null space's dimension n - r decides (Sec. III): a 1-D RNS along its reactionless path, a larger one
by a target in its reactionless-reachable set. Everything that differs by this choice asks the class this
returns (its attributes ``kind``, ``follows``, ``shows``, ``compensates``, ``laws``) instead of the model.
"""

from __future__ import annotations

from functools import cache

from rns_viz.live.operator.dual_arm import is_dual
from rns_viz.live.operator.operator import Operator
from rns_viz.live.operator.path_operator import PathOperator
from rns_viz.live.operator.target_operators import ReachOperator, TaskArmOperator
from rns_viz.model import FsmsModel


def operator_class(model: FsmsModel) -> type[Operator]:
    """The operator of ``model`` with its selection S: a task arm, a reactionless path or a reachable set."""
    if is_dual(model):
        return TaskArmOperator
    return PathOperator if model.n - len(model.selected) == 1 else ReachOperator


@cache
def operator_class_of(key: str) -> type[Operator]:
    """:func:`operator_class` of the model a model key names (bundled or a file, with its S)."""
    return operator_class(FsmsModel.from_key(key))
