"""The simulation loop: a control law driving the plant, with force events and a step log.

Default: RK4 at 1 ms with the external force, a continuous input, sampled at the RK4 stage times
t, t + dt/2 and t + dt. A law that is sampled at t (``law.sampled(t)``: vibration suppression in
force) is a digital controller: its torque is computed once per step and held over it. One that is
not (a joint servo holding or moving the arm, a law with g_b = 0) is evaluated at every RK4 stage,
its state and time, as a continuous-time loop: a held arm is held, and the base rings as the
structure alone instead of being fed back half a step late. ``hold_control=False`` treats every
law so (continuous time), where a closed-form continuous closed loop is the oracle. The log's
``tau`` and ``fext`` columns hold the torque and force at the row's time t (the first stage).

For laws (15) and (30) the whole step (law + RK4) runs in C++ when the optional native module is
installed (:mod:`rns_viz.sim.native`); ``native=False`` forces Python.
"""

from __future__ import annotations

import math

import numpy as np

from rns_viz.control.common import ControlLaw, ControlOutput
from rns_viz.model import FsmsModel
from rns_viz.sim import native as native_step
from rns_viz.sim.disturbance import ForceInput, NoForce, stage_forces
from rns_viz.sim.log import RowLayout, StepLog
from rns_viz.sim.plant import Plant

INTEGRATORS = ("rk4", "semi-implicit-euler")
_DIVERGED = "the state became non-finite at t = {t:.3f} s; kept the last finite state"


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
        native: bool = True,
    ) -> None:
        if not (np.isfinite(dt) and 0 < dt <= 0.05):
            raise ValueError(f"dt must be in (0, 0.05] s, got {dt}")
        if integrator not in INTEGRATORS:
            raise ValueError(f"integrator must be one of {INTEGRATORS}, got {integrator!r}")
        if integrator != "rk4" and not hold_control:
            raise ValueError("continuous-time control needs the RK4 integrator")
        self.model = model
        self.plant = Plant(model)
        self.dt = dt
        self.force = force or NoForce()
        self.integrator = integrator
        self.hold_control = hold_control
        self.use_native = native and native_step.available() and integrator == "rk4"
        self.law = law
        self.log_ee = log_ee  # end-effector columns; filled when the log is read (see _complete_rows)
        self._nv = model.nv
        self._layout = RowLayout(model)
        self._ee_data = model.pin_model.createData()  # log reads never touch the laws' pinocchio data
        self.log = StepLog(self._layout.columns, self._layout.units, log_capacity, self._complete_rows)
        self.reset(q0, v0)

    @property
    def law(self) -> ControlLaw:
        return self._law

    @law.setter
    def law(self, law: ControlLaw) -> None:
        self._law = law
        # a bare callable (no ``sampled``) is a digital controller: its torque is held over each step
        self._sampled = getattr(law, "sampled", _always_sampled)
        self._native = native_step.step_for(self.model, law) if self.use_native else None

    @property
    def native(self) -> bool:
        """True while steps run in C++ (see rns_viz.sim.native for the laws it covers)."""
        return self._native is not None

    # -- state: q and v are views of one stacked array x = (q, v) ------------------------------------
    @property
    def q(self) -> np.ndarray:
        """(x_b, theta) at time t (a view of the state: writing into it changes the state)."""
        return self._x[: self._nv]

    @q.setter
    def q(self, value: np.ndarray) -> None:
        self._x = np.concatenate((self._checked(value, "q"), self._x[self._nv :]))

    @property
    def v(self) -> np.ndarray:
        """(x_b', theta') at time t (a view of the state)."""
        return self._x[self._nv :]

    @v.setter
    def v(self, value: np.ndarray) -> None:
        self._x = np.concatenate((self._x[: self._nv], self._checked(value, "v")))

    def _checked(self, value: np.ndarray, name: str) -> np.ndarray:
        arr = np.array(value, dtype=float)
        if arr.shape != (self._nv,):
            raise ValueError(f"{name} must have {self._nv} entries")
        return arr

    def reset(self, q0: np.ndarray | None = None, v0: np.ndarray | None = None, t0: float = 0.0) -> None:
        model = self.model
        self.t = t0
        q = model.q(model.spec.default_configuration) if q0 is None else q0
        v = np.zeros(model.nv) if v0 is None else v0
        if np.shape(q) != (model.nv,) or np.shape(v) != (model.nv,):
            raise ValueError(f"q0 and v0 must have {model.nv} entries")
        self._x = np.concatenate((np.asarray(q, dtype=float), np.asarray(v, dtype=float)))
        self.log.clear()
        self.last: ControlOutput | None = None
        self.last_force: np.ndarray | None = None

    # -- stepping ------------------------------------------------------------------------------------
    def step(self) -> ControlOutput:
        """Compute the control at t, advance the state by dt, log the step; returns the control."""
        t, x, dt = self.t, self._x, self.dt
        force = self.force
        forces = None if type(force) is NoForce else stage_forces(force, t, dt)  # at t, t + dt/2, t + dt
        f = None if forces is None else forces[0]
        staged = not (self.hold_control and self._sampled(t))  # the law at every RK4 stage
        try:  # law and RK4 in one C++ call, which checks finiteness (None: the law is Python's)
            stepped = self._native(t, x, forces, dt, staged) if self._native is not None else None
        except FloatingPointError:
            raise SimulationDiverged(_DIVERGED.format(t=t)) from None
        if stepped is not None:
            x_next, out = stepped
        else:
            q, v = x[: self._nv], x[self._nv :]
            law = self._law
            out = law(t, q, v)
            if self.integrator == "rk4":
                at_stage = (lambda h, q_s, v_s: law(t + h, q_s, v_s).tau) if staged else None
                x_next = self.plant.rk4_state_step(x, out.tau, forces, dt, at_stage)
            else:
                x_next = np.concatenate(self.plant.semi_implicit_euler_step(q, v, out.tau, f, dt))
            # no inf or NaN in x or tau: their sum of squares is finite (one number to test; entries
            # beyond 1e154, where it overflows, mean a diverged run too)
            tau = out.tau
            if not math.isfinite(x_next.dot(x_next) + tau.dot(tau)):
                raise SimulationDiverged(_DIVERGED.format(t=t))
        self._layout.write(self.log.next_row(), t, x, out, f)
        self._x, self.t = x_next, t + dt
        self.last, self.last_force = out, f
        return out

    def _complete_rows(self, rows: np.ndarray) -> None:
        """The end-effector columns of newly logged rows, from their joint angles (run on reading)."""
        layout = self._layout
        if self.log_ee:
            thetas = rows[:, layout.theta]
            rows[:, layout.ee] = self.model.ee_positions(thetas, self._ee_data)
        else:
            rows[:, layout.ee] = np.nan

    def resize_log(self, capacity: int) -> None:
        """Keep ``capacity`` rows from now on (the current rows are dropped)."""
        self.log = StepLog(self.log.columns, self.log.units, capacity, self._complete_rows)

    def run(self, duration: float) -> StepLog:
        """Advance by ``duration`` seconds (rounded to whole steps) and return the log."""
        if not (np.isfinite(duration) and duration >= 0):
            raise ValueError(f"duration must be a non-negative number of seconds, got {duration}")
        for _ in range(round(duration / self.dt)):
            self.step()
        return self.log


def _always_sampled(t: float) -> bool:
    return True
