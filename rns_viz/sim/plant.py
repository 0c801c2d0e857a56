"""The plant: Eq. (1) with base spring K_b and damper D_b, joint damping D_m, external base force.

Forward dynamics by pinocchio's ABA; states are (q, v) with q = (x_b, theta).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from rns_viz.model import FsmsModel


class Plant:
    """q'' = M^-1 (tau_gen - c) with tau_gen = (-K_b x_b - D_b x_b' + f_ext, tau - D_m theta')."""

    def __init__(self, model: FsmsModel) -> None:
        self.model = model
        self._data = model.pin_model.createData()  # own data: the controller may use the model's
        self._u = np.zeros(model.nv)
        m = model.m
        self._K, self._D, self._Dm = model.K_b, model.D_b, np.diag(model.D_m).copy()
        self._scalar_base = m == 1
        self._k, self._d = float(self._K[0, 0]), float(self._D[0, 0])
        self._arm_damped = bool(np.any(self._Dm))

    def acceleration(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, f_ext: np.ndarray | None) -> np.ndarray:
        """Generalised acceleration (x_b'', theta'') for torques tau and base force f_ext."""
        m, u = self.model.m, self._u
        if self._scalar_base:
            u[0] = -self._k * q[0] - self._d * v[0]
        else:
            u[:m] = -self._K @ q[:m] - self._D @ v[:m]
        if f_ext is not None:
            u[:m] += f_ext
        u[m:] = tau
        if self._arm_damped:
            u[m:] -= self._Dm * v[m:]
        return pin.aba(self.model.pin_model, self._data, q, v, u)

    def rk4_step(
        self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, f_ext: np.ndarray | None, dt: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """One classical RK4 step with tau and f_ext held constant over it (a digital controller)."""
        a1 = self.acceleration(q, v, tau, f_ext)
        h = 0.5 * dt
        v2 = v + h * a1
        a2 = self.acceleration(q + h * v, v2, tau, f_ext)
        v3 = v + h * a2
        a3 = self.acceleration(q + h * v2, v3, tau, f_ext)
        v4 = v + dt * a3
        a4 = self.acceleration(q + dt * v3, v4, tau, f_ext)
        s = dt / 6.0
        return q + s * (v + 2.0 * (v2 + v3) + v4), v + s * (a1 + 2.0 * (a2 + a3) + a4)

    def semi_implicit_euler_step(
        self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, f_ext: np.ndarray | None, dt: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """The cheap option: one dynamics call, symplectic for the base spring."""
        v_next = v + dt * self.acceleration(q, v, tau, f_ext)
        return q + dt * v_next, v_next

    def energy(self, q: np.ndarray, v: np.ndarray) -> float:
        """Kinetic plus spring energy, J (zero gravity)."""
        M = pin.crba(self.model.pin_model, self._data, q)
        x = q[: self.model.m]
        return float(0.5 * v @ M @ v + 0.5 * x @ self._K @ x)
