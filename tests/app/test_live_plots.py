"""The live plots in the app without a browser: chart options that never change (a changed option
rebuilds the chart in the browser, which pinned fig3's time axis outside its data), a session nobody
watched restarting for its first visitor, and the legend and caption of each model and of its replay
(units, colouring, peaks: tests/unit/; the plot history in a session: tests/session/)."""

from __future__ import annotations

from collections.abc import Callable

import pytest

from rns_viz.viz.server.app import IDLE_RESTART_S, start_app
from tests.support.browser import wait_for_clients, wait_until
from tests.support.protocol_client import ProtocolClient


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


def test_a_session_nobody_watched_restarts_for_its_first_visitor(monkeypatch: pytest.MonkeyPatch) -> None:
    assert IDLE_RESTART_S == 60.0
    monkeypatch.setattr("rns_viz.viz.server.app.IDLE_RESTART_S", 1.0)  # s: the test runs 2 s, not 61
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
        # the render thread switches the runs, then writes the caption and shows the charts: wait for all of it
        wait_until(lambda: plots.runs == "compensation" and "held still" in plots.caption.content, 20, "trep2's panel")
        wait_until(lambda: plots.xb.visible and _legend(plots.xb)[0] == "compensation on", 20.0, "trep2's charts")
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
        wait_until(lambda: plots.runs == "suppression" and "suppression on" in plots.caption.content, 20, "TREP")
        wait_until(lambda: plots.xb.visible and _legend(plots.xb)[0] == "suppression on", 20.0, "TREP's charts")
        assert _legend(plots.xb) == ("suppression on", "suppression off") and plots.xb.visible
        assert "suppression on" in plots.caption.content
    finally:
        app.stop()
