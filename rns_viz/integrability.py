"""Is the reaction null-space distribution integrable (Sec. III-A)? Lie brackets of the columns of P_RNS.

Where every bracket [P_i, P_j] lies in the distribution again it is involutive (Frobenius): reactionless
motions stay on an (n - r)-dimensional integral manifold (always so for a 1-D RNS, and for a translating
base, Eq. 26). Where brackets leave it, reactionless motion reaches a larger set of configurations.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from rns_viz.rns import rns_projector


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
    worst = 0.0
    rns_dim = 0
    for theta in np.atleast_2d(samples):
        rns_dim, residuals = _bracket_residuals(coupling, theta)
        worst = max([worst, *(float(np.linalg.norm(r)) for r in residuals)])
    return Integrability(bool(worst < tol), worst, len(np.atleast_2d(samples)), rns_dim)


@dataclass(frozen=True)
class BracketRank:
    """The RNS distribution and its first Lie brackets at one configuration (Sec. III-A)."""

    rns_dim: int  # n - r
    with_brackets: int  # rank of [P_RNS, [P_i, P_j]]: > rns_dim where the distribution is not involutive
    residual: float  # largest |(E - P) [P_i, P_j]| / (|P_i| |P_j|)

    @property
    def involutive(self) -> bool:
        return self.with_brackets == self.rns_dim

    def words(self) -> str:
        if self.involutive:
            return (
                f"The distribution is involutive here (Lie brackets stay in it, residual {self.residual:.1e}): "
                f"reactionless motions stay on an integral manifold, the reachable set is {self.rns_dim}-dimensional "
                "in joint space."
            )
        return (
            f"The distribution is not involutive here (the Lie brackets add {self.with_brackets - self.rns_dim} "
            f"direction(s), rank {self.with_brackets} of n; residual {self.residual:.2g}): reactionless motions "
            f"reach a set larger than {self.rns_dim}-dimensional in joint space (at least {self.with_brackets})."
        )


def bracket_rank(coupling: Callable[[np.ndarray], np.ndarray], theta: np.ndarray, tol: float = 1e-6) -> BracketRank:
    """Rank of the columns of P_RNS with their pairwise Lie brackets at ``theta`` (central differences).

    ``coupling(theta)`` returns S H_bm. Brackets are measured relative to the columns' norms; a
    component out of the distribution below ``tol`` counts as zero.
    """
    theta = np.asarray(theta, dtype=float)
    rns_dim, out_of = _bracket_residuals(coupling, theta)
    worst = max((float(np.linalg.norm(r)) for r in out_of), default=0.0)
    extra = 0
    if out_of:
        s = np.linalg.svd(np.array(out_of).T, compute_uv=False)
        extra = int(np.sum(s > tol * max(1.0, np.sqrt(len(out_of)))))
    return BracketRank(rns_dim, min(theta.size, rns_dim + extra), worst)


def _bracket_residuals(coupling: Callable[[np.ndarray], np.ndarray], theta: np.ndarray) -> tuple[int, list[np.ndarray]]:
    """The RNS dimension at theta and, for every pair of columns i < j of P_RNS (the Moore-Penrose one) that
    are not ~0, the part of their Lie bracket outside the distribution, (E - P)[P_i, P_j] / (|P_i| |P_j|)."""

    def column(j: int) -> Callable[[np.ndarray], np.ndarray]:
        return lambda th: rns_projector(coupling(th))[:, j]

    P = rns_projector(coupling(theta))
    n = theta.size
    out_of = []
    for i in range(n):
        for j in range(i + 1, n):
            scale = float(np.linalg.norm(P[:, i]) * np.linalg.norm(P[:, j]))
            if scale < 1e-6:
                continue
            bracket = lie_bracket(column(i), column(j), theta)
            out_of.append((bracket - P @ bracket) / scale)
    return round(float(np.trace(P))), out_of
