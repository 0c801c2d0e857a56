"""Reaction null-space maths (Sec. III): damped inverse, P_RNS, n, restricted Jacobian, Lie brackets.

Pure numpy on matrices that the model supplies; no pinocchio, no viser.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

# Default singularity-robust settings: below ``threshold`` (smallest singular value, in the units
# of the matrix) damping rises smoothly to ``max_damping`` (Nakamura & Hanafusa, 1986).
DEFAULT_THRESHOLD = 1e-3
DEFAULT_MAX_DAMPING = 1e-3


class DampedInverse(NamedTuple):
    """A singularity-robust right inverse A^T (A A^T + lambda^2 E)^-1 and how close A is to singular.

    A named tuple rather than a dataclass: it is built at every control step.
    """

    inverse: np.ndarray  # (cols, rows)
    sigma_min: float  # smallest singular value of A: the distance to singularity
    damping: float  # lambda actually used (0 away from singularities)


def damped_pinv(
    A: np.ndarray, threshold: float = DEFAULT_THRESHOLD, max_damping: float = DEFAULT_MAX_DAMPING
) -> DampedInverse:
    """Right pseudoinverse of a wide matrix, damped near rank loss so it always stays finite.

    lambda^2 = (1 - (sigma_min/threshold)^2) max_damping^2 when sigma_min < threshold, else 0.
    """
    A = np.atleast_2d(np.asarray(A, dtype=float))
    rows = A.shape[0]
    if rows == 1:  # closed form for a single row (the 1-DOF base): ~20x cheaper than an SVD
        a = A[0]
        inverse, sigma, lam2 = damped_row_inverse(a, threshold, max_damping)
        return DampedInverse(inverse[:, None], sigma, math.sqrt(lam2))
    sigma = float(np.linalg.svd(A, compute_uv=False)[-1])
    lam2 = damping_squared(sigma, threshold, max_damping)
    inverse = A.T @ np.linalg.solve(A @ A.T + lam2 * np.eye(rows), np.eye(rows))
    return DampedInverse(inverse, sigma, math.sqrt(lam2))


def damped_row_inverse(a: np.ndarray, threshold: float, max_damping: float) -> tuple[np.ndarray, float, float]:
    """The damped inverse of one row a, as the column a / (|a|^2 + lambda^2), with sigma = |a| and lambda^2.

    Plain floats and two numpy calls: this runs at every control step of a 1-DOF base.
    """
    sigma2 = float(a.dot(a))
    sigma = math.sqrt(sigma2)
    lam2 = damping_squared(sigma, threshold, max_damping)
    return a / (sigma2 + lam2), sigma, lam2


def damping_squared(sigma: float, threshold: float, max_damping: float) -> float:
    """lambda^2 of the damped inverse for smallest singular value sigma (0 above ``threshold``)."""
    if sigma >= threshold:
        return 0.0
    return (1.0 - (sigma / threshold) ** 2) * max_damping**2


def rns_projector(H_bm: np.ndarray, rank_tol: float = 1e-12) -> np.ndarray:
    """P_RNS = E - H_bm^+ H_bm, the orthogonal projector onto the reaction null space (Eq. 9).

    Built from the SVD's null-space basis, so it is exactly symmetric and idempotent.
    """
    H = np.atleast_2d(np.asarray(H_bm, dtype=float))
    _, s, Vt = np.linalg.svd(H)
    rank = int(np.sum(s > rank_tol * max(1.0, s[0] if s.size else 0.0)))
    range_basis = Vt[:rank]
    return np.eye(H.shape[1]) - range_basis.T @ range_basis


def null_vector(H_bm: np.ndarray) -> np.ndarray:
    """n for a 1-D RNS (n = m + 1): the generalised cross product of the rows of H_bm.

    n_i = (-1)^i det(H_bm without column i). For m = 1 this is Eq. (27), n = (h_2, -h_1).
    It is smooth, has the magnitude of the rows' volume, and vanishes where H_bm loses rank.
    """
    H = np.atleast_2d(np.asarray(H_bm, dtype=float))
    rows, cols = H.shape
    if cols != rows + 1:
        raise ValueError(f"null_vector needs an m x (m+1) matrix for a 1-D RNS, got {H.shape}")
    if rows == 1:
        return np.array([H[0, 1], -H[0, 0]])
    return np.array([(-1) ** i * np.linalg.det(np.delete(H, i, axis=1)) for i in range(cols)])


def restricted_jacobian(J: np.ndarray, P_rns: np.ndarray) -> np.ndarray:
    """J-bar = J P_RNS, the restricted Jacobian of Eq. (22)."""
    return J @ P_rns


@dataclass(frozen=True)
class Integrability:
    """Result of the Frobenius test: is the RNS distribution involutive at the sampled points?"""

    integrable: bool
    max_residual: float  # largest |(E - P) [X_i, X_j]| / (|X_i| |X_j|) over samples and pairs
    samples: int
    rns_dim: int


def lie_bracket(
    X: Callable[[np.ndarray], np.ndarray], Y: Callable[[np.ndarray], np.ndarray], theta: np.ndarray, eps: float = 1e-6
) -> np.ndarray:
    """[X, Y](theta) = DY X - DX Y, Jacobians by central differences."""
    n = theta.size
    DX = np.empty((n, n))
    DY = np.empty((n, n))
    for k in range(n):
        d = np.zeros(n)
        d[k] = eps
        DX[:, k] = (X(theta + d) - X(theta - d)) / (2 * eps)
        DY[:, k] = (Y(theta + d) - Y(theta - d)) / (2 * eps)
    return DY @ X(theta) - DX @ Y(theta)


def check_integrability(
    coupling: Callable[[np.ndarray], np.ndarray], samples: np.ndarray, tol: float = 1e-6
) -> Integrability:
    """Frobenius test of the distribution spanned by the columns of P_RNS (Sec. III-A).

    ``coupling(theta)`` returns S H_bm. The distribution is involutive where every bracket of
    two columns of P_RNS lies in it again, i.e. (E - P_RNS)[P_i, P_j] = 0. A 1-D distribution
    (n - m = 1) always passes.
    """

    def column(j: int) -> Callable[[np.ndarray], np.ndarray]:
        return lambda th: rns_projector(coupling(th))[:, j]

    worst = 0.0
    rns_dim = 0
    for theta in np.atleast_2d(samples):
        P = rns_projector(coupling(theta))
        rns_dim = round(float(np.trace(P)))
        n = theta.size
        for i in range(n):
            for j in range(i + 1, n):
                Xi, Xj = P[:, i], P[:, j]
                scale = np.linalg.norm(Xi) * np.linalg.norm(Xj)
                if scale < 1e-6:
                    continue
                bracket = lie_bracket(column(i), column(j), theta)
                worst = max(worst, float(np.linalg.norm(bracket - P @ bracket)) / scale)
    return Integrability(bool(worst < tol), worst, len(np.atleast_2d(samples)), rns_dim)
