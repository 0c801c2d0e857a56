"""Issue 11 in a real headless Chromium: a student walks lesson 1 (kick the base, watch it swing) with
the ghost of the shadow run shown. Screenshots: artifacts/lesson1_start.png, lesson1_done.png and
ghost_trep.png (the base deflection drawn x50: the arm swings, the ghost with suppression has settled),
and picture_trep.png, saved by the app's Save picture button.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pytest

from rns_viz.viz.app import RnsApp, start_app
from rns_viz.viz.ghost import Ghost
from rns_viz.viz.scene import FsmsScene
from rns_viz.viz.teach_scene import TeachScene
from tests.browser import (
    ARTIFACTS,
    browser_page,
    dismiss_notifications,
    local_position,
    requires_chromium,
    screenshot,
    wait_for_frames,
    wait_for_nodes,
    wait_until,
)

pytestmark = [pytest.mark.browser, requires_chromium]


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
        page.mouse.move(5, 5)
        wait_for_frames(page, 20)
        assert screenshot(page, "lesson1_start").stat().st_size > 10_000

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
        wait_for_frames(page, 20)
        assert screenshot(page, "ghost_trep").stat().st_size > 10_000
        shadow_x = 50.0 * s.snapshot().q_shadow[0]
        operated_x = 50.0 * s.snapshot().q[0]
        assert np.isfinite([shadow_x, operated_x]).all()

        wait_until(lambda: s.snapshot().lesson is not None and s.snapshot().lesson.done, 40.0, "lesson 1's check")
        page.get_by_text("Lesson 1 of 6: The base is a spring ✓", exact=False).wait_for(timeout=20_000)
        dismiss_notifications(page)
        wait_for_frames(page, 20)
        assert screenshot(page, "lesson1_done").stat().st_size > 10_000

        # Pictures: one button, a PNG of the scene rendered by the browser, downloaded.
        with page.expect_download(timeout=60_000) as download:
            page.get_by_role("button", name="Save picture (PNG)").click()
        path = ARTIFACTS / "picture_trep.png"
        download.value.save_as(path)
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and path.stat().st_size > 10_000
        assert app.pictures.saved == 1
