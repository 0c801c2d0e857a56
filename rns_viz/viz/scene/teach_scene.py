"""What the eye can't see, drawn: the shadow run's ghost, the coupling momentum L, the null-space
vector n as the hand velocity it produces, and arrows for the direction of increasing ū on the path.

Built with the scene (and again after a model switch) and drawn by the render thread each frame;
each part follows its checkbox in *Show in the scene* (:mod:`rns_viz.viz.scene.view_toggles`).
"""

from __future__ import annotations

import numpy as np
import viser

from rns_viz.live.outputs.readouts import coupling_sigma, null_motion
from rns_viz.live.published.snapshot import Snapshot
from rns_viz.live.reach.region import arm_reach
from rns_viz.model import FsmsModel
from rns_viz.viz.scene.fsms_scene import PATH_HIGHLIGHT, FsmsScene
from rns_viz.viz.scene.ghost import Ghost
from rns_viz.viz.scene.quantities import MOMENTUM, REACTION
from rns_viz.viz.scene.region_outline import outline_points
from rns_viz.viz.scene.view_toggles import ViewToggles

L_COLOUR = (120, 40, 170)  # purple: coupling momentum
N_COLOUR = (235, 130, 0)  # orange: null-space direction at the hand
OUTLINE_COLOUR = (110, 60, 190)  # the reachable region's edge, darker than its dots
EDGE_TEXT = "edge of the reactionless region:\na fold, J̄ loses rank"  # two lines: one is wider than a phone
PATH_ARROWS = 8  # arrowheads along the current path
L_REF_RATE = 1.0  # rad/s: a joint rate that draws L at full arrow length (with sigma_min(S H_bm) at the start)


class TeachScene:
    """Ghost and teaching arrows of one model's scene."""

    COUPLING = "/base/coupling"
    NULL = "/base/null_vector"
    PATH_ARROWS = "/base/path_arrows"
    OUTLINE = "/base/reach_outline"

    def __init__(self, server: viser.ViserServer, model: FsmsModel, scene: FsmsScene) -> None:
        self.server, self.model, self.scene = server, model, scene
        st = scene.style
        self.ghost = Ghost(server, model, st)
        r = st.marker_radius
        arrow = {"shaft_radius": 0.2 * r, "head_radius": 0.5 * r, "head_length": 1.2 * r, "visible": False}
        self.coupling = server.scene.add_arrows(self.COUPLING, np.zeros((1, 2, 3)), L_COLOUR, **arrow)  # type: ignore[arg-type]
        label = f"{self.COUPLING}/label"
        self.coupling_label = server.scene.add_label(label, "", anchor="bottom-center", visible=False)
        self.null = server.scene.add_arrows(self.NULL, np.zeros((1, 2, 3)), N_COLOUR, **arrow)  # type: ignore[arg-type]
        self.null_label = server.scene.add_label(f"{self.NULL}/label", "", anchor="bottom-left", visible=False)
        self.path_arrows = server.scene.add_arrows(
            self.PATH_ARROWS,
            np.zeros((1, 2, 3)),
            tuple(int(255 * c) for c in PATH_HIGHLIGHT),
            shaft_radius=0.15 * r,
            head_radius=0.6 * r,
            head_length=1.5 * r,
            position=(0.0, 0.0, st.overlay_z),
            visible=False,
        )
        self.outline = server.scene.add_point_cloud(
            self.OUTLINE,
            np.zeros((1, 3)),
            OUTLINE_COLOUR,
            point_size=0.6 * r,
            point_shape="circle",
            position=(0.0, 0.0, st.overlay_z - 0.5 * r),  # just above the region's dots (_outline_offset)
            visible=False,
        )
        # the edge's name: a callout placed off the arm and inside every page (its point: the edge's top)
        self.edge_callout = scene.callouts.add("region_edge", EDGE_TEXT, parent=self.OUTLINE)
        self.edge_callout.shown = False
        self._edge_top = np.zeros(3)  # m, in the outline node's frame
        self._outline_offset = np.array([0.0, 0.0, st.overlay_z - 0.5 * r])  # the outline node in the base's frame
        self._has_path = False
        self.has_reach = False  # the reachable set is drawn (set by the renderer with the overlays)
        self.one_d = model.n - len(model.selected) == 1  # a 1-D reaction null space: n and a path exist
        reach = arm_reach(model)
        theta0 = model.spec.default_configuration
        # Fixed scales per model (m of arrow per unit): the start pose draws n at 40 % of the reach
        # and L at the force arrow's full length for a joint rate of 1 rad/s.
        jn0 = float(np.linalg.norm(null_motion(model, theta0)[1])) if self.one_d else 1.0
        self.n_scale = 0.4 * reach / max(jn0, 1e-12)  # m per (m/s per unit u-bar)
        self.L_scale = st.force_arrow_max / max(coupling_sigma(model, theta0) * L_REF_RATE, 1e-12)
        self._L_origin = np.asarray(st.force_origin) + np.array([0.0, 0.0, 2.5 * r])
        self._axis = model.base_axes()[0] if model.base_is_translational else np.array([1.0, 0.0, 0.0])
        # What was drawn (tests read these): n (kg m) and J n (m/s per unit u-bar) at the drawn theta, L (N s).
        self.n: np.ndarray | None = None
        self.jn: np.ndarray | None = None
        self.L = float("nan")
        self._theta: np.ndarray | None = None

    # ---------------------------------------------------------------- per frame
    def draw(self, snap: Snapshot, q_shadow: np.ndarray | None, exaggeration: float, view: ViewToggles) -> None:
        """Ghost (``q_shadow`` as drawn, or None), L and n for the snapshot; hidden parts cost nothing."""
        self._apply_toggles(snap, view)
        if self.edge_callout.shown:  # tied to the drawn base, as the outline node is
            base = self.scene.robot.base_placement()
            at = base.translation + base.rotation @ self._outline_offset
            self.edge_callout.attach(base.rotation, at, self._edge_top)
        shadow_on = not (snap.readouts.compensating if snap.readouts.dual else snap.settings.suppress)
        self.ghost.update(q_shadow if view.on("ghost") else None, exaggeration, self._shadow_label(snap), shadow_on)
        self._draw_coupling(snap.readouts.L if view.on("coupling") else None)
        theta = snap.q[self.model.m :]
        self._draw_null(theta if view.on("null_vector") and self.one_d and np.all(np.isfinite(theta)) else None)
        want = self._has_path and view.on("path_arrows")
        if self.path_arrows.visible != want:
            self.path_arrows.visible = want

    def _shadow_label(self, snap: Snapshot) -> str:
        if snap.readouts.dual:
            return f"ghost: compensator {'held' if snap.readouts.compensating else 'cancelling'}"
        return f"ghost: suppression {'off' if snap.settings.suppress else 'on'}"  # the panel's *Ghost run*

    def _apply_toggles(self, snap: Snapshot, view: ViewToggles) -> None:
        """The scene's own drawings that have a checkbox: reaction arrow, trail, reachable set."""
        sc = self.scene
        if view.on("reaction") != sc.show_force:
            sc.show_force = view.on("reaction")
            f = snap.readouts.reaction
            sc.set_reaction_force(f if np.isfinite(f) else 0.0, REACTION.name, snap.readouts.reaction_wrench)
        if view.on("trail") != sc.show_trail:
            sc.show_trail = view.on("trail")
            sc.trail_node.visible = sc.show_trail and len(sc.trail.points()) >= 2
        if view.on("reach") != sc.show_reach:
            sc.show_reach = view.on("reach")
            sc.reachable.visible = sc.show_reach and self.has_reach
            self.outline.visible = self.edge_callout.shown = sc.show_reach and self.has_reach

    def _draw_coupling(self, L: float | None) -> None:
        if L is None or not np.isfinite(L):
            if self.coupling.visible:
                self.coupling.visible = self.coupling_label.visible = False
            return
        L = round(L, 4)  # N s: finer changes are not drawn
        if L == self.L and self.coupling.visible:
            return
        self.L = L
        st = self.scene.style
        length = float(np.clip(L * self.L_scale, -st.force_arrow_max, st.force_arrow_max))
        show = abs(length) > self.coupling.head_length
        with self.server.atomic():
            self.coupling_label.visible = True
            tip = self._L_origin + length * self._axis
            self.coupling_label.position = tip if show else self._L_origin
            self.coupling_label.text = f"{MOMENTUM.name} = {L:.3g} {MOMENTUM.unit}"
            self.coupling.visible = show
            if show:
                self.coupling.points = np.stack([self._L_origin, tip])[None]

    def _draw_null(self, theta: np.ndarray | None) -> None:
        if theta is None:
            if self.null.visible:
                self.null.visible = self.null_label.visible = False
            return
        theta = np.round(theta, 4)
        if self._theta is not None and np.array_equal(theta, self._theta) and self.null.visible:
            return
        self._theta = theta
        model = self.model
        n, jn = null_motion(model, theta)  # kg m (Eq. 27); m/s per unit u-bar
        self.n, self.jn = n, jn
        ee = model.ee_position(theta) + np.array([0.0, 0.0, self.scene.style.overlay_z])
        tip = ee + self.n_scale * jn
        with self.server.atomic():
            self.null.points = np.stack([ee, tip])[None]
            self.null_label.position = tip
            self.null_label.text = f"J n = {1e3 * np.linalg.norm(jn):.3g} mm/s per unit ū"
            self.null.visible = self.null_label.visible = True

    # ---------------------------------------------------------------- overlays
    def set_reach(self, points: np.ndarray | None) -> None:
        """The outline of the reactionless-reachable region (base frame points, (N, 3)), or None."""
        self.has_reach = points is not None and len(points) > 2 and bool(np.all(np.isfinite(points)))
        # a planar region only (the 3R's, at one height): a spatial set (boom7) is drawn as its point cloud alone
        self.has_reach = self.has_reach and float(np.ptp(np.asarray(points)[:, 2])) < 1e-6
        edge = outline_points(np.asarray(points)) if self.has_reach else np.zeros((0, 3))
        self.has_reach = self.has_reach and len(edge) > 0
        show = self.has_reach and self.scene.show_reach
        with self.server.atomic():
            if len(edge):
                self.outline.points = edge.astype(np.float32)
                self.outline.colors = np.array(OUTLINE_COLOUR, dtype=np.uint8)
                self._edge_top = edge[int(np.argmax(edge[:, 1]))]
            self.outline.visible = self.edge_callout.shown = show

    def set_path(self, curve: np.ndarray | None) -> None:
        """Arrowheads along the current path's end-effector curve (base frame, in path order = increasing ū)."""
        pts = None if curve is None else np.asarray(curve, dtype=float)
        if pts is None or len(pts) < 3 or not np.all(np.isfinite(pts)) or not self.one_d:
            self._has_path = False
            self.path_arrows.visible = False
            return
        step = np.linalg.norm(np.diff(pts, axis=0), axis=1)
        s = np.concatenate([[0.0], np.cumsum(step)])  # m, arc length along the curve
        if s[-1] <= 0.0:
            self._has_path = False
            return
        at = np.searchsorted(s, (np.arange(PATH_ARROWS) + 0.5) / PATH_ARROWS * s[-1])
        at = np.clip(at, 0, len(pts) - 2)
        d = pts[at + 1] - pts[at]
        d /= np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-12)
        length = 2.5 * self.scene.style.marker_radius
        self.path_arrows.points = np.stack([pts[at], pts[at] + length * d], axis=1)
        self._has_path = True
