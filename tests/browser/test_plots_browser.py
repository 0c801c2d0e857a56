"""The live plots in a real headless Chromium, for every paper preset and a model switch.

Each preset is loaded by a click on its button (it starts paused), resumed and run; the page's
charts must then hold curves over a time axis that covers their data (loading a preset used to
pin the axis far outside it, "50-150 s", when the chart was rebuilt in the same frame as new data),
and the peaks shown on the page must carry the paper's contrast: fig11-joint2 moves the base
hundreds of times more than fig11-fast. Screenshots of both go to artifacts/plots_<preset>_<width>.png.
The y axes' tick labels, as uPlot drew them, must read: no label twice, no number of five digits.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest
from playwright.sync_api import Page

from rns_viz.live.published.plot_buffers import PLOT_SERIES
from rns_viz.scenarios import SCENARIOS, presets_for
from rns_viz.viz.panels.live_plots import SCALES, LivePlots
from rns_viz.viz.server.app import RnsApp, start_app
from tests.support.browser import (
    browser_page,
    dismiss_notifications,
    local_server,
    screenshot,
    settle_for_picture,
    wait_until,
)

RUN_S = 4.0  # s simulated per preset: every preset's kick or motion is over by then
CHART_JS = """(uuid) => {
    const tp = window.__viserTestpoints?.uplots?.[uuid];
    if (!tp) return null;
    const c = tp.chart, xs = c.data[0], on = c.data[1];
    let peak = 0;
    for (const v of on) peak = Math.max(peak, Math.abs(v));
    return {n: xs.length, x0: xs[0], x1: xs[xs.length - 1], min: c.scales.x.min, max: c.scales.x.max, peak: peak};
}"""


Y_TICKS_JS = """(uuid) => {
    const c = window.__viserTestpoints?.uplots?.[uuid]?.chart;
    return c ? {label: c.axes[1].label, ticks: [...(c.axes[1]._values ?? [])], n: c.data[0].length} : null;
}"""


def y_ticks(page: Page, handle: Any) -> dict[str, Any] | None:
    """The y axis of a chart as the page drew it: its label and its tick labels."""
    return page.evaluate(Y_TICKS_JS, handle._impl.uuid)


def readable(axis: dict[str, Any] | None) -> bool:
    """The y tick labels are at least two, all different, and none has five digits (e.g. "100,000")."""
    labels = [t for t in (axis or {}).get("ticks", []) if t]
    digits = [len(re.sub(r"\D", "", t.split(".")[0])) for t in labels]
    return len(labels) >= 2 and len(set(labels)) == len(labels) and max(digits) <= 4


def assert_readable_ticks(page: Page, handle: Any, what: str) -> None:
    """The chart's y axis, once drawn for its new data, reads (:func:`readable`). The page draws new data and
    its axis in its own time, so a read may still see the axis of the data before (a flat run's lone "0"): the
    test waits up to 30 s for a readable axis (a software-rendered page on a busy machine draws a chart it has
    just been switched to that late), and an axis that stays unreadable fails with what it shows."""
    try:
        wait_until(lambda: readable(y_ticks(page, handle)), 30.0, f"readable y ticks of {what}")
    except AssertionError:
        raise AssertionError((what, y_ticks(page, handle))) from None


@pytest.fixture
def app() -> Iterator[RnsApp]:
    app = start_app("trep", port=0, realtime=False, verbose=False)
    yield app
    app.stop()


def chart(page: Page, handle: Any) -> dict[str, float] | None:
    return page.evaluate(CHART_JS, handle._impl.uuid)


def page_peak(page: Page, key: str) -> float:
    """A peak as the page shows it (the cell's SI value), NaN if none."""
    return float(page.locator(f'[data-peak="{key}"]').first.get_attribute("data-si") or "nan")


def assert_curves(page: Page, app: RnsApp, t_end: float, what: str) -> None:
    """Both plots of the shown scale hold the run's curves on a time axis that covers them."""
    charts = app.gui.plots.charts[app.gui.plots.mode]
    for name, handle in charts.items():

        def drawn(handle: Any = handle) -> bool:
            c = chart(page, handle)
            return c is not None and c["n"] > 100 and abs(c["x1"] - t_end) < 0.1 and c["peak"] > 0.0

        wait_until(drawn, 20.0, f"the {name} plot of {what} to show its curves")
        c = chart(page, handle)
        assert c is not None
        assert_readable_ticks(page, handle, f"{what}: {name}")
        assert c["min"] <= c["x0"] + 0.05 and c["max"] >= c["x1"] - 0.05, (what, name, c)  # data in view
        assert c["max"] - c["min"] < 2.0 * (c["x1"] - c["x0"]) + 0.1, (what, name, c)  # and not squashed


def run_preset(page: Page, app: RnsApp, name: str) -> None:
    s = app.session
    page.get_by_role("button", name=name, exact=True).click()
    wait_until(lambda: "LoadPreset" in s.pending_commands(), 10.0, f"{name} to be queued")
    s.advance(0.0)
    assert s.wait_background()
    snap = s.snapshot()
    assert snap.settings.preset == name and snap.paused and snap.t == 0.0  # waits for Resume
    s.resume()
    s.advance(RUN_S)
    assert_curves(page, app, s.snapshot().t, name)


def shoot(page: Page, name: str, top: str = "Operate") -> None:
    """A screenshot with the panel scrolled to ``top`` (Operate: kick, presets and plots on one screen)."""
    page.get_by_text(top, exact=True).evaluate("e => e.scrollIntoView({block: 'start'})")
    page.mouse.move(5, 5)
    dismiss_notifications(page)
    settle_for_picture(page, 10)
    screenshot(page, name)


def test_every_preset_fills_the_plots_and_fig11_shows_the_contrast(app: RnsApp) -> None:
    s = app.session
    trep_presets, planar3r_presets = presets_for("trep"), presets_for("planar3r")
    assert set(trep_presets) | set(planar3r_presets) == set(SCENARIOS)
    with browser_page(app.server, width=1400, height=900) as page:
        dismiss_notifications(page)
        peaks: dict[str, float] = {}
        for name in ("fig3", "fig4", *trep_presets):  # fig3 first: from TREP, with a model switch
            run_preset(page, app, name)
            wait_until(lambda: page_peak(page, "xb-on") > 0.0, 10.0, f"the peaks of {name}")
            peaks[name] = page_peak(page, "xb-on")
            if name in ("fig11-fast", "fig11-joint2"):
                shoot(page, f"plots_{name}_1400")
                page.set_viewport_size({"width": 800, "height": 900})
                shoot(page, f"plots_{name}_800")
                page.set_viewport_size({"width": 1400, "height": 900})
                app.gui.plots.scale.value = SCALES["symlog"]  # runs the dropdown's callback
                wait_until(lambda: app.gui.plots.mode == "symlog", 10.0, "the symmetric-log charts")
                assert_curves(page, app, s.snapshot().t, f"{name}, symmetric log")
                shoot(page, f"plots_{name}_symlog_1400", "Live plots (last 10 s)")
                app.gui.plots.scale.value = SCALES["linear"]
                wait_until(lambda: app.gui.plots.mode == "linear", 10.0, "the linear charts")
        # The paper's Fig. 11: the same end points in joint space move the base ~500x more (m, SI).
        assert peaks["fig11-joint2"] > 100.0 * peaks["fig11-fast"], peaks
        # fig10-off runs with suppression off: its shadow is the "on" curve, the same kick (first swing)
        assert peaks["fig10-off"] == pytest.approx(peaks["fig10-on"], rel=0.05), peaks

        # A model switch from the menu's session call, then a kick: the plots restart and fill again.
        s.switch_model("planar3r")
        s.advance(0.5)
        s.kick(5.0)
        s.advance(RUN_S)
        assert_curves(page, app, s.snapshot().t, "planar3r after a switch")


def test_views_follow_presets_and_notices_reach_the_page(app: RnsApp) -> None:
    """After a preset the path slider is disabled at 0 and no old path stays lit; a path motion asked
    for while the path is computed waits with a notice and then runs; a target off the path is moved
    with a notice (TREP)."""
    s, g = app.session, app.gui
    with browser_page(app.server, width=1400, height=900) as page:
        dismiss_notifications(page)
        assert s.wait_background()  # the default path
        s.advance(0.1)
        wait_until(lambda: not g.sigma.disabled and app.scene.paths.visible, 10.0, "the live path and slider")
        g.sigma.value = 20.0  # scrub along the path: the slider holds a value of the live path
        wait_until(lambda: "Scrub" in s.pending_commands(), 10.0, "the scrub")
        s.advance(1.0)
        run_preset(page, app, "fig11-fast")
        wait_until(lambda: g.sigma.disabled and g.sigma.value == 0.0, 10.0, "the path slider to rest at 0")
        assert s.snapshot().target is None

        # Play slowly while the path through the preset's configuration is still being computed.
        page.get_by_role("button", name="Play path slowly").first.click()
        wait_until(lambda: "Play" in s.pending_commands(), 10.0, "the play command")
        s.advance(0.0)
        wait_until(lambda: page.get_by_text("Waiting for the path").count() > 0, 10.0, "the waiting notice")
        assert s.wait_background()
        s.advance(1.0)
        assert "path" in s.snapshot().mode and s.snapshot().settings.preset is None
        wait_until(lambda: not g.sigma.disabled, 10.0, "the slider on the new path")

        # A target far off the reactionless path is moved onto it, and the page says so.
        client_id = next(iter(app.server.get_clients()))
        s.set_target((0.0, -0.3), final=True, client=client_id)
        s.advance(0.01)
        wait_until(lambda: page.get_by_text("Target moved").count() > 0, 10.0, "the 'Target moved' notice")


def test_tick_labels_read_for_every_magnitude() -> None:
    """Windows from 0.2 nm to 2 m (x_b, |e|) and 5 nN·s to 30 N·s (L), on both scales: each chart shown
    labels its y axis with distinct numbers of at most four digits (a linear one names its unit). A window
    of 0.2 nm shown in mm read "0" five times, 25 mm in µm read "-20,000", the symmetric-log x_b "100,000"."""
    magnitudes = ((2e-10, 5e-9), (2e-9, 2e-7), (2e-7, 3e-5), (5e-6, 0.02), (3e-4, 2.5), (2.5e-2, 30.0), (2.0, 1e-3))
    with local_server() as server:
        plots = LivePlots(server.gui)
        with browser_page(server, width=900, height=1400) as page:
            for k, (length, momentum) in enumerate(magnitudes):  # (m, N s)
                for mode in SCALES:
                    samples = 400 + 2 * k + (mode == "symlog")  # a count of its own: the page has the new data
                    t = np.linspace(0.0, 10.0, samples)
                    wave = np.sin(2.0 * np.pi * 0.7 * t)
                    arrays = {key: np.zeros_like(t) for key in PLOT_SERIES}
                    arrays["t"], arrays["suppress"] = t, np.ones_like(t)
                    arrays["xb"], arrays["xb_shadow"] = 1e3 * length * wave, 0.3e3 * length * wave  # mm
                    arrays["L"], arrays["L_shadow"] = momentum * wave, 0.5 * momentum * wave  # N s
                    arrays["ee_error"] = 1e3 * length * np.abs(wave)  # mm
                    plots.show_mode(mode)
                    assert plots.update(arrays)
                    shown = [plots.error, *plots.charts[mode].values()]

                    def arrived(shown: list[Any] = shown, samples: int = samples) -> bool:
                        return all((y_ticks(page, c) or {}).get("n") == samples for c in shown)

                    wait_until(arrived, 10.0, f"the charts of {length:g} m, {momentum:g} N s")
                    for handle in shown:
                        axis = y_ticks(page, handle)
                        assert axis is not None
                        what = f"{mode}, x_b and |e| {length:g} m, L {momentum:g} N s: {axis}"
                        assert_readable_ticks(page, handle, what)
                        if handle is plots.error or mode == "linear":
                            assert re.search(r"\((nm|µm|mm|m|nN·s|µN·s|mN·s|N·s)\)$", axis["label"]), what
