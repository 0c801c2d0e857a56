"""Pacing of slow pages, the rule on its own: the rate controller given answer times, and the
gate on one client's stream of windows (the app with protocol-level clients: tests/app/test_client_pace.py)."""

from __future__ import annotations

import asyncio
import itertools
import math
from collections.abc import AsyncGenerator, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import pytest
from viser import _messages as m

from rns_viz.viz.server.page_pacing import _paced, touches_scene
from rns_viz.viz.server.page_rate import (
    FAST_ANSWER_S,
    FULL_HZ,
    HOLD_BASES,
    HOLD_S,
    MIN_HZ,
    NOTICE_BELOW_HZ,
    NOTICE_GONE_HZ,
    QUEUE_GROWS_S,
    SLOW_ANSWER_S,
    PaceController,
)


def answer(c: PaceController, now: float, after_s: float) -> float:
    """Ask at ``now`` and get the answer ``after_s`` later; returns the time of the answer."""
    c.ping_sent(now)
    c.ping_answered(now + after_s)
    return now + after_s


# ---------------------------------------------------------------- the rule
def test_a_page_that_keeps_up_is_never_paced() -> None:
    c, now = PaceController(), 0.0
    for _ in range(50):
        now = answer(c, now, 0.5 * FAST_ANSWER_S) + 0.25
        assert c.hz == FULL_HZ and c.interval_s() == 0.0 and c.wait_s(now, 0.0) == 0.0
        assert not c.update_notice(now)


def test_slow_answers_halve_the_rate_down_to_the_floor() -> None:
    c, now, rates = PaceController(), 0.0, []
    for _ in range(12):
        now = answer(c, now, 2.0 * SLOW_ANSWER_S)
        rates.append(c.hz)
    assert rates[0] == FULL_HZ / 2 and rates[1] == FULL_HZ / 4
    assert all(b <= a for a, b in itertools.pairwise(rates)) and rates[-1] == MIN_HZ
    assert c.interval_s() == pytest.approx(1.0 / MIN_HZ)
    assert c.wait_s(now, 0.25) == pytest.approx(1.0 / MIN_HZ - 0.25)  # the rest of the interval
    assert c.wait_s(now, 2.0) == 0.0


def test_answers_in_between_keep_the_rate() -> None:
    c = PaceController(hz=20.0)
    answer(c, 0.0, 0.5 * (FAST_ANSWER_S + SLOW_ANSWER_S))
    assert c.hz == 20.0


def test_a_page_slow_to_draw_but_building_no_queue_keeps_its_rate_and_a_queue_halves_it() -> None:
    c, now, frame_s = PaceController(), 0.0, 0.5 * (FAST_ANSWER_S + SLOW_ANSWER_S)  # one slow frame per answer
    for _ in range(30):
        now = answer(c, now, frame_s) + 0.25
    assert c.hz == FULL_HZ and c.base_s() == pytest.approx(frame_s)
    now = answer(c, now, frame_s + 2.0 * QUEUE_GROWS_S)  # the same page, now with a queue
    assert c.hz == FULL_HZ / 2
    c.ping_sent(now)  # such a page is held only after several of its own answer times
    assert not c.held(now + HOLD_S) or HOLD_BASES * frame_s <= HOLD_S
    assert c.held(now + max(HOLD_S, HOLD_BASES * frame_s))


def test_a_page_that_catches_up_climbs_back_and_the_notice_goes_when_it_is_nearly_there() -> None:
    c, now = PaceController(hz=MIN_HZ), 0.0
    assert c.update_notice(now)
    rates, notices = [], []
    while c.hz < FULL_HZ:
        now = answer(c, now, 0.5 * FAST_ANSWER_S) + 0.25
        rates.append(c.hz)
        notices.append(c.update_notice(now))
    assert all(b > a for a, b in itertools.pairwise(rates))  # strictly up, no oscillation
    assert len(rates) <= 8  # from 1 Hz back to full in a few answers
    for hz, shown in zip(rates, notices, strict=True):
        assert shown == (hz < NOTICE_GONE_HZ)
    assert any(NOTICE_BELOW_HZ <= r < NOTICE_GONE_HZ for r in rates)  # hysteresis: still shown up there
    c.hz = 0.5 * (NOTICE_BELOW_HZ + NOTICE_GONE_HZ)
    assert not c.update_notice(now)  # ... but not shown again there on the way down


def test_an_unanswered_question_holds_the_stream_until_it_is_answered() -> None:
    c = PaceController()
    c.ping_sent(10.0)
    assert c.wait_s(10.0 + 0.5 * SLOW_ANSWER_S, 0.0) == 0.0  # not late yet: full rate
    late = 10.0 + 0.5 * (SLOW_ANSWER_S + HOLD_S)  # late, not yet held: the slowest rate
    assert not c.held(late) and c.wait_s(late, 0.25) == pytest.approx(1.0 / MIN_HZ - 0.25)
    assert c.held(10.0 + HOLD_S) and math.isinf(c.wait_s(10.0 + HOLD_S, 1e3))
    assert c.update_notice(10.0 + HOLD_S)
    c.ping_sent(11.5)  # asked again: the oldest question still counts
    assert c.ping_answered(130.0) == pytest.approx(120.0)  # a tab frozen for two minutes
    assert not c.held(130.0) and c.hz == FULL_HZ / 2


# ---------------------------------------------------------------- the gate on one client's windows
def test_the_gate_is_asked_before_each_window_but_not_inside_a_split_update() -> None:
    sizes = [3, 128, 128, 5, 4]  # a small update, one split over three windows, another small one
    events: list[str] = []

    async def windows() -> AsyncGenerator[Sequence[Any], None]:
        for n in sizes:
            yield list(range(n))

    def wait_s(client: int, since_last_send_s: float) -> float:
        assert client == 7 and since_last_send_s >= 0.0
        events.append("gate")
        return 0.0

    async def take() -> None:
        async for window in _paced(windows(), 7, wait_s, max_window=128):
            events.append(str(len(window)))

    # a thread of its own: a test process that drove Chromium (Playwright's sync API) has a loop in this one
    with ThreadPoolExecutor(1) as pool:
        pool.submit(asyncio.run, take()).result()
    assert events == ["gate", "3", "gate", "128", "128", "5", "gate", "4", "gate"]  # (the last: before the end)


def test_only_windows_with_scene_messages_touch_the_scene() -> None:
    """The GUI-only set matches what viser's page applies without a frame: panel values, new controls
    and notifications are GUI-only; a pose, a scene node or a localStorage question is not."""
    gui = m.GuiUpdateMessage(uuid="u", updates={"value": 1.0})
    note = m.RemoveNotificationMessage(uuid="n")
    pose = m.SetPositionMessage(name="/base", position=(0.0, 0.0, 0.0))
    ask = m.LocalStorageGetItemRequestMessage(key="k", request_uuid="r")
    assert not touches_scene([gui, note]) and not touches_scene([])
    assert touches_scene([gui, pose]) and touches_scene([ask])
