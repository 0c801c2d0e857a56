"""The live plots without a browser: units, the on/off colouring, the peaks, chart options that never
change (a changed option rebuilds the chart in the browser, which pinned fig3's time axis outside
its data), the plot history restarting on a suppression switch, and presets that start paused."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pytest

from rns_viz.live.plots import PLOT_SERIES
from rns_viz.live.session import Session
from rns_viz.viz.app import IDLE_RESTART_S, start_app
from rns_viz.viz.live_plots import LENGTH_UNITS, MOMENTUM_UNITS, display_unit, on_off, peaks_html
from rns_viz.viz.units import si
from tests.browser import wait_for_clients, wait_until
from tests.protocol_client import ProtocolClient


def test_si_prefixes_and_zeros() -> None:
    assert si(2.1e-6, "m") == "2.1 µm"
    assert si(0.00132, "m") == "1.32 mm"
    assert si(0.45, "N·s") == "450 mN·s"
    assert si(-1.2e-42, "N", floor=1e-6) == "0 N"  # not "-1.2e-42 N"
    assert si(0.9997e-3, "m") == "1 mm"  # not "1e+03 µm"
    assert si(3.0, "N", sign=True) == "+3 N" and si(math.nan, "m") == "—"


def test_display_units_suit_the_window() -> None:
    """The unit a linear chart shows: its peak reads 1 to 1000 of it, kept from 0.5 to 2000 (no flapping)."""
    assert display_unit(2e-10, LENGTH_UNITS, "mm") == "nm"  # below 1 nm: drawn as 0, in nm
    assert display_unit(2e-7, LENGTH_UNITS, "mm") == "nm"  # 200 nm, not 0.0002 mm ("0" five times)
    assert display_unit(2.5e-2, LENGTH_UNITS, "µm") == "mm"  # 25 mm, not 25,000 µm
    assert display_unit(3.0, LENGTH_UNITS, "mm") == "m"
    assert display_unit(1.5e-3, LENGTH_UNITS, "µm") == "µm"  # 1500 µm: kept (four digits)
    assert display_unit(0.6e-6, LENGTH_UNITS, "µm") == "µm" and display_unit(0.4e-6, LENGTH_UNITS, "µm") == "nm"
    assert display_unit(5e-9, MOMENTUM_UNITS, "mN·s") == "nN·s" and display_unit(30.0, MOMENTUM_UNITS, "mN·s") == "N·s"
    assert display_unit(0.0, LENGTH_UNITS, "µm") == "µm" and display_unit(math.nan, LENGTH_UNITS, "mm") == "mm"


def test_curves_are_coloured_by_suppression_sample_by_sample() -> None:
    a = {k: np.zeros(4) for k in PLOT_SERIES}
    a["xb"], a["xb_shadow"] = np.array([1.0, 2.0, 3.0, 4.0]), np.array([-1.0, -2.0, -3.0, -4.0])
    a["suppress"] = np.array([1.0, 1.0, 0.0, 0.0])  # suppression switched off after two samples
    on, off = on_off(a, "xb")
    assert on.tolist() == [1.0, 2.0, -3.0, -4.0] and off.tolist() == [-1.0, -2.0, 3.0, 4.0]


def test_peaks_table_carries_si_values() -> None:
    text = peaks_html({"xb": (2.8e-6, 1.3e-3), "L": (0.02, math.nan), "e": (4e-3, math.nan)})
    assert 'data-peak="xb-on" data-si="2.8e-06"' in text and "2.8 µm" in text and "1.3 mm" in text
    assert 'data-peak="L-off" data-si="nan"' in text and "—" in text
    assert "suppression on" in text and "suppression off" in text


def _options(handle: object) -> tuple[str, ...]:
    props = handle._impl.props  # type: ignore[attr-defined]
    return tuple(repr(getattr(props, k)) for k in ("title", "series", "scales", "axes", "legend", "padding"))


def test_chart_options_never_change_with_presets_models_and_suppression() -> None:
    app = start_app("trep", port=0, realtime=False, verbose=False)
    try:
        s, plots = app.session, app.gui.plots
        charts = plots.all_charts()
        before = [_options(c) for c in charts]

        def sent(what: str, step: Callable[[], object]) -> None:
            """Step the stepped app, then wait for the render loop to send that step's plots (the app is
            not real-time: nothing changes between steps, so each phase must be seen on its own)."""
            updates = app.plot_updates
            step()
            wait_until(lambda: app.plot_updates > updates, 10.0, f"the plots after {what}")
            assert [_options(c) for c in charts] == before, what

        sent("a kick", lambda: (s.kick(0.8), s.advance(1.0)))
        sent("suppression and shadow off", lambda: (s.set_suppression(False), s.set_shadow(False), s.advance(0.5)))

        def fig3() -> None:
            s.load_preset("fig3")
            s.advance(0.0)
            assert s.wait_background()
            s.advance(1.0)

        sent("the fig3 preset", fig3)
    finally:
        app.stop()


def test_suppression_switch_restarts_both_runs_and_the_plot_history() -> None:
    s = Session("trep", realtime=False)
    try:
        s.kick(0.8)
        s.advance(1.0)
        assert len(s.plot_arrays()["t"]) == 50 and np.all(s.plot_arrays()["suppress"] == 1.0)
        before = s.snapshot()
        assert before.q_shadow is not None and abs(before.q_shadow[0] - before.q[0]) > 5e-4  # m: rings apart
        s.set_suppression(False)
        s.advance(0.001)
        snap = s.snapshot()
        assert snap.q_shadow is not None  # the shadow restarted from the operated state (one step apart)
        assert abs(snap.q_shadow[0] - snap.q[0]) < 2e-5 and np.allclose(snap.q_shadow, snap.q, atol=1e-3)
        s.advance(0.099)
        a = s.plot_arrays()
        assert len(a["t"]) == 5 and np.all(a["suppress"] == 0.0)  # only samples since the switch
        s.set_suppression(False)  # no change: nothing restarts
        s.advance(0.1)
        assert len(s.plot_arrays()["t"]) == 10
    finally:
        s.stop()


def test_a_preset_can_start_paused() -> None:
    s = Session("trep", realtime=False)
    try:
        s.load_preset("fig11-fast", paused=True)
        s.advance(0.0)
        assert s.wait_background()
        s.advance(1.0)
        snap = s.snapshot()
        assert snap.settings.preset == "fig11-fast" and snap.paused and snap.t == 0.0
        s.resume()
        s.advance(0.5)
        assert s.snapshot().t == pytest.approx(0.5)
    finally:
        s.stop()


def test_a_session_nobody_watched_restarts_for_its_first_visitor(monkeypatch: pytest.MonkeyPatch) -> None:
    assert IDLE_RESTART_S == 60.0
    monkeypatch.setattr("rns_viz.viz.app.IDLE_RESTART_S", 1.0)  # s: the test runs 2 s, not 61
    app = start_app("trep", port=0, realtime=False, verbose=False)
    try:
        s = app.session
        s.advance(2.0)
        first = ProtocolClient(app.port)
        wait_for_clients(app, 1, "the first visitor")
        wait_until(lambda: "Reset" in s.pending_commands(), 10.0, "the restart")
        s.advance(0.5)
        second = ProtocolClient(app.port)  # a second tab while someone watches: nothing restarts
        wait_for_clients(app, 2, "the second visitor")
        s.advance(0.0)
        assert s.snapshot().t == pytest.approx(0.5) and "Reset" not in s.pending_commands()
        first.close()
        second.close()
    finally:
        app.stop()


def _legend(handle: object) -> tuple[str, ...]:
    return tuple(s["label"] for s in handle._impl.props.series[1:])  # type: ignore[attr-defined]


def test_legend_and_caption_name_the_two_runs_of_the_model_served_and_of_its_replay() -> None:
    """trep2's runs are compensation on / compensator held still; TREP's stay suppression on / off."""
    app = start_app("trep", port=0, realtime=False, verbose=False)
    try:
        plots = app.gui.plots
        shown = [c for c in plots.all_charts() if c.visible and c is not plots.error]
        assert len(shown) == 2 and all(_legend(c) == ("suppression on", "suppression off") for c in shown)
        assert "suppression on" in plots.caption.content and "second arm" not in plots.caption.content
        app.session.switch_model("trep2")
        app.session.advance(0.01)
        wait_until(lambda: plots.runs == "compensation", 20.0, "the trep2 panel")
        shown = [c for c in plots.all_charts() if c.visible and c is not plots.error]
        assert len(shown) == 2 and all(_legend(c) == ("compensation on", "compensator held still") for c in shown)
        assert "held still" in plots.caption.content and "suppression on" not in plots.caption.content
        assert "compensating" in plots.peaks.content and "suppression on" not in plots.peaks.content
        s = app.session
        s.set_target((0.05, 0.25), final=True)
        s.advance(1.0)
        s.start_replay(1.0)
        s.advance(0.0)
        wait_until(lambda: s.snapshot().replay is not None, 10.0, "the replay")
        s.seek_replay(0.9)
        s.advance(0.0)
        wait_until(lambda: float(plots.xb.data[0][-1]) > 0.8, 10.0, "the replay's plots up to the playhead")
        assert all(c.visible for c in shown)  # the replay fills trep2's charts, named for its runs
        assert plots.xb in shown and _legend(plots.xb) == ("compensation on", "compensator held still")
        app.session.switch_model("trep")
        app.session.advance(0.01)
        wait_until(lambda: plots.runs == "suppression", 20.0, "the TREP panel")
        assert _legend(plots.xb) == ("suppression on", "suppression off") and plots.xb.visible
        assert "suppression on" in plots.caption.content
    finally:
        app.stop()
