"""Simulator and control laws: closed-form closed loop, invariants, damping, determinism."""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import replace

import numpy as np
import pytest
from scipy.linalg import expm

from rns_viz.control import (
    AccelerationLaw,
    FixedReference,
    Gains,
    InvalidGain,
    JointServo,
    TorqueLaw,
    VelocityLaw,
)
from rns_viz.control.common import ControlOutput
from rns_viz.control.null_input import NullOutput
from rns_viz.model import FsmsModel
from rns_viz.sim import ForcePulse, SimulationDiverged, Simulator


class ZeroTorque:
    def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> ControlOutput:
        return ControlOutput(tau=np.zeros(len(q) - 1), coupling_momentum=np.zeros(1), sigma_hbm=np.nan)


def cubic_response(H_b: float, k: float, d: float, g_b: float, G_m: float, x0: float, t: np.ndarray) -> np.ndarray:
    """x_b(t) of H_b s^3 + (H_b (G_m + g_b) + d) s^2 + (k + d G_m) s + k G_m = 0 (docs/physics-notes.md).

    State (x, x', L): H_b x'' = -k x - d x' - L',  L' = H_b g_b x' - G_m L  (L = H_bm theta').
    """
    A = np.array(
        [
            [0.0, 1.0, 0.0],
            [-k / H_b, -(d / H_b + g_b), G_m / H_b],
            [0.0, H_b * g_b, -G_m],
        ]
    )
    x_init = np.array([x0, 0.0, 0.0])
    return np.array([(expm(A * ti) @ x_init)[0] for ti in t])


@pytest.mark.parametrize(
    ("name", "g_b", "G_m", "x0"), [("trep", 24.0, 20.0, 2e-3), ("trep", 10.0, 2.0, 1e-3), ("planar3r", 10.0, 1.0, 1e-2)]
)
def test_acceleration_law_matches_closed_loop_cubic(
    name: str, g_b: float, G_m: float, x0: float, bundled_model: Callable[[str], FsmsModel]
) -> None:
    model = bundled_model(name)
    law = AccelerationLaw(model, Gains(g_b=g_b, g_m=G_m))
    q0 = model.q(model.spec.default_configuration, [x0])
    sim = Simulator(model, law, hold_control=False, q0=q0, log_capacity=5001)
    sim.run(5.0)
    t = sim.log.column("t")
    expected = cubic_response(
        model.arm_mass + (1.225 - 0.43 if name == "trep" else 1.0), model.K_b[0, 0], model.D_b[0, 0], g_b, G_m, x0, t
    )
    np.testing.assert_allclose(sim.log.column("xb_1"), expected, atol=1e-9, rtol=0)
    assert np.ptp(sim.log.column("theta_1")) > 1e-3  # the arm really moved to absorb the deflection


def test_cubic_oracle_is_not_trivial() -> None:
    """The oracle distinguishes gains: a wrong g_b gives a visibly different response."""
    t = np.linspace(0, 5, 51)
    a = cubic_response(1.225, 77.9218, 0.0, 24.0, 20.0, 2e-3, t)
    b = cubic_response(1.225, 77.9218, 0.0, 20.0, 20.0, 2e-3, t)
    assert np.abs(a - b).max() > 1e-5


@pytest.mark.parametrize("name", ["trep", "planar3r"])
def test_passive_system_conserves_energy_and_momentum(name: str, bundled_model: Callable[[str], FsmsModel]) -> None:
    """Zero torque, no damping: energy constant; total momentum changes only by the spring impulse."""
    spec = bundled_model(name).spec
    model = FsmsModel(replace(spec, base=replace(spec.base, damping=np.zeros((1, 1)))))  # no base damper
    rng = np.random.default_rng(1)
    q0 = model.q(model.spec.default_configuration, [0.01])
    v0 = np.concatenate([[0.0], rng.normal(scale=0.5, size=model.n)])
    sim = Simulator(model, ZeroTorque(), q0=q0, v0=v0)
    e0 = sim.plant.energy(sim.q, sim.v)
    sim.run(2.0)
    assert abs(sim.plant.energy(sim.q, sim.v) - e0) <= 1e-8 * e0


@pytest.mark.parametrize("law_cls", [AccelerationLaw, TorqueLaw])
def test_composite_laws_damp_a_kick(law_cls: type, trep: FsmsModel) -> None:
    """With suppression the kick dies out; with the joints held, TREP (no base damping) keeps vibrating."""
    model = trep

    def peak_after(suppress: bool) -> float:
        gains = Gains(g_b=24.0, g_m=5.0)
        theta0 = model.spec.default_configuration
        law = law_cls(model, gains) if suppress else JointServo(model, gains, FixedReference(theta0))
        sim = Simulator(model, law, force=ForcePulse(0.2, 0.1, (0.8,)))
        sim.run(6.0)
        xb = sim.log.column("xb_1")
        return float(np.abs(xb[-1000:]).max() / np.abs(xb).max())

    assert peak_after(True) < 0.05
    assert peak_after(False) > 0.9


def test_torque_law_sign_convention(trep: FsmsModel) -> None:
    """A negative gain must excite: the sign of G_b in (16) is the damping one."""
    model = trep
    law = TorqueLaw(model, Gains(g_b=2.0, g_m=0.0))
    law.gains = Gains.__new__(Gains)  # bypass validation to test the sign: g_b = -2
    object.__setattr__(law.gains, "g_b", -2.0)
    object.__setattr__(law.gains, "g_m", 0.0)
    sim = Simulator(model, law, q0=model.q(model.spec.default_configuration, [1e-3]))
    sim.run(1.0)
    assert np.abs(sim.log.column("xb_1")).max() > 2e-3


def test_reactionless_motion_does_not_move_the_base(trep: FsmsModel) -> None:
    """Joint velocity along n from a resting base: the coupling momentum stays zero, so does x_b."""
    model = trep
    theta0 = np.array([1.0, 1.0])
    h = model.coupling_matrix(model.q(theta0))[0]
    n = np.array([h[1], -h[0]])
    v0 = np.concatenate([[0.0], 30.0 * n])
    law = AccelerationLaw(model, Gains(g_b=0.0, g_m=0.0), suppress=False)
    law.null_input = lambda t, cp, q, v: NullOutput(np.zeros(2))  # coast along the RNS
    sim = Simulator(model, law, hold_control=False, q0=model.q(theta0), v0=v0)
    sim.run(1.0)
    assert np.abs(sim.log.column("xb_1")).max() < 1e-9
    assert np.abs(sim.log.column("L_1")).max() < 1e-9
    assert np.ptp(sim.log.column("theta_2")) > 0.5


def test_velocity_law_damps_and_holds(trep: FsmsModel) -> None:
    model = trep
    theta0 = model.spec.default_configuration
    sim = Simulator(
        model, VelocityLaw(model, Gains(g_b=24.0, g_m=20.0), FixedReference(theta0)), q0=model.q(theta0, [5e-3])
    )
    sim.run(10.0)
    assert abs(sim.q[0]) < 3e-4
    np.testing.assert_allclose(sim.q[1:], theta0, atol=0.05)


def test_joint_servo_holds_against_a_kick(planar3r: FsmsModel) -> None:
    model = planar3r
    theta0 = model.spec.default_configuration
    sim = Simulator(model, JointServo(model, Gains(), FixedReference(theta0)), force=ForcePulse(0.1, 0.2, (5.0,)))
    sim.run(3.0)
    assert np.abs(sim.log.column("xb_1")).max() > 5e-3
    np.testing.assert_allclose(sim.q[1:], theta0, atol=1e-3)


def test_simulation_is_deterministic(trep: FsmsModel) -> None:
    model = trep

    def run() -> np.ndarray:
        law = AccelerationLaw(model, Gains(g_b=24.0, g_m=20.0))
        sim = Simulator(model, law, force=ForcePulse(0.1, 0.1, (0.8,)))
        sim.run(1.0)
        return sim.log.array()

    np.testing.assert_array_equal(run(), run())


def test_no_nan_at_the_trep_singularity(trep: FsmsModel) -> None:
    """Start on H_bm = 0 (arm along x) with a deflection: the damped inverse keeps numbers finite."""
    model = trep
    for theta in ([0.0, 0.0], [0.0, np.pi], [np.pi, 0.0]):
        for law in (
            AccelerationLaw(model, Gains(g_b=24.0, g_m=2.0)),
            TorqueLaw(model, Gains(g_b=24.0, g_m=2.0)),
            VelocityLaw(model, Gains(g_b=24.0, g_m=20.0), FixedReference(np.array(theta))),
        ):
            sim = Simulator(model, law, q0=model.q(np.array(theta), [0.01]))
            sim.run(2.0)
            state = [c for c in sim.log.columns if re.fullmatch(r"(xb|xbdot|theta|thetadot|tau|L)_\d", c)]
            assert np.all(np.isfinite([sim.log.column(c) for c in state]))


def test_divergence_is_reported_not_hidden(trep: FsmsModel) -> None:
    model = trep

    class Wild:
        def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> ControlOutput:
            return ControlOutput(tau=np.array([np.inf, 0.0]), coupling_momentum=np.zeros(1), sigma_hbm=1.0)

    sim = Simulator(model, Wild())
    q_before = sim.q.copy()
    with pytest.raises(SimulationDiverged):
        sim.step()
    np.testing.assert_array_equal(sim.q, q_before)


@pytest.mark.parametrize("bad", [float("nan"), float("inf"), -1.0, 1e9, "3"])
def test_gains_refuse_bad_values(bad: object) -> None:
    with pytest.raises(InvalidGain):
        Gains(g_b=bad)  # type: ignore[arg-type]


def test_cheap_integrator_is_close_to_rk4(trep: FsmsModel) -> None:
    """The semi-implicit Euler option tracks the RK4 reference to within a few per cent at 1 ms."""
    model = trep
    theta0 = model.spec.default_configuration

    def run(integrator: str) -> np.ndarray:
        law = VelocityLaw(model, Gains(g_b=24.0, g_m=20.0), FixedReference(theta0))
        sim = Simulator(model, law, integrator=integrator, q0=model.q(theta0, [5e-3]))
        sim.run(3.0)
        return sim.log.column("xb_1")

    rk4, euler = run("rk4"), run("semi-implicit-euler")
    assert np.abs(rk4 - euler).max() < 0.05 * np.abs(rk4).max()
    assert np.abs(rk4 - euler).max() > 0  # a different integrator, not the same code path
