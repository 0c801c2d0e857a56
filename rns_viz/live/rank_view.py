"""Rank deficiency of S H_bm as the workspace overlay draws it (Sec. III-B, the fourth case).

:func:`rank_overlay` finds the configurations where S H_bm loses rank (:mod:`rns_viz.rank`) and gives,
for each, the arm's pose as the polyline base-frame joint positions -> end effector, what the scene
draws. For one base row (TREP, the 3R) the set is a few isolated poses with every link along the
deflection axis; the drawn pose is that configuration, so each drawn point carries its sigma_min.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import numpy as np
import pinocchio as pin

from rns_viz.live.dual import is_dual
from rns_viz.model import FsmsModel
from rns_viz.rank import rank_deficient_configurations

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
    sigma_min: np.ndarray  # (K,) sigma_min(S H_bm) there, kg m
    scale: float  # the largest ||S H_bm|| over the search grid (the most coupled direction), kg m


def arm_pose(model: FsmsModel, theta: np.ndarray) -> np.ndarray:
    """Positions of the arm joints and the end effector in the base frame at theta, (n + 1, 3), m."""
    pm = model.pin_model
    data = pm.createData()
    pin.forwardKinematics(pm, data, model.q(theta))
    pin.updateFramePlacement(pm, data, model.ee_frame_id)
    base = data.oMi[model.base_joint_id]
    points = [data.oMi[j].translation for j in range(model.base_joint_id + 1, pm.njoints)]
    points.append(data.oMf[model.ee_frame_id].translation)
    return np.array([base.rotation.T @ (p - base.translation) for p in points])


@cache
def rank_overlay(key: str) -> RankOverlay | None:
    """The overlay of a single-arm model (by model key) with 2 or 3 joints (None otherwise: a search over a
    larger joint grid is too slow to run on demand)."""
    model = FsmsModel.from_key(key)
    if is_dual(model) or model.n not in SEEDS_PER_JOINT:
        return None
    loss = rank_deficient_configurations(model, points_per_joint=SEEDS_PER_JOINT[model.n])
    poses = np.array([arm_pose(model, t) for t in loss.theta]).reshape(-1, model.n + 1, 3)
    return RankOverlay(loss.theta, poses, loss.sigma_min, loss.scale)
