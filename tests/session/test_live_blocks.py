"""The live blocks together in a session: a play right after a reset waits for the path, then runs along it."""

from __future__ import annotations

import numpy as np


def test_play_right_after_reset_waits_for_the_path_and_then_runs() -> None:
    from rns_viz.live.loop.session import Session

    s = Session("trep", realtime=False)
    try:
        s.load_preset("fig10-on")
        s.advance(0.001)  # the command is applied: the preset is built in the background
        assert s.wait_background() and s.snapshot().settings.preset == "fig10-on"
        s.play_slow()  # leaving a preset, the path is computed anew: the play waits for it
        s.advance(0.002)
        assert any(n.title == "Waiting for the path" for n in s.pop_notices())
        assert s.wait_background()
        theta0 = s.state.runs.theta.copy()
        s.advance(1.0)
        assert s.snapshot().mode.startswith("quintic along the path")
        assert np.linalg.norm(s.state.runs.theta - theta0) > 0.05  # rad: the arm moves along the path
    finally:
        s.stop()
