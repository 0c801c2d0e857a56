"""The rank-deficiency overlay: the poses where S H_bm loses rank, drawn in the base frame.

Data from the live layer (:func:`rns_viz.live.teaching.rank_view.rank_overlay`); computed the first time the
*Show in the scene* box is ticked (under a second for the 3R), then kept. Each pose is drawn as the
arm's links (line segments) with a dot at its end effector, and a short label; the full sentence of
why is the checkbox's hint (``RANK_HINT``).
"""

from __future__ import annotations

import numpy as np
import viser

from rns_viz.live.teaching.rank_view import RANK_LABEL, RankOverlay, rank_overlay
from rns_viz.model import FsmsModel
from rns_viz.viz.scene.style import SceneStyle

RANK_COLOUR = (200, 120, 0)  # amber: configurations to know about, not to use


class RankScene:
    """Poses of rank loss of S H_bm for one model's scene (nothing for models without an overlay)."""

    NODE = "/base/rank_loss"

    def __init__(self, server: viser.ViserServer, model: FsmsModel, style: SceneStyle) -> None:
        self.server, self.model, self.style = server, model, style
        self.overlay: RankOverlay | None = None  # what is drawn (tests read it)
        self._built = False
        self._nodes: list[viser.SceneNodeHandle] = []
        self.shown = False

    def draw(self, on: bool) -> None:
        """Show (computing it the first time) or hide the overlay."""
        if on == self.shown:
            return
        self.shown = on
        if on and not self._built:
            self._built = True
            self.overlay = rank_overlay(self.model.name)
            if self.overlay is not None and len(self.overlay.poses):
                self._build(self.overlay)
        for node in self._nodes:
            node.visible = on

    def _build(self, overlay: RankOverlay) -> None:
        st = self.style
        z = np.array([0.0, 0.0, st.overlay_z + 0.5 * st.marker_radius])
        poses = overlay.poses + z
        segments = np.concatenate([np.stack([p[:-1], p[1:]], axis=1) for p in poses])
        ends = poses[:, -1, :]
        self._nodes = [
            self.server.scene.add_line_segments(
                f"{self.NODE}/links",
                segments.astype(np.float32),
                RANK_COLOUR,
                thickness=3.0,
                thickness_units="screen",
                visible=False,
            ),
            self.server.scene.add_point_cloud(
                f"{self.NODE}/ends",
                ends.astype(np.float32),
                RANK_COLOUR,
                point_size=1.2 * st.marker_radius,
                point_shape="circle",
                visible=False,
            ),
            self.server.scene.add_label(
                f"{self.NODE}/label",
                RANK_LABEL,
                position=tuple(ends[int(np.argmax(ends[:, 0]))] + np.array([0.0, 2.0 * st.marker_radius, 0.0])),
                anchor="bottom-left",
                visible=False,
            ),
        ]
