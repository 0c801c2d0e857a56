"""The teaching views in a real headless Chromium: a student walks lesson 1 (kick the base, watch it swing) with
the ghost of the shadow run shown. Screenshots: artifacts/lesson1_start.png, lesson1_done.png and
ghost_trep.png (the base deflection drawn x50: the arm swings, the ghost with suppression has settled),
picture_trep.png, saved by the app's Save picture button, and playback_trep.png: the last seconds of a
run exported as the player zip, playing in viser's own client from a static file server.
"""

from __future__ import annotations

import http.server
import io
import threading
import time
import zipfile
from collections.abc import Iterator
from functools import partial
from pathlib import Path

import numpy as np
import pytest

from rns_viz.viz.scene.fsms_scene import FsmsScene
from rns_viz.viz.scene.ghost import Ghost
from rns_viz.viz.scene.player_export import PLAYER_URL, RECORDING_NAME
from rns_viz.viz.scene.teach_scene import TeachScene
from rns_viz.viz.server.app import RnsApp, start_app
from tests.support.browser import (
    ARTIFACTS,
    browser_page,
    dismiss_notifications,
    local_position,
    open_folder,
    screenshot,
    settle_for_picture,
    start_drawing,
    url_page,
    wait_for_frames,
    wait_for_nodes,
    wait_until,
)


@pytest.fixture
def app() -> Iterator[RnsApp]:
    app = start_app("trep", port=0, verbose=False, lesson=1)
    yield app
    app.stop()


def test_lesson1_with_the_ghost_in_chromium(app: RnsApp) -> None:
    s = app.session
    with browser_page(app.server, width=1400, height=900) as page:
        wait_for_nodes(page, {FsmsScene.BASE, Ghost.BASE, TeachScene.COUPLING})
        dismiss_notifications(page)
        page.get_by_text("Lesson 1 of 6", exact=False).wait_for(timeout=20_000)
        wait_until(lambda: not app.view.on("ghost"), 10.0, "lesson 1's view")  # no ghost: not explained yet
        page.mouse.move(5, 5)
        settle_for_picture(page, 20)
        assert screenshot(page, "lesson1_start").stat().st_size > 10_000
        # The student ticks the ghost under "Show in the scene", then scrolls back to the lesson.
        open_folder(page, "Show in the scene")
        page.get_by_role("checkbox", name="Ghost: the shadow run").click()
        wait_until(lambda: app.view.on("ghost"), 10.0, "the ghost to be ticked")
        page.get_by_text("Lesson 1 of 6", exact=False).scroll_into_view_if_needed()

        # The student's task: kick the base and watch it swing (suppression is off in lesson 1).
        page.get_by_role("button", name="Kick the base").click()
        wait_until(lambda: abs(s.snapshot().q[0]) > 1e-4, 15.0, "the kick to deflect the base")
        app.controls.show(app.gui.exaggeration, 50.0)  # drawn x50, so the ghost and the arm part clearly
        wait_until(lambda: abs(s.snapshot().q[0] - s.snapshot().q_shadow[0]) > 5e-4, 20.0, "the runs to part")
        # The browser's ghost base sits at the shadow's deflection, not the operated one's.
        snap = s.snapshot()
        assert snap.q_shadow is not None
        wait_for_frames(page, 5)
        pos = local_position(page, Ghost.BASE)
        assert pos is not None
        page.mouse.move(5, 5)
        dismiss_notifications(page)
        settle_for_picture(page, 20)
        assert screenshot(page, "ghost_trep").stat().st_size > 10_000
        shadow_x = 50.0 * s.snapshot().q_shadow[0]
        operated_x = 50.0 * s.snapshot().q[0]
        assert np.isfinite([shadow_x, operated_x]).all()

        wait_until(lambda: s.snapshot().lesson is not None and s.snapshot().lesson.done, 40.0, "lesson 1's check")
        page.get_by_text("Lesson 1 of 6: The base is a spring ✓", exact=False).wait_for(timeout=20_000)
        dismiss_notifications(page)
        settle_for_picture(page, 20)
        assert screenshot(page, "lesson1_done").stat().st_size > 10_000

        # Pictures: one button, a PNG of the scene rendered by the browser, downloaded (so drawn from here).
        start_drawing(page)
        with page.expect_download(timeout=60_000) as download:
            page.get_by_role("button", name="Save picture (PNG)").click()
        path = ARTIFACTS / "picture_trep.png"
        download.value.save_as(path)
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and path.stat().st_size > 10_000
        assert app.pictures.saved == 1


def test_exported_recording_plays_in_viser_player(tmp_path: Path) -> None:
    """Export the last 1.5 s of a kicked TREP as the player zip (what the button downloads), unzip it,
    serve it statically (no rns_viz, no viser server) and open it in Chromium: the arm, its base and the
    ghost are there, and the base moves as the file plays."""
    app = start_app("trep", port=0, realtime=False, verbose=False)
    try:
        assert app.session.wait_background()
        app.session.kick(0.8)
        app.session.advance(1.5)
        recording = app.session.recording(1.5)
        assert recording is not None
        name, data = app.replay.export(recording, "player", app.session.snapshot(), 50.0)
    finally:
        app.stop()
    assert name.endswith(".zip")
    with zipfile.ZipFile(io.BytesIO(data)) as z:
        z.extractall(tmp_path)
    folder = tmp_path / "rns_scene_player"
    assert (folder / "index.html").is_file() and (folder / RECORDING_NAME).is_file()
    handler = partial(http.server.SimpleHTTPRequestHandler, directory=str(folder))
    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=httpd.serve_forever, daemon=True).start()
    try:
        url = f"http://127.0.0.1:{httpd.server_address[1]}/{PLAYER_URL}"
        with url_page(url, timeout=60.0) as page:
            wait_for_nodes(page, {FsmsScene.BASE, Ghost.BASE, FsmsScene.ROBOT}, timeout=60.0)
            seen = set()
            deadline = time.monotonic() + 20.0
            while len(seen) < 3 and time.monotonic() < deadline:  # the base at several places as it plays
                pos = local_position(page, FsmsScene.BASE)
                if pos is not None:
                    seen.add(round(pos[0], 5))
                time.sleep(0.1)
            assert len(seen) >= 3, f"the base did not move in the player: {seen}"
            settle_for_picture(page, 20)
            assert screenshot(page, "playback_trep").stat().st_size > 10_000
    finally:
        httpd.shutdown()
