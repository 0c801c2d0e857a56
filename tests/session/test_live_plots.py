"""The live plots' data in a session: the plot history restarts on a suppression switch, and a preset
can start paused."""

from __future__ import annotations

import numpy as np
import pytest

from rns_viz.live.loop.session import Session


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
