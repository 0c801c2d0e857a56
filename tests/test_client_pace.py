"""Pacing of slow pages (issue 14): the rate rule on its own (a pure controller, given times), then
the app with protocol-level clients that answer the server's questions late or not at all."""

from __future__ import annotations

import asyncio
import itertools
import math
import time
from collections.abc import AsyncGenerator, Iterator, Sequence
from typing import Any

import numpy as np
import pytest
from viser import _messages as m

from rns_viz.viz.app import RnsApp, start_app
from rns_viz.viz.client_pace import PING_KEY, _paced, touches_scene
from rns_viz.viz.pace_control import (
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
from tests.app_helpers import realtime_app
from tests.browser import live_group, wait_for_clients, wait_until
from tests.protocol_client import ProtocolClient

pytestmark = live_group  # servers running in real time: one at a time (tests/browser.py)


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

    asyncio.run(take())
    assert events == ["gate", "3", "gate", "128", "128", "5", "gate", "4", "gate"]  # (the last: before the end)


# ---------------------------------------------------------------- the app, protocol-level clients
@pytest.fixture
def trep_app() -> Iterator[RnsApp]:
    yield from realtime_app("trep")


def client_id(app: RnsApp, before: set[int]) -> int:
    wait_until(lambda: set(app.pace.pages) - before, 10.0, "the client's pacer")
    return next(iter(set(app.pace.pages) - before))


def poses_during(client: ProtocolClient, seconds: float) -> int:
    n = len(client.pose_times)
    time.sleep(seconds)
    return len(client.pose_times) - n


def test_a_slow_client_gets_fewer_updates_a_fast_one_all_and_a_frozen_one_none(trep_app: RnsApp) -> None:
    app = trep_app
    fast = ProtocolClient(app.port, decode=True, watch_node="/base/link1")
    fast_id = client_id(app, set())
    slow = ProtocolClient(app.port, decode=True, watch_node="/base/link1", answer_delay_s=2.0 * SLOW_ANSWER_S)
    slow_id = client_id(app, {fast_id})
    try:
        wait_for_clients(app, 2, "two clients")
        app.session.cyclic(True)  # the arm moves all the time: a new pose every frame
        wait_until(lambda: app.pace.state(slow_id)["hz"] <= FULL_HZ / 8, 30.0, "the slow client's rate to drop")
        assert app.pace.state(slow_id)["notice"] and not app.pace.state(fast_id)["notice"]
        notice = app.pace.pages[slow_id].notice_text
        wait_until(lambda: "Display slowed to" in (notice() or ""), 10.0, "the slowed-display line")
        assert app.pace.pages[fast_id].notice_text() is None
        assert app.pace.state(fast_id)["hz"] == FULL_HZ
        fast_before = len(fast.pose_times)
        slow_poses = poses_during(slow, 3.0)
        fast_poses = len(fast.pose_times) - fast_before
        assert fast_poses > 2 * slow_poses > 0  # fewer, not none; the fast client is not held back

        # The slow client's inputs count as ever (its socket is read at once).
        app.lock.take(slow_id)
        before = app.session.snapshot().q[0]
        slow.click(app.gui.kick._impl.uuid)  # type: ignore[attr-defined]
        wait_until(lambda: abs(app.session.snapshot().q[0] - before) > 1e-5, 10.0, "the slow client's kick")

        # A frozen page: nothing more is sent to it until it answers; then the current state.
        slow.frozen.set()
        wait_until(lambda: app.pace.state(slow_id)["held"], 30.0, "the frozen client to be held")
        time.sleep(0.5)
        assert poses_during(slow, 2.0) == 0 and poses_during(fast, 0.5) > 0
        slow.answer_delay_s = 0.0
        slow.thaw()
        wait_until(lambda: not app.pace.state(slow_id)["held"], 10.0, "the thawed client to answer")
        wait_until(lambda: app.pace.state(slow_id)["hz"] == FULL_HZ, 30.0, "the thawed client's full rate")
        wait_until(lambda: not app.pace.state(slow_id)["notice"], 5.0, "the notice to go")
        wait_until(lambda: notice() is None, 10.0, "the slowed-display line to go")
        assert poses_during(slow, 1.0) > 0
    finally:
        slow.close()
        fast.close()
    assert np.isfinite(app.session.snapshot().t)


def test_a_page_with_nothing_new_to_show_is_asked_nothing() -> None:
    """Every question makes viser's page draw 3-D frames (a question is not a GUI-only message), so a
    page whose stream is quiet is not asked: a paused app's page draws nothing. Once the scene moves,
    the questions (and the pacing) come back."""
    app = start_app("trep", port=0, realtime=False, verbose=False)  # moves only when the test steps it
    client = ProtocolClient(app.port, decode=True, watch_node="/base/link1")
    try:
        wait_for_clients(app, 1, "a client")
        page = app.pace.pages[client_id(app, set())]
        wait_until(lambda: page.answered_once, 10.0, "the first answer")
        time.sleep(1.0)  # the first scene and panel have gone out
        asked = client.answers_to[PING_KEY]
        time.sleep(1.5)  # six question gaps (PING_GAP_S) with nothing sent
        assert client.answers_to[PING_KEY] == asked, "a page with nothing new to show was asked"
        app.session.kick(5.0)
        app.session.advance(0.5)  # the arm and base move: new poses go out
        wait_until(lambda: client.answers_to[PING_KEY] > asked, 10.0, "a question once the stream moved")
        assert app.pace.state(page.client.client_id)["hz"] == FULL_HZ  # a page that keeps up
    finally:
        client.close()
        app.stop()


def test_a_running_app_at_rest_asks_nothing_while_only_the_panel_changes() -> None:
    """A real-time app whose arms rest still streams its panel (status line, plots: GUI-only messages,
    which viser's page applies without a 3-D frame). Those windows make no question due, so the page
    draws no frames for the questions; a kick moves the scene and the questions come back."""
    app = start_app("trep", port=0, verbose=False)  # real time, at rest
    client = ProtocolClient(app.port, decode=True, watch_node="/base/link1")
    try:
        wait_for_clients(app, 1, "a client")
        page = app.pace.pages[client_id(app, set())]
        wait_until(lambda: page.answered_once, 10.0, "the first answer")
        time.sleep(1.5)  # the first scene and panel have gone out, the last question answered
        asked, panel, poses = client.answers_to[PING_KEY], sum(client.gui_updates.values()), len(client.pose_times)
        time.sleep(1.5)  # six question gaps (PING_GAP_S)
        assert sum(client.gui_updates.values()) > panel + 5, "the running app's panel did not stream"
        assert len(client.pose_times) == poses, "the resting arm was sent new poses"
        assert client.answers_to[PING_KEY] == asked, "a page with only panel updates was asked"
        app.session.kick(0.8)
        wait_until(lambda: client.answers_to[PING_KEY] > asked, 10.0, "a question once the scene moved")
    finally:
        client.close()
        app.stop()


def test_only_windows_with_scene_messages_touch_the_scene() -> None:
    """The GUI-only set matches what viser's page applies without a frame: panel values, new controls
    and notifications are GUI-only; a pose, a scene node or a localStorage question is not."""
    gui = m.GuiUpdateMessage(uuid="u", updates={"value": 1.0})
    note = m.RemoveNotificationMessage(uuid="n")
    pose = m.SetPositionMessage(name="/base", position=(0.0, 0.0, 0.0))
    ask = m.LocalStorageGetItemRequestMessage(key="k", request_uuid="r")
    assert not touches_scene([gui, note]) and not touches_scene([])
    assert touches_scene([gui, pose]) and touches_scene([ask])


def test_pacing_switched_off_sends_every_client_everything() -> None:
    app = start_app("trep", port=0, verbose=False, pace=False)
    slow = ProtocolClient(app.port, decode=True, answer_delay_s=1.0)
    try:
        wait_for_clients(app, 1, "a client")
        time.sleep(1.0)
        assert app.pace.pages == {} and slow.answers_to[PING_KEY] == 0  # no pace questions asked
    finally:
        slow.close()
        app.stop()
