"""Readouts of the live session: distances to singularity, the null-space vector."""

from __future__ import annotations

from functools import cache

import numpy as np

from rns_viz.live.operator.dual_arm import compensator_sigmas
from rns_viz.live.operator.kinds import operator_class
from rns_viz.live.published.snapshot import Readouts
from rns_viz.model import FsmsModel
from rns_viz.rns import null_vector, rns_projector, singularity_distance, truncated_inverse


def _sigmas(model: FsmsModel, theta: np.ndarray) -> tuple[np.ndarray, float, float, int]:
    """S H_bm, its distance to singularity (kg m, rns.singularity_distance), the RNS-rank-th singular value
    of J-bar and the RNS dimension
    (dual arms: the compensator's sigma_min(W S H_bm,2) and the task arm's sigma_min(J_1) instead)."""
    if operator_class(model).compensates:
        return compensator_sigmas(model, theta)
    H = model.coupling_at(theta)
    rns_dim = model.n - H.shape[0]
    # the (n - r)-th singular value when the RNS has fewer directions than task rows: the truncation the
    # reference and Eq. (24) invert with (rns.truncated_inverse), so every readout of sigma(J-bar) agrees
    s_j = truncated_inverse(model.ee_jacobian(theta) @ rns_projector(H), rns_dim, 1e-12).sigma_min
    s_h = float(singularity_distance(H, model.coupling_weights))
    return H, s_h, s_j if rns_dim >= 1 else float("nan"), rns_dim


def null_motion(model: FsmsModel, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For a 1-D RNS at theta: n (kg m, Eq. 27) and the end-effector velocity J n it makes (3-vector,
    base frame, m/s per unit u-bar), the arrow the teaching view draws."""
    n = model.null_vector(theta)
    jn = np.zeros(3)
    jn[model.task_rows] = model.ee_jacobian(theta) @ n
    return n, jn


def coupling_sigma(model: FsmsModel, theta: np.ndarray) -> float:
    """The distance to singularity of S H_bm at theta, sigma_min(W S H_bm) in kg m: the arm's grip on the base."""
    return _sigmas(model, np.asarray(theta, dtype=float))[1]


@cache
def _warning_levels(name: str) -> tuple[float, float]:
    """10 % of both distances at the model's default configuration: below that the GUI warns."""
    model = FsmsModel.from_key(name)
    _, s_h, s_j, _ = _sigmas(model, model.spec.default_configuration)
    return 0.1 * s_h, 0.1 * s_j


def compute_readouts(
    model: FsmsModel, q: np.ndarray, L: float, ee_error: float, reaction: float, reaction_t: float = float("nan")
) -> Readouts:
    """Readouts at the configuration q = (x_b, theta); ``model`` is the loop's own instance."""
    H, s_h, s_j, rns_dim = _sigmas(model, q[model.m :])
    warn_h, warn_j = _warning_levels(model.name)
    return Readouts(
        sigma_hbm=s_h,
        sigma_jbar=s_j,
        warn_hbm=warn_h,
        warn_jbar=warn_j,
        n=tuple(float(v) for v in null_vector(H)) if rns_dim == 1 else None,
        rns_dim=rns_dim,
        base_dof=model.m,
        L=L,
        ee_error=ee_error,
        reaction=reaction,
        reaction_t=reaction_t,
        dual=operator_class(model).compensates,
    )
