"""The boundary of the 3R's reactionless-reachable region, from its sample points.

The region's edge is where J-bar = J P_RNS loses rank: the fold curves, along which the hand cannot
move outward without moving the arm's centre of mass along the spring. From the samples alone: the
points go on a grid (60 cells across at least), a closing joins the samples and fills holes, and a
region cell with an empty neighbour is on the boundary.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage
from scipy.spatial import cKDTree

CELLS = 60  # grid cells across the region's longer side (at least)


def sample_spacing(xy: np.ndarray) -> float:
    """Median distance from (up to 400 of) the points to their nearest other point, m (coincident points
    count once; a k-d tree, not the 400 x N distance matrix, which took 0.2 s for the 3R's 6580 samples)."""
    sample = xy[:: max(1, len(xy) // 400)]
    distance, _ = cKDTree(np.unique(xy, axis=0)).query(sample, k=2)  # itself, then its nearest other point
    return float(np.median(distance[:, 1]))


def outline_points(points: np.ndarray, cell: float | None = None) -> np.ndarray:
    """Centres of the boundary cells of the region covered by ``points`` (N, 2|3), as (K, 3) at z = 0."""
    xy = np.asarray(points, dtype=float)[:, :2]
    if len(xy) < 3:
        return np.zeros((0, 3))
    extent = float(np.ptp(xy, axis=0).max())
    h = cell if cell is not None else max(3.0 * sample_spacing(xy), extent / CELLS)
    if not np.isfinite(h) or h <= 0.0:
        return np.zeros((0, 3))
    lo = xy.min(axis=0) - 3 * h
    ij = np.floor((xy - lo) / h).astype(int)
    occ = np.zeros(tuple(ij.max(axis=0) + 4), dtype=bool)
    occ[ij[:, 0], ij[:, 1]] = True
    # Closing (dilate, then erode) joins samples a cell apart; holes inside the region are filled.
    region = ndimage.binary_fill_holes(ndimage.binary_closing(occ, iterations=2))
    edge = region & ~ndimage.binary_erosion(region)
    centres = lo + (np.argwhere(edge) + 0.5) * h
    return np.column_stack([centres, np.zeros(len(centres))])
