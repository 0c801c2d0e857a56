"""The pacer's arithmetic with an injected wall clock: backlog, re-anchoring, speed changes,
dropped backlogs, the real-time factor and the falling-behind flag."""

from __future__ import annotations

import math
from collections.abc import Iterator

import pytest

from rns_viz.live.loop import wall_clock as pacing
from rns_viz.live.loop.wall_clock import RTF_WINDOW_S, SKIPPED_HOLD_S, SPEEDS, Pacer


class Clock:
    """Stands in for the ``time`` module inside rns_viz.live.loop.wall_clock: wall time moves when told."""

    def __init__(self, now: float = 100.0) -> None:
        self.now = now

    def perf_counter(self) -> float:
        return self.now


@pytest.fixture
def clock(monkeypatch: pytest.MonkeyPatch) -> Iterator[Clock]:
    fake = Clock()
    monkeypatch.setattr(pacing, "time", fake)
    yield fake


def test_backlog_is_the_wall_time_the_simulation_is_behind(clock: Clock) -> None:
    p = Pacer(1.0)
    assert p.backlog(0.0, clock.now) == 0.0
    assert p.backlog(0.05, clock.now + 0.1) == pytest.approx(0.05)  # 0.1 s due, 0.05 s done
    assert p.backlog(0.15, clock.now + 0.1) == pytest.approx(-0.05)  # ahead
    slow = Pacer(0.25)
    # At 1/4 speed 0.1 wall s makes 0.025 sim s due; 0.0125 sim s missing is 0.05 wall s of backlog.
    assert slow.backlog(0.0125, clock.now + 0.1) == pytest.approx(0.05)


def test_reanchor_starts_afresh_from_the_given_simulated_time(clock: Clock) -> None:
    p = Pacer(1.0)
    clock.now += 5.0  # a long pause: 5 s of backlog if not re-anchored
    assert p.backlog(1.0, clock.now) == pytest.approx(4.0)
    p.reanchor(1.0)
    assert p.backlog(1.0, clock.now) == 0.0
    assert p.backlog(1.2, clock.now + 0.2) == pytest.approx(0.0)
    assert math.isnan(p.rtf())  # the samples went with the old anchor


@pytest.mark.parametrize("speed", SPEEDS)
def test_a_speed_change_keeps_the_simulated_time_and_changes_its_rate(clock: Clock, speed: float) -> None:
    p = Pacer(1.0)
    clock.now += 1.0
    p.set_speed(speed, 1.0)
    assert p.speed == speed and p.backlog(1.0, clock.now) == 0.0
    assert p.backlog(1.0 + 0.4 * speed, clock.now + 0.4) == pytest.approx(0.0)  # on schedule at the new rate


def test_only_the_offered_speeds_are_accepted(clock: Clock) -> None:
    p = Pacer(1.0)
    for bad in (0.0, 3.0, -1.0, math.nan):
        with pytest.raises(ValueError):
            p.set_speed(bad, 0.0)
    assert p.speed == 1.0


def test_a_dropped_backlog_is_counted_re_anchored_and_said_for_a_while(clock: Clock) -> None:
    p = Pacer(1.0)
    clock.now += 0.8  # a stall
    assert p.backlog(0.3, clock.now) == pytest.approx(0.5)
    p.drop_backlog(0.3)
    assert p.dropped == 1 and p.backlog(0.3, clock.now) == 0.0
    assert p.skipped() == pytest.approx(0.5)  # simulated s given up
    assert not p.behind()  # no rate measured under the speed: the skip is said, not a slow rate
    clock.now += 0.5
    p.drop_backlog(0.7)  # another stall soon after: 0.8 s due, 0.7 run, 0.1 s more given up (summed)
    assert p.skipped() == pytest.approx(0.6)
    clock.now += SKIPPED_HOLD_S + 0.01
    assert p.skipped() == 0.0


def test_at_half_speed_a_skip_is_in_simulated_seconds(clock: Clock) -> None:
    p = Pacer(0.5)
    clock.now += 1.0  # 0.5 simulated s due
    p.drop_backlog(0.1)
    assert p.skipped() == pytest.approx(0.4)


def test_real_time_factor_over_the_last_window(clock: Clock) -> None:
    p = Pacer(1.0)
    assert math.isnan(p.rtf())
    start = clock.now
    p.sample(0.0, start)
    p.sample(0.1, start + 0.1)
    assert math.isnan(p.rtf())  # too short a span to mean anything
    for k in range(1, 31):  # 3 s at 0.8 x real time, sampled every 0.1 s
        p.sample(0.08 * k, start + 0.1 * k)
    clock.now = start + 3.0
    assert p.rtf() == pytest.approx(0.8)
    assert p.behind()  # 0.8 < 0.95 x speed
    for k in range(31, 31 + round(10 * (RTF_WINDOW_S + 1.0))):  # real time for longer than the window
        p.sample(0.08 * 30 + 0.1 * (k - 30), start + 0.1 * k)
    assert p.rtf() == pytest.approx(1.0)  # measured over the last RTF_WINDOW_S only
    assert not p.behind()


def test_behind_is_relative_to_the_chosen_speed(clock: Clock) -> None:
    p = Pacer(0.5)
    start = clock.now
    for k in range(11):  # exactly half speed
        p.sample(0.05 * k, start + 0.1 * k)
    assert p.rtf() == pytest.approx(0.5) and not p.behind()


def test_a_restart_forgets_the_backlog_and_the_skips(clock: Clock) -> None:
    p = Pacer(1.0)
    clock.now += 0.8
    p.drop_backlog(0.3)
    clock.now += 0.4  # a backlog again
    p.restart(0.3)
    assert p.skipped() == 0.0 and p.backlog(0.3, clock.now) == 0.0
