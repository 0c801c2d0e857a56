"""Rank deficiency of S H_bm as the workspace overlay draws it (Sec. III-B, the fourth case).

:func:`rank_overlay` finds the configurations where S H_bm loses rank (:mod:`rns_viz.rank`) and gives,
for each, the arm's pose as the polyline base-frame joint positions -> end effector
(:meth:`FsmsModel.arm_points`), what the scene draws. For one base row (TREP, the 3R) the set is a few
isolated poses with every link along the deflection axis; the drawn pose is that configuration, so each
drawn point carries its sigma_min.
:func:`rank_inset` gives the same configurations in a plane of two joints, over sigma_min(W S H_bm),
for the joint-space inset.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import numpy as np

from rns_viz.live.operator.kinds import operator_class
from rns_viz.model import FsmsModel
from rns_viz.rank import rank_deficient_configurations, sigma_grid

RANK_HINT = (
    "Rank loss of S H_bm: every link lies along the base's swing axis, so small joint motions move the "
    "arm's centre of mass across the swing and push the base not at all; the paper does not rely on it "
    "because these are isolated poses, reactionless only to first order, and the inverse of (9)-(10) "
    "blows up near them."
)
RANK_LABEL = "S H_bm loses rank: links along the swing axis (reactionless to first order only; not relied on)"
SEEDS_PER_JOINT = {2: 12, 3: 6}  # grid nodes per joint of the search (3 joints: 216 seeds, under 1 s)


@dataclass(frozen=True)
class RankOverlay:
    """Rank-deficient configurations of S H_bm and the poses drawn for them."""

    theta: np.ndarray  # (K, n) configurations, rad
    poses: np.ndarray  # (K, n + 1, 3) joint positions then the end effector, base frame, m
    sigma_min: np.ndarray  # (K,) sigma_min(W S H_bm) there, kg m
    scale: float  # the largest ||S H_bm|| over the search grid (the most coupled direction), kg m


def has_rank_inset(model: FsmsModel) -> bool:
    """The model has a rank-loss overlay and inset: one arm of 2 or 3 joints."""
    return not operator_class(model).compensates and model.n in SEEDS_PER_JOINT


@cache
def rank_overlay(key: str) -> RankOverlay | None:
    """The overlay of a single-arm model (by model key) with 2 or 3 joints (None otherwise: a search over a
    larger joint grid is too slow to run on demand)."""
    model = FsmsModel.from_key(key)
    if not has_rank_inset(model):
        return None
    loss = rank_deficient_configurations(model, points_per_joint=SEEDS_PER_JOINT[model.n])
    poses = np.array([model.arm_points(t) for t in loss.theta]).reshape(-1, model.n + 1, 3)
    return RankOverlay(loss.theta, poses, loss.sigma_min, loss.scale)


INSET_SLICE_STEP = np.deg2rad(5.0)  # rad: the 3R's slice follows theta_1 in steps of this
INSET_POINTS = {2: 61, 3: 41}  # grid nodes per axis of the sigma_min field (the 3R's is recomputed per slice)


@dataclass(frozen=True)
class RankInset:
    """The joint-space picture of rank loss: a plane of two joints, sigma_min(W S H_bm) over it, the rank-loss
    configurations and where they fall in the plane.

    TREP: the whole (theta_1, theta_2) plane, every rank-loss pose in it. The 3R: the (theta_2, theta_3)
    plane through the arm's theta_1 (rounded to INSET_SLICE_STEP): its eight poses have theta_1 = 0 or pi
    (every link along the swing axis), so a slice through them alone would hide where the arm is, and a
    (theta_1, .) slice would show at most two of them; the rank-loss poses of another theta_1 are drawn
    as rings at their (theta_2, theta_3), those in the slice filled.
    """

    columns: tuple[int, int]  # the joints on the axes (indices into theta)
    fixed: float | None  # rad: theta_1 of the 3R's slice, None for TREP
    axis: np.ndarray  # (P,) rad, both axes
    sigma: np.ndarray  # (P, P) sigma_min(W S H_bm) / scale, [i along columns[0], j along columns[1]]
    theta: np.ndarray  # (K, n) the rank-loss configurations drawn (each checked: sigma_min <= 1e-9 scale)
    in_plane: np.ndarray  # (K,) bool: the configuration lies in the drawn plane (filled), else a ring
    scale: float  # kg m: the most coupled ||S H_bm|| of the search


def inset_slice(key: str, theta: np.ndarray) -> float | None:
    """theta_1 of the slice drawn for the arm at ``theta`` (None: the model's whole plane)."""
    theta = np.asarray(theta, dtype=float)
    if theta.size != 3:
        return None
    return float(np.round(np.angle(np.exp(1j * theta[0])) / INSET_SLICE_STEP) * INSET_SLICE_STEP)


@cache
def rank_inset(key: str, fixed: float | None = None) -> RankInset | None:
    """The inset of a model (2 or 3 joints; None otherwise) for the slice ``fixed`` (see :func:`inset_slice`)."""
    overlay = rank_overlay(key)
    if overlay is None:
        return None
    model = FsmsModel.from_key(key)
    columns = (0, 1) if model.n == 2 else (1, 2)
    base = model.spec.default_configuration.copy()
    if fixed is not None:
        base[0] = fixed
    axis, _, sigma = sigma_grid(model, columns, INSET_POINTS[model.n], theta=base)
    wrapped = np.angle(np.exp(1j * (overlay.theta[:, 0] - base[0])))
    in_plane = np.ones(len(overlay.theta), bool) if model.n == 2 else np.abs(wrapped) < 0.5 * INSET_SLICE_STEP
    return RankInset(columns, fixed, axis, sigma / overlay.scale, overlay.theta, in_plane, overlay.scale)
