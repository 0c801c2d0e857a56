"""trep2 in a real headless Chromium: the page loads both arms, a mouse drag of the target handle's x
arrow moves the task arm's target, the compensating arm answers, and a screenshot is saved
(artifacts/app_trep2.png).
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pytest
from playwright.sync_api import Page

from rns_viz.viz.scene.fsms_scene import FsmsScene
from rns_viz.viz.server.app import TARGET_HANDLE, RnsApp, start_app
from tests.browser import (
    browser_marks,
    browser_page,
    dismiss_notifications,
    screenshot,
    settle_for_picture,
    wait_for_frames,
    wait_for_nodes,
    wait_until,
)

pytestmark = browser_marks

# Screen position (px) of a point on a scene node's local x axis, ``offset`` m from its origin: the
# client's camera matrices applied to the node's world matrix (three.js, column-major).
PROJECT = """([name, offset]) => {
  const m = window.__viserMutable, obj = m.nodeRefFromName[name], cam = m.camera;
  obj.updateWorldMatrix(true, false);
  cam.updateMatrixWorld();
  const e = obj.matrixWorld.elements;
  const p = [e[12] + offset * e[0], e[13] + offset * e[1], e[14] + offset * e[2], 1];
  const mul = (M, v) => [0, 1, 2, 3].map((r) => M[r] * v[0] + M[4 + r] * v[1] + M[8 + r] * v[2] + M[12 + r] * v[3]);
  const c = mul(cam.projectionMatrix.elements, mul(cam.matrixWorldInverse.elements, p));
  const rect = m.canvas.getBoundingClientRect();
  return [rect.left + ((c[0] / c[3] + 1) / 2) * rect.width, rect.top + ((1 - c[1] / c[3]) / 2) * rect.height];
}"""


@pytest.fixture
def app() -> Iterator[RnsApp]:
    app = start_app("trep2", port=0, verbose=False)
    yield app
    app.stop()


DRAG_STEP_S = 0.1  # s between the drag's ten mouse moves: a hand's pace (a whole drag in about a second)


def drag_handle_along_x(page: Page, app: RnsApp, pixels: float) -> None:
    """Press on the handle's x arrow (30 % of its length out), move ``pixels`` along it in about a second
    (not at the pace of the page's frames, which depends on how fast the machine draws), release."""
    x0, y0 = page.evaluate(PROJECT, [TARGET_HANDLE, 0.3 * app.handle.scale])
    x1, y1 = page.evaluate(PROJECT, [TARGET_HANDLE, 0.6 * app.handle.scale])
    d = np.array([x1 - x0, y1 - y0]) / max(float(np.hypot(x1 - x0, y1 - y0)), 1e-9)
    page.mouse.move(x0, y0)
    page.mouse.down()
    for k in range(1, 11):
        page.mouse.move(x0 + d[0] * pixels * k / 10, y0 + d[1] * pixels * k / 10)
        wait_for_frames(page, 2)
        page.wait_for_timeout(1000 * DRAG_STEP_S)
    page.mouse.up()


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
