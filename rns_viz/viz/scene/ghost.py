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

GHOST_COLOUR = (90, 140, 235)  # pale blue, RGB 0-255
GHOST_OPACITY = 0.35


class GhostMeshes(RobotMeshes):
    """The URDF visuals in one translucent colour (glTF meshes carry no opacity in viser)."""

    def _add_mesh(self, server: viser.ViserServer, name: str, mesh: trimesh.Trimesh) -> viser.SceneNodeHandle:
        return server.scene.add_mesh_simple(
            name,
            np.asarray(mesh.vertices, dtype=np.float32),
            np.asarray(mesh.faces, dtype=np.uint32),
            color=GHOST_COLOUR,
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
        self.root.visible = False

    def update(self, q: np.ndarray | None, exaggeration: float, label: str) -> None:
        """Pose the ghost at the shadow's q = (x_b, theta) (base drawn x exaggeration); None hides it."""
        if q is None or not np.all(np.isfinite(q)):
            if self.root.visible:
                self.root.visible = False
            return
        if not self.root.visible:
            self.root.visible = True
        self.label_text = label
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

    def drawn_base_position(self) -> np.ndarray:
        """World position of the ghost's base node as last sent (m; exaggerated)."""
        return np.asarray(self.robot.base_node.position, dtype=float)


def _ghost_base(
    server: viser.ViserServer, model: FsmsModel, style: DoubleBeamStyle | CartSpringStyle | BoomStyle | None
) -> DoubleBeamDrawing | CartSpringDrawing | BoomDrawing | None:
    """The model's base drawing under /ghost, translucent, without its fixed parts (clamp, wall)."""
    if isinstance(style, BoomStyle):
        boom = BoomDrawing(server, model, style, root="/ghost/boom")
        boom.mesh.color, boom.mesh.opacity = GHOST_COLOUR, GHOST_OPACITY
        boom.stripe.colors = _tinted(boom.stripe.points)
        _hide(server, "/ghost/boom/clamp")
        return boom
    if isinstance(style, DoubleBeamStyle):
        beam = DoubleBeamDrawing(server, model, style, root="/ghost/beam")
        beam.mesh.color, beam.mesh.opacity = GHOST_COLOUR, GHOST_OPACITY
        beam.edges.colors = _tinted(beam.edges.points)
        _hide(server, "/ghost/beam/clamp")
        return beam
    if isinstance(style, CartSpringStyle):
        spring = CartSpringDrawing(server, model, style, root="/ghost/spring")
        spring.spring.colors = _tinted(spring.spring.points)
        _hide(server, "/ghost/spring/wall")
        return spring
    return None


def _hide(server: viser.ViserServer, name: str) -> None:
    handle = server.scene.get_handle_by_name(name)
    if handle is not None:
        handle.visible = False


def _tinted(points: np.ndarray) -> np.ndarray:
    """Per-vertex colours of a line-segment node (N, 2, 3), all the ghost's colour."""
    return np.tile(np.array(GHOST_COLOUR, dtype=np.uint8), (*np.shape(points)[:2], 1))
