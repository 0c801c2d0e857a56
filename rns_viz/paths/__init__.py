"""Where the arm can go without reaction: reactionless paths (Def. 3, Eq. 27, Fig. 8) and reachable sets.

- :mod:`~rns_viz.paths.field`: S H_bm and its coupling potential (Eq. 26) at many configurations at once.
- :mod:`~rns_viz.paths.tracing`: integral curves of n for a 1-D RNS, their seeds, the family of Fig. 8.
- :mod:`~rns_viz.paths.table`: one path as a table over sigma, the integral of u-bar dt (Eq. 30).
- :mod:`~rns_viz.paths.reachable`: the reachable set of a translating base, a level set of the potential.
- :mod:`~rns_viz.paths.turning`: the reachable set of a base that turns, the RNS distribution integrated.
"""

from rns_viz.paths.field import CouplingField
from rns_viz.paths.reachable import ReachableSet, reactionless_reachable_set
from rns_viz.paths.table import PathTable, build_path_table
from rns_viz.paths.tracing import (
    ReactionlessPath,
    default_seeds,
    nearby_seeds,
    path_family,
    potential,
    trace_paths,
)
from rns_viz.paths.turning import Explored, explore_rns

__all__ = [
    "CouplingField",
    "Explored",
    "PathTable",
    "ReachableSet",
    "ReactionlessPath",
    "build_path_table",
    "default_seeds",
    "explore_rns",
    "nearby_seeds",
    "path_family",
    "potential",
    "reactionless_reachable_set",
    "trace_paths",
]
