"""The structure with the arm locked: the base's own modes, from K_b, D_b and H_b(theta) alone.

With theta' = theta'' = 0 the base rows of Eq. (1) are H_b x_b'' + D_b x_b' + K_b x_b = f (linear in
x_b about x_b = 0), so x = (x_b, x_b') obeys x' = A x, A = [[0, E], [-H_b^-1 K_b, -H_b^-1 D_b]]. Each
underdamped mode is a conjugate pair of eigenvalues of A; the mode's coordinate in a simulated or
measured state is w_i^H x with w_i its left eigenvector, and it decays as exp(lambda_i t). This is
what a held arm must leave the base: a kick then rings and decays in exactly these modes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rns_viz.model import FsmsModel


@dataclass(frozen=True)
class LockedModes:
    """The m modes of the base with the arm locked, slowest first (by |lambda|)."""

    poles: np.ndarray  # (m,) complex lambda_i, Im > 0, 1/s
    left: np.ndarray  # (m, 2m) w_i^H: mode i's coordinate is left[i] @ (x_b, x_b')
    H_b: np.ndarray  # (m, m) the locked base inertia, kg, kg m, kg m^2

    @property
    def frequency_hz(self) -> np.ndarray:
        """Undamped natural frequencies |lambda_i| / 2 pi, Hz."""
        return np.abs(self.poles) / (2.0 * np.pi)

    @property
    def damping_ratio(self) -> np.ndarray:
        """zeta_i = -Re lambda_i / |lambda_i| (the energy of mode i decays at 2 zeta_i |lambda_i|)."""
        return -self.poles.real / np.abs(self.poles)


def locked_modes(model: FsmsModel, theta: np.ndarray) -> LockedModes:
    """The base's modes with the arm locked at ``theta`` (rad), x_b = 0; ValueError for an overdamped mode."""
    m = model.m
    H_b = model.mass_matrix(model.q(theta), model.pin_model.createData())[:m, :m].copy()
    A = np.block(
        [
            [np.zeros((m, m)), np.eye(m)],
            [-np.linalg.solve(H_b, model.K_b), -np.linalg.solve(H_b, model.D_b)],
        ]
    )
    poles, vectors = np.linalg.eig(A)
    left = np.linalg.inv(vectors)  # rows: left eigenvectors with left @ vectors = E
    upper = poles.imag > 0
    if np.count_nonzero(upper) != m:
        raise ValueError(f"{model.name}: a locked-arm mode is overdamped (real poles), it has no frequency")
    order = np.argsort(np.abs(poles[upper]))
    return LockedModes(poles[upper][order], left[upper][order], H_b)
