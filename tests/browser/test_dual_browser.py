"""trep2 in a real headless Chromium: the page loads both arms, a mouse drag of the target handle's x
arrow moves the task arm's target, the compensating arm answers, and a screenshot is saved
(artifacts/app_trep2.png).
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pytest

from rns_viz.viz.scene.fsms_scene import FsmsScene
from rns_viz.viz.server.app import TARGET_HANDLE, RnsApp, start_app
from tests.support.browser import (
    browser_page,
    dismiss_notifications,
    drag_handle_along_x,
    screenshot,
    settle_for_picture,
    wait_for_frames,
    wait_for_nodes,
    wait_until,
)


@pytest.fixture
def app() -> Iterator[RnsApp]:
    app = start_app("trep2", port=0, verbose=False)
    yield app
    app.stop()


def test_drag_the_task_arm_in_chromium(app: RnsApp) -> None:
    s = app.session
    model = app.model
    comp = model.arm_groups["compensating"].index + model.m
    with browser_page(app.server, width=1400, height=900) as page:
        wait_for_nodes(page, {FsmsScene.BASE, FsmsScene.TARGET, TARGET_HANDLE, "/base/c_link1", "/base/link1"})
        dismiss_notifications(page)
        wait_for_frames(page, 10)
        before = np.array(s.snapshot().target, dtype=float)
        start = s.snapshot().q[comp].copy()
        for attempt in range(3):  # a software-rendered page may miss a press made while it re-lays the panel
            drag_handle_along_x(page, app, 60.0)
            try:
                wait_until(lambda: abs(s.snapshot().target[0] - before[0]) > 0.01, 10.0, "the target to move")
                break
            except AssertionError:
                if attempt == 2:
                    raise
        wait_until(lambda: s.snapshot().mode == "holding at the target", 30.0, "the task arm to arrive")
        snap = s.snapshot()
        assert np.abs(snap.q[comp] - start).max() > 0.02  # rad: the compensator moved to cancel
        assert snap.readouts.dual and snap.readouts.cancel is None
        assert snap.q_shadow is not None and abs(snap.q_shadow[0]) > 10 * abs(snap.q[0])  # held: the beam swings
        app.scene.set_initial_camera()
        page.mouse.move(5, 5)
        dismiss_notifications(page)
        settle_for_picture(page, 30)
        assert screenshot(page, "app_trep2").stat().st_size > 10_000
