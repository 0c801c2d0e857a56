"""boom7's kick in every direction the panel offers, at the slider's largest peak: the run goes on and the
suppression takes the kick out. About a rotation the panel's kick is the moment of its force at
KICK_LEVER_M; a moment as large as the force in N would stop the run, which is why."""

from __future__ import annotations

import numpy as np
import pytest

from rns_viz.defaults import defaults_for
from rns_viz.live.loop.session import Session
from rns_viz.model import FsmsModel
from rns_viz.viz.panels.base_panel import kick_weights

PEAK_N = defaults_for("boom7").kick_range_N  # the slider's end (20 N)


@pytest.fixture(scope="module")
def turns(boom7: FsmsModel) -> tuple[bool, ...]:
    return boom7.base_rotational


@pytest.mark.parametrize("index", [0, 1, 2, 3, 4, 5, None], ids=["x", "y", "z", "rx", "ry", "rz", "all"])
def test_every_offered_direction_at_the_largest_peak_is_suppressed(turns: tuple[bool, ...], index: int | None) -> None:
    s = Session("boom7", realtime=False)
    try:
        s.advance(0.05)
        s.kick(PEAK_N, direction=kick_weights(turns, index))
        s.advance(1.0)
        snap = s.snapshot()
        assert snap.diverged is None and not snap.paused
        assert np.abs(snap.q_shadow[:6]).max() > 0.0  # type: ignore[index]  # the kick reached the boom
        assert np.abs(s.state.runs.sim.v[6:]).max() < 5.0  # rad/s: the arm absorbs it without whipping
        s.advance(2.0)
        late, late_shadow = s.snapshot().q[:6], s.snapshot().q_shadow[:6]  # type: ignore[index]
        assert np.linalg.norm(late) < 0.05 * np.linalg.norm(late_shadow)  # suppressed; the shadow still swings
    finally:
        s.stop()


def test_a_moment_as_large_as_the_force_stops_the_run_with_a_reason() -> None:
    """5 N m about z (a 1 m lever): the suppression asks the arm for over 100 rad/s; the guard stops the run
    and says so instead of integrating nonsense, and the shadow run had no such trouble."""
    s = Session("boom7", realtime=False)
    try:
        s.advance(0.05)
        s.kick(5.0, direction=(0.0, 0.0, 0.0, 0.0, 0.0, 1.0))
        s.advance(1.0)
        snap = s.snapshot()
        assert snap.diverged is not None and "rad/s" in snap.diverged
    finally:
        s.stop()
