"""boom-panda in a real headless Chromium: the Panda's own meshes load on the boom, a kick from the page
is suppressed; the screenshot goes to artifacts/app_boom_panda.png. Needs example-robot-data (the
rns-viz[panda] extra); skipped without it.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pytest

from rns_viz import robots
from rns_viz.viz.scene.fsms_scene import FsmsScene
from rns_viz.viz.server.app import TARGET_HANDLE, RnsApp
from tests.support.app_helpers import realtime_app
from tests.support.browser import (
    browser_page,
    dismiss_notifications,
    screenshot,
    settle_for_picture,
    wait_for_nodes,
    wait_until,
)

pytestmark = [
    pytest.mark.skipif(
        not robots.is_installed("example-robot-data/panda"),
        reason="example-robot-data is not installed (pip install 'rns-viz[panda]')",
    ),
]


@pytest.fixture
def panda_app() -> Iterator[RnsApp]:
    yield from realtime_app("boom-panda")


def test_boom_panda_in_chromium_shows_the_meshes_and_suppresses_a_kick(panda_app: RnsApp) -> None:
    app, s = panda_app, panda_app.session
    meshes = {mesh.name for mesh in app.scene.robot.meshes if ".dae" in mesh.name}
    assert len(meshes) >= 10  # every link's visual .dae (several parts each)
    with browser_page(app.server, width=1400, height=900) as page:
        wait_for_nodes(page, {FsmsScene.BASE, TARGET_HANDLE, "/boom/tube", *meshes}, timeout=90.0)
        dismiss_notifications(page)
        page.get_by_role("button", name="Kick the base").click()
        wait_until(lambda: abs(s.snapshot().q_shadow[1]) > 1e-4, 15.0, "the kick to bend the boom")  # type: ignore[index]
        wait_until(lambda: np.abs(s.snapshot().q[:6]).max() < 1e-6, 30.0, "suppression to bring the boom to rest")
        wait_until(lambda: app.plot_updates > 5, 15.0, "live plot updates")
        app.scene.set_initial_camera()
        page.mouse.move(5, 5)
        page.get_by_text("Operate", exact=True).scroll_into_view_if_needed()
        for _ in range(2):  # a software-rendered page may raise its WebGL toast late
            dismiss_notifications(page)
            settle_for_picture(page, 30)
        assert screenshot(page, "app_boom_panda").stat().st_size > 10_000
