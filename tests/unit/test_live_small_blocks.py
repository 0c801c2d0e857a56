"""Small building blocks of the live session: goal followers, operator kicks, the divergence guard."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rns_viz.live.operator.follower import Follower, ScalarFollower
from rns_viz.live.runs.divergence_guard import MAX_BASE_SPEED, MAX_JOINT_SPEED, Bounds
from rns_viz.live.runs.kicks import MAX_KICK_N, KickSchedule, kick_pulse
from rns_viz.model import FsmsModel
from rns_viz.sim.disturbance import ForcePulse

DT = 1e-3


# ---------------------------------------------------------------- followers
@pytest.mark.parametrize("goal", [3.0, -0.02, 0.0])
def test_scalar_follower_respects_its_limits_and_arrives_without_overshoot(goal: float) -> None:
    f = ScalarFollower(0.0, v_max=2.0, k=5.0)
    a_max = 1.5 * f.k * f.v_max
    side = math.copysign(1.0, goal) if goal else 0.0
    arrived_at = None
    for step in range(10_000):
        v_before = f.v
        done = f.step(goal, DT, tol=1e-6)
        assert abs(f.v) <= f.v_max + 1e-12
        assert abs(f.v - v_before) <= a_max * DT + 1e-12
        assert side * (goal - f.x) >= -1e-12  # never past the goal
        if done:
            arrived_at = step
            break
    assert arrived_at is not None and f.x == goal and f.v == 0.0
    if goal == 3.0:  # far: it cruises at v_max, then closes in as a first-order lag of time constant 1/k
        cruise, approach = goal / f.v_max, math.log(f.v_max / (f.k * 1e-6)) / f.k
        assert cruise / DT < arrived_at < (cruise + approach + 0.1) / DT


def test_scalar_follower_reset_stops_it_where_told() -> None:
    f = ScalarFollower(0.0, v_max=1.0)
    for _ in range(100):
        f.step(1.0, DT)
    assert f.v > 0
    f.reset(-2.0)
    assert f.x == -2.0 and f.v == 0.0


def test_vector_follower_bounds_speed_and_acceleration_in_norm() -> None:
    f = Follower(np.zeros(2), v_max=0.5, k=4.0)
    goal = np.array([0.3, -0.4])  # 0.5 m away
    direction = goal / np.linalg.norm(goal)
    for _ in range(5000):
        v_before = f.v.copy()
        done = f.step(goal, DT, tol=1e-7)
        assert np.linalg.norm(f.v) <= f.v_max + 1e-12
        assert np.linalg.norm(f.v - v_before) <= f.k * f.v_max * DT + 1e-12
        assert np.linalg.norm(f.x - (f.x @ direction) * direction) < 1e-12  # straight at the goal
        if done:
            break
    assert done and np.array_equal(f.x, goal) and not np.any(f.v)


# ---------------------------------------------------------------- kicks
def test_a_kick_is_a_half_sine_along_the_first_base_coordinate() -> None:
    pulse = kick_pulse(1.0, 0.8, 0.1, m=2)
    assert pulse(0.99) is None and pulse(1.11) is None
    assert np.allclose(pulse(1.05), [0.8, 0.0]) and np.allclose(pulse(1.025), [0.8 * math.sin(math.pi / 4), 0.0])
    assert np.allclose(pulse.impulse, [2 * 0.8 * 0.1 / math.pi, 0.0])


@pytest.mark.parametrize("peak", [math.nan, math.inf, -math.inf, MAX_KICK_N * 1.01, -MAX_KICK_N * 2])
def test_a_kick_that_is_no_force_is_refused(peak: float) -> None:
    with pytest.raises(ValueError):
        kick_pulse(0.0, peak, 0.1, 1)


def test_kick_schedule_adds_pulses_to_the_preset_and_forgets_ended_ones() -> None:
    preset = ForcePulse(start=0.0, duration=1.0, peak=(1.0,))
    schedule = KickSchedule(preset)
    schedule.add(kick_pulse(0.5, 2.0, 0.2, 1))
    assert np.allclose(schedule(0.6), preset(0.6) + 2.0)  # both at their peaks
    twin = schedule.copy()
    assert np.allclose(schedule(0.9), preset(0.9)) and schedule.pulses == []  # ended: dropped
    assert len(twin.pulses) == 1  # a copy keeps its own list
    twin.clear()
    assert twin.pulses == [] and np.allclose(twin(0.5), preset(0.5))
    assert KickSchedule()(0.3) is None  # no force at all


# ---------------------------------------------------------------- the divergence guard
def test_guard_accepts_physics_and_names_what_left_it(trep: FsmsModel) -> None:
    bounds = Bounds(trep)
    q, v = trep.q(trep.spec.default_configuration), np.zeros(trep.nv)
    assert bounds.violation(q, v) is None
    assert "finite" in (bounds.violation(np.r_[math.nan, q[1:]], v) or "")
    assert "finite" in (bounds.violation(q, np.r_[0.0, math.inf, 0.0]) or "")
    beyond = q.copy()
    beyond[0] = bounds.upper[0] * 1.01 + 1e-9
    assert "base coordinate 1" in (bounds.violation(beyond, v) or "")
    assert "base moves" in (bounds.violation(q, np.r_[1.01 * MAX_BASE_SPEED, 0.0, 0.0]) or "")
    assert "joint turns" in (bounds.violation(q, np.r_[0.0, 0.0, -1.01 * MAX_JOINT_SPEED]) or "")
    assert bounds.violation(q, np.r_[0.99 * MAX_BASE_SPEED, 0.99 * MAX_JOINT_SPEED, 0.0]) is None
