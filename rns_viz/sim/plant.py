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
        # (-K_b, 0, -D_b, 0): the base rows of tau_gen, -K_b x_b - D_b x_b', as one product with the
        # stacked state (q, v) into u's first m entries (one call per RK4 stage instead of five)
        self._spring_damper = np.zeros((m, 2 * nv))
        self._spring_damper[:, :m] = -self._K
        self._spring_damper[:, nv : nv + m] = -self._D
        self._u_base = self._u[:m]
        self._held_x = np.zeros(2 * nv)  # (q, v) stacked for held_acceleration
        self._held_q, self._held_v = self._held_x[:nv], self._held_x[nv:]
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
        if not self._scalar_base:
            self._held_q[:] = q
            self._held_v[:] = v
            return self._stacked_acceleration(self._held_x, self._held_q, self._held_v)
        u = self._u
        u[0] = -self._k * q.item(0) - self._d * v.item(0) + self._f0
        if self._arm_damped:
            u[1:] = self._tau - self._Dm * v[1:]
        return pin.aba(self._pin_model, self._data, q, v, u)

    def _stacked_acceleration(self, x: np.ndarray, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """:meth:`held_acceleration` of an m-DOF base at x = (q, v), given with its views q and v."""
        u = self._u
        np.dot(self._spring_damper, x, self._u_base)
        if self._f is not None:
            self._u_base += self._f
        if self._arm_damped:
            u[self._m :] = self._tau - self._Dm * v[self._m :]
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
        return self._rk4_any_base(x, f_ext if sampled else None, dt, torque_at)  # type: ignore[arg-type]

    def _rk4_any_base(
        self, x: np.ndarray, samples: StageForces | None, dt: float, torque_at: StageTorque | None
    ) -> np.ndarray:
        """:meth:`rk4_state_step` for an m-DOF base, inputs set by :meth:`hold`: each stage's acceleration
        (:meth:`_stacked_acceleration`) from the stage's row of the buffer, everything it reads bound once."""
        q, v, a, xs, k = self._stage_q, self._stage_v, self._stage_a, self._stage_x, self._stage_k
        aba, pin_model, data, u, dot, add = pin.aba, self._pin_model, self._data, self._u, np.dot, np.add
        base, spring_damper, m, D_m, damped = self._u_base, self._spring_damper, self._m, self._Dm, self._arm_damped
        f = self._f  # f(t); with samples, f(t + dt/2) for k_2, k_3 and f(t + dt) for k_4
        forces = (f, f, f, f) if samples is None else (f, samples[1], samples[1], samples[2])
        xs[0][:] = x
        weights, steps = self._weights(dt)
        for s, c in enumerate(steps):
            dot(spring_damper, xs[s], base)
            if forces[s] is not None:
                base += forces[s]
            if damped:
                u[m:] = self._tau - D_m * v[s][m:]
            a[s][:] = aba(pin_model, data, q[s], v[s], u)
            if c is not None:
                add(x, c * k[s], xs[s + 1])
                if torque_at is not None:
                    self._set_torque(torque_at(c, q[s + 1], v[s + 1]))
        return x + weights.dot(self._slopes)

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
