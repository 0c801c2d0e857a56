"""A simulation per visitor (``rns-viz serve --each-visitor``): protocol-level clients of one server.

Each page gets its own session and app in viser's per-client scope: a kick or a drag from one page moves
only that page's simulation (and a page cannot press another page's buttons); a page that leaves frees its
simulation (threads ended, objects collectable); past the cap a page is told the class is full and gets the
next free place without a reload; an idle page's simulation is paused, then closed with an offer to start
again. Sessions are stepped by the test (no real-time loop) except where threads are the point.
"""

from __future__ import annotations

import gc
import time
import weakref
from collections.abc import Iterator

import numpy as np
import pytest

from rns_viz.live.loop.session import Session
from rns_viz.viz.server.app import TARGET_HANDLE, RnsApp
from rns_viz.viz.server.classroom import Classroom, default_visitor_cap, start_classroom
from rns_viz.viz.server.page_rate import FULL_HZ, SLOW_ANSWER_S
from tests.support.app_helpers import uuid
from tests.support.browser import live_group, wait_until
from tests.support.protocol_client import ProtocolClient

KICK_S = 0.3  # s simulated after a kick: the base has swung by then


def stepped(model: str) -> Session:
    return Session(model, realtime=False)


@pytest.fixture
def room() -> Iterator[Classroom]:
    """A per-visitor server for at most two pages, their sessions stepped by the test."""
    room = start_classroom("trep", port=0, max_visitors=2, verbose=False, make_session=stepped)
    yield room
    room.stop()


def visitors(room: Classroom, count: int) -> list[tuple[ProtocolClient, RnsApp]]:
    """``count`` pages, each with its app (in the order they connected), once every app took its page."""
    clients = []
    for _ in range(count):
        clients.append(ProtocolClient(room.port))
        wait_until(lambda: len(room.apps()) == len(clients), 60.0, "the visitor's app")
    apps = room.apps()
    wait_until(lambda: all(len(app.lock.clients()) == 1 for app in apps.values()), 10.0, "the apps' clients")
    return [(client, apps[cid]) for client, cid in zip(clients, sorted(apps), strict=True)]


def base_swing(app: RnsApp) -> float:
    """The base's largest deflection so far in the operated run's log, m or rad."""
    log = app.session.state.runs.sim.log.array(None)
    m = app.model.m
    return float(np.abs(log[:, 1 : 1 + m]).max()) if len(log) else 0.0


def wait_applied(app: RnsApp) -> None:
    wait_until(lambda: not app.session.pending_commands(), 10.0, "the input to be queued and applied")


def test_two_visitors_kick_and_drag_each_their_own_simulation(room: Classroom) -> None:
    (a, app_a), (b, app_b) = visitors(room, 2)
    assert app_a.session is not app_b.session and app_a.lock.operator is not None
    for app in (app_a, app_b):  # a page with a simulation of its own operates it: no Operator panel to give it away
        (cid,) = app.lock.clients()
        assert app.lock.operator == cid and app.connections.panels.panel(cid) is None
    for app in (app_a, app_b):
        app.session.advance(0.1)

    # A page cannot press another page's button: B's kick sent from A's page kicks nobody.
    a.click(uuid(app_b.gui.kick))
    kicks_b = app_b.session.state.kicks_sent
    a.click(uuid(app_a.gui.kick))  # A's own kick
    wait_until(lambda: app_a.session.state.kicks_sent > 0 or app_a.session.pending_commands(), 10.0, "A's kick")
    for app in (app_a, app_b):
        app.session.advance(KICK_S)
    assert app_a.session.state.kicks_sent == 1 and app_b.session.state.kicks_sent == kicks_b == 0
    assert base_swing(app_a) > 1e-4  # A's base swings
    assert base_swing(app_b) == 0.0  # B's has not moved at all

    # B drags its target 3 cm off its hand; A has no target and gets none.
    assert app_a.session.snapshot().target is None and app_b.session.snapshot().target is None
    ee = app_b.model.ee_position(app_b.session.snapshot().q[app_b.model.m :])
    owner = str(app_b.lock.clients()[0])  # B's handle is in B's own scope (the page echoes its owner)
    b.drag(TARGET_HANDLE, (ee[0] + 0.03, ee[1], ee[2]), phase="start", owner=owner)
    b.drag(TARGET_HANDLE, (ee[0] + 0.03, ee[1], ee[2]), phase="end", owner=owner)

    def b_target_moved() -> bool:  # the drag starts at the hand, then the target follows the handle
        app_b.session.advance(0.01)
        target = app_b.session.snapshot().target
        return target is not None and np.linalg.norm(np.asarray(target)[:2] - ee[:2]) > 0.01

    wait_until(b_target_moved, 10.0, "B's drag to move its target")
    app_a.session.advance(0.05)
    assert app_a.session.snapshot().target is None
    a.close()
    b.close()


@live_group  # real time: one such test at a time (tests/support/browser.py)
def test_a_visitor_leaving_frees_the_simulation() -> None:
    """Real-time sessions: the simulation and render threads end and nothing holds the session any more."""
    room = start_classroom("trep", port=0, max_visitors=2, verbose=False)
    try:
        (page, app), (other, app_other) = visitors(room, 2)
        sim_thread, render_thread = app.session._thread, app.render_thread
        assert sim_thread is not None and sim_thread.is_alive() and render_thread.is_alive()
        session_ref, app_ref = weakref.ref(app.session), weakref.ref(app)
        del app
        page.close()
        wait_until(lambda: len(room.apps()) == 1, 20.0, "the visitor's app to go")
        wait_until(lambda: not sim_thread.is_alive() and not render_thread.is_alive(), 10.0, "its threads to end")
        # A callback thread of the app may still be waiting on the page it had (an unanswered question ends
        # when viser drops the client): the session is free once it returns.
        wait_until(lambda: gc.collect() >= 0 and session_ref() is None and app_ref() is None, 30.0, "the session freed")
        assert app_other.session._thread is not None and app_other.session._thread.is_alive()  # the other runs on
        other.close()
    finally:
        room.stop()


def test_past_the_cap_a_page_is_told_and_gets_the_next_free_place(room: Classroom) -> None:
    (a, _), (b, _) = visitors(room, 2)
    late = ProtocolClient(room.port, decode=True)
    wait_until(lambda: len(room.waiting) == 1, 20.0, "the third page to wait")
    late_id = room.waiting[0]
    wait_until(lambda: room.notice_text(late_id) is not None, 10.0, "the full-class message")
    assert "class is full" in room.notice_text(late_id) and "All 2 simulations" in room.notice_text(late_id)
    assert late_id not in room.apps() and len(room.apps()) == 2
    a.close()  # a place frees: the waiting page gets it, no reload
    wait_until(lambda: late_id in room.apps(), 60.0, "the waiting page to get the free place")
    assert room.notice_text(late_id) is None and not room.waiting
    b.close()
    late.close()


def test_an_idle_visitor_is_paused_then_closed_and_may_start_again(room: Classroom) -> None:
    ((page, app),) = visitors(room, 1)
    cid = next(iter(room.apps()))
    start = room.visitors[cid].last_input
    room.check_idle(now=start + room.idle_pause_s + 1.0)
    app.session.advance(0.01)
    assert app.session.snapshot().paused and room.apps()[cid] is app
    page.camera((1.0, 0.0, 0.0, 0.0), (0.6, 0.5, 0.5))  # the visitor moves the view: input, so it runs again
    wait_until(lambda: not room.visitors[cid].idle_paused, 10.0, "the input to be seen")
    app.session.advance(0.01)
    assert not app.session.snapshot().paused
    room.check_idle(now=room.visitors[cid].last_input + room.idle_close_s + 1.0)
    assert cid not in room.apps() and "closed" in (room.notice_text(cid) or "")
    assert not app.render_thread.is_alive()
    page.click(uuid(room.visitors[cid].start_again))
    wait_until(lambda: cid in room.apps(), 60.0, "a new simulation for the page")
    assert room.apps()[cid] is not app and room.notice_text(cid) is None
    page.close()


def test_the_presenter_shows_their_simulation_on_every_page_view_only(room: Classroom) -> None:
    """Only the first page is the presenter's here. While it shows its simulation, the other page draws the
    presenter's session (its own paused) and its inputs are refused with a message; unticked, the page gets
    its own simulation back, running again."""
    room.is_presenter = lambda cid: not room.visitors  # the first page to arrive
    (a, app_a), (b, app_b) = visitors(room, 2)
    a_id, b_id = sorted(room.apps())
    assert room.visitors[b_id].extra is None  # no switch on a student's page
    own_b = app_b.session
    a.set_value(uuid(room.visitors[a_id].extra), True)
    wait_until(lambda: room.visitors[b_id].watching and room.visitors[b_id].app is not None, 30.0, "B to watch")
    watching = room.apps()[b_id]
    own_b.advance(0.01)
    assert watching.session.snapshot() is app_a.session.snapshot() and own_b.snapshot().paused
    assert not app_b.render_thread.is_alive()  # B's own app is off its page

    a.click(uuid(app_a.gui.kick))  # the presenter drives
    wait_until(lambda: app_a.session.pending_commands(), 10.0, "the presenter's kick")
    app_a.session.advance(KICK_S)
    assert app_a.session.state.kicks_sent == 1 and base_swing(app_a) > 1e-4
    b.click(uuid(watching.gui.kick))  # a watcher's kick goes nowhere, and the watcher is told
    wait_until(lambda: any(t == "Watching the presenter" for t, _ in b.notifications), 10.0, "the refusal")
    app_a.session.advance(0.01)
    assert app_a.session.state.kicks_sent == 1 and own_b.state.kicks_sent == 0

    a.set_value(uuid(room.visitors[a_id].extra), False)
    wait_until(lambda: not room.visitors[b_id].watching and room.visitors[b_id].app is not None, 30.0, "B's own")
    back = room.apps()[b_id]
    own_b.advance(0.01)
    assert back.session is own_b and not own_b.snapshot().paused and not watching.render_thread.is_alive()
    assert room.apps()[a_id] is app_a  # the presenter's app was never touched
    a.close()
    b.close()


@live_group
def test_a_slow_page_gets_fewer_updates_of_its_own_simulation_and_a_fast_page_all() -> None:
    """Each page's own stream is paced by its own app: a page that answers late gets fewer, newer frames and
    is told so; the fast page next to it is paced by its own answers, above the slow one."""
    room = start_classroom("trep", port=0, max_visitors=2, verbose=False)
    try:
        fast = ProtocolClient(room.port, decode=True, watch_node="/base/link1")
        wait_until(lambda: len(room.apps()) == 1, 60.0, "the fast page's app")
        slow = ProtocolClient(room.port, decode=True, watch_node="/base/link1", answer_delay_s=2.0 * SLOW_ANSWER_S)
        wait_until(lambda: len(room.apps()) == 2, 60.0, "the slow page's app")
        (fast_id, fast_app), (slow_id, slow_app) = sorted(room.apps().items())
        assert fast_app.pace.enabled and slow_app.pace.enabled
        for app in (fast_app, slow_app):
            app.session.cyclic(True)  # the arm moves all the time: a new pose every frame
        wait_until(lambda: (slow_app.pace.state(slow_id) or {}).get("hz", FULL_HZ) <= FULL_HZ / 4, 30.0, "slow")
        # Each page is paced by its own answers: the fast page stays above the slow one (at FULL_HZ on a quiet
        # machine; a busy one delays the fast page's answers too, and its app may halve its rate for a while).
        hz = lambda app, cid: (app.pace.state(cid) or {}).get("hz", FULL_HZ)  # noqa: E731
        wait_until(lambda: hz(fast_app, fast_id) > hz(slow_app, slow_id), 30.0, "the fast page paced above the slow")
        wait_until(lambda: "Display slowed to" in (slow_app.pace.pages[slow_id].notice_text() or ""), 10.0, "told")
        fast_before, slow_before = len(fast.pose_times), len(slow.pose_times)
        drawn_before = slow_app.scene_updates
        time.sleep(3.0)
        fast_poses, slow_poses = len(fast.pose_times) - fast_before, len(slow.pose_times) - slow_before
        drawn = slow_app.scene_updates - drawn_before
        # Fewer, not none: fewer than its own app drew and than the fast page got (on a quiet machine about a
        # quarter; on a busy one the apps draw fewer frames for both, so no fixed ratio is asked).
        assert 0 < slow_poses < min(drawn, fast_poses), (slow_poses, drawn, fast_poses)
        slow.close()
        fast.close()
    finally:
        room.stop()


def test_the_default_cap_follows_the_cores_and_the_step() -> None:
    """More simulations with the native step (a fifth of a core each, measured) than with the Python step,
    one interpreter's worth at most whatever the cores, never none."""
    assert default_visitor_cap(1, native=False) == 1 and default_visitor_cap(2, native=False) == 2
    assert default_visitor_cap(2, native=True) == 5 and default_visitor_cap(1, native=True) == 2
    assert default_visitor_cap(64, native=False) == 3 and default_visitor_cap(64, native=True) == 5
    assert default_visitor_cap(None, native=None) >= 1  # this machine, whatever it has
