"""What the app and session tests share: a stepped app, a real-time app, a stepped session, boom7 kicked
in every row, a lesson driver, a handle's uuid, waiting for queued commands, a user's model file, the
exceptions threads reported."""

from __future__ import annotations

import shutil
import threading
import traceback
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from rns_viz.live.loop.session import Session
from rns_viz.params import ASSETS_DIR
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


def user_model(folder: Path) -> Path:
    """A user's own model: the planar 3R's URDF and parameters under another name, in another folder (without the
    3R's [app] table: the app's generic defaults)."""
    shutil.copy(ASSETS_DIR / "planar3r.urdf", folder / "my_arm.urdf")
    text = (ASSETS_DIR / "planar3r.toml").read_text()
    text = text[: text.index("\n[app]")]
    text = text.replace('name = "planar3r"', 'name = "my_arm"').replace('"planar3r.urdf"', '"my_arm.urdf"')
    path = folder / "my_arm.toml"
    path.write_text(
        text.replace(
            "default_configuration_deg = [60.0, -60.0, -60.0]", "default_configuration_deg = [50.0, -60.0, -60.0]"
        )
    )
    return path


class Faults:
    """Every exception a thread, worker or callback reported: the app's threads print what they catch
    (traceback.print_exc), uncaught ones reach threading.excepthook. ``install`` for the test's duration."""

    def __init__(self) -> None:
        self.seen: list[str] = []

    def install(self, monkeypatch: pytest.MonkeyPatch) -> None:
        print_exc, hook = traceback.print_exc, threading.excepthook

        def record_print_exc(*args: Any, **kwargs: Any) -> None:
            self.seen.append(traceback.format_exc())
            print_exc(*args, **kwargs)

        def record_hook(exc: threading.ExceptHookArgs) -> None:
            self.seen.append(f"{exc.thread}: {exc.exc_type.__name__}: {exc.exc_value}")
            hook(exc)

        monkeypatch.setattr(traceback, "print_exc", record_print_exc)
        monkeypatch.setattr(threading, "excepthook", record_hook)
