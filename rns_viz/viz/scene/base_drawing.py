"""The elastic base drawn around the URDF: TREP's bending double beam, the 3R's spring and wall.

Each drawing is built once and then moved by ``update(base_translation)``, where the argument is
the world position of the drawn (already exaggerated) base joint frame.
"""

from __future__ import annotations

import numpy as np
import viser

from rns_viz.model import FsmsModel
from rns_viz.viz.scene.shapes import (
    beam_centrelines,
    plate_strip_faces,
    plate_strip_vertices,
    polyline_segments,
    zigzag,
)
from rns_viz.viz.scene.style import CartSpringStyle, DoubleBeamStyle

STEEL = (150, 156, 166)
DARK = (70, 72, 78)
SPRING = (200, 60, 50)


class DoubleBeamDrawing:
    """Two plates clamped at the base joint's parent origin, guided at the base joint (TREP).

    The beam runs from the clamp to the base joint's rest position; its tip moves with the base
    joint, and every station s is offset by x_b (3 (s/L)^2 - 2 (s/L)^3) along the base axis.
    """

    def __init__(
        self, server: viser.ViserServer, model: FsmsModel, style: DoubleBeamStyle, root: str = "/beam"
    ) -> None:
        if model.m != 1 or not model.base_is_translational:
            raise ValueError(f"{model.name}: the double-beam drawing needs one prismatic base joint")
        pm = model.pin_model
        rest = pm.jointPlacements[1]  # base joint frame in the clamp (world) frame at x_b = 0
        self.tip_rest = rest.translation.copy()
        self.length = float(np.linalg.norm(self.tip_rest))
        self.along = self.tip_rest / self.length
        self.lateral = rest.rotation @ model.base_axes()[0]
        self.up = np.cross(self.lateral, self.along)
        self.style = style
        self.offset = np.asarray(style.centre_offset, dtype=float)
        self.faces = plate_strip_faces(2, style.stations)
        # Every drawn point is rest + x_b * weight * lateral: precompute rest shapes and weights.
        self._rest_vertices = self.vertices(0.0)
        self._vertex_shift = self.vertices(1.0) - self._rest_vertices
        self._rest_edges = self.edge_segments(0.0)
        self._edge_shift = self.edge_segments(1.0) - self._rest_edges
        self.mesh = server.scene.add_mesh_simple(
            f"{root}/plates", self._rest_vertices, self.faces, color=STEEL, side="double", flat_shading=False
        )
        self.edges = server.scene.add_line_segments(
            f"{root}/edges", self._rest_edges, DARK, thickness=1.5, thickness_units="screen"
        )
        clamp_centre = self.offset - 0.5 * style.clamp_size[1] * self.along
        server.scene.add_box(f"{root}/clamp", color=DARK, dimensions=style.clamp_size, position=clamp_centre)
        self.x_b = 0.0

    def centrelines(self, x_b: float) -> np.ndarray:
        """(2, stations, 3) plate mid-height lines for a drawn tip deflection ``x_b`` (m)."""
        return beam_centrelines(
            self.offset, self.along, self.lateral, self.length, self.style.spacing, x_b, self.style.stations
        )

    def vertices(self, x_b: float) -> np.ndarray:
        """Plate mesh vertices for a drawn tip deflection ``x_b`` (m)."""
        return plate_strip_vertices(self.centrelines(x_b), self.up, self.style.height)

    def edge_segments(self, x_b: float) -> np.ndarray:
        """Top and bottom edges of both plates, so the bend reads clearly from any angle."""
        half = 0.5 * self.style.height * self.up
        lines = self.centrelines(x_b)
        return np.concatenate([polyline_segments(p + sign * half) for p in lines for sign in (-1.0, 1.0)])

    def update(self, base_translation: np.ndarray) -> None:
        """Bend the plates so their tip follows the drawn base position (world, m)."""
        x_b = float(self.lateral @ (base_translation - self.tip_rest))
        if x_b == self.x_b:
            return
        self.x_b = x_b
        self.mesh.vertices = self._rest_vertices + x_b * self._vertex_shift
        self.edges.points = self._rest_edges + x_b * self._edge_shift


class CartSpringDrawing:
    """A wall and a zig-zag spring from the wall to the cart (the 3R's translating base)."""

    def __init__(
        self, server: viser.ViserServer, model: FsmsModel, style: CartSpringStyle, root: str = "/spring"
    ) -> None:
        if model.m != 1 or not model.base_is_translational:
            raise ValueError(f"{model.name}: the cart-and-spring drawing needs one prismatic base joint")
        self.style = style
        self.attach = np.asarray(style.attach, dtype=float)
        rest = model.pin_model.jointPlacements[1].translation
        self.anchor = np.array([style.wall_x, rest[1] + self.attach[1], rest[2] + self.attach[2]])
        self.normal = np.array([0.0, 1.0, 0.0])
        self.spring = server.scene.add_line_segments(
            f"{root}/coil", self.segments(rest + self.attach), SPRING, thickness=0.025
        )
        wx, _, wz = style.wall_size
        wall_centre = (style.wall_x - 0.5 * wx, self.anchor[1], self.anchor[2] + 0.5 * wz - 0.15)
        server.scene.add_box(f"{root}/wall", color=DARK, dimensions=style.wall_size, position=wall_centre)
        self.end = rest + self.attach

    def segments(self, end: np.ndarray) -> np.ndarray:
        pts = zigzag(self.anchor, end, self.normal, self.style.coils, self.style.amplitude)
        return polyline_segments(pts)

    def update(self, base_translation: np.ndarray) -> None:
        end = base_translation + self.attach
        if np.array_equal(end, self.end):
            return
        self.end = end
        self.spring.points = self.segments(end)
