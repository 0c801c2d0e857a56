"""Pacing of slow pages in the app, with protocol-level clients that answer the server's
questions late or not at all (the rule on its own: tests/unit/test_client_pace.py)."""

from __future__ import annotations

import time
from collections.abc import Iterator

import numpy as np
import pytest

from rns_viz.viz.server.app import RnsApp, start_app
from rns_viz.viz.server.page_pacing import PING_KEY
from rns_viz.viz.server.page_rate import (
    FULL_HZ,
    SLOW_ANSWER_S,
)
from tests.support.app_helpers import realtime_app
from tests.support.browser import live_group, wait_for_clients, wait_until
from tests.support.protocol_client import ProtocolClient

pytestmark = live_group  # the app meets slow and frozen clients: one such test at a time (tests/support/browser.py)


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
