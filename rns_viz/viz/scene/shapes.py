"""Pure-numpy drawing geometry for the scene: bent beams, springs, polylines, path colours.

Nothing here imports viser, so every shape is testable headless. Lengths in metres.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np


def guided_cantilever(s_over_L: np.ndarray) -> np.ndarray:
    """Lateral shape of a clamped-guided beam: u(s)/u(L) = 3 (s/L)^2 - 2 (s/L)^3.

    Zero offset and slope at the clamp (s = 0), unit offset and zero slope at the guided tip, so
    the tip block translates without turning, as the prismatic base joint says.
    """
    return s_over_L**2 * (3.0 - 2.0 * s_over_L)


def beam_centrelines(
    root: np.ndarray, along: np.ndarray, lateral: np.ndarray, length: float, spacing: float, x_b: float, stations: int
) -> np.ndarray:
    """Centre lines of two parallel plates (2, stations, 3), offset +-spacing/2 along ``lateral``.

    ``along`` and ``lateral`` are unit vectors; the tip moves by ``x_b`` along ``lateral``.
    """
    xi = np.linspace(0.0, 1.0, stations)
    line = root + np.outer(xi * length, along) + np.outer(x_b * guided_cantilever(xi), lateral)
    half = 0.5 * spacing * lateral
    return np.stack([line - half, line + half])


def plate_strip_vertices(centrelines: np.ndarray, up: np.ndarray, height: float) -> np.ndarray:
    """Vertices of vertical strips along each centre line: (plates * stations * 2, 3).

    Vertex order per plate: station 0 bottom, station 0 top, station 1 bottom, ...
    """
    half = 0.5 * height * up
    verts = np.stack([centrelines - half, centrelines + half], axis=2)  # (plates, stations, 2, 3)
    return verts.reshape(-1, 3)


def plate_strip_faces(plates: int, stations: int) -> np.ndarray:
    """Triangles (plates * (stations-1) * 2, 3) for :func:`plate_strip_vertices`."""
    faces = []
    for p in range(plates):
        base = 2 * stations * p
        for k in range(stations - 1):
            a, b, c, d = base + 2 * k, base + 2 * k + 1, base + 2 * k + 2, base + 2 * k + 3
            faces += [(a, c, b), (b, c, d)]
    return np.array(faces, dtype=np.uint32)


def zigzag(start: np.ndarray, end: np.ndarray, normal: np.ndarray, coils: int, amplitude: float) -> np.ndarray:
    """Points (2*coils + 3, 3) of a zig-zag spring from ``start`` to ``end`` swinging along ``normal``.

    Short straight leads at both ends; the zig-zag fills the middle 80 %.
    """
    t = np.concatenate([[0.0], np.linspace(0.1, 0.9, 2 * coils + 1), [1.0]])
    swing = np.zeros_like(t)
    swing[2:-2] = np.where(np.arange(2 * coils - 1) % 2 == 0, amplitude, -amplitude)
    return start + np.outer(t, end - start) + np.outer(swing, normal)


def polyline_segments(points: np.ndarray) -> np.ndarray:
    """Consecutive points (k, 3) as segments (k-1, 2, 3)."""
    return np.stack([points[:-1], points[1:]], axis=1)


def thin(points: np.ndarray, max_points: int) -> np.ndarray:
    """At most ``max_points`` of a polyline, evenly spaced by index, keeping both ends."""
    if len(points) <= max_points:
        return points
    idx = np.unique(np.round(np.linspace(0, len(points) - 1, max_points)).astype(int))
    return points[idx]


def simplify(points: np.ndarray, tolerance: float) -> np.ndarray:
    """The polyline's points that keep it within ``tolerance`` (m) of the original (Ramer-Douglas-Peucker).

    Both ends are kept; every dropped point lies within ``tolerance`` of the chord that replaces it.
    With fewer than 3 points or ``tolerance`` <= 0 the polyline is returned as given.
    A browser without a GPU draws a line segment by segment, so fewer segments is a faster frame.
    """
    n = len(points)
    if n < 3 or tolerance <= 0.0:  # a tolerance of 0 keeps every point, even collinear ones
        return points
    keep = np.zeros(n, dtype=bool)
    keep[[0, -1]] = True
    spans = [(0, n - 1)]
    while spans:
        first, last = spans.pop()
        if last - first < 2:
            continue
        chord = points[last] - points[first]
        offsets = points[first + 1 : last] - points[first]
        length_sq = float(chord @ chord)
        if length_sq > 0.0:
            along = np.clip(offsets @ chord / length_sq, 0.0, 1.0)
            offsets = offsets - np.outer(along, chord)
        distance = np.linalg.norm(offsets, axis=1)
        farthest = int(np.argmax(distance))
        if distance[farthest] > tolerance:
            split = first + 1 + farthest
            keep[split] = True
            spans += [(first, split), (split, last)]
    return points[keep]


def path_family_segments(
    polylines: Sequence[np.ndarray],
    current: int | None,
    max_points: int,
    colour: tuple[float, float, float],
    highlight: tuple[float, float, float],
    tolerance: float = 0.0,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """All polylines as one segment array, with colours and each segment's polyline index.

    Each polyline is thinned to ``max_points`` and then simplified to within ``tolerance`` (m).
    Returns (segments (N, 2, 3), colours (N, 2, 3) in [0, 1], owner (N,)). The current polyline
    is moved last so it draws over the others where they cross.
    """
    order = [i for i in range(len(polylines)) if i != current] + ([current] if current is not None else [])
    segs, owner = [], []
    for i in order:
        pts = simplify(thin(np.asarray(polylines[i], dtype=float), max_points), tolerance)
        if len(pts) >= 2:
            segs.append(polyline_segments(pts))
            owner.append(np.full(len(pts) - 1, i))
    if not segs:
        return np.zeros((0, 2, 3)), np.zeros((0, 2, 3)), np.zeros(0, dtype=int)
    segments = np.concatenate(segs)
    owners = np.concatenate(owner)
    return segments, path_colours(owners, current, colour, highlight), owners


def path_colours(
    owners: np.ndarray, current: int | None, colour: tuple[float, float, float], highlight: tuple[float, float, float]
) -> np.ndarray:
    """Per-segment colours (N, 2, 3): ``highlight`` for the current polyline, ``colour`` otherwise."""
    colours = np.empty((len(owners), 2, 3))
    colours[:] = colour
    if current is not None:
        colours[owners == current] = highlight
    return colours


class Trail:
    """A bounded polyline of recent points (m).

    A point closer than ``min_step`` to the last one is dropped; one farther than ``max_jump``
    (a teleport: reset, new preset) starts a new trail instead of drawing a chord.
    """

    def __init__(self, capacity: int, min_step: float, max_jump: float = np.inf) -> None:
        if capacity < 2:
            raise ValueError(f"a trail needs room for at least 2 points, got capacity={capacity}")
        self.capacity = capacity
        self.min_step = min_step
        self.max_jump = max_jump
        self._buf = np.zeros((capacity, 3))
        self._count = 0
        self._head = 0  # index the next point goes to

    def __len__(self) -> int:
        return self._count

    def clear(self) -> None:
        self._count = 0
        self._head = 0

    def push(self, point: np.ndarray) -> bool:
        """Append a point; True if it was kept (the trail changed)."""
        if self._count:
            step = float(np.linalg.norm(point - self._buf[self._head - 1]))
            if step < self.min_step:
                return False
            if step > self.max_jump:
                self.clear()
        self._buf[self._head] = point
        self._head = (self._head + 1) % self.capacity
        self._count = min(self._count + 1, self.capacity)
        return True

    def points(self) -> np.ndarray:
        """The kept points, oldest first, (len, 3)."""
        if self._count < self.capacity:
            return self._buf[: self._count].copy()
        return np.roll(self._buf, -self._head, axis=0)
