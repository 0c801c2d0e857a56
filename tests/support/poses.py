"""Poses reachable without reaction, for the orientation tests: S H_bm at a configuration, a random
reactionless walk, and the angle between two rotations."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from rns_viz.model import FsmsModel
from rns_viz.rns import rns_projector


def coupling(model: FsmsModel, theta: np.ndarray) -> np.ndarray:
    """S H_bm at theta (kg m)."""
    return model.mass_matrix(model.q(theta))[model.selected, model.m :]


def rns_walk(model: FsmsModel, theta: np.ndarray, seed: int, steps: int = 300) -> np.ndarray:
    """A configuration reached by a random reactionless motion: its pose is reachable without reaction."""
    z = np.random.default_rng(seed).normal(size=model.n)
    theta = np.array(theta, dtype=float)
    for _ in range(steps):
        theta = theta + 1e-3 * rns_projector(coupling(model, theta)) @ z
    return theta


def angle_deg(A: np.ndarray, B: np.ndarray) -> float:
    return float(np.degrees(np.linalg.norm(pin.log3(A @ B.T))))
