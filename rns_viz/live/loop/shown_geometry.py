"""The geometry the live session shows and the operator needs: the current reactionless path (1-D RNS)
or reactionless-reachable set (otherwise) through the arm's configuration, and the path family.

:class:`Geometry` asks the background for them, keeps what arrived and makes the overlays readers
draw. The default configuration's path table is kept per model, so a reset needs no recomputation.
"""

from __future__ import annotations

import numpy as np

from rns_viz.live.jobs.background import Background
from rns_viz.live.operator.operator import Operator
from rns_viz.live.published.snapshot import Overlays
from rns_viz.live.reach.region import ReachRegion
from rns_viz.model import FsmsModel
from rns_viz.paths import CouplingField, PathTable


class Geometry:
    def __init__(self, background: Background) -> None:
        self.background = background
        self.default_tables: dict[str, PathTable] = {}
        self.version = 0
        self.restart()

    def restart(self) -> None:
        self.current_path: np.ndarray | None = None  # (k, 3) end-effector points of the current path, m
        self.reach_points: np.ndarray | None = None  # (N, 3) reachable end-effector points, m
        self.reach_note = ""  # the Lie-bracket test where the reachable set was explored from
        self.shown_level: np.ndarray | None = None  # coupling potential of what is shown, kg m

    def request(
        self, kind: type[Operator], model: FsmsModel, field: CouplingField, epoch: int, theta: np.ndarray, default: bool
    ) -> None:
        """What the operator's ``kind`` shows through ``theta``: the current reactionless path (1-D RNS) or the
        reachable set (otherwise); nothing for a task arm, which goes anywhere in its workspace."""
        self.shown_level = field.potentials(np.asarray(theta, dtype=float)[None])[0]
        shows = kind.shows
        if shows == "path":
            self.background.path_table(epoch, model.name, theta, default)
            self.background.family(epoch, model.name)
        elif shows == "reachable set":  # on the potential's level set (a translating base) or along the distribution
            self.background.reach(epoch, model.name, theta)

    def took_table(self, model: str, table: PathTable, default: bool) -> None:
        if default:
            self.default_tables[model] = table
        self.current_path = table.ee

    def took_reach(self, region: ReachRegion) -> None:
        self.reach_points = region.points
        self.reach_note = region.note

    def overlays(self, model: str, epoch: int) -> Overlays:
        """What model ``model`` shows in the loop's ``epoch`` (the overlays say so: readers check)."""
        self.version += 1
        family = self.background.families.get(model)
        return Overlays(family, self.current_path, self.reach_points, self.version, self.reach_note, model, epoch)
