"""The simulation loop: a control law driving the plant, with force events and a step log.

Default: RK4 at 1 ms with the torque computed once per step and held over it (a digital
controller). ``hold_control=False`` evaluates the law at every RK4 stage (continuous time),
used where a closed-form continuous closed loop is the oracle.
"""

from __future__ import annotations

import numpy as np

from rns_viz.control.common import ControlLaw, ControlOutput
from rns_viz.model import FsmsModel
from rns_viz.sim.disturbance import ForceInput, NoForce
from rns_viz.sim.log import StepLog, log_columns
from rns_viz.sim.plant import Plant

INTEGRATORS = ("rk4", "semi-implicit-euler")


class SimulationDiverged(RuntimeError):
    """The state left finite numbers; the simulator keeps its last finite state."""


class Simulator:
    """Owns (t, q, v); ``step()`` advances one control period."""

    def __init__(
        self,
        model: FsmsModel,
        law: ControlLaw,
        dt: float = 1e-3,
        force: ForceInput | None = None,
        integrator: str = "rk4",
        hold_control: bool = True,
        q0: np.ndarray | None = None,
        v0: np.ndarray | None = None,
        log_capacity: int = 20000,
        log_ee: bool = True,
    ) -> None:
        if not (np.isfinite(dt) and 0 < dt <= 0.05):
            raise ValueError(f"dt must be in (0, 0.05] s, got {dt}")
        if integrator not in INTEGRATORS:
            raise ValueError(f"integrator must be one of {INTEGRATORS}, got {integrator!r}")
        if integrator != "rk4" and not hold_control:
            raise ValueError("continuous-time control needs the RK4 integrator")
        self.model = model
        self.plant = Plant(model)
        self.law = law
        self.dt = dt
        self.force = force or NoForce()
        self.integrator = integrator
        self.hold_control = hold_control
        self.log_ee = log_ee
        r = len(model.selected)
        p = len(model.task_rows)
        self.log = StepLog(log_columns(model.m, model.n, r, p), log_capacity)
        self._row = np.full(len(self.log.columns), np.nan)
        self._p = p
        self.reset(q0, v0)

    def reset(self, q0: np.ndarray | None = None, v0: np.ndarray | None = None, t0: float = 0.0) -> None:
        model = self.model
        self.t = t0
        self.q = model.q(model.spec.default_configuration) if q0 is None else np.array(q0, dtype=float)
        self.v = np.zeros(model.nv) if v0 is None else np.array(v0, dtype=float)
        if self.q.shape != (model.nv,) or self.v.shape != (model.nv,):
            raise ValueError(f"q0 and v0 must have {model.nv} entries")
        self.log.clear()
        self.last: ControlOutput | None = None
        self.last_force: np.ndarray | None = None

    def step(self) -> ControlOutput:
        """Compute the control at t, advance the state by dt, log the step; returns the control."""
        t, q, v, dt = self.t, self.q, self.v, self.dt
        out = self.law(t, q, v)
        f = self.force(t)
        if not self.hold_control:
            q_next, v_next = self._rk4_continuous(t, q, v, dt)
        elif self.integrator == "rk4":
            q_next, v_next = self.plant.rk4_step(q, v, out.tau, f, dt)
        else:
            q_next, v_next = self.plant.semi_implicit_euler_step(q, v, out.tau, f, dt)
        if not (np.all(np.isfinite(q_next)) and np.all(np.isfinite(v_next)) and np.all(np.isfinite(out.tau))):
            raise SimulationDiverged(f"the state became non-finite at t = {t:.3f} s; kept the last finite state")
        self._record(out, f)
        self.q, self.v, self.t = q_next, v_next, t + dt
        self.last, self.last_force = out, f
        return out

    def _rk4_continuous(self, t: float, q: np.ndarray, v: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
        def acc(ts: float, qs: np.ndarray, vs: np.ndarray) -> np.ndarray:
            return self.plant.acceleration(qs, vs, self.law(ts, qs, vs).tau, self.force(ts))

        h = 0.5 * dt
        a1 = acc(t, q, v)
        v2 = v + h * a1
        a2 = acc(t + h, q + h * v, v2)
        v3 = v + h * a2
        a3 = acc(t + h, q + h * v2, v3)
        v4 = v + dt * a3
        a4 = acc(t + dt, q + dt * v3, v4)
        s = dt / 6.0
        return q + s * (v + 2.0 * (v2 + v3) + v4), v + s * (a1 + 2.0 * (a2 + a3) + a4)

    def _record(self, out: ControlOutput, f: np.ndarray | None) -> None:
        model, row = self.model, self._row
        m, n = model.m, model.n
        row[:] = np.nan
        row[0] = self.t
        i = 1
        row[i : i + m] = self.q[:m]
        row[i + m : i + 2 * m] = self.v[:m]
        i += 2 * m
        row[i : i + n] = self.q[m:]
        row[i + n : i + 2 * n] = self.v[m:]
        row[i + 2 * n : i + 3 * n] = out.tau
        i += 3 * n
        row[i : i + m] = 0.0 if f is None else f
        i += m
        if self.log_ee:
            row[i : i + 3] = model.ee_position(self.q[m:])
        i += 3
        r = len(out.coupling_momentum)
        row[i : i + r] = out.coupling_momentum
        i += r
        row[i] = out.sigma_hbm
        row[i + 1] = out.sigma_jbar
        i += 2
        if out.theta_ref is not None:
            row[i : i + n] = out.theta_ref
        i += n
        if out.ee_ref is not None:
            row[i : i + len(out.ee_ref)] = out.ee_ref
        self.log.append(row)

    def resize_log(self, capacity: int) -> None:
        """Keep ``capacity`` rows from now on (the current rows are dropped)."""
        self.log = StepLog(self.log.columns, capacity)

    def run(self, duration: float) -> StepLog:
        """Advance by ``duration`` seconds (rounded to whole steps) and return the log."""
        if not (np.isfinite(duration) and duration >= 0):
            raise ValueError(f"duration must be a non-negative number of seconds, got {duration}")
        for _ in range(round(duration / self.dt)):
            self.step()
        return self.log
