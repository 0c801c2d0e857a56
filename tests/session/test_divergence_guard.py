"""The divergence guard in a session: a state outside physical bounds pauses it, tells everyone, and
Reset recovers a finite state (the bounds: tests/unit/; the app's clients told: tests/app/)."""

from __future__ import annotations

import numpy as np

from rns_viz.live.loop.session import Session


def test_base_pushed_past_its_limit_pauses_and_reset_recovers() -> None:
    s = Session("trep", realtime=False)
    try:
        s.advance(0.1)
        s.state.runs.sim.q[0] = 0.15  # as if a huge force had thrown the base beyond its 0.1 m limit
        s.advance(0.1)
        snap = s.snapshot()
        assert snap.paused and snap.diverged and "physical bounds" in snap.diverged
        notices = s.pop_notices()
        assert any(n.client is None and n.level == "error" and "Reset" in n.body for n in notices)
        t = snap.t
        s.resume()  # refused: Reset first
        s.advance(0.1)
        assert s.snapshot().t == t and s.snapshot().diverged
        s.reset()
        s.advance(0.2)
        snap = s.snapshot()
        assert not snap.paused and snap.diverged is None and np.all(np.isfinite(snap.q))
        assert abs(snap.q[0]) < 1e-6
    finally:
        s.stop()
