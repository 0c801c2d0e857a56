"""A flexible boom drawn bending and twisting in 3-D: a tube from its clamp to the base joint frame.

The boom is clamped at the world origin and its tip is the last base joint's frame (boom7: a tip
with three translations and three small rotations). The drawn centre line is the cubic (Hermite)
shape a clamped beam takes with the tip's lateral offset d and slope s, d (3 xi^2 - 2 xi^3) +
L s (xi^3 - xi^2), xi = s/L, plus the axial stretch and a twist growing linearly to the tip's. The
geometry functions are pure numpy (tested headless); :class:`BoomDrawing` sends them to viser.
"""

from __future__ import annotations

from functools import cache

import numpy as np
import pinocchio as pin
import viser

from rns_viz.model import FsmsModel
from rns_viz.viz.scene.shapes import polyline_segments
from rns_viz.viz.scene.style import BoomStyle

BOOM = (150, 156, 166)
STRIPE = (40, 40, 46)
CLAMP = (70, 72, 78)


def boom_frames(
    length: float, axes: np.ndarray, offset: np.ndarray, rotation: np.ndarray, stations: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Centre line (stations, 3), unit tangents and twisted normals of a clamped boom, world frame.

    ``axes``: rows a (along the boom), b1, b2 (lateral), orthonormal; ``offset``: tip displacement from
    rest (m); ``rotation``: tip rotation relative to rest (3x3, small).
    """
    a, b1, b2 = axes
    phi = pin.log3(rotation)  # rad, rotation vector of the tip
    slope = np.cross(phi, a)  # how the tip's tangent turned
    xi, bend, bend_d, turn, turn_d = _shape_functions(stations)
    line = np.outer(xi * (length + offset @ a), a)
    tangent = np.tile((length + offset @ a) * a, (stations, 1))
    for b in (b1, b2):
        line += np.outer(bend * (offset @ b) + length * turn * (slope @ b), b)
        tangent += np.outer(bend_d * (offset @ b) + length * turn_d * (slope @ b), b)
    tangent /= np.linalg.norm(tangent, axis=1)[:, None]
    twist = xi * (phi @ a)
    normal = np.cos(twist)[:, None] * b2 + np.sin(twist)[:, None] * np.cross(a, b2)
    normal -= np.einsum("ij,ij->i", normal, tangent)[:, None] * tangent
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    return line, tangent, normal


@cache
def _shape_functions(stations: int) -> tuple[np.ndarray, ...]:
    """xi and the Hermite shapes of :func:`boom_frames` (bend, turn and their xi-derivatives) at the
    stations: the same every frame (two booms drawn per frame with the ghost), so computed once."""
    xi = np.linspace(0.0, 1.0, stations)
    shapes = (xi, 3 * xi**2 - 2 * xi**3, 6 * xi - 6 * xi**2, xi**3 - xi**2, 3 * xi**2 - 2 * xi)
    for array in shapes:
        array.flags.writeable = False
    return shapes


@cache
def _ring(sides: int) -> tuple[np.ndarray, np.ndarray]:
    """cos and sin of the tube's ``sides`` angles, (1, sides, 1) each (computed once)."""
    angle = np.linspace(0.0, 2 * np.pi, sides, endpoint=False)
    cos, sin = np.cos(angle)[None, :, None], np.sin(angle)[None, :, None]
    cos.flags.writeable = sin.flags.writeable = False
    return cos, sin


def tube_vertices(line: np.ndarray, tangent: np.ndarray, normal: np.ndarray, radius: float, sides: int) -> np.ndarray:
    """Vertices (stations * sides, 3) of a tube of ``radius`` around the centre line."""
    cos, sin = _ring(sides)
    other = np.cross(tangent, normal)
    ring = cos * normal[:, None, :] + sin * other[:, None, :]
    return (line[:, None, :] + radius * ring).reshape(-1, 3)


def tube_faces(stations: int, sides: int) -> np.ndarray:
    """Triangles of :func:`tube_vertices`' side surface."""
    faces = []
    for k in range(stations - 1):
        for j in range(sides):
            a, b = k * sides + j, k * sides + (j + 1) % sides
            faces += [(a, b, a + sides), (b, b + sides, a + sides)]
    return np.array(faces, dtype=np.uint32)


class BoomDrawing:
    """The boom as a tube with a dark stripe along its top (so a twist shows) and a clamp block."""

    def __init__(self, server: viser.ViserServer, model: FsmsModel, style: BoomStyle, root: str = "/boom") -> None:
        rest = model.pin_model.jointPlacements[1]  # the tip at rest, in the clamp (world) frame
        self.tip_rest = rest.translation.copy()
        self.length = float(np.linalg.norm(self.tip_rest))
        if self.length <= 0.0:
            raise ValueError(f"{model.name}: the boom drawing needs the base joint away from the clamp")
        a = self.tip_rest / self.length
        helper = np.array([0.0, 0.0, 1.0]) if abs(a[2]) < 0.9 else np.array([0.0, 1.0, 0.0])
        b2 = helper - (helper @ a) * a
        b2 /= np.linalg.norm(b2)
        self.axes = np.stack([a, np.cross(b2, a), b2])
        self.rest_rotation = rest.rotation.copy()
        self.style = style
        self.faces = tube_faces(style.stations, style.sides)
        line, tangent, normal = boom_frames(self.length, self.axes, np.zeros(3), np.eye(3), style.stations)
        self.mesh = server.scene.add_mesh_simple(
            f"{root}/tube", tube_vertices(line, tangent, normal, style.radius, style.sides), self.faces, color=BOOM
        )
        self.stripe = server.scene.add_line_segments(
            f"{root}/stripe", self._stripe(line, normal), STRIPE, thickness=3.0, thickness_units="screen"
        )
        size = 3.0 * style.radius
        server.scene.add_box(f"{root}/clamp", color=CLAMP, dimensions=(size, size, size), position=-0.5 * size * a)
        self._last: tuple[tuple[float, ...], tuple[float, ...]] | None = None

    def _stripe(self, line: np.ndarray, normal: np.ndarray) -> np.ndarray:
        return polyline_segments(line + 1.05 * self.style.radius * normal)

    def pose(self, tip: pin.SE3) -> None:
        """Bend and twist the tube so its tip is the drawn base frame ``tip`` (world)."""
        key = (tuple(np.round(tip.translation, 7)), tuple(np.round(tip.rotation.ravel(), 7)))
        if key == self._last:
            return
        self._last = key
        offset = tip.translation - self.tip_rest
        rotation = tip.rotation @ self.rest_rotation.T
        line, tangent, normal = boom_frames(self.length, self.axes, offset, rotation, self.style.stations)
        self.mesh.vertices = tube_vertices(line, tangent, normal, self.style.radius, self.style.sides)
        self.stripe.points = self._stripe(line, normal)
