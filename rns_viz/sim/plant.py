"""The plant: Eq. (1) with base spring K_b and damper D_b, joint damping D_m, external base force.

Forward dynamics by pinocchio's ABA; states are (q, v) with q = (x_b, theta), or both stacked as
x = (q, v) for the RK4 step, which runs at every control step and reuses its stage buffers.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pinocchio as pin

from rns_viz.model import FsmsModel
from rns_viz.sim.disturbance import StageForces

RK4_WEIGHTS = np.array([1.0, 2.0, 2.0, 1.0]) / 6.0  # b_i of the classical RK4
# (h, q_s, v_s) -> the torque at an RK4 stage: its time t + h (h = dt/2, dt/2, dt) and state
StageTorque = Callable[[float, np.ndarray, np.ndarray], np.ndarray]


class Plant:
    """q'' = M^-1 (tau_gen - c) with tau_gen = (-K_b x_b - D_b x_b' + f_ext, tau - D_m theta')."""

    def __init__(self, model: FsmsModel) -> None:
        self.model = model
        self._pin_model = model.pin_model  # read at every RK4 stage: one attribute, not a chain
        self._data = model.pin_model.createData()  # own data: the controller may use the model's
        m, nv = model.m, model.nv
        self._m = m
        self._u = np.zeros(nv)  # generalised force tau_gen, rebuilt for each evaluation
        self._K, self._D, self._Dm = model.K_b, model.D_b, np.diag(model.D_m).copy()
        self._minus_K = -self._K  # (-K_b) x_b per evaluation: the negation done once
        self._scalar_base = m == 1
        self._k, self._d = float(self._K[0, 0]), float(self._D[0, 0])
        self._arm_damped = bool(np.any(self._Dm))
        self._tau = np.zeros(model.n)
        self._f: np.ndarray | None = None
        self._f0 = 0.0  # f_ext as a float for a 1-DOF base
        # RK4 stages: row s of the buffer holds (q_s, v_s, a_s); its tail (v_s, a_s) is the slope k_s.
        self._stages = np.zeros((4, 3 * nv))
        self._stage_q = [row[:nv] for row in self._stages]
        self._stage_v = [row[nv : 2 * nv] for row in self._stages]
        self._stage_a = [row[2 * nv :] for row in self._stages]
        self._stage_x = [row[: 2 * nv] for row in self._stages]
        self._stage_k = [row[nv:] for row in self._stages]
        self._slopes = self._stages[:, nv:]  # (4, 2 nv): k_1 .. k_4
        self._weights_dt = (0.0, RK4_WEIGHTS * 0.0, (0.0, 0.0, 0.0, None))  # (dt, b_i dt, stage steps), cached

    def hold(self, tau: np.ndarray, f_ext: np.ndarray | None) -> None:
        """Set the joint torques and base force used by :meth:`held_acceleration`."""
        self._tau = tau
        self._u[self._m :] = tau
        self._set_force(f_ext)

    def _set_force(self, f_ext: np.ndarray | None) -> None:
        self._f = f_ext
        if self._scalar_base:
            self._f0 = 0.0 if f_ext is None else float(f_ext[0])

    def held_acceleration(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Generalised acceleration (x_b'', theta'') at (q, v) for the inputs set by :meth:`hold`."""
        m, u = self._m, self._u
        if self._scalar_base:
            u[0] = -self._k * q.item(0) - self._d * v.item(0) + self._f0
        else:
            u[:m] = self._minus_K @ q[:m] - self._D @ v[:m]
            if self._f is not None:
                u[:m] += self._f
        if self._arm_damped:
            u[m:] = self._tau - self._Dm * v[m:]
        return pin.aba(self._pin_model, self._data, q, v, u)

    def acceleration(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, f_ext: np.ndarray | None) -> np.ndarray:
        """Generalised acceleration (x_b'', theta'') for torques tau and base force f_ext."""
        self.hold(tau, f_ext)
        return self.held_acceleration(q, v)

    def rk4_step(
        self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, f_ext: np.ndarray | None, dt: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """One classical RK4 step with tau and f_ext held constant over it (a digital controller)."""
        x = self.rk4_state_step(np.concatenate((q, v)), tau, f_ext, dt)
        nv = self.model.nv
        return x[:nv], x[nv:]

    def rk4_state_step(
        self,
        x: np.ndarray,
        tau: np.ndarray,
        f_ext: np.ndarray | StageForces | None,
        dt: float,
        torque_at: StageTorque | None = None,
    ) -> np.ndarray:
        """:meth:`rk4_step` on the stacked state x = (q, v); returns a new array.

        Stages x_{s+1} = x + c_s k_s (c = dt/2, dt/2, dt) with slopes k_s = (v_s, a_s); the step is
        x + dt (k_1 + 2 k_2 + 2 k_3 + k_4) / 6. ``f_ext``: one base force held over the step, or
        its samples at the stage times (f(t), f(t + dt/2), f(t + dt)) for k_1, k_2 and k_3, k_4.
        ``torque_at``: None holds ``tau`` over the step; else ``tau`` is the first stage's torque
        and ``torque_at(h, q_s, v_s)`` gives the others' at their times t + h and states (a law
        evaluated wherever the plant is: a joint servo, or continuous-time control).
        """
        sampled = isinstance(f_ext, tuple)
        self.hold(tau, f_ext[0] if sampled else f_ext)  # type: ignore[index, arg-type]
        if self._scalar_base:
            samples = f_ext if sampled else None
            if torque_at is not None:  # a servo at every stage: the general stages, the torque set per stage
                return self._rk4_staged_scalar_base(x, samples, dt, torque_at)  # type: ignore[arg-type]
            return self._rk4_scalar_base(x, samples, dt)  # type: ignore[arg-type]
        q, v, a, xs, k = self._stage_q, self._stage_v, self._stage_a, self._stage_x, self._stage_k
        xs[0][:] = x
        for s, c in enumerate((0.5 * dt, 0.5 * dt, dt)):
            a[s][:] = self.held_acceleration(q[s], v[s])
            np.add(x, c * k[s], out=xs[s + 1])
            if sampled and s != 1:  # k_2 and k_3 at t + dt/2, k_4 at t + dt
                self._set_force(f_ext[s // 2 + 1])  # type: ignore[index]
            if torque_at is not None:
                self._set_torque(torque_at(c, q[s + 1], v[s + 1]))
        a[3][:] = self.held_acceleration(q[3], v[3])
        return x + self._weights(dt)[0].dot(self._slopes)

    def _set_torque(self, tau: np.ndarray) -> None:
        self._tau = tau
        self._u[self._m :] = tau

    def _rk4_scalar_base(self, x: np.ndarray, samples: StageForces | None, dt: float) -> np.ndarray:
        """:meth:`rk4_state_step` for a 1-DOF base, inputs set by :meth:`hold`: the same stages, with
        :meth:`held_acceleration`'s base force -k x_b - d x_b' + f as a number written inline and
        everything it reads bound once (four stages per control step; TREP, the 3R, arm7)."""
        q, v, a, xs, k = self._stage_q, self._stage_v, self._stage_a, self._stage_x, self._stage_k
        aba, pin_model, data, u, add = pin.aba, self._pin_model, self._data, self._u, np.add
        k_b, d_b, tau, D_m, damped = self._k, self._d, self._tau, self._Dm, self._arm_damped
        f = self._f0  # f(t); with samples, f(t + dt/2) for k_2, k_3 and f(t + dt) for k_4
        if samples is None:
            forces = (f, f, f, f)
        else:
            f_mid, f_end = (0.0 if g is None else float(g[0]) for g in samples[1:])
            forces = (f, f_mid, f_mid, f_end)
        xs[0][:] = x
        weights, steps = self._weights(dt)
        for s, c in enumerate(steps):
            q_s, v_s = q[s], v[s]
            u[0] = -k_b * q_s.item(0) - d_b * v_s.item(0) + forces[s]
            if damped:
                u[1:] = tau - D_m * v_s[1:]
            a[s][:] = aba(pin_model, data, q_s, v_s, u)
            if c is not None:
                add(x, c * k[s], xs[s + 1])
        return x + weights.dot(self._slopes)

    def _rk4_staged_scalar_base(
        self, x: np.ndarray, samples: StageForces | None, dt: float, torque_at: StageTorque
    ) -> np.ndarray:
        """:meth:`_rk4_scalar_base` with the torque of stages 2-4 from ``torque_at`` (held_acceleration
        per stage: a servo's four law evaluations cost far more than the inlined base force saves)."""
        q, v, a, xs, k = self._stage_q, self._stage_v, self._stage_a, self._stage_x, self._stage_k
        forces = (self._f, self._f, self._f) if samples is None else samples
        xs[0][:] = x
        for s, c in enumerate((0.5 * dt, 0.5 * dt, dt)):
            a[s][:] = self.held_acceleration(q[s], v[s])
            np.add(x, c * k[s], out=xs[s + 1])
            if s != 1:  # k_2 and k_3 at t + dt/2, k_4 at t + dt
                self._set_force(forces[s // 2 + 1])
            self._set_torque(torque_at(c, q[s + 1], v[s + 1]))
        a[3][:] = self.held_acceleration(q[3], v[3])
        return x + self._weights(dt)[0].dot(self._slopes)

    def _weights(self, dt: float) -> tuple[np.ndarray, tuple[float, float, float, None]]:
        """b_i dt and the stage steps (dt/2, dt/2, dt, None: after the last stage), cached for dt."""
        if self._weights_dt[0] != dt:
            self._weights_dt = (dt, RK4_WEIGHTS * dt, (0.5 * dt, 0.5 * dt, dt, None))
        return self._weights_dt[1], self._weights_dt[2]

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
