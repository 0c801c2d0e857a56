"""The FSMS scene in viser: robot, elastic base, end-effector trail, reaction arrow and overlays.

``FsmsScene(server, model)`` builds everything once; ``update(q, exaggeration)`` poses it for a
configuration q = (x_b, theta) inside one ``server.atomic()`` block. Base deflections are drawn
multiplied by ``exaggeration`` (the arm rides on the exaggerated base too). Overlays given in the
base frame (path family, reachable set, target, reaction arrow) hang under the ``/base`` node,
which follows the drawn base, so the end effector stays on its drawn path while the base moves.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import Literal

import numpy as np
import pinocchio as pin
import viser

from rns_viz.model import FsmsModel
from rns_viz.paths import ReactionlessPath
from rns_viz.viz.scene.base_drawing import CartSpringDrawing, DoubleBeamDrawing
from rns_viz.viz.scene.boom_drawing import BoomDrawing
from rns_viz.viz.scene.callouts import Callout, Callouts
from rns_viz.viz.scene.framing import (
    DEFAULT_ASPECT,
    DEFAULT_FOV,
    NARROW_BAND,
    CameraPose,
    frame_points,
    framed_points,
    framing_holds,
    is_narrow,
)
from rns_viz.viz.scene.quantities import BASE_VIBRATION
from rns_viz.viz.scene.reaction_arrows import WrenchArrows
from rns_viz.viz.scene.robot import RobotMeshes
from rns_viz.viz.scene.shapes import Trail, path_colours, path_family_segments, polyline_segments
from rns_viz.viz.scene.style import BoomStyle, CartSpringStyle, DoubleBeamStyle, SceneStyle, style_for

PATH_COLOUR = (0.60, 0.63, 0.68)  # other reactionless paths: grey (the ghost is the blue), RGB in [0, 1]
PATH_HIGHLIGHT = (0.90, 0.05, 0.30)  # the current path: crimson (the reaction arrow is the red)
# The family is drawn in screen pixels: world-unit lines get a second, blended antialiasing pass in
# viser's client, which made the ~1200 segments the costliest node of a software-rendered frame.
PATH_WIDTH_PX = 4.0
TRAIL_COLOUR = (0.20, 0.65, 0.30)
FORCE_COLOUR = (180, 0, 0)  # lit arrows render lighter than their colour
TARGET_COLOUR = (30, 170, 90)
REFRAME_SETTLE_S = 2.0  # s after a framing in which a page's new size frames it again (a resize comes in steps)
MAP_FRAMED_TOP = 0.45  # NDC: the points framed with the gain map stay under this (the panel: ~200 px of 768)
REACH_COLOUR = (196, 182, 236)  # pale, under the arm


class FsmsScene:
    """Everything the FSMS app draws. Node names are class constants so tests can find them."""

    BASE = "/base"
    # The base frame with the base at rest. The target handle hangs here, not under BASE: viser's page
    # turns a drag into a pose in the handle's parent frame as that frame stands at each mouse move, so
    # under the drawn (magnified) shaking base the handle would move by the base's motion since the press.
    BASE_AT_REST = "/base_at_rest"
    PATHS = "/base/paths"
    REACHABLE = "/base/reachable"
    TARGET = "/base/target"
    FORCE = "/base/reaction"
    FORCE_LABEL = "/base/reaction/label"
    TRAIL = "/trail"  # world-frame trail; a base-frame trail is BASE_TRAIL
    BASE_TRAIL = "/base/trail"
    GRID = "/grid"
    ROBOT = "/robot"

    def __init__(
        self,
        server: viser.ViserServer,
        model: FsmsModel,
        style: SceneStyle | None = None,
        trail_frame: Literal["world", "base"] = "world",
    ) -> None:
        """Build the scene. ``trail_frame="world"`` shows the drawn base's shaking in the trail;
        ``"base"`` traces the end effector relative to the base (the frame reactionless paths live in).
        """
        self.server = server
        self.model = model
        self.style = style or style_for(model)
        st = self.style
        scene = server.scene
        scene.configure_environment_map(None)  # the default HDRI freezes software-rendered pages
        scene.configure_default_lights(enabled=True, cast_shadow=False)  # a key light from above
        scene.add_light_ambient("/lights/ambient", intensity=0.8)
        # A directional light shines from its node position towards the world origin.
        scene.add_light_directional("/lights/fill", intensity=1.0, position=(1.0, -2.0, 1.5))
        self.grid = scene.add_grid(
            self.GRID,
            width=st.grid_size,
            height=st.grid_size,
            cell_size=st.grid_cell,
            section_size=5 * st.grid_cell,
            position=(0.0, 0.0, st.grid_z),
        )
        lift = (0.0, 0.0, st.overlay_z)  # base-frame overlays sit at the drawn end effector's height
        self._lift = np.array(lift)
        self._trail_lift = self._lift + np.array([0.0, 0.0, st.line_thickness])  # drawn over the path it follows
        self.robot = RobotMeshes(server, model, base_name=self.BASE, root=self.ROBOT)
        self.base_node = self.robot.base_node
        rest = self.robot.rest_base_placement()
        wxyz = pin.Quaternion(rest.rotation).coeffs()[[3, 0, 1, 2]]  # pinocchio stores x, y, z, w
        scene.add_frame(self.BASE_AT_REST, show_axes=False, position=rest.translation, wxyz=wxyz)
        self.base_drawing = _make_base_drawing(server, model, st.base)
        self.paths = scene.add_line_segments(
            self.PATHS,
            np.zeros((1, 2, 3)),
            PATH_COLOUR,
            thickness=PATH_WIDTH_PX,
            thickness_units="screen",
            position=lift,
            visible=False,
        )
        self._path_owners = np.zeros(0, dtype=int)
        self.current_path: int | None = None
        self.reachable = scene.add_point_cloud(
            self.REACHABLE,
            np.zeros((1, 3)),
            REACH_COLOUR,
            point_size=0.3 * st.marker_radius,
            point_shape="circle",
            precision="float32",
            position=(0.0, 0.0, st.overlay_z - st.marker_radius),  # just below the arm
            visible=False,
        )
        self.target = scene.add_icosphere(
            self.TARGET, radius=st.marker_radius, color=TARGET_COLOUR, opacity=0.7, visible=False
        )
        self.force = scene.add_arrows(
            self.FORCE,
            np.zeros((1, 2, 3)),
            FORCE_COLOUR,
            shaft_radius=0.25 * st.marker_radius,
            head_radius=0.6 * st.marker_radius,
            head_length=1.5 * st.marker_radius,
            visible=False,
        )
        self.force_label = scene.add_label(self.FORCE_LABEL, "", anchor="top-center", visible=False)
        self._force = 0.0
        # a 6-DOF base: the whole reaction, force and moment (the single arrow above stays hidden)
        self.wrench = WrenchArrows(server, st, FORCE_COLOUR) if model.m == 6 else None
        self.show_force = self.show_trail = self.show_reach = True  # the view toggles (render thread)
        self._force_axis = model.base_axes()[0] if model.base_is_translational else np.array([1.0, 0.0, 0.0])
        self._force_origin = np.asarray(st.force_origin, dtype=float)
        self.trail = Trail(st.trail_capacity, st.trail_step or 0.25 * st.marker_radius, st.trail_jump)
        self.trail_in_base = trail_frame == "base"
        self.trail_node = scene.add_line_segments(
            self.BASE_TRAIL if self.trail_in_base else self.TRAIL,
            np.zeros((1, 2, 3)),
            TRAIL_COLOUR,
            thickness=1.5 * st.line_thickness,
            visible=False,
        )
        self.callouts = Callouts(server)  # labels placed off the arm each frame (the renderer adds its own)
        self.base_callout = self._add_labels()
        self.base_label = self.base_callout.label
        self.framed = framed_points(model)  # world points the camera frames
        self.also_framed: np.ndarray | None = None  # more of them while shown (the gain map's corners)
        # page -> (canvas px, camera position m, time s) when it was last framed
        self.framed_pages: dict[int, tuple[tuple[int, int], np.ndarray, float]] = {}
        self.set_initial_camera()
        self.q = model.q(model.spec.default_configuration)
        self.exaggeration = 1.0
        self.update(self.q, 1.0)

    # -- per frame -----------------------------------------------------------------------------
    def update(self, q: np.ndarray, exaggeration: float = 1.0, trail: bool = True) -> None:
        """Pose robot, base drawing and base-frame overlays for q = (x_b, theta); base drawn x exaggeration."""
        m = self.model.m
        q_draw = np.array(q, dtype=float)
        if q_draw.shape != (self.model.nv,):
            raise ValueError(f"q must be (x_b, theta) with shape ({self.model.nv},), got {q_draw.shape}")
        q_draw[:m] *= exaggeration
        with self.server.atomic():
            if exaggeration != self.exaggeration:  # the factor written is the factor drawn
                self.base_callout.text = self.base_label.text = base_label(exaggeration)
            self.q, self.exaggeration = np.asarray(q, dtype=float).copy(), exaggeration
            self.robot.pose(q_draw)
            if isinstance(self.base_drawing, BoomDrawing):
                self.base_drawing.pose(self.robot.base_placement())
            elif self.base_drawing is not None:
                self.base_drawing.update(self.robot.base_placement().translation)
            if trail and self.trail.push(self._trail_point()):
                self._draw_trail()

    def set_reaction_force(self, f: float, label: str = "F", wrench: Sequence[float] = ()) -> None:
        """Arrow along the base axis at the base: ``f`` in N (the base reaction, paper's F_b).

        The arrow's label reads "<label> = f N". A 6-DOF base draws ``wrench`` (all six rows of the
        reaction, N and N m) as a force and a moment arrow instead.
        """
        if self.wrench is not None:
            self.wrench.set(wrench, label, self.show_force)
            return
        if f == self._force and self.force.visible == self.show_force:
            return
        self._force = f
        st = self.style
        length = float(np.clip(f * st.force_scale, -st.force_arrow_max, st.force_arrow_max))
        show = self.show_force and abs(length) > 0.5 * self.force.head_length
        with self.server.atomic():
            self.force.visible = show
            self.force_label.visible = show
            if show:
                tip = self._force_origin + length * self._force_axis
                self.force.points = np.stack([self._force_origin, tip])[None]
                self.force_label.position = tip
                self.force_label.text = f"{label} = {f:.3g} N"

    # -- overlays ------------------------------------------------------------------------------
    def set_path_family(
        self, paths: Sequence[ReactionlessPath] | Sequence[np.ndarray], current_index: int | None
    ) -> None:
        """Draw all paths (base-frame end-effector curves) as one line-segment node; highlight one."""
        curves = [p.ee if isinstance(p, ReactionlessPath) else np.asarray(p) for p in paths]
        if current_index is not None and not 0 <= current_index < len(curves):
            raise IndexError(f"current_index {current_index} is not one of the {len(curves)} paths")
        segs, colours, owners = path_family_segments(
            curves, current_index, self.style.path_points, PATH_COLOUR, PATH_HIGHLIGHT, self.style.path_tolerance
        )
        self._path_owners, self.current_path = owners, current_index
        with self.server.atomic():
            if len(segs):
                self.paths.points = segs
                self.paths.colors = colours
            self.paths.visible = bool(len(segs))

    def set_current_path(self, current_index: int | None) -> None:
        """Re-colour the drawn family only (cheap); the current path is not moved to the top."""
        if current_index == self.current_path or not len(self._path_owners):
            return
        self.current_path = current_index
        self.paths.colors = path_colours(self._path_owners, current_index, PATH_COLOUR, PATH_HIGHLIGHT)

    def set_reachable_set(self, points: np.ndarray | None) -> None:
        """Base-frame end-effector points (N, 3) reachable without reaction (the 3R), or None to hide."""
        if points is None or len(points) == 0:
            self.reachable.visible = False
            return
        with self.server.atomic():
            self.reachable.points = np.asarray(points, dtype=np.float32)
            self.reachable.colors = np.array(REACH_COLOUR, dtype=np.uint8)
            self.reachable.visible = self.show_reach

    def set_target(self, position: np.ndarray | None) -> None:
        """End-effector target marker at a base-frame position (m), or None to hide it."""
        if position is None:
            self.target.visible = False
            return
        with self.server.atomic():
            self.target.position = np.asarray(position, dtype=float) + self._lift
            self.target.visible = True

    def clear_trail(self) -> None:
        """Forget the end-effector trail (after a reset or a jump to a new configuration)."""
        self.trail.clear()
        self.trail_node.visible = False

    # -- camera --------------------------------------------------------------------------------
    def set_initial_camera(self, clients: bool = True) -> None:
        """The framed view for new clients (viser's Reset View); ``clients`` also frames connected ones."""
        pose = self.camera_pose()
        cam = self.server.initial_camera
        cam.position = pose.position
        cam.look_at = pose.look_at
        cam.near = 0.005 * float(np.linalg.norm(pose.position - pose.look_at))
        if clients:
            for client in self.server.get_clients().values():
                self.frame_client(client)

    def camera_pose(
        self, fov: float = DEFAULT_FOV, aspect: float = DEFAULT_ASPECT, narrow: bool = False, top: float = 1.0
    ) -> CameraPose:
        """Where a camera of this field of view and aspect sees the robot framed (framing.py), with the
        points of :meth:`frame_also`; ``narrow``: a phone's page (the robot above viser's sheet); ``top``: the
        NDC height the framed points stay under on a wide page."""
        direction = np.subtract(self.style.camera_position, self.style.camera_look_at)
        points = self.framed if self.also_framed is None else np.vstack([self.framed, self.also_framed])
        return frame_points(points, direction, fov, aspect, band=NARROW_BAND if narrow else (-1.0, top))

    def frame_also(self, points: np.ndarray | None) -> None:
        """Frame the world ``points`` (N, 3), m, with the robot from now on (None: the robot alone), and
        frame every connected camera so."""
        self.also_framed = None if points is None else np.asarray(points, dtype=float).reshape(-1, 3)
        self.set_initial_camera(clients=True)

    def frame_client(self, client: viser.ClientHandle) -> None:
        """Point ``client``'s camera at the robot, framed for its page's size."""
        cam = client.camera
        width, height = cam.image_width, cam.image_height
        aspect = width / height if width > 0 and height > 0 else DEFAULT_ASPECT
        narrow = is_narrow(width, height)
        # the map's top and title below the floating panel (the robot alone may reach under it); a fraction of
        # the view, not the panel's px: a page's reported size changes with its drawing density, its framing not
        top = MAP_FRAMED_TOP if self.also_framed is not None and not narrow else 1.0
        pose = self.camera_pose(cam.fov, aspect, narrow, top)
        with client.atomic():
            cam.up_direction = (0.0, 0.0, 1.0)
            cam.position = pose.position  # (viser moves look_at with the position: it is set after)
            cam.look_at = pose.look_at
        self.framed_pages[client.client_id] = (
            (width, height),
            np.asarray(pose.position, dtype=float),
            time.monotonic(),
        )

    def follow_page_size(self, client: viser.ClientHandle) -> None:
        """On a page's camera message: frame it if :meth:`needs_framing` says so."""
        if self.needs_framing(client):
            self.frame_client(client)

    def needs_framing(self, client: viser.ClientHandle) -> bool:
        """Whether the page's last camera message asks for a framing: it never was framed; or its canvas
        changed size (beyond :func:`framing_holds`) while its view is still the one framed (nobody moved it) or
        the page is still settling from the last framing (a resize comes as several sizes, while the view may
        still glide), or it turned narrow or wide (a phone's panel sheet then covers or leaves the scene's lower
        part, where the arm would hide). A view the user moved stays."""
        cam = client.camera
        width, height = cam.image_width, cam.image_height
        if width <= 0 or height <= 0:
            return False
        last = self.framed_pages.get(client.client_id)
        if last is None:
            return True
        (w0, h0), position, when = last
        if framing_holds((w0, h0), (width, height)):
            return False
        turned = is_narrow(w0, h0) != is_narrow(width, height)
        distance = float(np.linalg.norm(np.subtract(cam.position, cam.look_at)))
        untouched = bool(np.allclose(cam.position, position, atol=1e-4 * max(distance, 1e-3)))
        return turned or untouched or time.monotonic() - when < REFRAME_SETTLE_S

    # -- internals -----------------------------------------------------------------------------
    def _trail_point(self) -> np.ndarray:
        ee = self.robot.ee_position(self._trail_lift)  # world, m
        if not self.trail_in_base:
            return ee
        base = self.robot.base_placement()
        return base.rotation.T @ (ee - base.translation)

    def _draw_trail(self) -> None:
        pts = self.trail.points()
        if len(pts) < 2:
            return
        self.trail_node.points = polyline_segments(pts)
        self.trail_node.visible = self.show_trail

    def attach_base_callout(self) -> None:
        """Tie the base's callout to the drawn base frame as last posed (its point: the style's, in that frame)."""
        base = self.robot.base_placement()
        self.base_callout.attach(base.rotation, base.translation, np.asarray(self.style.base_label, dtype=float))

    def _add_labels(self) -> Callout:
        """The names written in the scene, all callouts (placed off the arm, each other and the page's edges);
        returns the base's (its label writes the drawn factor). The fixed parts' points are in their root
        node's frame, which is the world's."""
        st = self.style
        label = self.callouts.add("base", base_label(1.0), parent=self.BASE)
        fixed: tuple[str, str, tuple[float, float, float]] | None = None
        if isinstance(st.base, DoubleBeamStyle):
            fixed = ("/beam", "clamp", (0.0, -0.05, 0.04))
        elif isinstance(st.base, BoomStyle):
            fixed = ("/boom", "clamp", (0.0, 0.0, 2.0 * st.base.radius))
        elif isinstance(st.base, CartSpringStyle):
            fixed = ("/spring", "spring k_b", (0.5 * (st.base.wall_x + st.base.attach[0]), 0.0, 0.05))
        if fixed is not None:
            root, text, point = fixed
            self.callouts.add(text.split()[0], text, parent=root).attach(np.eye(3), np.zeros(3), np.array(point))
        return label


def base_label(exaggeration: float) -> str:
    """The base's label: what it is, and how much larger than simulated its deflection is drawn."""
    return f"{BASE_VIBRATION.name} (drawn ×{exaggeration:g})"


def _make_base_drawing(
    server: viser.ViserServer, model: FsmsModel, style: DoubleBeamStyle | CartSpringStyle | BoomStyle | None
) -> DoubleBeamDrawing | CartSpringDrawing | BoomDrawing | None:
    if isinstance(style, BoomStyle):
        return BoomDrawing(server, model, style)
    if isinstance(style, DoubleBeamStyle):
        return DoubleBeamDrawing(server, model, style)
    if isinstance(style, CartSpringStyle):
        return CartSpringDrawing(server, model, style)
    return None
