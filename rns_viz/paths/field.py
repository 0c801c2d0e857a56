"""S H_bm and its potential at many configurations at once: what every reactionless-path tool evaluates."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from rns_viz import _native
from rns_viz.model import FsmsModel

TWO_PI = 2.0 * np.pi


def periodic_joints(model: FsmsModel) -> np.ndarray:
    """(n,) bool: the joints whose limits span at least a full turn (angles compared modulo 2 pi)."""
    return (model.upper - model.lower) >= TWO_PI * (1 - 1e-6)


_NO_COM = np.empty(0)  # "no centre of mass wanted" for the native kernel


class CouplingField:
    """The coupling rows S H_bm, and their potential where one exists, at many configurations.

    For a translating base, row i of H_bm is M_total a_i . J_com (the base momentum along axis
    a_i) and M_total a_i . r_com its potential (Eq. 26, up to a constant): one
    jacobianCenterOfMass call gives both. Other bases read H_bm from crba and have no potential.
    With the optional native module installed, the K configurations of a call go to pinocchio in
    one C++ call (``native=False``: one Python call each, the same numbers). ``data``: pinocchio data to
    work in (default: the model's own, which the laws also use).
    """

    def __init__(self, model: FsmsModel, native: bool = True, data: pin.Data | None = None) -> None:
        self.model = model
        self.data = model.data if data is None else data
        self.native = _native.robot_model(model) if native else None
        self.q = np.zeros(model.nv)
        self.rows = model.selected
        self.m = model.m
        self.translational = model.base_is_translational
        pin.forwardKinematics(model.pin_model, self.data, self.q)
        total_mass = float(sum(inertia.mass for inertia in model.pin_model.inertias))
        world_axes = (self.data.oMi[model.base_joint_id].rotation @ model.base_axes().T).T[self.rows]
        self.scaled_axes = total_mass * world_axes  # (r, 3)

    def rows_at(self, thetas: np.ndarray, want_potential: bool = False) -> tuple[np.ndarray, np.ndarray | None]:
        """S H_bm (K, r, n) and, if asked and defined, the potentials (K, r) in kg m."""
        pm, data, q, m, rows = self.model.pin_model, self.data, self.q, self.m, self.rows
        K, n = thetas.shape
        if not self.translational:
            H = np.empty((K, len(rows), n))
            for k in range(K):
                q[m:] = thetas[k]
                H[k] = self.model.coupling_matrix(q, data)
            return H, None
        J = np.empty((K, 3, n))
        com = np.empty((K, 3))
        if self.native is not None:
            flat = np.ascontiguousarray(thetas, dtype=float).reshape(-1)
            self.native.com_jacobians(m, flat, J.reshape(-1), com.reshape(-1) if want_potential else _NO_COM)
            H = np.einsum("ra,kan->krn", self.scaled_axes, J)
            return H, (com @ self.scaled_axes.T if want_potential else None)
        jacobian_com = pin.jacobianCenterOfMass
        for k in range(K):
            q[m:] = thetas[k]
            J[k] = jacobian_com(pm, data, q, False)[:, m:]
            if want_potential:
                com[k] = data.com[0]
        H = np.einsum("ra,kan->krn", self.scaled_axes, J)
        return H, (com @ self.scaled_axes.T if want_potential else None)

    def potentials(self, thetas: np.ndarray) -> np.ndarray:
        """Potentials (K, r) alone, kg m: one centerOfMass call each (translating base only)."""
        pm, data, q, m = self.model.pin_model, self.data, self.q, self.m
        com = np.empty((len(thetas), 3))
        if self.native is not None:
            self.native.centers_of_mass(m, np.ascontiguousarray(thetas, dtype=float).reshape(-1), com.reshape(-1))
            return com @ self.scaled_axes.T
        for k in range(len(thetas)):
            q[m:] = thetas[k]
            com[k] = pin.centerOfMass(pm, data, q, False)
        return com @ self.scaled_axes.T

    def project(self, thetas: np.ndarray, levels: np.ndarray, newton_steps: int = 3) -> np.ndarray:
        """Move each configuration onto its level set c(theta) = level along H_bm (min-norm Newton).

        A base that turns has no potential of its angular rows (angular momentum is not a gradient):
        the configurations are returned unchanged, the integration alone keeps them on the path.
        """
        thetas = thetas.copy()
        if not self.translational:
            return thetas
        for _ in range(newton_steps):
            H, pot = self.rows_at(thetas, want_potential=True)
            thetas -= right_inverse_times(H, pot - levels)
        return thetas


def right_inverse_times(H: np.ndarray, r: np.ndarray) -> np.ndarray:
    """H_k^+ r_k for a stack of full-row-rank H_k (K, rows, n): the minimum-norm Newton step."""
    if H.shape[1] == 1:
        h = H[:, 0, :]
        hh = np.einsum("ij,ij->i", h, h)  # 0 where H loses rank: no step there (never 0/0)
        return h * (r[:, 0] / np.where(hh > 1e-300, hh, np.inf))[:, None]
    return np.einsum("kir,kr->ki", np.linalg.pinv(H), r)
