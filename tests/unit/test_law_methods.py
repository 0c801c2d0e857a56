"""What a live loop calls on a law between steps: kind, retune, set_suppression, follow (and Switched)."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np
import pytest

from rns_viz.control import (
    AccelerationLaw,
    ControlLaw,
    DampNullMotion,
    FixedReference,
    Gains,
    JointSample,
    JointServo,
    Switched,
    TaskSample,
    TorqueLaw,
    TrackEndEffector,
    TrackJointReference,
    VelocityLaw,
)
from rns_viz.model import FsmsModel
from rns_viz.sim import Simulator

RNG = np.random.default_rng(11)


def state(model: FsmsModel) -> tuple[np.ndarray, np.ndarray]:
    """A deflected, moving state away from singularities."""
    theta = model.spec.default_configuration + RNG.uniform(-0.2, 0.2, model.n)
    return model.q(theta, RNG.uniform(-0.01, 0.01, model.m)), RNG.normal(scale=0.3, size=model.nv)


def torque_map(model: FsmsModel, q: np.ndarray) -> np.ndarray:
    """d tau / d theta'' of resolved acceleration (Fig. 1): H_m - H_bm^T H_b^-1 H_bm, from Eq. (1)."""
    M, m = model.mass_matrix(q), model.m
    return M[m:, m:] - M[:m, m:].T @ np.linalg.solve(M[:m, :m], M[:m, m:])


def test_kinds(trep: FsmsModel) -> None:
    theta0 = trep.spec.default_configuration
    assert AccelerationLaw(trep, Gains()).kind == "acceleration"
    assert TorqueLaw(trep, Gains()).kind == "torque"
    assert VelocityLaw(trep, Gains(), FixedReference(theta0)).kind == "velocity"
    assert JointServo(trep, Gains(), FixedReference(theta0)).kind == "servo"
    switched = Switched(JointServo(trep, Gains(), FixedReference(theta0)), TorqueLaw(trep, Gains()), at=1.0)
    assert switched.kind == "torque"


@pytest.mark.parametrize("name", ["trep", "planar3r"])
def test_retune_of_g_m_changes_theta_ddot_by_minus_delta_g_m_theta_dot(
    name: str, bundled_model: Callable[[str], FsmsModel]
) -> None:
    """Eq. (15) with the default null input: -G_m (E - P) theta' - G_m P theta' = -G_m theta', so
    retuning g_m alone changes theta'' by -(g_m' - g_m) theta', and tau by that through Fig. 1."""
    model = bundled_model(name)
    q, v = state(model)
    law = AccelerationLaw(model, Gains(g_b=5.0, g_m=1.0))
    before = law(0.0, q, v).tau
    law.retune(Gains(g_b=5.0, g_m=4.0))
    assert isinstance(law.null_input, DampNullMotion) and law.null_input.g_m == 4.0
    after = law(0.0, q, v).tau
    expected = torque_map(model, q) @ (-(4.0 - 1.0) * v[model.m :])
    np.testing.assert_allclose(after - before, expected, rtol=1e-9, atol=1e-12)


def test_retune_of_g_b_changes_theta_ddot_along_h_pinv(trep: FsmsModel) -> None:
    """Eq. (15): the G_b term is H_bm^+ H_b g_b x_b', so a change of g_b moves theta'' by
    (g_b' - g_b) h^T H_b x_b' / |h|^2 (no damping away from singularities)."""
    q, v = state(trep)
    law = AccelerationLaw(trep, Gains(g_b=2.0, g_m=1.0))
    before = law(0.0, q, v).tau
    law.retune(Gains(g_b=12.0, g_m=1.0))
    after = law(0.0, q, v).tau
    M = trep.mass_matrix(q)
    h = M[0, 1:]
    delta_thetaddot = 10.0 * h * M[0, 0] * v[0] / (h @ h)
    np.testing.assert_allclose(after - before, torque_map(trep, q) @ delta_thetaddot, rtol=1e-9, atol=1e-12)


def test_retune_reaches_the_tracking_inputs(planar3r: FsmsModel) -> None:
    joint = TrackJointReference(FixedReference(planar3r.spec.default_configuration), 1.0, 1.0)
    target = TrackEndEffector(planar3r, TaskSample.held(np.zeros(2)), 1.0, 1.0)
    AccelerationLaw(planar3r, Gains(), joint).retune(Gains(k_p=7.0, k_d=3.0))
    TorqueLaw(planar3r, Gains(), target).retune(Gains(G_p=70.0, G_d=30.0))
    assert (joint.k_p, joint.k_d) == (7.0, 3.0)
    assert (target.G_p, target.G_d) == (70.0, 30.0)


@pytest.mark.parametrize("kind", ["acceleration", "torque", "velocity"])
def test_suppression_off_is_the_law_with_g_b_zero(trep: FsmsModel, kind: str) -> None:
    theta0 = trep.spec.default_configuration

    def law(gains: Gains) -> ControlLaw:
        if kind == "velocity":
            return VelocityLaw(trep, gains, FixedReference(theta0))
        return (AccelerationLaw if kind == "acceleration" else TorqueLaw)(trep, gains)

    q, v = state(trep)
    switched_off = law(Gains(g_b=20.0, g_m=2.0))
    on = switched_off(0.0, q, v).tau
    switched_off.set_suppression(False)
    assert not switched_off.suppress
    off = switched_off(0.0, q, v).tau
    np.testing.assert_allclose(off, law(Gains(g_b=0.0, g_m=2.0))(0.0, q, v).tau, rtol=1e-13, atol=1e-13)
    assert np.abs(on - off).max() > 1e-3  # the g_b term was there: x_b, x_b' are not zero
    switched_off.set_suppression(True)
    np.testing.assert_allclose(switched_off(0.0, q, v).tau, on, rtol=1e-13, atol=1e-13)


def test_follow_joint_sample_is_what_the_servo_tracks(planar3r: FsmsModel) -> None:
    """JointServo: theta'' = theta_r'' + k_d (theta_r' - theta') + k_p (theta_r - theta) for the sample followed."""
    q, v = state(planar3r)
    gains = Gains(k_p=50.0, k_d=10.0)
    law = JointServo(planar3r, gains, FixedReference(planar3r.spec.default_configuration))
    old = law(0.0, q, v)
    sample = JointSample(np.array([0.3, -0.2, 0.5]), np.array([0.1, 0.0, -0.1]), np.array([1.0, 2.0, 3.0]))
    law.follow(sample)
    new = law(0.0, q, v)
    np.testing.assert_array_equal(new.theta_ref, sample.theta)
    theta, thetadot = q[1:], v[1:]
    old_thetaddot = -gains.k_d * thetadot + gains.k_p * (planar3r.spec.default_configuration - theta)
    new_thetaddot = sample.thetaddot + gains.k_d * (sample.thetadot - thetadot) + gains.k_p * (sample.theta - theta)
    expected = torque_map(planar3r, q) @ (new_thetaddot - old_thetaddot)
    np.testing.assert_allclose(new.tau - old.tau, expected, rtol=1e-9, atol=1e-11)


def test_followed_joint_sample_is_reached(trep: FsmsModel) -> None:
    """The joint servo with a held sample: the joints settle on it."""
    law = JointServo(trep, Gains(k_p=400.0, k_d=40.0), FixedReference(trep.spec.default_configuration))
    goal = trep.spec.default_configuration + np.array([0.2, -0.3])
    law.follow(JointSample.held(goal))
    sim = Simulator(trep, law, native=False)
    sim.run(1.0)
    np.testing.assert_allclose(sim.q[1:], goal, atol=1e-4)  # from 0.3 rad away; the base still rings


def test_velocity_law_commands_toward_the_followed_sample(trep: FsmsModel) -> None:
    """Eq. (30): theta'_cmd = h^+ H_b g_b x_b + g_m (theta_r - theta) [+ theta_r'] for the sample followed."""
    q, v = state(trep)
    law = VelocityLaw(
        trep, Gains(g_b=24.0, g_m=20.0), FixedReference(trep.spec.default_configuration), feedforward=True
    )
    sample = JointSample(q[1:] + np.array([0.2, -0.3]), np.array([0.5, -0.1]), np.zeros(2))
    law.follow(sample)
    command, theta_ref, _ = law.command(0.0, q, v)
    M = trep.mass_matrix(q)
    h = M[0, 1:]
    expected = h / (h @ h) * M[0, 0] * 24.0 * q[0] + 20.0 * np.array([0.2, -0.3]) + sample.thetadot
    np.testing.assert_allclose(command, expected, rtol=1e-12)
    np.testing.assert_array_equal(theta_ref, sample.theta)


def test_followed_task_sample_is_reached(planar3r: FsmsModel) -> None:
    """Eq. (24): after follow(TaskSample), the end effector converges on the new target."""
    theta0 = planar3r.spec.default_configuration
    start = planar3r.ee_position(theta0)[planar3r.task_rows]
    null = TrackEndEffector(planar3r, TaskSample.held(start), 100.0, 20.0)
    law = AccelerationLaw(planar3r, Gains(g_b=2.5, g_m=1.0), null)
    goal = start + np.array([0.02, -0.01])
    law.follow(TaskSample.held(goal))
    sim = Simulator(planar3r, law, native=False)
    sim.run(2.0)
    np.testing.assert_allclose(planar3r.ee_position(sim.q[1:])[planar3r.task_rows], goal, atol=1e-4)
    assert law(sim.t, sim.q, sim.v).ee_ref is not None


def test_follow_of_the_wrong_sample_raises(trep: FsmsModel) -> None:
    theta0 = trep.spec.default_configuration
    joint, task = JointSample.held(theta0), TaskSample.held(np.zeros(2))
    refuses = [
        (AccelerationLaw(trep, Gains()), joint),  # the default input damps; it tracks nothing
        (AccelerationLaw(trep, Gains()), task),
        (TorqueLaw(trep, Gains(), TrackJointReference(FixedReference(theta0), 1.0, 1.0)), task),
        (AccelerationLaw(trep, Gains(), TrackEndEffector(trep, TaskSample.held(np.zeros(2)), 1.0, 1.0)), joint),
        (VelocityLaw(trep, Gains(), FixedReference(theta0)), task),
        (JointServo(trep, Gains(), FixedReference(theta0)), task),
    ]
    for law, sample in refuses:
        with pytest.raises(TypeError):
            law.follow(sample)


def test_switched_delegates(trep: FsmsModel) -> None:
    theta0 = trep.spec.default_configuration
    before = JointServo(trep, Gains(), FixedReference(theta0))
    after = VelocityLaw(trep, Gains(g_b=1.0), FixedReference(theta0))
    law = Switched(before, after, at=0.5)
    gains = Gains(g_b=9.0, g_m=3.0, k_p=11.0)
    law.retune(gains)
    assert before.gains is gains and after.gains is gains and law.gains is gains
    law.set_suppression(False)
    assert not after.suppress and not law.suppress
    sample = JointSample.held(theta0 + 0.1)
    law.follow(sample)
    assert before.reference is sample and after.reference is sample
    q, v = state(trep)
    np.testing.assert_array_equal(law(0.4, q, v).tau, before(0.4, q, v).tau)
    np.testing.assert_array_equal(law(0.6, q, v).tau, after(0.6, q, v).tau)


def test_samples_are_frozen_and_held_samples_rest() -> None:
    sample = JointSample.held([0.1, 0.2])
    assert sample(3.0)[0].tolist() == [0.1, 0.2]
    assert not np.any(sample.thetadot) and not np.any(sample.thetaddot)
    with pytest.raises(dataclasses.FrozenInstanceError):
        sample.theta = np.zeros(2)  # type: ignore[misc]
    target = TaskSample.held([1.0, 2.0])
    assert not np.any(target(0.0)[1]) and not np.any(target(0.0)[2])
