"""boom7's reaction in a session: the live loop publishes all six rows of the arm's reaction
−(H_bm θ'' + c_b) (Eq. 1), the first selected row being the readout's number."""

from __future__ import annotations

import numpy as np

from rns_viz.live.loop.session import Session


def test_the_loop_publishes_all_six_rows_of_the_reaction() -> None:
    s = Session("boom7", realtime=False)
    try:
        assert s.wait_background(120.0)
        s.kick(5.0, direction=(0.0, 1.0, 0.0, 0.0, 0.0, 0.0))
        s.advance(0.25)  # in the kick: the arm moves to absorb it
        r = s.snapshot().readouts
        wrench = np.array(r.reaction_wrench)
        assert wrench.shape == (6,) and np.all(np.isfinite(wrench))
        assert wrench[0] == r.reaction  # the first selected row is the readout's number, unrounded
        assert np.abs(wrench[:3]).max() > 1e-3 and np.abs(wrench[3:]).max() > 1e-4  # N, N m: both parts act
    finally:
        s.stop()
