"""Rank deficiency of S H_bm, the fourth way a reaction null space exists (Sec. III-B).

Where S H_bm(theta) loses rank, joint velocities along its enlarged kernel give no coupling momentum
L = S H_bm theta' (Eq. 8), hence no reaction on the base, although outside these configurations
they would: motion there is reactionless because the arm's centre-of-mass motion is momentarily
orthogonal to the selected base directions. The paper does not rely on it: the set is thin (a
submanifold; for one base row, as TREP and the 3R have, the whole row must vanish, which happens
only at isolated configurations with every link along the deflection axis), so it limits the
reachable workspace, the reactionless property holds only to first order as the arm leaves it,
and the pseudoinverse of (9)-(10) is ill-conditioned nearby.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from rns_viz.model import FsmsModel
from rns_viz.rns import singularity_distance


@dataclass(frozen=True)
class RankLoss:
    """Configurations where S H_bm (its columns ``columns``) is rank deficient, and their images."""

    theta: np.ndarray  # (K, n) full joint configurations, rad, angles of ``columns`` in (-pi, pi]
    ee: np.ndarray  # (K, 3) end-effector positions in the base frame, m
    sigma_min: np.ndarray  # (K,) sigma_min(W S H_bm[:, columns]) there, kg m (rns.singularity_distance)
    scale: float  # largest sigma_max of W S H_bm[:, columns] on the search grid: the most coupled direction
    columns: np.ndarray  # indices into theta of the joints searched


def _coupling(model: FsmsModel, theta: np.ndarray, columns: np.ndarray) -> np.ndarray:
    """W S H_bm[:, columns]: the moment rows divided by the arm's reach (rns.singularity_distance), kg m."""
    H = model.coupling_matrix(model.q(theta))[:, columns]
    return H if model.coupling_weights is None else H * model.coupling_weights[:, None]


def _residual(model: FsmsModel, theta: np.ndarray, columns: np.ndarray, u: np.ndarray) -> np.ndarray:
    """u^T A(theta): its norm is sigma_min(A) when u is A's left singular vector of sigma_min."""
    return u @ _coupling(model, theta, columns)


def _newton(
    model: FsmsModel, theta: np.ndarray, columns: np.ndarray, tol: float, iterations: int = 40, eps: float = 1e-6
) -> tuple[np.ndarray, float]:
    """Gauss-Newton (minimum-norm steps) on sigma_min(A(theta)) = 0 from one seed; returns theta, sigma_min."""
    theta = theta.copy()
    sigma = np.inf
    for _ in range(iterations):
        U, s, _ = np.linalg.svd(_coupling(model, theta, columns))
        sigma = float(s[-1]) if len(s) == U.shape[0] else 0.0
        if sigma <= tol:
            break
        u = U[:, -1]
        f = _residual(model, theta, columns, u)
        jac = np.empty((f.size, columns.size))
        for j, c in enumerate(columns):  # central differences of u^T A along each searched joint
            step = np.zeros_like(theta)
            step[c] = eps
            jac[:, j] = (_residual(model, theta + step, columns, u) - _residual(model, theta - step, columns, u)) / (
                2 * eps
            )
        theta[columns] -= np.linalg.lstsq(jac, f, rcond=None)[0]
    return theta, sigma


def rank_deficient_configurations(
    model: FsmsModel,
    columns: Sequence[int] | None = None,
    points_per_joint: int = 12,
    tol: float = 1e-12,
) -> RankLoss:
    """Configurations where sigma_min(S H_bm) = 0, by Gauss-Newton from every node of a joint grid.

    ``columns``: the joints searched (default: every arm joint; e.g. a compensating arm's alone);
    the other joints stay at the default configuration. Seeds cover (-pi, pi] with
    ``points_per_joint`` nodes per joint; a point is kept when sigma_min <= tol * scale, with scale
    the largest sigma_max of S H_bm[:, columns] on the grid. Rank loss of an r x k matrix has
    codimension k - r + 1, so for one base row (TREP, the 3R) the points are isolated
    configurations; for more rows they sample curves or surfaces. See the module docstring for why
    motion there is reactionless and why the paper avoids relying on it.
    """
    cols = np.arange(model.n) if columns is None else np.asarray(columns, dtype=int)
    theta0 = model.spec.default_configuration
    nodes = np.linspace(-np.pi, np.pi, points_per_joint, endpoint=False) + np.pi / points_per_joint
    seeds = []
    scale = 0.0
    for combo in itertools.product(nodes, repeat=cols.size):
        theta = theta0.copy()
        theta[cols] = combo
        seeds.append(theta)
        scale = max(scale, float(np.linalg.norm(_coupling(model, theta, cols), 2)))
    found: dict[tuple[int, ...], tuple[np.ndarray, float]] = {}
    for seed in seeds:
        theta, sigma = _newton(model, seed, cols, tol * scale)
        if sigma > tol * scale:
            continue
        theta[cols] = np.angle(np.exp(1j * theta[cols]))  # wrap to (-pi, pi]
        theta[cols] = np.where(theta[cols] <= -np.pi + 1e-9, np.pi, theta[cols])
        key = tuple(np.round(theta[cols] * 1e6).astype(int))
        found.setdefault(key, (theta, sigma))
    thetas = np.array([t for t, _ in found.values()]).reshape(-1, model.n)
    sigmas = np.array([s for _, s in found.values()])
    ee = model.ee_positions(thetas) if len(thetas) else np.empty((0, 3))
    return RankLoss(thetas, ee, sigmas, scale, cols)


def kernel_coupling(model: FsmsModel, theta: np.ndarray, columns: Sequence[int] | None = None) -> tuple[float, float]:
    """``|S H_bm v|`` for a unit joint velocity v along the kernel of S H_bm[:, columns], and sigma_max there.

    The kernel direction is the right singular vector of the smallest singular value (any direction
    where the matrix vanishes). Rows weighted as :func:`rns_viz.rns.singularity_distance`: kg m per rad/s.
    """
    cols = np.arange(model.n) if columns is None else np.asarray(columns, dtype=int)
    A = _coupling(model, np.asarray(theta, dtype=float), cols)
    _, s, Vt = np.linalg.svd(A)
    return float(np.linalg.norm(A @ Vt[-1])), float(s[0])


def sigma_grid(
    model: FsmsModel, columns: Sequence[int], points_per_joint: int = 73, theta: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """sigma_min(S H_bm) on a grid of two joints over [-pi, pi] (others at ``theta``, default: the model's
    default configuration), for the joint-space inset.

    Returns the two axes (rad) and sigma_min(W S H_bm) (points_per_joint, points_per_joint), kg m
    (rns.singularity_distance); rank deficiency is its zero level.
    """
    cols = np.asarray(columns, dtype=int)
    if cols.size != 2:
        raise ValueError("sigma_grid draws two joints")
    axis = np.linspace(-np.pi, np.pi, points_per_joint)
    theta = (model.spec.default_configuration if theta is None else np.asarray(theta, dtype=float)).copy()
    field = np.empty((axis.size, axis.size))
    for i, a in enumerate(axis):
        for j, b in enumerate(axis):
            theta[cols] = (a, b)
            field[i, j] = singularity_distance(model.coupling_matrix(model.q(theta)), model.coupling_weights)
    return axis, axis.copy(), field
