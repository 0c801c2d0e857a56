"""Where a planar target may go: the reactionless reachable set as a point cloud, and clamping to it."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rns_viz.model import FsmsModel
from rns_viz.paths import CouplingField, reactionless_reachable_set


@dataclass(frozen=True)
class ReachRegion:
    """End-effector points reachable without reaction from one configuration (base frame, m)."""

    points: np.ndarray  # (N, 3)
    thetas: np.ndarray  # (N, n) rad: the configurations that reach them
    radius: float  # m: a target within this distance of a sample counts as reachable
    level: np.ndarray  # (r,) coupling potential of the configuration it was explored from, kg m

    def distance(self, xy: np.ndarray) -> float:
        d = self.points[:, :2] - np.asarray(xy, dtype=float)[:2]
        return float(np.sqrt(np.min(np.einsum("ij,ij->i", d, d))))

    def clamp(self, xy: np.ndarray) -> tuple[np.ndarray, bool]:
        """The target itself if reachable, else the reachable point nearest it; and whether it was moved."""
        xy = np.asarray(xy, dtype=float)[:2]
        if self.distance(xy) <= self.radius:
            return xy.copy(), False
        d = self.points[:, :2] - xy
        nearest = self.points[int(np.argmin(np.einsum("ij,ij->i", d, d))), :2]
        lo, hi = 0.0, 1.0  # bisect along nearest -> target for the last point still inside
        for _ in range(20):
            mid = 0.5 * (lo + hi)
            if self.distance(nearest + mid * (xy - nearest)) <= self.radius:
                lo = mid
            else:
                hi = mid
        return nearest + lo * (xy - nearest), True


def build_reach_region(model: FsmsModel, theta: np.ndarray, spacing: float = 0.12) -> ReachRegion:
    """Explore the reachable set from ``theta`` and size the inside test by the sample spacing."""
    found = reactionless_reachable_set(model, theta, spacing=spacing)
    pts = found.ee
    if len(pts) < 2:
        radius = 1e-3
    else:
        sample = pts[:: max(1, len(pts) // 400), :2]
        d = np.sqrt(((sample[:, None, :] - pts[None, :, :2]) ** 2).sum(axis=2))
        d[d == 0.0] = np.inf
        radius = 1.5 * float(np.median(d.min(axis=1)))
    level = CouplingField(model).potentials(np.atleast_2d(theta))[0]
    return ReachRegion(pts, np.asarray(found.theta, dtype=float), radius, level)
