"""One student's app as jupyter-server-proxy starts it (``rns-viz serve --pause-unwatched``): the simulation
waits for the first page and pauses when the last page closes, so a forgotten server costs little, and runs
on, where it was, when a page comes back. A simulation the student paused stays paused."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from rns_viz.viz.server.app import RnsApp, start_app
from tests.support.browser import wait_for_clients, wait_until
from tests.support.protocol_client import ProtocolClient


@pytest.fixture
def app() -> Iterator[RnsApp]:
    app = start_app("trep", port=0, realtime=False, verbose=False, pause_unwatched=True)
    yield app
    app.stop()


def test_the_simulation_pauses_while_no_page_is_open_and_runs_on_when_one_comes(app: RnsApp) -> None:
    s = app.session
    s.advance(0.1)
    assert s.snapshot().paused and s.snapshot().t == 0.0  # nobody has opened the page yet
    page = ProtocolClient(app.port)
    wait_for_clients(app, 1, "the page")
    wait_until(lambda: s.pending_commands(), 10.0, "the resume to be sent")
    s.advance(0.2)
    assert not s.snapshot().paused
    t = s.snapshot().t
    page.close()
    wait_until(lambda: not app.server.get_clients() and s.pending_commands(), 10.0, "the pause to be sent")
    s.advance(0.2)
    assert s.snapshot().paused and s.snapshot().t == pytest.approx(t, abs=0.011)  # no time passes unwatched
    again = ProtocolClient(app.port)
    wait_until(lambda: app.server.get_clients() and s.pending_commands(), 10.0, "the resume to be sent")
    s.advance(0.2)
    assert not s.snapshot().paused and s.snapshot().t > t + 0.15  # on from where it was, not restarted
    s.pause()  # the student's own pause outlives their page
    s.advance(0.01)
    again.close()
    wait_until(lambda: not app.server.get_clients(), 10.0, "the page to close")
    third = ProtocolClient(app.port)
    wait_for_clients(app, 1, "the third page")
    s.advance(0.1)
    assert s.snapshot().paused
    third.close()
