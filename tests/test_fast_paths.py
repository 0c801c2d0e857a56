"""The simulator's fast paths give what the plain formulas give (issue "Figures to reach", performance)."""

from __future__ import annotations

import numpy as np
import pytest

from rns_viz.control import AccelerationLaw, FixedReference, Gains, JointServo
from rns_viz.control.null_input import DampNullMotion
from rns_viz.model import FsmsModel
from rns_viz.sim import ForcePulse, Simulator


class PlainDamping(DampNullMotion):
    """The same null input, but not the exact type: AccelerationLaw takes its general path (numpy, P formed)."""


@pytest.mark.parametrize("name", ["trep", "planar3r"])
def test_default_null_input_shortcut_equals_general_law(name: str) -> None:
    model = FsmsModel.from_name(name)
    rng = np.random.default_rng(7)
    singular = [np.zeros(model.n), np.r_[np.pi, np.zeros(model.n - 1)]]
    for k in range(200):
        theta = singular[k % 2] if k % 10 == 0 else rng.uniform(-np.pi, np.pi, model.n)
        q = np.concatenate([rng.uniform(-0.02, 0.02, model.m), theta])
        v = rng.normal(scale=0.5, size=model.nv)
        gains = Gains(g_b=rng.uniform(0, 30), g_m=rng.uniform(0, 30))
        g_u = gains.g_m if k % 2 else rng.uniform(0, 30)  # the null input may have its own gain
        fast = AccelerationLaw(model, gains, null_input=DampNullMotion(g_u))(0.0, q, v)
        plain = AccelerationLaw(model, gains, null_input=PlainDamping(g_u))(0.0, q, v)
        scale = 1.0 + np.abs(plain.tau).max()
        np.testing.assert_allclose(fast.tau, plain.tau, atol=1e-12 * scale, rtol=0)
        np.testing.assert_allclose(fast.coupling_momentum, plain.coupling_momentum, rtol=1e-13, atol=1e-16)
        assert fast.sigma_hbm == pytest.approx(plain.sigma_hbm, rel=1e-14)


def test_coupling_blocks_match_the_mass_matrix(planar3r: FsmsModel) -> None:
    law = AccelerationLaw(planar3r, Gains())
    q = planar3r.q(planar3r.spec.default_configuration, [0.01])
    v = np.array([0.1, 0.2, -0.3, 0.4])
    cp = law.coupling(q, v)
    M = planar3r.mass_matrix(q)
    np.testing.assert_array_equal(cp.H_b, M[:1, :1])
    np.testing.assert_array_equal(cp.H_bm, M[:1, 1:])
    np.testing.assert_array_equal(cp.H_m, M[1:, 1:])
    np.testing.assert_array_equal(cp.x_b, q[:1])
    np.testing.assert_array_equal(cp.xdot_b, v[:1])
    np.testing.assert_array_equal(cp.theta, q[1:])
    np.testing.assert_allclose(cp.H_bm_pinv, np.linalg.pinv(M[:1, 1:]), rtol=1e-13)
    np.testing.assert_allclose(cp.P, np.eye(3) - np.linalg.pinv(M[:1, 1:]) @ M[:1, 1:], atol=1e-15)
    np.testing.assert_allclose(cp.project(v[1:]), cp.P @ v[1:], atol=1e-15)


@pytest.mark.parametrize("capacity", [50, 1000])
def test_logged_end_effector_is_forward_kinematics(trep: FsmsModel, capacity: int) -> None:
    """ee columns are filled when the log is read; reads mid-run and ring wrap-around included."""
    theta0 = trep.spec.default_configuration
    law = JointServo(trep, Gains(), FixedReference(theta0 + 0.3))
    sim = Simulator(trep, law, force=ForcePulse(0.0, 0.1, (0.8,)), log_capacity=capacity)
    for steps in (30, 1, 170):
        sim.run(steps * sim.dt)
        rows = sim.log.array()
        thetas = rows[:, [sim.log.index["theta_1"], sim.log.index["theta_2"]]]
        ee = rows[:, [sim.log.index[c] for c in ("ee_x", "ee_y", "ee_z")]]
        expected = np.array([trep.ee_position(theta) for theta in thetas])
        np.testing.assert_allclose(ee, expected, atol=1e-15, rtol=0)
    assert len(sim.log) == min(capacity, 201)


def test_no_end_effector_columns_without_log_ee(trep: FsmsModel) -> None:
    sim = Simulator(trep, JointServo(trep, Gains(), FixedReference(trep.spec.default_configuration)), log_ee=False)
    sim.run(0.05)
    assert np.all(np.isnan(sim.log.column("ee_x")))
    assert np.all(np.isfinite(sim.log.column("theta_1")))


def test_state_views_and_setters(trep: FsmsModel) -> None:
    sim = Simulator(trep, JointServo(trep, Gains(), FixedReference(trep.spec.default_configuration)))
    sim.q = trep.q(np.array([0.5, 0.5]), [0.001])
    sim.v = np.array([0.0, 0.1, 0.0])
    np.testing.assert_array_equal(sim.q, [0.001, 0.5, 0.5])
    np.testing.assert_array_equal(sim.v, [0.0, 0.1, 0.0])
    held = sim.q
    sim.step()
    np.testing.assert_array_equal(held, [0.001, 0.5, 0.5])  # a step makes a new state, old views keep theirs
    with pytest.raises(ValueError):
        sim.q = np.zeros(2)


def test_plant_rk4_step_splits_the_stacked_step(planar3r: FsmsModel) -> None:
    sim = Simulator(planar3r, JointServo(planar3r, Gains(), FixedReference(planar3r.spec.default_configuration)))
    q, v, tau = planar3r.q(planar3r.spec.default_configuration, [0.01]), np.full(4, 0.1), np.array([1.0, -2.0, 3.0])
    q1, v1 = sim.plant.rk4_step(q, v, tau, np.array([2.0]), 1e-3)
    x1 = sim.plant.rk4_state_step(np.concatenate([q, v]), tau, np.array([2.0]), 1e-3)
    np.testing.assert_array_equal(np.concatenate([q1, v1]), x1)
