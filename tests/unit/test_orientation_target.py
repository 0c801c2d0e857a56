"""Orientation targets on boom7: the reactionless resolved-rate reference tracks the position in the RNS
(Eq. 24's J-bar = J P_RNS) and the orientation as a secondary task in the RNS directions that leave the
hand still (task priority). r = 1 reaches a full pose; forces only (n - r = 4) tracks one rotational DOF
by least squares without disturbing the position; the secondary term is checked against finite
differences; bad quaternions are refused and the simulation runs on.
"""

from __future__ import annotations

import time
from collections.abc import Iterator

import numpy as np
import pinocchio as pin
import pytest

from rns_viz.live.loop.session import Session
from rns_viz.live.operator.moving_references import ResolvedRate
from rns_viz.live.operator.operator import orientation_note
from rns_viz.model import FsmsModel
from rns_viz.rns import rns_projector

R1 = (True, False, False, False, False, False)
FORCES = (True, True, True, False, False, False)


def boom(flags: tuple[bool, ...]) -> FsmsModel:
    return FsmsModel.from_name("boom7").with_selection([int(f) for f in flags])


def coupling(model: FsmsModel, theta: np.ndarray) -> np.ndarray:
    """S H_bm at theta (kg m)."""
    return model.mass_matrix(model.q(theta))[model.selected, model.m :]


def rns_walk(model: FsmsModel, theta: np.ndarray, seed: int, steps: int = 300) -> np.ndarray:
    """A configuration reached by a random reactionless motion: its pose is reachable without reaction."""
    z = np.random.default_rng(seed).normal(size=model.n)
    theta = np.array(theta, dtype=float)
    for _ in range(steps):
        theta = theta + 1e-3 * rns_projector(coupling(model, theta)) @ z
    return theta


def angle_deg(A: np.ndarray, B: np.ndarray) -> float:
    return float(np.degrees(np.linalg.norm(pin.log3(A @ B.T))))


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


@pytest.fixture
def live() -> Iterator[Session]:
    s = Session("boom7", realtime=False)
    assert s.wait_background(120.0)
    yield s
    s.stop()


def test_live_pose_target_the_arm_follows_and_bad_quaternions_are_refused(live: Session) -> None:
    s = live
    s.set_selection(R1)
    s.advance(0.01)
    view = s.snapshot().orientation
    assert view is not None and view.on and view.offered and "3 of 3" in view.note
    model = s.state.model
    theta0 = s.snapshot().q[6:]
    goal = rns_walk(model, theta0, seed=4, steps=200)
    rr = s.state.operator.rr  # type: ignore[union-attr]
    x_goal, R_goal = rr.ee(goal), rr.ee_rotation(goal)
    wxyz = pin.Quaternion(R_goal)
    for bad in ((np.nan, 0.0, 0.0, 1.0), (0.0, 0.0, 0.0, 0.0), (1.0, 0.0, 0.0)):
        with pytest.raises(ValueError, match="quaternion"):
            s.set_target(tuple(x_goal), True, wxyz=bad)
    s.set_target(tuple(x_goal), True, wxyz=(wxyz.w, wxyz.x, wxyz.y, wxyz.z))
    s.advance(4.0)
    snap = s.snapshot()
    assert not snap.paused and snap.diverged is None and snap.t > 4.0  # the bad inputs left it running
    theta = snap.q[6:]
    assert np.linalg.norm(rr.ee(theta) - x_goal) < 2e-3  # the simulated arm, not only the reference
    assert angle_deg(rr.ee_rotation(theta), R_goal) < 1.0
    # only the axial force (S1) is selected: that coordinate stays still, the free ones are excited
    assert abs(snap.q[0]) < 1e-5 < np.abs(snap.q[1:6]).max()  # m, rad
    s.track_orientation(False)
    s.advance(0.01)
    assert s.snapshot().orientation.on is False  # type: ignore[union-attr]


def test_at_r_5_sigma_jbar_is_the_second_singular_value_and_orientation_is_refused(live: Session) -> None:
    s = live
    s.set_selection((True,) * 5 + (False,))
    s.advance(0.01)
    s.pop_notices()
    snap = s.snapshot()
    model = s.state.model
    theta = snap.q[6:]
    sv = np.linalg.svd(model.ee_jacobian(theta) @ rns_projector(coupling(model, theta)), compute_uv=False)
    assert sv[2] < 1e-9 * sv[0]  # rank n - r = 2 < 3 task rows
    assert snap.readouts.sigma_jbar == pytest.approx(sv[1], rel=1e-9) and sv[1] > 0.0
    assert snap.orientation is not None and not snap.orientation.offered and "not offered" in snap.orientation.note
    s.track_orientation(True)
    s.advance(0.01)
    refused = [n for n in s.pop_notices() if n.title == "Input not applied"]
    assert refused and "not offered" in refused[0].body
    assert not s.snapshot().paused


def test_bad_quaternions_from_a_client_are_told_and_the_simulation_runs_on() -> None:
    """The handle's drag with a NaN or zero quaternion, as a client could send it (tests/protocol_client.py)."""
    from rns_viz.viz.server.app import TARGET_HANDLE
    from tests.app_helpers import stepped_app
    from tests.browser import wait_for_clients, wait_until
    from tests.protocol_client import ProtocolClient

    apps = stepped_app("boom7")
    app = next(apps)
    s = app.session
    s.set_selection(R1)
    s.advance(0.01)
    wait_until(lambda: app.controls.pose_target, 20.0, "the pose handle")
    ws = ProtocolClient(app.port, decode=True)
    try:
        wait_for_clients(app, 1, "the websocket client")
        before = np.array(s.snapshot().target, dtype=float)
        goal_R = s.state.operator.rr.goal_R.copy()  # type: ignore[union-attr]
        lifted = before + app.controls.target_lift + np.array([0.02, 0.0, 0.0])
        for bad in ((np.nan, 0.0, 0.0, 1.0), (0.0, 0.0, 0.0, 0.0)):
            told = ws.types["NotificationShowMessage"]
            # mid-drag updates (at a drag's end viser calls back once more with the handle as it is then)
            ws.drag(TARGET_HANDLE, tuple(lifted), "update", wxyz=bad)
            wait_until(lambda told=told: ws.types["NotificationShowMessage"] > told, 10.0, "a notice")
            # the refused drag sends the handle home (render thread); wait for it before the next drag,
            # whose callback would otherwise read the handle's pose as the renderer set it
            wait_until(lambda: not app.controls._handle_home_requested, 10.0, "the handle sent home")
            time.sleep(0.5)  # the render frame that took the request writes the handle's pose (30 Hz frames)
        assert "DragTarget" not in s.pending_commands()  # refused before anything was queued
        t0 = s.snapshot().t
        s.advance(0.5)
        snap = s.snapshot()
        assert not snap.paused and snap.diverged is None and snap.t == pytest.approx(t0 + 0.5)
        assert np.allclose(snap.target, before)  # the target in force is untouched
        assert np.allclose(s.state.operator.rr.goal_R, goal_R)  # type: ignore[union-attr]
    finally:
        ws.close()
        apps.close()
