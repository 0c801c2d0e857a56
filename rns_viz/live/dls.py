"""Superseded by :func:`rns_viz.rns.damped_pinv`, which has the two-row closed form now; kept only
until live/references.py calls it directly."""

from __future__ import annotations

import numpy as np

from rns_viz.rns import damped_pinv


def damped_inverse(A: np.ndarray, threshold: float) -> tuple[np.ndarray, float]:
    """:func:`rns_viz.rns.damped_pinv` with max damping = threshold: the inverse and sigma_min."""
    inverse = damped_pinv(A, threshold, threshold)
    return inverse.inverse, inverse.sigma_min
