"""Orientation targets on boom7: the reactionless resolved-rate reference tracks the position in the RNS
(Eq. 24's J-bar = J P_RNS) and the orientation as a secondary task in the RNS directions that leave the
hand still (task priority). r = 1 reaches a full pose; forces only (n - r = 4) tracks one rotational DOF
by least squares without disturbing the position; the secondary term is checked against finite
differences. The simulated arm and bad quaternions: tests/session/ and tests/app/test_orientation_target.py.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from rns_viz.live.operator.moving_references import ResolvedRate
from rns_viz.live.operator.operator import orientation_note
from rns_viz.model import FsmsModel
from rns_viz.rns import rns_projector
from tests.support.poses import angle_deg, coupling, rns_walk

R1 = (True, False, False, False, False, False)
FORCES = (True, True, True, False, False, False)


def boom(flags: tuple[bool, ...]) -> FsmsModel:
    return FsmsModel.from_name("boom7").with_selection([int(f) for f in flags])


def run(rr: ResolvedRate, steps: int) -> tuple[np.ndarray, float]:
    """Step the reference; the hand's positions (m) and the worst relative reaction |S H_bm theta'|."""
    xs, worst = [], 0.0
    for _ in range(steps):
        rr.step(1e-3)
        H = coupling(rr.model, rr.theta)
        speed = float(np.linalg.norm(rr.thetadot))
        if speed > 0.0:
            worst = max(worst, float(np.linalg.norm(H @ rr.thetadot)) / (np.linalg.norm(H) * speed))
        xs.append(rr.ee(rr.theta))
    return np.array(xs), worst


def test_with_r_1_a_reachable_pose_is_reached_without_reaction() -> None:
    model = boom(R1)
    theta0 = model.spec.default_configuration
    rr = ResolvedRate(model, theta0, v_max=0.1)
    assert rr.orient_dof == 3 and rr.orienting  # n - r = 6: three position and three rotation directions
    goal = rns_walk(model, theta0, seed=1)
    x_goal, R_goal = rr.ee(goal), rr.ee_rotation(goal)
    assert np.linalg.norm(x_goal - rr.ee(theta0)) > 0.03 and angle_deg(R_goal, rr.ee_rotation(theta0)) > 10.0
    rr.set_goal(x_goal)
    rr.set_goal_rotation(R_goal)
    _, worst = run(rr, 6000)
    assert rr.idle  # came to rest at the pose
    assert np.linalg.norm(rr.ee(rr.theta) - x_goal) < 2e-3  # m
    assert angle_deg(rr.ee_rotation(rr.theta), R_goal) < 1.0  # deg
    assert worst < 1e-9  # every step stays in the RNS: S H_bm theta' = 0


def test_forces_only_the_secondary_task_helps_and_leaves_the_position_alone() -> None:
    model = boom(FORCES)
    theta0 = model.spec.default_configuration
    assert ResolvedRate(model, theta0).orient_dof == 1  # n - r = 4: one direction beyond the position
    goal = rns_walk(model, theta0, seed=4)  # its straight-line way stays clear of folds of J-bar
    tilt = pin.exp3(np.radians(25.0) * np.array([0.3, -0.8, 0.5]) / np.linalg.norm([0.3, -0.8, 0.5]))
    runs = {}
    for on in (True, False):
        rr = ResolvedRate(model, theta0, v_max=0.1)
        rr.set_orientation(on)
        R_goal = tilt @ rr.ee_rotation(goal)  # not reachable exactly with one rotational DOF
        rr.set_goal(rr.ee(goal))
        rr.set_goal_rotation(R_goal)
        xs, worst = run(rr, 5000)
        assert worst < 1e-9
        runs[on] = (xs, angle_deg(rr.ee_rotation(rr.theta), R_goal), rr.theta)
    (xs_on, err_on, th_on), (xs_off, err_off, th_off) = runs[True], runs[False]
    x_goal = ResolvedRate(model, theta0).ee(goal)
    assert np.linalg.norm(xs_on[-1] - x_goal) < 2e-3 and np.linalg.norm(xs_off[-1] - x_goal) < 2e-3
    # the hand's path is the primary task's: the secondary moves only directions with J-bar theta' = 0
    assert np.abs(xs_on - xs_off).max() < 1e-4  # m, over the whole motion
    assert np.linalg.norm(th_on - th_off) > 1e-2  # while the arm's configuration differs
    assert err_on < err_off - 1.0  # deg: the free rotation was used to turn toward the goal


@pytest.mark.parametrize("flags", [R1, FORCES])
def test_the_secondary_term_leaves_the_hand_still_and_the_base_unreacted(flags: tuple[bool, ...]) -> None:
    model = boom(flags)
    rng = np.random.default_rng(3)
    pm, m = model.pin_model, model.m
    for _ in range(5):
        theta = model.spec.default_configuration + rng.uniform(-0.4, 0.4, model.n)
        rr = ResolvedRate(model, theta)
        rr.set_goal_rotation(pin.exp3(rng.normal(size=3) * 0.2) @ rr.ee_rotation(theta))
        q = model.q(theta)
        data = pm.createData()
        J6 = pin.computeFrameJacobian(pm, data, q, model.ee_frame_id, pin.LOCAL_WORLD_ALIGNED)[:, m:]
        Rb = data.oMi[model.base_joint_id].rotation.T
        P = rns_projector(coupling(model, theta))
        J_p, J_o = Rb @ J6[:3], Rb @ J6[3:]
        primary = P @ rng.normal(size=model.n)  # any primary joint rate in the RNS
        V = np.linalg.svd(J_p @ P)[2][:3]  # the primary task's joint directions (rank 3 here)
        z = rr.orientation_rate(V, P, J_o, rr.ee_rotation(theta), primary)
        scale = float(np.linalg.norm(z))
        assert scale > 1e-6
        # finite differences (central, eps = 1e-6 rad): the hand does not move, the base feels nothing
        eps = 1e-6 / scale
        dx = (rr.ee(theta + eps * z) - rr.ee(theta - eps * z)) / (2 * eps)
        assert np.linalg.norm(dx) < 1e-7 * np.linalg.norm(J_p) * scale
        assert np.linalg.norm(coupling(model, theta) @ z) < 1e-9 * np.linalg.norm(coupling(model, theta)) * scale
        assert np.allclose(P @ z, z, atol=1e-12 * scale)  # in the RNS
        sigma_o = np.linalg.svd(J_o @ (P - V.T @ V), compute_uv=False)[-1]
        if rr.orient_dof == 3 and sigma_o > rr.threshold:  # three rotations free, undamped: w is made exactly
            w = rr.k * pin.log3(rr.goal_R @ rr.ee_rotation(theta).T)
            w *= min(1.0, rr.omega_max / np.linalg.norm(w))
            R_plus, R_minus = rr.ee_rotation(theta + eps * z), rr.ee_rotation(theta - eps * z)
            omega = pin.log3(R_plus @ R_minus.T) / (2 * eps)
            assert np.allclose(omega + J_o @ primary, w, atol=1e-6 * np.linalg.norm(w))


@pytest.mark.parametrize(("r", "free"), [(1, 3), (2, 2), (3, 1), (4, 0), (5, 0)])
def test_the_rotational_dof_offered_follow_n_minus_r(r: int, free: int) -> None:
    flags = tuple(i < r for i in range(6))
    model = boom(flags)
    rr = ResolvedRate(model, model.spec.default_configuration)
    assert rr.orient_dof == free and rr.orienting == (free == 3)  # on by default for the whole pose only
    note = orientation_note(model)
    if free:
        assert f"{free} of 3 rotational DOF free (n − r = {7 - r})" in note
    else:
        assert "not offered" in note and f"n − r = {7 - r}" in note
        with pytest.raises(ValueError):
            rr.set_orientation(True)
