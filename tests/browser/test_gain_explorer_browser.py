"""The gain explorer in a real headless Chromium: the map appears beside the robot, a real mouse click
on it applies the cell's gains, and screenshots go to artifacts/gain_map_<model>.png."""

from __future__ import annotations

import time

import numpy as np
from playwright.sync_api import Page

from rns_viz.viz.panels.gain_panel import QUANTITIES
from rns_viz.viz.scene.gain_scene import GainScene, axis_fraction
from rns_viz.viz.server.app import RnsApp
from tests.support.browser import (
    browser_page,
    dismiss_notifications,
    each_model_app,  # noqa: F401 (the fixture 'app')
    screenshot,
    settle_for_picture,
    wait_for_nodes,
    wait_until,
)


def screen_point(page: Page, local: tuple[float, float, float]) -> tuple[float, float] | None:
    """Page pixel of a point given in the map's frame, projected by the page's own camera."""
    return page.evaluate(
        """(p) => {
            const m = window.__viserMutable;
            const node = m?.nodeRefFromName?.["/gain_map"];
            const camera = m?.camera;
            const canvas = [...document.querySelectorAll("canvas")].sort(
                (a, b) => b.clientWidth * b.clientHeight - a.clientWidth * a.clientHeight
            )[0];  // the scene's, not a plot's
            if (!node || !camera || !canvas) return null;
            node.updateWorldMatrix(true, false);
            const v = node.localToWorld(new node.position.constructor(p[0], p[1], p[2])).project(camera);
            const r = canvas.getBoundingClientRect();
            return [r.left + (v.x + 1) / 2 * r.width, r.top + (1 - v.y) / 2 * r.height];
        }""",
        list(local),
    )


def test_gain_map_in_chromium(app: RnsApp) -> None:
    ex = app.renderer.explorer
    with browser_page(app.server, width=1500, height=900) as page:
        wait_until(lambda: ex.scene is not None and ex.scene.gain_map is not None, 60.0, "the gain map")
        wait_for_nodes(page, {GainScene.FRAME, GainScene.IMAGE, GainScene.NOW})
        dismiss_notifications(page)
        scene = ex.scene
        assert scene is not None and scene.gain_map is not None
        gm = scene.gain_map
        # A real click on a stable cell applies it (when the page lets us find the camera).
        i, j = 18, 30
        assert gm.stable[i, j]
        u, v = axis_fraction(gm.g_b, gm.g_b[i]), axis_fraction(gm.g_m, gm.g_m[j])
        pixel = screen_point(page, ((u - 0.5) * scene.size, (v - 0.5) * scene.size, 0.0))
        if pixel is not None:
            want = (float(gm.g_b[i]), float(gm.g_m[j]))

            def applied() -> bool:
                return (app.session.snapshot().settings.gains.g_b, app.session.snapshot().settings.gains.g_m) == want

            # A toast arriving late (a busy machine) can sit over the map's corner and take the click:
            # close toasts and click again, as a user would; the gains must then be the cell's.
            for _ in range(3):
                dismiss_notifications(page)
                page.mouse.click(*pixel)
                deadline = time.monotonic() + 10.0
                while not applied() and time.monotonic() < deadline:
                    time.sleep(0.05)
                if applied():
                    break
            assert applied(), f"a click in the browser did not apply {want}"
        wait_until(lambda: app.plot_updates > 5, 15.0, "live plot updates")
        page.mouse.move(5, 5)
        page.get_by_text("Gain explorer", exact=True).scroll_into_view_if_needed()
        dismiss_notifications(page)
        settle_for_picture(page, 40)
        path = screenshot(page, f"gain_map_{app.model_name}")
        assert path.stat().st_size > 10_000
        page.get_by_text("Root locus: g_m", exact=False).first.scroll_into_view_if_needed()
        settle_for_picture(page, 10)
        assert screenshot(page, f"gain_loci_{app.model_name}").stat().st_size > 10_000
        # The arm mode's map: the second subsystem of Sec. VIII.
        legend = ex.scene.legend
        app.controls.show(ex.quantity, next(k for k, q in QUANTITIES.items() if q == "arm"))
        wait_until(lambda: legend.text.startswith("σ_a"), 10.0, "the arm mode's map")
        settle_for_picture(page, 20)
        assert screenshot(page, f"gain_map_arm_{app.model_name}").stat().st_size > 10_000
        assert np.isfinite(app.session.gain_view().predicted)
        if app.model_name == "trep":  # predicted vs measured, after a kick from the page's button
            app.controls.show(ex.quantity, next(iter(QUANTITIES)))
            page.get_by_role("button", name="Kick the base").click()
            wait_until(lambda: app.session.gain_view().measured is not None, 30.0, "the measured decay")
            wait_until(lambda: "measured" in ex.predicted.content, 10.0, "the panel to show it")
            page.get_by_text("Map shows", exact=True).first.scroll_into_view_if_needed()  # (the text above re-renders)
            dismiss_notifications(page)
            settle_for_picture(page, 20)
            assert screenshot(page, "gain_measured_trep").stat().st_size > 10_000
            view = app.session.gain_view()
            print(f"predicted {view.predicted:.3f} 1/s, measured {view.measured.rate:.3f} 1/s")
