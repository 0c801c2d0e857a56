"""The native closed-loop step: a law of the paper and RK4 with the torque held, in one C++ call.

The optional distribution ``rns-viz-native`` (``pip install ./native``; see :mod:`rns_viz._native`)
computes, on a pinocchio model it builds from the same URDF text:

- :class:`~rns_viz.control.AccelerationLaw` (15) with :class:`~rns_viz.control.DampNullMotion`,
  :class:`~rns_viz.control.TrackJointReference` or :class:`~rns_viz.control.TrackEndEffector`
  (Eq. 24) as null-space input;
- :class:`~rns_viz.control.VelocityLaw` (30) behind its velocity servo;

then :meth:`~rns_viz.sim.plant.Plant.rk4_state_step` with the force at the stage times.
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
    TrackEndEffector,
    TrackJointReference,
    VelocityLaw,
)
from rns_viz.model import FsmsModel
from rns_viz.sim.disturbance import StageForces

Ref = np.ndarray | None  # theta_ref, or ee_ref (the target x_d) for Eq. (24)
LawArgs = tuple[Callable[..., float | tuple[float, float]], tuple, Ref]

# The registry: exact type -> what the C++ step computes for it. Only these exact types run natively;
# a subclass (which may change the arithmetic) runs its Python body unless it is added here.
NATIVE_LAWS: dict[type, str] = {AccelerationLaw: "composite", VelocityLaw: "velocity"}
NATIVE_NULL_INPUTS: dict[type, str] = {DampNullMotion: "damp", TrackJointReference: "joint", TrackEndEffector: "task"}


def available() -> bool:
    return _native.core is not None


def unavailable_reason() -> str | None:
    """Why the native step is not available (None when it is)."""
    return _native.why


def native_kind(law: object) -> str | None:
    """What the C++ step computes for this law ("velocity", "damp", "joint" or "task"), looked up by
    exact type; None: the law runs in Python."""
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

    def __init__(self, model: FsmsModel, law: AccelerationLaw | VelocityLaw, robot: Any | None = None) -> None:
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
        self._velocity = type(law) is VelocityLaw
        self._law_args = self._velocity_args if self._velocity else self._composite_args
        self._damped_step = self._core.damped_step

    def __call__(
        self, t: float, x: np.ndarray, forces: StageForces | None, dt: float
    ) -> tuple[np.ndarray, ControlOutput] | None:
        """x_next and the control; None when the law's null-space input changed to one computed in
        Python only; FloatingPointError (nothing kept) when the step is not finite.

        ``forces``: the base force at t, t + dt/2 and t + dt (None: no force over the step)."""
        x_next, tau, L = np.empty(self._nx), np.empty(self._n), np.empty(self._r)
        f = self._no_force if forces is None else self._stacked(forces)
        law = self.law
        if not self._velocity and type(law.null_input) is DampNullMotion:  # type: ignore[union-attr]
            # the common case without a reference, kept short: this runs at every step
            g_b = law.suppression_gain(t)  # type: ignore[union-attr]
            sigma = self._damped_step(x, g_b, law.gains.g_m, law.null_input.g_m, f, dt, x_next, tau, L)  # type: ignore[union-attr]
            return x_next, ControlOutput(tau, L, sigma)
        law_args = self._law_args(t, control=False)
        if law_args is None:
            return None
        step, args, ref = law_args
        return x_next, self._output(step(x, *args, f, dt, x_next, tau, L), tau, L, ref)

    def _stacked(self, forces: StageForces) -> np.ndarray:
        out, m = self._forces, self._m
        for i, f in enumerate(forces):
            out[i * m : (i + 1) * m] = 0.0 if f is None else f
        return out

    def control(self, t: float, x: np.ndarray) -> ControlOutput:
        """The law alone at (t, x): what ``law(t, q, v)`` returns, computed natively."""
        law_args = self._law_args(t, control=True)
        if law_args is None:
            raise ValueError(f"the native step does not compute {type(self.law.null_input).__name__}")  # type: ignore[union-attr]
        control, args, ref = law_args
        tau, L = np.empty(self._n), np.empty(self._r)
        return self._output(control(np.ascontiguousarray(x, dtype=float), *args, tau, L), tau, L, ref)

    def _output(self, sigmas: float | tuple[float, float], tau: np.ndarray, L: np.ndarray, ref: Ref) -> ControlOutput:
        """The ControlOutput of a native call: sigma(s) as returned, theta_ref or ee_ref as passed in."""
        if isinstance(sigmas, tuple):  # Eq. (24): sigma of S H_bm and of J-bar; ref is the target
            return ControlOutput(tau, L, sigmas[0], sigma_jbar=sigmas[1], ee_ref=ref)
        return ControlOutput(tau, L, sigmas, theta_ref=ref)

    # The law's entry point, its arguments at time t (gains and references read now), theta_ref.
    def _composite_args(self, t: float, control: bool) -> LawArgs | None:
        law, core = self.law, self._core
        g_b, g_m, null = law.suppression_gain(t), law.gains.g_m, law.null_input  # type: ignore[union-attr]
        kind = native_kind(law)
        if kind == "damp":
            return (core.damped_control if control else core.damped_step), (g_b, g_m, null.g_m), None
        if kind == "task":
            x_d, xdot_d, xddot_d = (_vector(a) for a in null.target(t))
            args = (g_b, g_m, null.G_p, null.G_d, null.threshold, x_d, xdot_d, xddot_d)
            return (core.task_control if control else core.task_step), args, x_d
        if kind != "joint":
            return None
        theta_r, thetadot_r, thetaddot_r = (_vector(a) for a in null.reference(t))
        args = (g_b, g_m, null.k_p, null.k_d, theta_r, thetadot_r, thetaddot_r)
        return (core.tracking_control if control else core.tracking_step), args, theta_r

    def _velocity_args(self, t: float, control: bool) -> LawArgs | None:
        law, core = self.law, self._core
        theta_r, thetadot_r, _ = law.reference(t)  # type: ignore[union-attr]
        theta_r, thetadot_r = _vector(theta_r), _vector(thetadot_r)
        args = (law.suppression_gain(t), law.gains.g_m, law.gains.servo_bandwidth, law.feedforward, theta_r, thetadot_r)  # type: ignore[union-attr]
        return (core.velocity_control if control else core.velocity_step), args, theta_r


def _vector(a: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=float)
