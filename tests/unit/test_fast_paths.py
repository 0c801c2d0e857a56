"""Fast branches (one coupling row, a 1-DOF base) give what the general formulas give; the simulator's fast paths."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from rns_viz.control import (
    AccelerationLaw,
    DampNullMotion,
    FixedReference,
    Gains,
    JointSample,
    JointServo,
    TrackJointReference,
    acceleration,
    common,
)
from rns_viz.control.acceleration import composite_acceleration
from rns_viz.model import FsmsModel
from rns_viz.sim import ForcePulse, Simulator


def random_states(model: FsmsModel, count: int, rng: np.random.Generator) -> list[tuple[np.ndarray, np.ndarray]]:
    """(q, v) with random angles; every tenth on a singularity of H_bm (arm along the base axis)."""
    singular = [np.zeros(model.n), np.r_[np.pi, np.zeros(model.n - 1)]]
    states = []
    for k in range(count):
        theta = singular[k % 2] if k % 10 == 0 else rng.uniform(-np.pi, np.pi, model.n)
        states.append(
            (np.concatenate([rng.uniform(-0.02, 0.02, model.m), theta]), rng.normal(scale=0.5, size=model.nv))
        )
    return states


@pytest.mark.parametrize("name", ["trep", "planar3r"])
def test_one_row_branches_equal_the_general_ones(name: str, bundled_model: Callable[[str], FsmsModel]) -> None:
    """Eq. (15) and the resolved acceleration of Fig. 1: the 1-DOF-base branches give what the
    general (any rows, numpy blocks and a solve) branches give, to rounding, singularities included."""
    model = bundled_model(name)
    rng = np.random.default_rng(7)
    for q, v in random_states(model, 200, rng):
        gains = Gains(g_b=rng.uniform(0, 30), g_m=rng.uniform(0, 30))
        inputs = [
            DampNullMotion(rng.uniform(0, 30)),
            TrackJointReference(JointSample.held(rng.uniform(-1, 1, model.n)), 40.0, 10.0),
        ]
        for null_input in inputs:
            law = AccelerationLaw(model, gains, null_input=null_input)
            cp = law.coupling(q, v)
            null = null_input(0.0, cp, q, v)
            fast = acceleration._one_coupling_row(cp, gains.g_b, gains.g_m, null)
            general = acceleration._any_coupling_rows(cp, gains.g_b, gains.g_m, null)
            np.testing.assert_allclose(fast, general, rtol=0, atol=1e-12 * (1.0 + np.abs(general).max()))
            tau_fast = common._one_dof_base_torques(model, cp, q, v, general)
            tau_general = common._any_base_torques(model, cp, q, v, general)
            np.testing.assert_allclose(tau_fast, tau_general, rtol=0, atol=1e-12 * (1.0 + np.abs(tau_general).max()))


def test_null_input_is_projected_into_the_rns(planar3r: FsmsModel) -> None:
    """Eq. (14): whatever u, the law's P u leaves the coupling momentum's rate unchanged: H_bm P u = 0
    up to the damping of H_bm^+ (none away from singularities)."""
    rng = np.random.default_rng(8)
    for q, v in random_states(planar3r, 50, rng)[1:]:
        law = AccelerationLaw(
            planar3r, Gains(g_b=0.0, g_m=0.0), TrackJointReference(JointSample.held(q[1:] + 1), 9.0, 3.0)
        )
        cp = law.coupling(q, v)
        if cp.sigma < law.coupling.threshold:
            continue
        null = law.null_input(0.0, cp, q, v)
        with_input = composite_acceleration(cp, 0.0, 0.0, null)
        without = composite_acceleration(cp, 0.0, 0.0, type(null)())
        np.testing.assert_allclose(cp.H_bm @ (with_input - without), 0.0, atol=1e-12 * np.abs(null.u).max())


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


def test_one_row_coupling_numbers_are_the_mass_matrix_and_state(planar3r: FsmsModel) -> None:
    """The floats the one-row branches read (Coupling.row) are the numpy blocks the other laws read."""
    law = AccelerationLaw(planar3r, Gains())
    q = planar3r.q(planar3r.spec.default_configuration + 0.2, [0.01])
    v = np.array([0.1, 0.2, -0.3, 0.4])
    cp = law.coupling(q, v)
    M, _, hbm_dot = planar3r.dynamics(q, v)
    row = cp.row
    assert row is not None
    np.testing.assert_array_equal(row.M_rows, M)
    np.testing.assert_array_equal(row.h, M[0, 1:])
    np.testing.assert_array_equal(row.thetadot, cp.thetadot)
    assert (row.H_b, row.xdot_b, row.hbm_dot_thetadot) == (M[0, 0], v[0], hbm_dot[0])
    np.testing.assert_allclose(cp.coupling_momentum, M[:1, 1:] @ v[1:], rtol=1e-15)
    np.testing.assert_allclose(row.L, cp.coupling_momentum[0], rtol=1e-15)
    assert cp.sigma == pytest.approx(np.linalg.norm(M[0, 1:]), rel=1e-15)


def test_default_null_input_follows_its_gain() -> None:
    """The default null input's output is built once per g_m: a new g_m (retune or set) is used at once."""
    damp = DampNullMotion(2.0)
    assert damp(0.0, None, None, None).damping == 2.0  # type: ignore[arg-type]
    damp.retune(Gains(g_m=5.0))
    assert damp(0.0, None, None, None).damping == 5.0  # type: ignore[arg-type]
    damp.g_m = 7.0
    assert damp(0.0, None, None, None).damping == 7.0  # type: ignore[arg-type]


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
