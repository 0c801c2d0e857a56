"""The shadow run drawn in 3-D: a translucent ghost of the arm and its base, posed from the shadow's q.

The shadow run (rns_viz.live.runs.run_pair) gets the operated run's inputs and kicks with vibration suppression
the other way; the ghost shows its state over the operated arm, so suppression on and off are compared
in the scene. Everything hangs under ``/ghost`` (world frame), which hides it as a whole.
"""

from __future__ import annotations

import numpy as np
import trimesh
import viser

from rns_viz.model import FsmsModel
from rns_viz.viz.scene.base_drawing import CartSpringDrawing, DoubleBeamDrawing
from rns_viz.viz.scene.boom_drawing import BoomDrawing
from rns_viz.viz.scene.robot import RobotMeshes
from rns_viz.viz.scene.style import BoomStyle, CartSpringStyle, DoubleBeamStyle, SceneStyle

# The plots' colours, paled (RGB 0-255): the ghost's run has suppression (or compensation) on, or off.
GHOST_ON_COLOUR = (90, 140, 235)  # pale blue (the plots' blue #1f6fd1)
GHOST_OFF_COLOUR = (235, 110, 90)  # pale red (the plots' red #e0503a)
GHOST_OPACITY = 0.35


class GhostMeshes(RobotMeshes):
    """The URDF visuals in one translucent colour (glTF meshes carry no opacity in viser)."""

    def _add_mesh(self, server: viser.ViserServer, name: str, mesh: trimesh.Trimesh) -> viser.SceneNodeHandle:
        return server.scene.add_mesh_simple(
            name,
            np.asarray(mesh.vertices, dtype=np.float32),
            np.asarray(mesh.faces, dtype=np.uint32),
            color=GHOST_OFF_COLOUR,  # the shadow of a run with suppression on, the default
            opacity=GHOST_OPACITY,
            cast_shadow=False,
            receive_shadow=False,
        )


class Ghost:
    """The shadow system: arm meshes, base drawing and the words of its callout; ``update(q_shadow, ...)`` per frame."""

    ROOT = "/ghost"
    BASE = "/ghost/base"

    def __init__(self, server: viser.ViserServer, model: FsmsModel, style: SceneStyle) -> None:
        self.server = server
        self.model = model
        self.robot = GhostMeshes(server, model, base_name=self.BASE, root=self.ROOT)
        root = server.scene.get_handle_by_name(self.ROOT)
        assert root is not None
        self.root = root
        self.base_drawing = _ghost_base(server, model, style.base)
        self.label_text = "ghost"  # what its callout says (drawn by the renderer's callouts, off the arm)
        self.q: np.ndarray | None = None  # the shadow's q as drawn (before exaggeration)
        self.exaggeration = float("nan")
        self.colour = GHOST_OFF_COLOUR
        self.root.visible = False

    def update(self, q: np.ndarray | None, exaggeration: float, label: str, on: bool = False) -> None:
        """Pose the ghost at the shadow's q = (x_b, theta) (base drawn x exaggeration); None hides it. ``on``:
        the shadow run has suppression (or compensation) on: drawn blue, else red, as its plot lines."""
        if q is None or not np.all(np.isfinite(q)):
            if self.root.visible:
                self.root.visible = False
            return
        if not self.root.visible:
            self.root.visible = True
        self.label_text = label
        self._paint(GHOST_ON_COLOUR if on else GHOST_OFF_COLOUR)
        if self.q is not None and np.array_equal(q, self.q) and exaggeration == self.exaggeration:
            return
        self.q, self.exaggeration = np.array(q, dtype=float), exaggeration
        q_draw = self.q.copy()
        q_draw[: self.model.m] *= exaggeration
        with self.server.atomic():
            self.robot.pose(q_draw)
            if isinstance(self.base_drawing, BoomDrawing):
                self.base_drawing.pose(self.robot.base_placement())
            elif self.base_drawing is not None:
                self.base_drawing.update(self.robot.base_placement().translation)

    def _paint(self, colour: tuple[int, int, int]) -> None:
        if colour == self.colour:
            return
        self.colour = colour
        with self.server.atomic():
            for mesh in self.robot.meshes:
                mesh.color = colour  # type: ignore[attr-defined]
            _paint_base(self.base_drawing, colour)

    def drawn_base_position(self) -> np.ndarray:
        """World position of the ghost's base node as last sent (m; exaggerated)."""
        return np.asarray(self.robot.base_node.position, dtype=float)


def _ghost_base(
    server: viser.ViserServer, model: FsmsModel, style: DoubleBeamStyle | CartSpringStyle | BoomStyle | None
) -> DoubleBeamDrawing | CartSpringDrawing | BoomDrawing | None:
    """The model's base drawing under /ghost, translucent, without its fixed parts (clamp, wall)."""
    drawing: DoubleBeamDrawing | CartSpringDrawing | BoomDrawing
    if isinstance(style, BoomStyle):
        drawing = BoomDrawing(server, model, style, root="/ghost/boom")
        _hide(server, "/ghost/boom/clamp")
    elif isinstance(style, DoubleBeamStyle):
        drawing = DoubleBeamDrawing(server, model, style, root="/ghost/beam")
        _hide(server, "/ghost/beam/clamp")
    elif isinstance(style, CartSpringStyle):
        drawing = CartSpringDrawing(server, model, style, root="/ghost/spring")
        _hide(server, "/ghost/spring/wall")
    else:
        return None
    if not isinstance(drawing, CartSpringDrawing):
        drawing.mesh.opacity = GHOST_OPACITY
    _paint_base(drawing, GHOST_OFF_COLOUR)
    return drawing


def _paint_base(
    drawing: DoubleBeamDrawing | CartSpringDrawing | BoomDrawing | None, colour: tuple[int, int, int]
) -> None:
    """The base drawing's surfaces and lines in ``colour``."""
    if isinstance(drawing, BoomDrawing):
        drawing.mesh.color = colour
        drawing.stripe.colors = _tinted(drawing.stripe.points, colour)
    elif isinstance(drawing, DoubleBeamDrawing):
        drawing.mesh.color = colour
        drawing.edges.colors = _tinted(drawing.edges.points, colour)
    elif isinstance(drawing, CartSpringDrawing):
        drawing.spring.colors = _tinted(drawing.spring.points, colour)


def _hide(server: viser.ViserServer, name: str) -> None:
    handle = server.scene.get_handle_by_name(name)
    if handle is not None:
        handle.visible = False


def _tinted(points: np.ndarray, colour: tuple[int, int, int]) -> np.ndarray:
    """Per-vertex colours of a line-segment node (N, 2, 3), all ``colour``."""
    return np.tile(np.array(colour, dtype=np.uint8), (*np.shape(points)[:2], 1))
