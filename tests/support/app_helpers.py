"""What the app and session tests share: a stepped app, a real-time app, a stepped session, boom7 kicked
in every row, a lesson driver, a handle's uuid, waiting for queued commands."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

from rns_viz.live.loop.session import Session
from rns_viz.viz.server.app import RnsApp, start_app
from tests.support.browser import wait_until


def stepped_app(model: str) -> Iterator[RnsApp]:
    """An app the test steps itself (no real-time loop), background jobs done; stopped afterwards."""
    app = start_app(model, port=0, realtime=False, verbose=False)
    assert app.session.wait_background()
    yield app
    app.stop()


def realtime_app(model: str, **options: Any) -> Iterator[RnsApp]:
    """An app whose own loop runs the simulation in real time (as ``rns-viz`` does); stopped afterwards."""
    app = start_app(model, port=0, verbose=False, **options)
    yield app
    app.stop()


def stepped_session(model: str, background_s: float = 120.0) -> Iterator[Session]:
    """A session without a server, stepped by the test, its background jobs (path, reachable set) done."""
    s = Session(model, realtime=False)
    assert s.wait_background(background_s)
    yield s
    s.stop()


BOOM7_KICK_N = 5.0  # N: the app's kick, along the tip's y and z


def kicked_boom7() -> Iterator[tuple[Session, dict[float, object]]]:
    """boom7 kicked sideways (y and z) with suppression on, 0.6 s stepped; every published snapshot by time."""
    s = Session("boom7", realtime=False)
    assert s.wait_background(120.0)
    s.kick(BOOM7_KICK_N, direction=(0.0, 1.0, 1.0, 0.0, 0.0, 0.0))
    snaps = {}
    for _ in range(60):
        s.advance(0.01)
        snap = s.snapshot()
        snaps[snap.t] = snap
    yield s, snaps
    s.stop()


def run_lesson(
    s: Session, model: str, number: int, student: Callable[[Session], None], background_s: float = 120.0
) -> tuple[bool, str]:
    """Start lesson ``number`` of ``model``, let ``student`` act; the lesson's (done, progress) after."""
    s.start_lesson(model, number)
    s.advance(0.01)
    assert s.wait_background(background_s)  # the path or the reachable set of the lesson's start
    s.advance(0.05)
    status = s.snapshot().lesson
    assert status is not None and status.number == number and not status.done
    student(s)
    status = s.snapshot().lesson
    assert status is not None
    return status.done, status.progress


def uuid(handle: object) -> str:
    return handle._impl.uuid  # type: ignore[attr-defined]


def queued(app: RnsApp, kind: str, count: int = 1) -> None:
    """Wait until the GUI callbacks (viser's thread pool) have queued ``count`` commands of ``kind``."""
    wait_until(lambda: app.session.pending_commands().count(kind) >= count, 10.0, f"{count} '{kind}' command(s)")
