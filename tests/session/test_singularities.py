"""Singular configurations never put a non-finite number into the state, the plots or the readouts:
TREP's arm stretched along x (S H_bm = 0), the 3R stretched (J-bar loses rank), unreachable targets.
The readouts flag the singularity (below the warning level) and the run carries on."""

from __future__ import annotations

import numpy as np
import pytest

from rns_viz.live.loop.session import Session


def put_arm_at(s: Session, theta: list[float]) -> None:
    m = s.state.runs.sim.model.m
    s.state.runs.sim.q[m:] = theta
    s.state.runs.shadow.q[m:] = theta
    s.state.hold_here()  # live laws from this configuration, as after leaving a preset
    assert s.wait_background()


def assert_finite(s: Session) -> None:
    snap = s.snapshot()
    assert snap.diverged is None and not snap.paused
    for run in (s.state.runs.sim, s.state.runs.shadow):
        assert np.all(np.isfinite(run.q)) and np.all(np.isfinite(run.v))
    assert snap.target is None or np.all(np.isfinite(snap.target))
    assert all(np.all(np.isfinite(a)) for a in s.plot_arrays().values())
    r = snap.readouts
    assert np.isfinite([r.sigma_hbm, r.sigma_jbar, r.L, r.reaction]).all()


@pytest.mark.parametrize("name", ["trep", "planar3r"])
def test_stretched_arm_is_flagged_and_the_run_carries_on(name: str) -> None:
    s = Session(name, realtime=False)
    try:
        assert s.wait_background()
        put_arm_at(s, [0.0] * s.state.model.n)
        s.advance(0.3)
        r = s.snapshot().readouts
        assert r.sigma_hbm < r.warn_hbm  # shown in the warning colour
        if name == "trep":
            for sigma in (5.0, -5.0, 40.0):
                s.scrub(sigma)
                s.advance(0.5)
            s.play_fast()
            s.advance(1.0)
            targets = [(0.0, 0.0), (100.0, 0.0), (0.2, 0.0)]
        else:
            targets = [(10.0, 0.0), (0.0, 0.0), (-3.0, 0.1), (999.0, -999.0), (2.9, 0.0)]
        for xy in targets:  # unreachable ones are clamped, with a notice
            s.set_target(xy, True)
            s.advance(1.0)
            assert_finite(s)
        s.kick(2.0)
        s.advance(1.0)
        assert_finite(s)
        notices = [(n.title, n.body) for n in s.pop_notices()]
        if name == "trep":  # no reactionless path through a singular configuration: said so, nothing moved
            assert any("singularity of the coupling" in body for _, body in notices)
        else:
            assert any(title == "Target moved" for title, _ in notices)
    finally:
        s.stop()
