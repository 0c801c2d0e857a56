"""Reaction null-space maths (Sec. III): damped inverse, P_RNS, n, restricted Jacobian, the distance to
singularity, and the one RK4 step that integrates a field of the RNS distribution (n, n u-bar, P_RNS v).
Whether the distribution is integrable (Lie brackets): :mod:`rns_viz.integrability`.

numpy on matrices that the model supplies (the per-step SVD and solve by LAPACK directly, rns_viz.lapack);
no pinocchio, no viser.
"""

from __future__ import annotations

import math
import operator
from collections.abc import Callable, Iterator
from functools import cache
from typing import Any

import numpy as np

from rns_viz.lapack import singular_values, solve

# Default singularity-robust settings: below ``threshold`` (smallest singular value, in the units
# of the matrix) damping rises smoothly to ``max_damping`` (Nakamura & Hanafusa, 1986).
DEFAULT_THRESHOLD = 1e-3
DEFAULT_MAX_DAMPING = 1e-3


class DampedInverse:
    """A singularity-robust right inverse A^T (A A^T + lambda^2 E)^-1 and how close A is to singular.

    Unpacks as (inverse, sigma_min, damping). For one row a the inverse is a^T * ``row_scale``
    (a number, None for more rows) and is formed only when asked for: per-step code on a 1-DOF
    base works with the number. A slotted class rather than a dataclass: it is built every step.
    """

    __slots__ = ("_inverse", "_row", "damping", "row_scale", "sigma_min")

    def __init__(
        self,
        inverse: np.ndarray | None,
        sigma_min: float,
        damping: float,
        row: list[float] | None = None,
        row_scale: float | None = None,
    ) -> None:
        self._inverse, self._row = inverse, row  # row: a (a copy) when the inverse is a^T row_scale
        self.sigma_min = sigma_min  # smallest singular value of A: the distance to singularity
        self.damping = damping  # lambda actually used (0 away from singularities)
        self.row_scale = row_scale  # 1 / (|a|^2 + lambda^2) for one row, else None

    @property
    def inverse(self) -> np.ndarray:
        """(cols, rows) the damped inverse."""
        if self._inverse is None:
            self._inverse = np.array(self._row)[:, None] * self.row_scale  # type: ignore[operator]
        return self._inverse

    def __iter__(self) -> Iterator[np.ndarray | float]:
        return iter((self.inverse, self.sigma_min, self.damping))

    def __repr__(self) -> str:
        return f"DampedInverse(sigma_min={self.sigma_min!r}, damping={self.damping!r})"


def damped_pinv(
    A: np.ndarray, threshold: float = DEFAULT_THRESHOLD, max_damping: float = DEFAULT_MAX_DAMPING
) -> DampedInverse:
    """Right pseudoinverse A^T (A A^T + lambda^2 E)^-1 of a wide matrix, damped near rank loss.

    lambda^2 = (1 - (sigma_min/threshold)^2) max_damping^2 when sigma_min < threshold, else 0, so
    the inverse stays finite at singularities. The one damped inverse of the project: H_bm^+ in
    Eqs. (9), (15), (16), (30) and J-bar^+ in Eq. (24). One and two rows (the 1-DOF base, the
    planar task) take closed forms; more rows an SVD and a solve.
    """
    if type(A) is not np.ndarray or A.ndim != 2 or A.dtype.char != "d":  # per step: skip when it is one
        A = np.atleast_2d(np.asarray(A, dtype=float))
    rows = A.shape[0]
    if rows == 1:
        return _one_row(A, threshold, max_damping)
    if rows == 2:
        closed = _two_rows(A, threshold, max_damping)
        if closed is not None:
            return closed
    return _any_rows(A, threshold, max_damping)


def weighted_damped_pinv(
    A: np.ndarray,
    weights: np.ndarray | None,
    threshold: float = DEFAULT_THRESHOLD,
    max_damping: float = DEFAULT_MAX_DAMPING,
) -> DampedInverse:
    """:func:`damped_pinv` of A with its rows weighted, (W A)^+ W with W = diag(weights): sigma_min and the
    damping are W A's, in the one unit the weights give every row (S H_bm's moment rows, kg m^2, divided
    by a length: :func:`singularity_distance`). Undamped it is A's own right inverse (row weights do not
    change it at full row rank); ``weights`` None: :func:`damped_pinv`."""
    if weights is None:
        return damped_pinv(A, threshold, max_damping)
    if A.shape[0] == 1:  # one row: w a, and the column a w^2 / (w^2 |a|^2 + lambda^2)
        w = float(weights[0])
        scaled = damped_row_pinv([w * a for a in A[0].tolist()], threshold, max_damping)
        return DampedInverse(None, scaled.sigma_min, scaled.damping, A[0].tolist(), w * w * scaled.row_scale)  # type: ignore[operator]
    if A.shape[0] == 2:
        scaled = damped_pinv(A * weights[:, None], threshold, max_damping)
        return DampedInverse(scaled.inverse * weights, scaled.sigma_min, scaled.damping)
    column = weights[:, None]
    return _any_rows(A * column, threshold, max_damping, column)


def singularity_distance(A: np.ndarray, weights: np.ndarray | None = None) -> np.ndarray | float:
    """sigma_min(W A): how far A (r x k, or a stack (..., r, k)) is from losing rank, with its rows
    weighted into one unit (W = diag(weights); None: A's own rows). For S H_bm the model's
    ``coupling_weights`` divide the moment rows (kg m^2) by the arm's length, so the distance is in kg m
    whatever the rows (an unweighted sigma_min of rows in kg m and kg m^2 would change with the unit)."""
    A = np.asarray(A, dtype=float)
    if weights is not None:
        A = A * weights[:, None]
    sigma = np.linalg.svd(A, compute_uv=False)[..., -1]
    return float(sigma) if sigma.ndim == 0 else sigma


def truncated_inverse(A: np.ndarray, rank: int, threshold: float) -> DampedInverse:
    """A^+ of a wide matrix of rank ``rank`` at most (fewer than its rows): inverted on the span of its
    ``rank`` largest singular values, damped below ``threshold``; sigma_min is the rank-th singular
    value. With ``rank`` >= rows, the project's damped inverse."""
    if A.shape[0] <= rank:
        return damped_pinv(A, threshold, threshold)
    return svd_inverse(*np.linalg.svd(A, full_matrices=False), rank, threshold)


def svd_inverse(U: np.ndarray, s: np.ndarray, Vt: np.ndarray, rank: int, threshold: float) -> DampedInverse:
    """:func:`truncated_inverse` from a thin SVD U diag(s) Vt already at hand: V diag(s / (s^2 + lambda^2)) U^T
    over the ``rank`` largest singular values (with all of them, equal to :func:`damped_pinv`'s)."""
    U, s, Vt = U[:, :rank], s[:rank], Vt[:rank]
    lam2 = (1.0 - (s[-1] / threshold) ** 2) * threshold**2 if s[-1] < threshold else 0.0
    return DampedInverse((Vt.T * (s / (s**2 + lam2))) @ U.T, float(s[-1]), float(np.sqrt(lam2)))


def _damping_squared(sigma: float, threshold: float, max_damping: float) -> float:
    """lambda^2 of the damped inverse for smallest singular value sigma (0 above ``threshold``)."""
    if sigma >= threshold:
        return 0.0
    return (1.0 - (sigma / threshold) ** 2) * max_damping**2


def _any_rows(A: np.ndarray, threshold: float, max_damping: float, weights: np.ndarray | None = None) -> DampedInverse:
    """Any number of rows: sigma_min from the SVD, then A^T G^-1 = (G^-1 A)^T with G = A A^T + lambda^2 E
    symmetric (one solve). ``weights`` (a column, A = W B already weighted): (G^-1 A)^T W, B's weighted inverse."""
    sigma = singular_values(A).item(-1)
    lam2 = _damping_squared(sigma, threshold, max_damping)
    G = A @ A.T
    if lam2:
        G += lam2 * _identity(A.shape[0])
    solved = solve(G, A)
    inverse = (solved if weights is None else solved * weights).T
    return DampedInverse(inverse, sigma, math.sqrt(lam2))


@cache
def _identity(rows: int) -> np.ndarray:
    """E (rows x rows), shared: never written to."""
    E = np.eye(rows)
    E.flags.writeable = False
    return E


def _one_row(A: np.ndarray, threshold: float, max_damping: float) -> DampedInverse:
    """One row a: :func:`damped_row_pinv`."""
    (a,) = A.tolist()
    return damped_row_pinv(a, threshold, max_damping)


def damped_row_pinv(
    a: list[float], threshold: float = DEFAULT_THRESHOLD, max_damping: float = DEFAULT_MAX_DAMPING
) -> DampedInverse:
    """:func:`damped_pinv` of the one-row matrix [a] given as Python floats (a 1-DOF base, per step):
    the column ``a / (|a|^2 + lambda^2)``, ``sigma = |a|``. No SVD, no numpy call."""
    sigma2 = sum(map(operator.mul, a, a))
    sigma = math.sqrt(sigma2)
    lam2 = _damping_squared(sigma, threshold, max_damping)
    return DampedInverse(None, sigma, math.sqrt(lam2), a, 1.0 / (sigma2 + lam2))


def _two_rows(A: np.ndarray, threshold: float, max_damping: float) -> DampedInverse | None:
    """Two rows a, b: the 2 x 2 matrix A A^T + lambda^2 E inverted in closed form (None if singular).

    det(A A^T) is the sum of the squared 2 x 2 minors of A (Lagrange's identity), which keeps
    sigma_min^2 = det / sigma_max^2 accurate near rank loss, where g_aa g_bb - g_ab^2 would cancel.
    Python floats: for a few columns cheaper than numpy calls.
    """
    a, b = A.tolist()
    g_aa, g_ab, g_bb = sum(map(operator.mul, a, a)), sum(map(operator.mul, a, b)), sum(map(operator.mul, b, b))
    cols = len(a)
    det = sum((a[i] * b[j] - a[j] * b[i]) ** 2 for i in range(cols) for j in range(i + 1, cols))
    half = 0.5 * (g_aa - g_bb)
    largest = 0.5 * (g_aa + g_bb) + math.sqrt(half * half + g_ab * g_ab)
    if largest <= 0.0:  # A = 0
        return None
    sigma = math.sqrt(det / largest)
    lam2 = _damping_squared(sigma, threshold, max_damping)
    damped_det = det + lam2 * (g_aa + g_bb + lam2)  # det(A A^T + lambda^2 E)
    if not damped_det > 0.0:
        return None
    # A^T (A A^T + lambda^2 E)^-1, the 2 x 2 inverse written out
    d_aa, d_bb, g = (g_aa + lam2) / damped_det, (g_bb + lam2) / damped_det, g_ab / damped_det
    inverse = np.array([[d_bb * a_i - g * b_i, d_aa * b_i - g * a_i] for a_i, b_i in zip(a, b, strict=True)])
    return DampedInverse(inverse, sigma, math.sqrt(lam2))


def rns_projector(H_bm: np.ndarray, H_bm_pinv: np.ndarray | None = None, *, rank_tol: float = 1e-12) -> np.ndarray:
    """P_RNS = E - H_bm^+ H_bm, the projector onto the reaction null space (Eqs. 9, 10).

    ``H_bm``: one (r, n) matrix, or a stack (..., r, n) for as many configurations (P is then (..., n, n)).
    ``H_bm_pinv``: the inverse to use, e.g. the damped one the laws use (:func:`damped_pinv`);
    by default the Moore-Penrose inverse, for which H_bm^+ H_bm = V_r V_r^T with V_r the SVD's
    row-space basis: P is then exactly symmetric and idempotent.
    """
    H = np.atleast_2d(np.asarray(H_bm, dtype=float))
    E = np.eye(H.shape[-1])
    if H_bm_pinv is not None:
        return E - H_bm_pinv @ H
    _, s, Vt = np.linalg.svd(H)
    if H.ndim == 2:
        rank = int(np.sum(s > rank_tol * max(1.0, s[0] if s.size else 0.0)))
        range_basis = Vt[:rank]
        return E - range_basis.T @ range_basis
    kept = s > rank_tol * np.maximum(1.0, s[..., :1])  # (..., r): each matrix's own rank
    range_basis = Vt[..., : s.shape[-1], :] * kept[..., None]
    return E - np.swapaxes(range_basis, -1, -2) @ range_basis


def project_onto_rns(u: np.ndarray, H_bm: np.ndarray, H_bm_pinv: np.ndarray | None = None) -> np.ndarray:
    """P_RNS u = u - H_bm^+ (H_bm u): :func:`rns_projector` applied to a vector, P never formed.

    One vector u (n,) with H_bm (r, n), or a stack u (K, n) with H_bm (K, r, n), one per configuration.
    ``H_bm_pinv``: the inverse the laws use (one matrix); None: the Moore-Penrose inverse of a full-row-rank
    H_bm, H_bm^T (H_bm H_bm^T)^-1, by one solve per configuration.
    """
    if H_bm_pinv is None:
        Hu = np.einsum("...rn,...n->...r", H_bm, u)
        multipliers = np.linalg.solve(H_bm @ np.swapaxes(H_bm, -1, -2), Hu[..., None])[..., 0]
        return u - np.einsum("...rn,...r->...n", H_bm, multipliers)
    if H_bm_pinv.shape[1] == 1:  # one coupling row: a scalar times the inverse column
        return u - H_bm_pinv[:, 0] * H_bm[0].dot(u)
    return u - H_bm_pinv @ (H_bm @ u)


def rns_basis(H_bm: np.ndarray) -> np.ndarray:
    """An orthonormal basis of the reaction null space N(S H_bm) of full row rank r: (n, n - r), or (..., n, n - r)
    for a stack; the SVD's right singular vectors beyond the rows (the columns span what P_RNS projects onto)."""
    Vt = np.linalg.svd(H_bm)[2]
    return np.swapaxes(Vt[..., H_bm.shape[-2] :, :], -1, -2)


def rk4_along(
    field: Callable[[Any, np.ndarray], np.ndarray],
    s: Any,
    x: np.ndarray,
    h: Any,
    k1: np.ndarray | None = None,
) -> np.ndarray:
    """x(s + h) by one classical Runge-Kutta step of dx/ds = field(s, x) from (s, x).

    The one integrator along a field of the RNS distribution: a reactionless path d theta/ds = n (Eq. 27, in
    arc length or in sigma), Eq. (30)'s reference theta_ref' = n u-bar(t), a move along P_RNS v. x may be a
    stack (K, n) with h (K, 1), K curves in lock-step. ``k1``: field(s, x), when the caller has it already.
    """
    if k1 is None:
        k1 = field(s, x)
    half = 0.5 * h
    k2 = field(s + half, x + half * k1)
    k3 = field(s + half, x + half * k2)
    k4 = field(s + h, x + h * k3)
    return x + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


def null_vector(H_bm: np.ndarray) -> np.ndarray:
    """n for a 1-D RNS (n = m + 1): the generalised cross product of the rows of H_bm.

    n_i = (-1)^i det(H_bm without column i). For m = 1 this is Eq. (27), n = (h_2, -h_1).
    It is smooth, has the magnitude of the rows' volume, and vanishes where H_bm loses rank.
    ``H_bm`` may be one (m, m + 1) matrix or a stack (K, m, m + 1); n is then (K, m + 1).
    """
    H = np.asarray(H_bm, dtype=float)
    if H.shape == (1, 2):  # one row, one matrix (TREP, the 3R): Eq. (27) as it stands, at every path step
        return np.array((H[0, 1], -H[0, 0]))
    if H.ndim == 1:
        H = H[None]
    rows, cols = H.shape[-2:]
    if cols != rows + 1:
        raise ValueError(f"null_vector needs an m x (m+1) matrix for a 1-D RNS, got {H.shape}")
    if rows == 1:
        return np.stack([H[..., 0, 1], -H[..., 0, 0]], axis=-1)
    # all m + 1 minors in one batched determinant: (..., m + 1, m, m), column i left out of minor i
    minors = np.linalg.det(np.swapaxes(H[..., _minor_columns(cols)], -3, -2))
    return minors * _ALTERNATING[:cols]


_ALTERNATING = np.array([1.0, -1.0] * 4)  # (-1)^i for up to 7 columns (m <= 6)


@cache
def _minor_columns(cols: int) -> np.ndarray:
    """(cols, cols - 1) column indices: row i lists every column but i."""
    return np.array([[j for j in range(cols) if j != i] for i in range(cols)])


def restricted_jacobian(J: np.ndarray, P_rns: np.ndarray) -> np.ndarray:
    """J-bar = J P_RNS, the restricted Jacobian of Eq. (22)."""
    return J @ P_rns
