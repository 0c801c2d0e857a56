"""Reloading a page and coming back: a reload (the page's connection closes, a new one opens from the same
browser) keeps the simulation, its recording and, for the operator's page, control; a session nobody
watched for over a minute of simulated time restarts for its first visitor; whoever takes control tells
the operator it had. Protocol-level clients with their own localStorage stand in for browser tabs."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from rns_viz.viz.clients.connections import BROWSER_KEY
from rns_viz.viz.server import app as app_module
from rns_viz.viz.server.app import RnsApp, start_app
from tests.support.app_helpers import stepped_app
from tests.support.browser import wait_until
from tests.support.protocol_client import ProtocolClient, gui_uuid


@pytest.fixture
def app() -> Iterator[RnsApp]:
    yield from stepped_app("trep")


def join(app: RnsApp, storage: dict[str, str]) -> tuple[ProtocolClient, int]:
    """A tab of the browser whose localStorage is ``storage``, connected and identified; (tab, client id)."""
    before = set(app.lock.clients())
    tab = ProtocolClient(app.port, storage=storage, decode=True)
    wait_until(lambda: len(set(app.lock.clients()) - before) == 1, 10.0, "the tab to connect")
    (cid,) = set(app.lock.clients()) - before
    wait_until(lambda: app.lock.browser(cid) and BROWSER_KEY in storage, 10.0, "the tab's browser to be known")
    assert app.lock.browser(cid) == storage[BROWSER_KEY]
    return tab, cid


def test_a_reload_keeps_the_simulation_its_recording_and_control(app: RnsApp) -> None:
    s = app.session
    a_browser: dict[str, str] = {}
    a, a_id = join(app, a_browser)
    b, b_id = join(app, {})
    assert app.lock.is_operator(a_id)
    s.kick(0.8)
    s.advance(3.0)
    before = s.snapshot()
    recorded = s.recording(60.0)
    assert recorded is not None and before.t > 2.9
    a.close()  # the operator's page reloads: its connection closes ...
    wait_until(lambda: a_id not in app.lock.clients(), 10.0, "the old page to leave")
    assert app.lock.operator is None  # ... control waits for it, not passed to the watcher
    a2, a2_id = join(app, a_browser)  # ... and the same browser connects again
    wait_until(lambda: app.lock.is_operator(a2_id), 10.0, "the reloaded page to operate again")
    after = s.snapshot()
    assert (after.epoch, after.t) == (before.epoch, before.t)  # the same run, not restarted
    again = s.recording(60.0)
    assert again is not None and again.span == recorded.span
    wait_until(lambda: any("reloaded" in body for _, body in a2.notifications), 10.0, "the reload to be told")
    # The watcher takes control: the operator is told.
    panel = app.connections.panels.panel(b_id)
    assert panel is not None
    b.click(gui_uuid(panel.take))
    wait_until(lambda: app.lock.is_operator(b_id), 10.0, "the watcher to take control")
    wait_until(
        lambda: any(t == "Control taken" and str(b_id) in body for t, body in a2.notifications),
        10.0,
        "the previous operator to be told who took control",
    )
    for tab in (a2, b):
        tab.close()


def test_an_operator_page_that_does_not_come_back_passes_control_on(app: RnsApp, monkeypatch) -> None:  # type: ignore[no-untyped-def]
    monkeypatch.setattr("rns_viz.live.operator.operator_lock.RELOAD_GRACE_S", 0.5)
    a, a_id = join(app, {})
    b, b_id = join(app, {})
    assert app.lock.is_operator(a_id)
    a.close()
    wait_until(lambda: app.lock.is_operator(b_id), 10.0, "control to pass on after the grace")
    wait_until(lambda: any("did not come back" in body for _, body in b.notifications), 10.0, "the heir to be told")
    b.close()


def test_a_session_nobody_watched_for_a_while_restarts_for_its_first_visitor(app: RnsApp, monkeypatch) -> None:  # type: ignore[no-untyped-def]
    monkeypatch.setattr(app_module, "IDLE_RESTART_S", 1.0)  # s of simulated time (the app's is 60)
    s = app.session
    a, _ = join(app, {})
    s.advance(1.5)  # watched all along: longer than the rule's time, so t alone must not restart it
    epoch = s.snapshot().epoch
    a.close()
    wait_until(lambda: not app.lock.clients(), 10.0, "the page to leave")
    s.advance(0.5)  # unwatched, briefly
    b, _ = join(app, {})
    s.advance(0.001)
    assert s.snapshot().epoch == epoch and s.snapshot().t > 1.9
    b.close()
    wait_until(lambda: not app.lock.clients(), 10.0, "the page to leave")
    s.advance(1.1)  # unwatched longer than the rule's time
    c, _ = join(app, {})
    wait_until(lambda: "Reset" in s.pending_commands() or s.snapshot().epoch != epoch, 10.0, "the restart")
    s.advance(0.001)
    assert s.snapshot().epoch != epoch and s.snapshot().t < 0.01
    c.close()


def test_a_browser_that_gave_the_password_is_not_asked_again_after_a_reload() -> None:
    app = start_app("trep", port=0, realtime=False, verbose=False, password="s3cret")
    try:
        browser: dict[str, str] = {}
        before = set(app.lock.clients())
        a = ProtocolClient(app.port, storage=browser, decode=True)
        wait_until(lambda: a.types["GuiModalMessage"] == 1, 10.0, "the password to be asked")
        (a_id,) = set(app.lock.clients()) - before
        assert app.lock.operator is None and app.lock.authenticate(a_id, "s3cret") and app.lock.is_operator(a_id)
        a.close()
        a2, a2_id = join(app, browser)
        wait_until(lambda: app.lock.is_operator(a2_id), 10.0, "the reloaded page to operate again")
        assert app.lock.may_operate(a2_id) and a2.types["GuiModalMessage"] == 0  # not asked again
        stranger, stranger_id = join(app, {})
        wait_until(lambda: stranger.types["GuiModalMessage"] == 1, 10.0, "another browser to be asked")
        assert not app.lock.may_operate(stranger_id)
        for tab in (a2, stranger):
            tab.close()
    finally:
        app.stop()
