"""Closed-form oracles from the paper, for tests only (the product uses pinocchio).

TREP: Table I and Eq. (26). Planar 3R: Sec. VI (1 m links, 10 kg at each link centre).
Angles are measured from the base x axis, as in the paper.
"""

from __future__ import annotations

import numpy as np

# TREP, Table I
L1, L2, LG1, LG2, M1, M2 = 0.1, 0.1, 0.096, 0.090, 0.310, 0.120
TREP_A = M1 * LG1 + M2 * L1  # kg m
TREP_B = M2 * LG2


def trep_hbm(theta: np.ndarray) -> np.ndarray:
    """Eq. (26): h_bm = [h_bm1, h_bm2]."""
    t1, t12 = theta[0], theta[0] + theta[1]
    return np.array([-TREP_A * np.sin(t1) - TREP_B * np.sin(t12), -TREP_B * np.sin(t12)])


def trep_wxcm(theta: np.ndarray) -> float:
    """w x_cm, whose gradient is h_bm (integral of Eq. 26)."""
    return float(TREP_A * np.cos(theta[0]) + TREP_B * np.cos(theta[0] + theta[1]))


def trep_ee(theta: np.ndarray) -> np.ndarray:
    t1, t12 = theta[0], theta[0] + theta[1]
    return np.array([L1 * np.cos(t1) + L2 * np.cos(t12), L1 * np.sin(t1) + L2 * np.sin(t12), 0.0])


# Planar 3R, Sec. VI
R3_MASS, R3_LINK = 10.0, 1.0


def r3_wxcm(theta: np.ndarray) -> float:
    c1 = np.cos(theta[0])
    c12 = np.cos(theta[0] + theta[1])
    c123 = np.cos(theta.sum())
    return float(R3_MASS * R3_LINK * (2.5 * c1 + 1.5 * c12 + 0.5 * c123))


def r3_hbm(theta: np.ndarray) -> np.ndarray:
    s1, s12, s123 = np.sin(theta[0]), np.sin(theta[0] + theta[1]), np.sin(theta.sum())
    k = R3_MASS * R3_LINK
    return -k * np.array([2.5 * s1 + 1.5 * s12 + 0.5 * s123, 1.5 * s12 + 0.5 * s123, 0.5 * s123])


def r3_ee(theta: np.ndarray) -> np.ndarray:
    angles = np.cumsum(theta)
    return np.array([np.cos(angles).sum(), np.sin(angles).sum(), 0.0]) * R3_LINK
