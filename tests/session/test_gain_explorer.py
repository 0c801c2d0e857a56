"""The live gain explorer: the map, loci and authority for the law in force, updated by the gain
sliders, after a kick the measured decay of x_b beside the prediction (within 10 %), and the panel's
reason where the map cannot predict."""

from __future__ import annotations

import numpy as np
import pytest

from rns_viz.analysis import modes_of
from rns_viz.live.loop.session import Session
from rns_viz.viz.panels.gain_panel import predicted_text


@pytest.mark.parametrize(("model", "kick_n", "seconds"), [("trep", 0.8, 13.0), ("planar3r", 5.0, 16.0)])
def test_prediction_matches_the_measured_decay(model: str, kick_n: float, seconds: float) -> None:
    s = Session(model, realtime=False)
    try:
        assert s.wait_background()
        view = s.gain_view()
        assert view.map is not None and view.map.base_decay_rate.shape == (60, 60)
        assert view.current is not None and np.isfinite(view.predicted) and view.predicted > 0
        assert view.authority is not None and view.path_points is not None
        assert len(view.authority.base_decay_rate) == len(view.path_points) > 10
        assert view.g_m_meaning  # says what g_m means in this law
        s.kick(kick_n)
        s.advance(seconds)
        s.wait_background()
        view = s.gain_view()
        assert view.measured is not None
        assert view.measured.rate == pytest.approx(view.predicted, rel=0.1)
    finally:
        s.stop()


def test_the_views_follow_the_gains_and_the_law() -> None:
    s = Session("trep", realtime=False)
    try:
        assert s.wait_background()
        at_20 = s.gain_view().predicted
        s.set_gains(g_m=50.0)
        s.advance(0.001)
        assert s.wait_background()
        view = s.gain_view()
        assert view.gains.g_m == 50.0 and view.predicted < 0.5 * at_20  # the Fig. 11 gain damps the base slower
        assert view.locus_g_b is not None and np.allclose(view.locus_g_b.poles.shape[0], len(view.locus_g_b.values))
        s.set_law("acceleration")
        s.advance(0.001)
        assert s.wait_background()
        view = s.gain_view()
        assert view.law == "acceleration" and view.map is not None and "(15)" in view.g_m_meaning
    finally:
        s.stop()


def test_the_panel_says_why_a_cell_is_not_predictable() -> None:
    s = Session("planar3r", realtime=False)
    try:
        assert s.wait_background()
        s.set_gains(g_b=3.29, g_m=0.1)
        s.advance(0.01)
        assert s.wait_background()
        view = s.gain_view()
        now = modes_of(view.map.loop, 3.29, 0.1)
        assert not bool(now.predictable)
        text = predicted_text(view)
        assert f"1/s: **no prediction**, {now.why_not()}" in text and "5 N, 0.2 s kick along x" in text
    finally:
        s.stop()
