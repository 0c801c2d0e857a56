"""The native closed-loop step: a law of the paper and RK4, in one C++ call.

The optional distribution ``rns-viz-native`` (``pip install ./native``; see :mod:`rns_viz._native`)
computes, on a pinocchio model it builds from the same URDF text:

- :class:`~rns_viz.control.AccelerationLaw` (15) with :class:`~rns_viz.control.DampNullMotion`,
  :class:`~rns_viz.control.TrackJointReference` or :class:`~rns_viz.control.TrackEndEffector`
  (Eq. 24) as null-space input;
- :class:`~rns_viz.control.VelocityLaw` (30) behind its velocity servo;
- :class:`~rns_viz.control.JointServo`, the arm held or moved by a joint servo;

then :meth:`~rns_viz.sim.plant.Plant.rk4_state_step` with the force at the stage times, the torque
held over the step or, when the law is not sampled (``law.sampled(t)`` False, or continuous-time
control), the law evaluated again at every stage, g_b and its reference sampled at the stage times
(``staged``).
:class:`~rns_viz.sim.Simulator` uses it for exactly these types (``NATIVE_LAWS``,
``NATIVE_NULL_INPUTS``): a subclass may change the arithmetic, so it runs in Python unless it is
added there. Gains, suppression, references and the force are read from the Python objects at every
step, so changing them takes effect as before. Tests compare trajectories.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from rns_viz import _native
from rns_viz.control import (
    AccelerationLaw,
    ControlOutput,
    DampNullMotion,
    JointServo,
    TrackEndEffector,
    TrackJointReference,
    VelocityLaw,
)
from rns_viz.model import FsmsModel
from rns_viz.sim.disturbance import StageForces

Ref = np.ndarray | None  # theta_ref, or ee_ref (the target x_d) for Eq. (24)
Entry = Callable[..., float | tuple[float, float]]
LawArgs = tuple[Entry, Entry, tuple, Ref]  # the law alone, the step, their arguments, theta_ref or x_d

# The registry: exact type -> what the C++ step computes for it. Only these exact types run natively;
# a subclass (which may change the arithmetic) runs its Python body unless it is added here.
NATIVE_LAWS: dict[type, str] = {AccelerationLaw: "composite", VelocityLaw: "velocity", JointServo: "servo"}
NATIVE_NULL_INPUTS: dict[type, str] = {DampNullMotion: "damp", TrackJointReference: "joint", TrackEndEffector: "task"}


def available() -> bool:
    return _native.core is not None


def unavailable_reason() -> str | None:
    """Why the native step is not available (None when it is)."""
    return _native.why


def native_kind(law: object) -> str | None:
    """What the C++ step computes for this law ("velocity", "servo", "damp", "joint" or "task"), looked
    up by exact type; None: the law runs in Python."""
    kind = NATIVE_LAWS.get(type(law))
    if kind == "composite":
        return NATIVE_NULL_INPUTS.get(type(law.null_input))  # type: ignore[attr-defined]
    return kind


def supports(law: object) -> bool:
    """The native step computes exactly this law (its exact type and its null-space input's)."""
    return native_kind(law) is not None


def step_for(model: FsmsModel, law: object) -> NativeStep | None:
    """The native step for this law, or None: not one of the registry's types, no native module,
    or a C++ model that does not reproduce the Python one."""
    if not supports(law):
        return None
    robot = _native.robot_model(model)
    return None if robot is None else NativeStep(model, law, robot)  # type: ignore[arg-type]


class NativeStep:
    """``(t, x, f_ext, dt) -> (x_next, ControlOutput)`` for one supported law; ``control(t, x)`` alone."""

    def __init__(
        self, model: FsmsModel, law: AccelerationLaw | VelocityLaw | JointServo, robot: Any | None = None
    ) -> None:
        robot = _native.robot_model(model) if robot is None else robot
        if robot is None:
            raise RuntimeError(_native.why or f"the native model of {model.name} differs from the Python one")
        if not supports(law):
            raise ValueError(f"the native step does not compute {type(law).__name__}")
        coupling = law.coupling
        self.law = law
        self._core = _native.core.ClosedLoop(  # type: ignore[union-attr]
            robot,
            [int(i) for i in model.selected],
            np.ones(len(model.selected)) if model.coupling_weights is None else model.coupling_weights,
            np.ascontiguousarray(model.K_b, dtype=float),
            np.ascontiguousarray(model.D_b, dtype=float),
            np.ascontiguousarray(model.D_m, dtype=float),
            float(coupling.threshold),
            float(coupling.max_damping),
            bool(model.cb_is_hbm_dot),
            model.spec.ee_frame,
            int(model.base_joint_id),
            [int(i) for i in model.task_rows],
        )
        self._nx, self._n, self._r = 2 * model.nv, model.n, len(model.selected)
        self._no_force = np.zeros(3 * model.m)
        self._forces = np.empty(3 * model.m)  # f at t, t + dt/2, t + dt (the RK4 stage times)
        self._m = model.m
        kind = native_kind(law)
        self._composite = kind not in ("velocity", "servo")
        self._has_g_b = kind != "servo"  # the arguments start with g_b
        entries = {"velocity": self._velocity_args, "servo": self._servo_args}
        self._law_args = entries.get(kind, self._composite_args)  # type: ignore[arg-type]
        self._damped_step = self._core.damped_step
        self._g_b = np.empty(1)  # g_b of a held step, reused

    def __call__(
        self, t: float, x: np.ndarray, forces: StageForces | None, dt: float, staged: bool = False
    ) -> tuple[np.ndarray, ControlOutput] | None:
        """x_next and the control; None when the law's null-space input changed to one computed in
        Python only; FloatingPointError (nothing kept) when the step is not finite.

        ``forces``: the base force at t, t + dt/2 and t + dt (None: no force over the step).
        ``staged``: the law at every RK4 stage, g_b and the reference at the stage times (a joint
        servo, :meth:`~rns_viz.control.ControlLaw.sampled`); else its torque at t held over the step."""
        x_next, tau, L = np.empty(self._nx), np.empty(self._n), np.empty(self._r)
        f = self._no_force if forces is None else self._stacked(forces)
        law = self.law
        times = (t, t + 0.5 * dt, t + dt) if staged else (t,)
        if self._composite and type(law.null_input) is DampNullMotion:  # type: ignore[union-attr]
            # the common case without a reference, kept short: this runs at every step
            g_b = self._g_b if not staged else np.empty(3)
            for i, s in enumerate(times):
                g_b[i] = law.suppression_gain(s)  # type: ignore[union-attr]
            g_m, g_u = law.gains.g_m, law.null_input.g_m  # type: ignore[union-attr]
            sigma = self._damped_step(x, g_b, g_m, g_u, f, dt, staged, x_next, tau, L)
            return x_next, ControlOutput(tau, L, sigma)
        law_args = self._law_args(times)
        if law_args is None:
            return None
        _, step, args, ref = law_args
        return x_next, self._output(step(x, *args, f, dt, staged, x_next, tau, L), tau, L, ref)

    def _stacked(self, forces: StageForces) -> np.ndarray:
        out, m = self._forces, self._m
        for i, f in enumerate(forces):
            out[i * m : (i + 1) * m] = 0.0 if f is None else f
        return out

    def control(self, t: float, x: np.ndarray) -> ControlOutput:
        """The law alone at (t, x): what ``law(t, q, v)`` returns, computed natively."""
        law_args = self._law_args((t,))
        if law_args is None:
            raise ValueError(f"the native step does not compute {type(self.law.null_input).__name__}")  # type: ignore[union-attr]
        control, _, args, ref = law_args
        args = (float(args[0][0]), *args[1:]) if self._has_g_b else args  # *_control takes g_b as a number
        tau, L = np.empty(self._n), np.empty(self._r)
        return self._output(control(np.ascontiguousarray(x, dtype=float), *args, tau, L), tau, L, ref)

    def _output(self, sigmas: float | tuple[float, float], tau: np.ndarray, L: np.ndarray, ref: Ref) -> ControlOutput:
        """The ControlOutput of a native call: sigma(s) as returned, theta_ref or ee_ref as passed in."""
        if isinstance(sigmas, tuple):  # Eq. (24): sigma of S H_bm and of J-bar; ref is the target
            return ControlOutput(tau, L, sigmas[0], sigma_jbar=sigmas[1], ee_ref=ref)
        return ControlOutput(tau, L, sigmas, theta_ref=ref)

    # The law's entry points (the law alone, the step), its arguments at the given times (gains read
    # now; g_b and the reference at each time, stacked), theta_ref or x_d at the first time.
    def _composite_args(self, times: tuple[float, ...]) -> LawArgs | None:
        law, core = self.law, self._core
        g_b = _stage_values(law.suppression_gain, times)  # type: ignore[union-attr]
        g_m, null = law.gains.g_m, law.null_input  # type: ignore[union-attr]
        kind = native_kind(law)
        if kind == "damp":
            return core.damped_control, core.damped_step, (g_b, g_m, null.g_m), None
        if kind == "task":
            x_d, xdot_d, xddot_d = _samples(null.target, times)
            args = (g_b, g_m, null.G_p, null.G_d, null.threshold, x_d, xdot_d, xddot_d)
            return core.task_control, core.task_step, args, _first(x_d, times)
        if kind != "joint":
            return None
        theta_r, thetadot_r, thetaddot_r = _samples(null.reference, times)
        args = (g_b, g_m, null.k_p, null.k_d, theta_r, thetadot_r, thetaddot_r)
        return core.tracking_control, core.tracking_step, args, _first(theta_r, times)

    def _velocity_args(self, times: tuple[float, ...]) -> LawArgs:
        law, core = self.law, self._core
        theta_r, thetadot_r, _ = _samples(law.reference, times)  # type: ignore[union-attr]
        g_b = _stage_values(law.suppression_gain, times)  # type: ignore[union-attr]
        args = (g_b, law.gains.g_m, law.gains.servo_bandwidth, law.feedforward, theta_r, thetadot_r)  # type: ignore[union-attr]
        return core.velocity_control, core.velocity_step, args, _first(theta_r, times)

    def _servo_args(self, times: tuple[float, ...]) -> LawArgs:
        law, core = self.law, self._core
        theta_r, thetadot_r, thetaddot_r = _samples(law.reference, times)  # type: ignore[union-attr]
        args = (law.gains.k_p, law.gains.k_d, theta_r, thetadot_r, thetaddot_r)
        return core.servo_control, core.servo_step, args, _first(theta_r, times)


def _stage_values(gain: Callable[[float], float], times: tuple[float, ...]) -> np.ndarray:
    """A time-varying gain (g_b) at each time."""
    return np.array([gain(s) for s in times])


def _samples(reference: Callable[[float], tuple[np.ndarray, ...]], times: tuple[float, ...]) -> tuple[np.ndarray, ...]:
    """A reference's arrays (value, rate, acceleration) at each time, each stacked over the times."""
    if len(times) == 1:
        return tuple(_vector(a) for a in reference(times[0]))
    return tuple(_vector(np.concatenate(parts)) for parts in zip(*(reference(s) for s in times), strict=True))


def _first(stacked: np.ndarray, times: tuple[float, ...]) -> np.ndarray:
    """The first time's sample of a stacked reference array."""
    return stacked[: len(stacked) // len(times)]


def _vector(a: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=float)
