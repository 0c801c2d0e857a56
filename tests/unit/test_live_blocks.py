"""The live layer's building blocks on their own: typed commands, the operator, the run pair.

Physics asserted: the operator's joint samples stay on the reactionless path (the coupling
potential w x_cm keeps its level, theta_ref' is parallel to n(theta), Eq. 27); the point-to-point
move ends where the path move would; the shadow always gets the opposite suppression.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from rns_viz.control import Gains, InvalidGain, JointSample, TaskSample
from rns_viz.live.loop import commands as c
from rns_viz.live.operator.kinds import operator_class
from rns_viz.live.operator.operator import UNCHANGED, InputRefused
from rns_viz.live.runs.run_pair import LawChoice, RunPair
from rns_viz.model import FsmsModel
from rns_viz.paths import CouplingField, build_path_table
from rns_viz.rns import null_vector

DT = 1e-3


# ---------------------------------------------------------------- commands
@pytest.mark.parametrize(
    "make",
    [
        lambda: c.Kick(math.nan),
        lambda: c.Kick(2e4),
        lambda: c.Kick(True),
        lambda: c.SetGains({"g_b": -1.0}),
        lambda: c.SetGains({"g_b": math.inf}),
        lambda: c.SetGains({"gb": 1.0}),
        lambda: c.SetSpeed(3.0),
        lambda: c.SetLaw("servo"),
        lambda: c.DragTarget((math.nan, 0.0)),
        lambda: c.DragTarget((1e9, 0.0)),
        lambda: c.DragTarget("xy"),
        lambda: c.Scrub(math.inf),
        lambda: c.Play(0.0),
        lambda: c.SetUbarSpeed(0.0),
        lambda: c.SetTargetSpeed(1e3),
        lambda: c.SetSuppression("yes"),
        lambda: c.SingleStep(0),
        lambda: c.SwitchModel("nope"),
        lambda: c.SwitchModel("boom7#S=12"),
        lambda: c.SetSelection(()),
        lambda: c.SetSelection((1, 0)),
        lambda: c.Kick(1.0, (0.0, 0.0)),
        lambda: c.Kick(1.0, (2.0,)),
        lambda: c.Kick(1.0, (math.nan,)),
        lambda: c.DragTarget((0.0, 0.0, 0.0, 0.0)),
        lambda: c.LoadPreset("nope"),
    ],
)
def test_bad_input_is_refused_when_the_command_is_made(make) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(ValueError):
        make()


def test_commands_are_frozen_and_normalised() -> None:
    drag = c.DragTarget(np.array([0.25, -0.5]), True, client=3)
    assert drag.xy == (0.25, -0.5) and isinstance(drag.xy[0], float) and drag.client == 3
    with pytest.raises(dataclasses.FrozenInstanceError):
        drag.final = False  # type: ignore[misc]
    gains = c.SetGains({"g_b": 7.0}).applied_to(Gains(g_b=1.0, g_m=2.0, k_p=5.0))
    assert (gains.g_b, gains.g_m, gains.k_p) == (7.0, 2.0, 5.0)
    with pytest.raises(TypeError):
        c.SetGains({"g_b": 7.0}).changes["g_b"] = 1.0  # type: ignore[index]
    with pytest.raises(InvalidGain):
        c.SetGains({"servo_bandwidth": 0.0})


# ---------------------------------------------------------------- operator (TREP: 1-D RNS)
@pytest.fixture(scope="module")
def trep_table(trep: FsmsModel):  # type: ignore[no-untyped-def]
    return build_path_table(trep, trep.spec.default_configuration)


def test_operator_holds_until_told(trep: FsmsModel) -> None:
    theta0 = trep.spec.default_configuration
    op = operator_class(trep)(trep, theta0, 30.0, 0.5)
    first = op.joint
    for k in range(5):
        assert op.advance(k * DT, DT) == UNCHANGED
    assert op.joint is first and np.array_equal(first.theta, theta0) and not np.any(first.thetadot)
    with pytest.raises(InputRefused):
        op.scrub(0.1)  # no path table yet: refused with a reason, nothing moved


def test_scrubbed_reference_stays_on_the_reactionless_path(trep: FsmsModel, trep_table) -> None:  # type: ignore[no-untyped-def]
    theta0 = trep.spec.default_configuration
    op = operator_class(trep)(trep, theta0, 30.0, 0.5)
    assert op.accept_table(trep_table, 1e-6)
    field = CouplingField(trep)
    level = field.potentials(np.asarray(theta0)[None])[0]
    held = op.joint
    held_theta = held.theta.copy()
    goal = op.sigma + 0.5  # 1/(kg m)
    op.scrub(goal)
    samples = []
    for k in range(1500):
        op.advance(k * DT, DT)
        samples.append(op.joint)
    assert np.array_equal(held.theta, held_theta)  # a sample handed out earlier never changes
    moving = [s for s in samples if np.linalg.norm(s.thetadot) > 1e-6]
    assert len(moving) > 50
    for s in moving[::10]:
        n = null_vector(trep.mass_matrix(trep.q(s.theta))[trep.selected, trep.m :])
        cos = abs(n @ s.thetadot) / (np.linalg.norm(n) * np.linalg.norm(s.thetadot))
        assert cos > 1 - 1e-9  # theta_ref' = n u-bar (Eq. 30's integrand)
    levels = field.potentials(np.array([s.theta for s in samples]))
    assert np.max(np.abs(levels - level)) < 1e-6 * trep.arm_mass  # kg m: the same reactionless path
    assert not np.any(samples[-1].thetadot)  # it came to rest ...
    reached = trep.ee_position(samples[-1].theta)[:2]
    assert np.linalg.norm(reached - trep_table.ee_at(goal)[:2]) < 1e-4  # ... at the scrubbed point (m)
    assert np.linalg.norm(samples[-1].theta - theta0) > 0.02  # rad: it did move


def test_point_to_point_reports_its_start_and_end(trep: FsmsModel, trep_table) -> None:  # type: ignore[no-untyped-def]
    op = operator_class(trep)(trep, trep.spec.default_configuration, 30.0, 0.5)
    op.accept_table(trep_table, 1e-6)
    op.point_to_point(0.0, duration=0.05)
    end = op.joint_move.end.copy()  # type: ignore[union-attr]
    changes = [op.advance(k * DT, DT) for k in range(80)]
    flagged = [k for k, ch in enumerate(changes) if ch.joint_move_changed]
    assert flagged == [0, 50]  # the servo takes over at the start and gives way at the end
    assert np.allclose(op.joint.theta, end) and not np.any(op.joint.thetadot)
    # the joint-space move ends on the same reactionless path it left (Fig. 11(b): same end points)
    field = CouplingField(trep)
    start_level = field.potentials(np.asarray(trep.spec.default_configuration)[None])[0]
    assert np.allclose(field.potentials(end[None])[0], start_level, atol=1e-6 * trep.arm_mass)


def test_operator_of_a_planar_3r_tracks_a_dragged_target(planar3r: FsmsModel) -> None:
    op = operator_class(planar3r)(planar3r, planar3r.spec.default_configuration, 30.0, 0.5)
    assert isinstance(op.task, TaskSample)
    start = op.task.x.copy()
    goal = start + np.array([-0.05, 0.05])
    assert op.drag(goal, final=True) is False  # no reachable set yet: not clamped
    for k in range(2000):
        op.advance(k * DT, DT)
    assert np.linalg.norm(op.task.x - goal) < 1e-4  # m
    x = planar3r.ee_position(op.joint.theta)[:2]
    assert np.linalg.norm(x - op.task.x) < 1e-4  # theta_ref puts the end effector on x_d


# ---------------------------------------------------------------- run pair
def test_run_pair_keeps_the_shadow_opposite_and_both_laws_on_the_same_sample(trep: FsmsModel) -> None:
    theta0 = trep.spec.default_configuration
    runs = RunPair.at_rest("trep", theta0)
    runs.install(LawChoice("velocity", Gains(g_b=24.0, g_m=20.0), True), JointSample.held(theta0))
    assert runs.sim.law.suppress and not runs.shadow.law.suppress
    runs.set_suppression(False)
    assert not runs.sim.law.suppress and runs.shadow.law.suppress
    runs.retune(Gains(g_b=5.0, g_m=3.0))
    assert runs.sim.law.gains.g_m == 3.0 and runs.shadow.law.gains.g_m == 3.0
    target = JointSample.held(np.asarray(theta0) + np.array([0.0, 0.1]))
    out = runs.step(target, None, shadow=True)
    assert np.array_equal(out.theta_ref, target.theta)
    assert np.array_equal(runs.shadow.last.theta_ref, target.theta)  # type: ignore[union-attr]


def test_a_kick_reaches_both_runs_alike_without_suppression(trep: FsmsModel) -> None:
    theta0 = trep.spec.default_configuration
    runs = RunPair.at_rest("trep", theta0)
    runs.install(LawChoice("acceleration", Gains(g_b=0.0, g_m=2.0), True), JointSample.held(theta0))
    from rns_viz.live.runs.kicks import kick_pulse

    runs.kick(kick_pulse(0.0, 0.8, 0.1, trep.m))
    for _ in range(200):
        runs.step(JointSample.held(theta0), None, shadow=True)
    # with g_b = 0 "on" and "off" are the same law: the runs stay together to rounding
    assert abs(runs.sim.q[0]) > 1e-3 and np.allclose(runs.sim.q, runs.shadow.q, atol=1e-12)


# ---------------------------------------------------------------- inputs that are moved
def test_a_target_off_the_path_is_moved_onto_it_and_said(trep: FsmsModel, trep_table) -> None:  # type: ignore[no-untyped-def]
    op = operator_class(trep)(trep, trep.spec.default_configuration, 30.0, 0.5)
    op.accept_table(trep_table, 1e-6)
    on_path = trep_table.ee_at(op.sigma + 0.3)[:2]
    assert op.drag(on_path, final=True) is False  # on the path: nothing to say
    assert op.drag(np.array([1.0, 1.0]), final=True) is True  # far from this path: moved onto it
    assert np.linalg.norm(op.target[:2] - trep_table.ee_at(op.motion.goal)[:2]) < 1e-12  # type: ignore[index]


@pytest.mark.parametrize(
    ("key", "kind", "follows", "shows"),
    [
        ("trep", "reactionless path", "path", "path"),  # n - r = 1
        ("planar3r", "reachable set", "target", "reachable set"),  # n - r = 2
        ("boom7", "reactionless path", "path", "path"),  # r = 6, n = 7
        ("boom7#S=111000", "reachable set", "target", "reachable set"),  # forces only: n - r = 4
        ("trep2", "task arm", "target", "workspace"),  # [arms]: a compensating arm
    ],
)
def test_what_the_operator_drives_is_chosen_once_from_the_rns_and_the_arms(
    key: str, kind: str, follows: str, shows: str
) -> None:
    model = FsmsModel.from_key(key)
    cls = operator_class(model)
    assert (cls.kind, cls.follows, cls.shows, cls.compensates) == (kind, follows, shows, kind == "task arm")
    op = cls(model, model.spec.default_configuration, 30.0, 0.5)
    assert (op.task is None) == (follows == "path")  # a path is followed in joint space, a target in task space
    if follows == "target":  # no path to scrub on a target's model: refused with a reason, not waited for
        with pytest.raises(InputRefused, match="No reactionless path"):
            op.scrub(0.1)
    for law in ("acceleration", "torque", "velocity"):
        if kind == "task arm" and law != "acceleration":
            with pytest.raises(ValueError, match="compensating law"):
                cls.check_law(key, law)
        else:
            cls.check_law(key, law)
