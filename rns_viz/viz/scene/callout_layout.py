"""Where a callout's words go on a page: beside the point they name, off the arm, inside the view.

A callout is a label tied by a leader line to a point P (the target handle's "drag me", the ghost's name).
Drawn at P, a label covers what it names. Here its box is moved, in the page's own pixels, to the nearest
place around P where it covers no link of either arm (each link's box, projected and filled on a coarse
grid of cells), no other callout and nothing else marked taken, and stays inside the canvas. Pure geometry
on numpy; the page's camera as viser reports it (OpenCV axes: x right, y down, z forward).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

CELL_PX = 8  # the grid's cell: a link's filled hull is grown by half a cell's diagonal, so none slips between
CHAR_PX = 7.4  # px per character of a label's text, and its box's padding and height (viser's labels at
PAD_PX = 12.0  # font_screen_scale 1, as measured on rendered pages; over-estimated a little on purpose)
HEIGHT_PX = 22.0
EDGE_PX = 4.0  # a box keeps this far inside the canvas ...
GAP_PX = 4.0  # ... and this far from a label placed before it
DISTANCES_PX = (10.0, 22.0, 38.0, 58.0, 84.0, 116.0, 156.0, 204.0, 260.0)  # tried around P, nearest first
# (direction on the page, the label anchor that puts the box on that side of its point)
SIDES: tuple[tuple[tuple[float, float], str], ...] = (
    ((1.0, -1.0), "bottom-left"),
    ((1.0, 0.0), "center-left"),
    ((1.0, 1.0), "top-left"),
    ((0.0, 1.0), "top-center"),
    ((-1.0, 1.0), "top-right"),
    ((-1.0, 0.0), "center-right"),
    ((-1.0, -1.0), "bottom-right"),
    ((0.0, -1.0), "bottom-center"),
)


@dataclass(frozen=True)
class PageCamera:
    """A page's camera: pixel = focal * (x, y) / z + centre, in the camera's axes (x right, y down, z ahead)."""

    position: np.ndarray  # (3,) m, world
    rotation: np.ndarray  # (3, 3) world from camera
    fov: float  # rad, vertical
    width: int  # px, the canvas
    height: int
    shown: tuple[float, float] | None = None  # px: the rows not under a panel (a phone's sheet); None: all
    covered: tuple[float, float, float, float] | None = None  # px: a box a floating panel covers (x0, y0, x1, y1)

    @cached_property  # (frozen: a page's camera does not change; read for every candidate place)
    def focal(self) -> float:
        return 0.5 * self.height / math.tan(0.5 * self.fov)

    def project(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """World points (..., 3) to canvas pixels (..., 2) and depths (...,) m; nan pixels behind the camera."""
        pts = np.asarray(points, dtype=float)
        cam = (pts - self.position) @ self.rotation  # rows: R^T (p - c)
        depth = cam[..., 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            z = np.where(depth > 1e-6, depth, np.nan)
            px = np.stack([cam[..., 0] / z, cam[..., 1] / z], axis=-1) * self.focal
        return px + np.array([0.5 * self.width, 0.5 * self.height]), depth

    def unproject(self, pixel: np.ndarray, depth: float) -> np.ndarray:
        """The world point at ``depth`` m ahead of the camera that the page draws at ``pixel``."""
        xy = (np.asarray(pixel, dtype=float) - np.array([0.5 * self.width, 0.5 * self.height])) * depth / self.focal
        return self.position + self.rotation @ np.array([xy[0], xy[1], depth])


LINE_PX = 16.0  # px each further line of a label adds (viser's labels break lines at newlines)


def text_size(text: str) -> tuple[float, float]:
    """A label's box on the page (width, height), px: its longest line's width, its lines' height."""
    lines = text.split("\n")
    return CHAR_PX * max(len(line) for line in lines) + PAD_PX, HEIGHT_PX + LINE_PX * (len(lines) - 1)


def box_at(point: np.ndarray, anchor: str, size: tuple[float, float]) -> np.ndarray:
    """(x0, y0, x1, y1) px of a label drawn at ``point`` with viser's ``anchor`` (which of its box's points
    sits there: 'bottom-left' puts the box above and right of it)."""
    w, h = size
    vertical, horizontal = anchor.split("-")
    x0 = float(point[0]) - {"left": 0.0, "center": 0.5 * w, "right": w}[horizontal]
    y0 = float(point[1]) - {"top": 0.0, "center": 0.5 * h, "bottom": h}[vertical]
    return np.array([x0, y0, x0 + w, y0 + h])


def convex_hull(points: np.ndarray) -> np.ndarray:
    """The convex hull (k, 2) of 2-D points, counter-clockwise in a y-up sense (Andrew's monotone chain)."""
    pts = sorted({(float(x), float(y)) for x, y in points})
    if len(pts) <= 2:
        return np.array(pts, dtype=float).reshape(-1, 2)

    def half(seq: list[tuple[float, float]]) -> list[tuple[float, float]]:
        out: list[tuple[float, float]] = []
        for p in seq:
            while len(out) >= 2 and _cross(out[-2], out[-1], p) <= 0:
                out.pop()
            out.append(p)
        return out

    lower, upper = half(pts), half(pts[::-1])
    return np.array(lower[:-1] + upper[:-1], dtype=float)


def _cross(o: tuple[float, float], a: tuple[float, float], b: tuple[float, float]) -> float:
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


class Occupancy:
    """Which cells of a page are taken (an arm's links, placed labels); a box is free if it covers none."""

    def __init__(self, width: int, height: int, shown: tuple[float, float] | None = None) -> None:
        self.width, self.height = width, height
        self.top, self.bottom = shown if shown is not None else (0.0, float(height))
        self.cells = np.zeros((max(1, math.ceil(height / CELL_PX)), max(1, math.ceil(width / CELL_PX))), dtype=bool)
        self._sums: np.ndarray | None = None  # the taken cells' summed-area table, built at the first count

    def add_solid(self, corners_px: np.ndarray) -> None:
        """Take the cells under the convex hull of one solid's projected corners (k, 2) (nan: behind the page)."""
        pts = corners_px[np.all(np.isfinite(corners_px), axis=1)]
        if len(pts) == 0:
            return
        hull = convex_hull(pts)
        rows, cols = self.cells.shape
        lo = np.clip(np.floor(hull.min(axis=0) / CELL_PX).astype(int) - 1, 0, [cols, rows])
        hi = np.clip(np.ceil(hull.max(axis=0) / CELL_PX).astype(int) + 1, 0, [cols, rows])
        if np.any(hi <= lo):
            return
        cx = (np.arange(lo[0], hi[0]) + 0.5) * CELL_PX
        cy = (np.arange(lo[1], hi[1]) + 0.5) * CELL_PX
        X, Y = np.meshgrid(cx, cy)
        grow = CELL_PX / math.sqrt(2.0)  # a cell whose centre is this near the hull touches it
        if len(hull) < 3:  # a point or a segment seen edge-on: the cells near it
            a, b = hull[0], hull[-1]
            inside = _segment_distance(X, Y, a, b) <= grow
        else:
            inside = np.ones_like(X, dtype=bool)
            for a, b in zip(hull, np.roll(hull, -1, axis=0), strict=True):
                edge = b - a
                length = float(np.hypot(*edge)) or 1.0
                inside &= (edge[0] * (Y - a[1]) - edge[1] * (X - a[0])) / length >= -grow
        self.cells[lo[1] : hi[1], lo[0] : hi[0]] |= inside
        self._sums = None

    def add_box(self, box: np.ndarray, grow: float = 0.0) -> None:
        i0, j0, i1, j1 = self._index(np.asarray(box, dtype=float) + np.array([-grow, -grow, grow, grow]))
        self.cells[j0:j1, i0:i1] = True
        self._sums = None

    def taken(self, box: np.ndarray) -> int:
        """How many taken cells the box (x0, y0, x1, y1) px covers."""
        i0, j0, i1, j1 = self._index(box)
        if i1 <= i0 or j1 <= j0:
            return 0
        if self._sums is None:  # a layout counts hundreds of boxes between two additions
            self._sums = np.zeros((self.cells.shape[0] + 1, self.cells.shape[1] + 1), dtype=np.int64)
            self._sums[1:, 1:] = self.cells.cumsum(axis=0).cumsum(axis=1)
        t = self._sums
        return int(t[j1, i1] - t[j0, i1] - t[j1, i0] + t[j0, i0])

    def inside(self, box: np.ndarray) -> bool:
        x0, y0, x1, y1 = box.tolist()  # (Python floats: compared many times per layout)
        return bool(
            x0 >= EDGE_PX and y0 >= self.top + EDGE_PX and x1 <= self.width - EDGE_PX and y1 <= self.bottom - EDGE_PX
        )

    def _index(self, box: np.ndarray) -> tuple[int, int, int, int]:
        rows, cols = self.cells.shape
        x0, y0, x1, y1 = (float(v) / CELL_PX for v in box)
        return (
            min(max(math.floor(x0), 0), cols),
            min(max(math.floor(y0), 0), rows),
            min(max(math.ceil(x1), 0), cols),
            min(max(math.ceil(y1), 0), rows),
        )


def _segment_distance(X: np.ndarray, Y: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    d = b - a
    t = np.clip(((X - a[0]) * d[0] + (Y - a[1]) * d[1]) / max(float(d @ d), 1e-12), 0.0, 1.0)
    return np.hypot(X - a[0] - t * d[0], Y - a[1] - t * d[1])


@dataclass(frozen=True)
class Placement:
    """A label's place: its anchor point ``offset`` px from the named point on the primary page, and viser's anchor."""

    offset: tuple[float, float]
    anchor: str


def candidates(away: np.ndarray | None) -> list[Placement]:
    """Every place tried, nearest first; at one distance the sides facing ``away`` (a page direction) first."""
    sides = list(SIDES)
    if away is not None and np.all(np.isfinite(away)) and np.any(away):
        sides.sort(key=lambda side: -float(np.dot(np.array(side[0]) / np.hypot(*side[0]), away / np.hypot(*away))))
    out = []
    for distance in DISTANCES_PX:
        for (dx, dy), anchor in sides:
            scale = distance / math.hypot(dx, dy)
            out.append(Placement((dx * scale, dy * scale), anchor))
    return out


def cost(placement: Placement, point_px: np.ndarray, size: tuple[float, float], page: Occupancy) -> float:
    """0 where the label's box is free and inside the page; else the cells it covers (+ a penalty outside)."""
    box = box_at(point_px + np.asarray(placement.offset), placement.anchor, size)
    return page.taken(box) + (0.0 if page.inside(box) else 1e6)
