"""Where a target may go: the arm's reach, the reactionless reachable set as a point cloud, and clamping to it.

A translating base (the planar 3R) is explored on the level set of its coupling potential
(:func:`rns_viz.paths.reactionless_reachable_set`); a base that turns (boom7 with r <= 4) by integrating
the RNS distribution (:func:`rns_viz.paths.explore_rns`), with the Lie-bracket test of whether it is
involutive (:func:`rns_viz.integrability.bracket_rank`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rns_viz.integrability import bracket_rank
from rns_viz.model import FsmsModel
from rns_viz.paths import CouplingField, explore_rns, reactionless_reachable_set


def arm_reach(model: FsmsModel) -> float:
    """Arm reach (m): joint-to-joint distances plus the end-effector offset (FsmsModel.arm_reach)."""
    return model.arm_reach


@dataclass(frozen=True)
class ReachRegion:
    """End-effector points reachable without reaction from one configuration (base frame, m)."""

    points: np.ndarray  # (N, 3)
    thetas: np.ndarray  # (N, n) rad: the configurations that reach them
    radius: float  # m: a target within this distance of a sample counts as reachable
    level: np.ndarray  # (r,) coupling potential of the configuration it was explored from, kg m (nan: none)
    dims: int = 2  # the task's coordinates: (x, y) for a planar task, (x, y, z) in space
    note: str = ""  # the Lie-bracket test where it was explored from, in words (empty: not made)
    surface: bool = False  # fewer RNS directions than task coordinates: the set is a surface, targets snap to it

    def distance(self, xy: np.ndarray) -> float:
        """Distance (m) from a target to the nearest sample; within ``radius`` counts as reachable."""
        d = self.points[:, : self.dims] - np.asarray(xy, dtype=float)[: self.dims]
        return float(np.sqrt(np.min(np.einsum("ij,ij->i", d, d))))

    def clamp(self, xy: np.ndarray) -> tuple[np.ndarray, bool]:
        """The target itself if reachable, else the reachable point nearest it; and whether it was moved."""
        xy = np.asarray(xy, dtype=float)[: self.dims]
        if self.distance(xy) <= (SNAP_M if self.surface else self.radius):
            return xy.copy(), False
        d = self.points[:, : self.dims] - xy
        nearest = self.points[int(np.argmin(np.einsum("ij,ij->i", d, d))), : self.dims]
        if self.surface:  # a point off a surface is not reachable: its nearest sample, which is
            return nearest.copy(), True
        lo, hi = 0.0, 1.0  # bisect along nearest -> target for the last point still inside
        for _ in range(20):
            mid = 0.5 * (lo + hi)
            if self.distance(nearest + mid * (xy - nearest)) <= self.radius:
                lo = mid
            else:
                hi = mid
        return nearest + lo * (xy - nearest), True


SNAP_M = 1e-3  # m: on a reachable surface, a target this close to a sample is taken as it is
VOXELS_PER_REACH = 20  # a turning base's set: end-effector voxels of the arm's reach / 20 (5.4 cm for boom7)


def build_reach_region(model: FsmsModel, theta: np.ndarray, spacing: float = 0.12) -> ReachRegion:
    """Explore the reachable set from ``theta`` and size the inside test by the sample spacing."""
    if not model.base_is_translational:
        voxel = arm_reach(model) / VOXELS_PER_REACH
        found = explore_rns(model, theta, voxel)
        rank = bracket_rank(model.coupling_at, theta)
        nan = np.full(len(model.selected), np.nan)
        dims, rns_dim = len(model.task_rows), model.n - len(model.selected)
        return ReachRegion(found.points, found.thetas, voxel, nan, dims, rank.words(), rns_dim < dims)
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
