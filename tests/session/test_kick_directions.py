"""boom7's kick in every direction the panel offers, at the slider's largest peak: the run goes on and the
suppression takes the kick out. About a rotation the panel's kick is the moment of its force at
KICK_LEVER_M; a moment as large as the force in N would ask the arm for more than the Panda's joint
velocity limits, which is why."""

from __future__ import annotations

import numpy as np
import pytest

from rns_viz.defaults import KICK_LEVER_M, defaults_for
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


def peak_joint_speed_share(moment: float) -> float:
    """The largest |theta'_i| / (URDF velocity limit of joint i) over 1 s after a kick of ``moment`` N m about z."""
    s = Session("boom7", realtime=False)
    try:
        s.advance(0.05)
        s.kick(moment, direction=(0.0, 0.0, 0.0, 0.0, 0.0, 1.0))
        sim, peak = s.state.runs.sim, 0.0
        limits = sim.model.pin_model.velocityLimit[sim.model.m :]
        for _ in range(100):
            s.advance(0.01)
            peak = max(peak, float(np.max(np.abs(sim.v[sim.model.m :]) / limits)))
        assert s.snapshot().diverged is None
        return peak
    finally:
        s.stop()


def test_a_moment_as_large_as_the_force_asks_more_than_the_arm_can_give() -> None:
    """At the slider's end a moment as large as the force (20 N m about z, a 1 m lever) has the suppression
    turn a joint at over twice its published velocity limit; the panel's 0.1 m lever (2 N m) keeps every
    joint below a tenth of it."""
    assert peak_joint_speed_share(PEAK_N * 1.0) > 2.0
    assert peak_joint_speed_share(PEAK_N * KICK_LEVER_M) < 0.1
