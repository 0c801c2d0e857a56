"""A damped right inverse with a closed form for two rows (the planar task), for per-step use."""

from __future__ import annotations

import math

import numpy as np

from rns_viz.rns import damped_pinv, damping_squared


def damped_inverse(A: np.ndarray, threshold: float) -> tuple[np.ndarray, float]:
    """Damped right inverse of A and its smallest singular value (m/rad for J-bar).

    The rule of :func:`rns_viz.rns.damped_pinv` with max damping = threshold; for two rows the
    2 x 2 Gram matrix is inverted in closed form (several times cheaper than an SVD and a solve).
    """
    if A.shape[0] != 2:
        inv = damped_pinv(A, threshold, threshold)
        return inv.inverse, inv.sigma_min
    a0, a1 = A[0], A[1]
    g00, g01, g11 = float(a0 @ a0), float(a0 @ a1), float(a1 @ a1)
    half = 0.5 * (g00 - g11)
    low = 0.5 * (g00 + g11) - math.sqrt(half * half + g01 * g01)
    sigma = math.sqrt(max(low, 0.0))
    lam2 = damping_squared(sigma, threshold, threshold)
    d00, d11 = g00 + lam2, g11 + lam2
    det = d00 * d11 - g01 * g01
    if det <= 1e-300:
        return np.zeros(A.shape[::-1]), sigma
    G_inv = np.array([[d11, -g01], [-g01, d00]]) / det
    return A.T @ G_inv, sigma
