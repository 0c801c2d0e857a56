"""What the headless app tests share: a stepped app, a handle's uuid, waiting for queued commands."""

from __future__ import annotations

from collections.abc import Iterator

from rns_viz.viz.app import RnsApp, start_app
from tests.browser import wait_until


def stepped_app(model: str) -> Iterator[RnsApp]:
    """An app the test steps itself (no real-time loop), background jobs done; stopped afterwards."""
    app = start_app(model, port=0, realtime=False, verbose=False)
    assert app.session.wait_background()
    yield app
    app.stop()


def uuid(handle: object) -> str:
    return handle._impl.uuid  # type: ignore[attr-defined]


def queued(app: RnsApp, kind: str, count: int = 1) -> None:
    """Wait until the GUI callbacks (viser's thread pool) have queued ``count`` commands of ``kind``."""
    wait_until(lambda: app.session.pending_commands().count(kind) >= count, 10.0, f"{count} '{kind}' command(s)")
