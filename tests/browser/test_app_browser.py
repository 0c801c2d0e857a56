"""The live app in a real headless Chromium: controls found by their labels, operated by clicks,
with the server's state checked after each action. Screenshots go to artifacts/app_<model>.png.
"""

from __future__ import annotations

import time

from rns_viz.viz.scene.fsms_scene import FsmsScene
from rns_viz.viz.server.app import TARGET_HANDLE, RnsApp
from tests.support.browser import (
    browser_page,
    click_track,
    dismiss_notifications,
    each_model_app,  # noqa: F401 (the fixture 'app')
    screenshot,
    settle_for_picture,
    wait_for_nodes,
    wait_until,
)


def test_operate_the_app_in_chromium(app: RnsApp) -> None:
    s = app.session
    name = app.model_name
    with browser_page(app.server, width=1400, height=900) as page:
        wait_for_nodes(page, {FsmsScene.BASE, FsmsScene.TARGET, TARGET_HANDLE})
        dismiss_notifications(page)

        # Kick: the operated run's base deflects.
        assert abs(s.snapshot().q[0]) < 1e-6
        page.get_by_role("button", name="Kick the base").click()
        wait_until(lambda: abs(s.snapshot().q[0]) > 1e-4, 15.0, "the kick to deflect the base")

        # Suppression off and on again.
        box = page.get_by_role("checkbox", name="Vibration suppression")
        box.click()
        wait_until(lambda: not s.snapshot().settings.suppress, 10.0, "suppression to switch off")
        box.click()
        wait_until(lambda: s.snapshot().settings.suppress, 10.0, "suppression to switch on")

        # Sliders, found by their labels: a click on the track sets the value.
        before = app.gui.kick_peak.value
        for attempt in range(3):  # a late toast or a re-laid panel can take a click: close toasts, click again
            click_track(page, app.gui.kick_peak.label, 0.8)
            try:
                wait_until(lambda: app.gui.kick_peak.value > before, 10.0, "the kick-peak slider to move")
                break
            except AssertionError:
                if attempt == 2:
                    raise
                dismiss_notifications(page)
        if name == "trep":  # the path slider moves the arm along its reactionless path
            wait_until(lambda: s.state.operator is not None and s.state.operator.table is not None, 20.0, "the path")
            # The render thread sets the slider's range from the path; click only once the page has it.
            wait_until(lambda: app.gui.sigma.max > 10.0 and not app.gui.sigma.disabled, 20.0, "the path slider")
            time.sleep(1.0)
            for attempt in range(3):  # a software-rendered page may drop a click made while it re-lays the panel
                click_track(page, app.gui.sigma.label, 0.7)
                try:
                    wait_until(lambda: (s.snapshot().sigma or 0.0) > 5.0, 15.0, "the arm to move along the path")
                    break
                except AssertionError:
                    if attempt == 2:
                        raise

        # Let the page show the plots and overlays, then a screenshot for a person to look at.
        wait_until(lambda: app.plot_updates > 5, 15.0, "live plot updates")
        app.scene.set_initial_camera()  # the model's view, whatever the clicks did to the camera
        page.mouse.move(5, 5)  # no tooltip over the panel
        page.get_by_text("Operate", exact=True).scroll_into_view_if_needed()
        dismiss_notifications(page)
        settle_for_picture(page, 30)
        path = screenshot(page, f"app_{name}")
        assert path.stat().st_size > 10_000
