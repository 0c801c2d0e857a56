"""The loop's own instance of the live model and what is derived from it once per model.

A model is named by its key (:func:`rns_viz.params.model_key`: a bundled name or a parameter file,
with the selection S); :meth:`LoopModel.load` reads and checks everything before anything is
replaced, so a malformed file (:class:`~rns_viz.params.ModelFileError`, naming the element at
fault) leaves the running session on the model it had.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rns_viz.integrability import check_integrability
from rns_viz.live.operator.kinds import operator_class
from rns_viz.live.operator.operator import InputRefused, Operator
from rns_viz.live.reach.region import arm_reach
from rns_viz.live.runs.divergence_guard import Bounds
from rns_viz.model import FsmsModel
from rns_viz.params import model_key, model_source, spec_for_key
from rns_viz.paths import CouplingField


@dataclass(frozen=True)
class LoopModel:
    model: FsmsModel  # for references and readouts (the runs have their own instances)
    kind: type[Operator]  # what the operator drives on it (a path, a reachable set, a task arm)
    field: CouplingField  # S H_bm and its potential at many configurations
    bounds: Bounds  # the divergence guard's physical bounds
    reach_m: float  # m: the arm's reach
    tol: float  # kg m: two configurations closer than this in the coupling potential are on one path

    @classmethod
    def load(cls, key: str) -> LoopModel:
        """Read model ``key``; raises ModelFileError (a ValueError) with the element at fault."""
        model = FsmsModel.from_key(key)
        reach = arm_reach(model)
        kind = operator_class(model)
        return cls(model, kind, CouplingField(model), Bounds(model), reach, 1e-4 * model.arm_mass * reach)

    def copy_model(self) -> FsmsModel:
        """Another instance of the same (already checked) model, with its own pinocchio data."""
        return FsmsModel(self.model.spec)


def key_of(model: FsmsModel) -> str:
    """The model key of a model built elsewhere (a preset's): its source, with its S if not the file's own."""
    source = model_source(model.name)
    flags = model.spec.base.selection
    if np.array_equal(spec_for_key(source).base.selection, flags):
        return source
    return model_key(source, [int(f) for f in flags])


def integrability_note(model: FsmsModel, theta: np.ndarray) -> str:
    """Frobenius test of the RNS distribution at ``theta`` (Lie brackets of the columns of P_RNS), in words."""
    test = check_integrability(model.coupling_at, np.asarray(theta, dtype=float))
    if test.integrable:
        return f"Lie brackets here: the RNS distribution is integrable (residual {test.max_residual:.1e})."
    return (
        f"Lie brackets here: the RNS distribution is not integrable (residual {test.max_residual:.2g}): "
        "reactionless motions can reach more than a fixed surface, as for a non-holonomic constraint."
    )


MAX_TRACKING_ROWS = 5  # r <= 5 (n - r >= 2): a 3-D target is tracked by Eq. (24) in the RNS (on a surface if 2-D)


def _surface_note(rns_dim: int) -> str:
    return (
        f"With a {rns_dim}-D RNS the hand's reactionless motions span a surface, not a volume: a dragged target "
        "is held at the nearest point of the drawn reachable set and the hand goes there along the surface. "
    )


def selection_key(model: FsmsModel, flags: tuple[bool, ...], theta: np.ndarray) -> tuple[str, str]:
    """The model key of ``model`` with selection S = ``flags`` (Sec. III-B) and what to tell the operator
    (for a multi-dimensional RNS, whether its distribution is integrable at ``theta``: Lie brackets, Sec. III-A);
    InputRefused if the app cannot operate that RNS: a 1-D RNS runs along reactionless paths, at most three
    selected rows track a target."""
    if len(flags) != model.m:
        raise InputRefused(f"{model.name} has {model.m} base coordinates; the selection has {len(flags)} flags")
    r = sum(bool(f) for f in flags)
    if r == 0:
        raise InputRefused("select at least one base reaction to cancel")
    if r >= model.n:
        raise InputRefused(f"with {r} reactions to cancel the {model.n}-joint arm has no reaction null space")
    if model.n - r != 1 and r > MAX_TRACKING_ROWS:
        raise InputRefused(
            f"r = {r} leaves a {model.n - r}-D reaction null space that the app does not operate: select "
            f"{model.n - 1} (a 1-D RNS: reactionless paths) or at most {MAX_TRACKING_ROWS} (end-effector tracking)"
        )
    selected = FsmsModel(model.spec.with_selection(flags))
    note = f"r = {r}: the reaction null space has dimension n − r = {model.n - r}. " + (
        "The arm moves without reaction along its reactionless path (scrub ū or drag the handle)."
        if model.n - r == 1
        else "Drag the handle: the hand tracks it in 3-D by Eq. (24) without the selected reactions. "
        + (_surface_note(model.n - r) if model.n - r < len(model.task_rows) else "")
        + integrability_note(selected, theta)
    )
    if r < model.m:
        note += (
            " The other base coordinates are left free: the arm's motion still excites them. Suppression "
            "(15) damps the selected rows of the base momentum, S H_b x_b', which carry the free "
            "coordinates' share too: on boom7 the free modes then decay as well, at the same gains as with all "
            "six selected; for another model, check its gain map and watch the base plot."
        )
    return key_of(selected), note
