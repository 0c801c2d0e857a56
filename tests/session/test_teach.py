"""The teaching views' numbers in a session: the reaction readout is Eq. (1)'s at its step (against an
independent evaluation from the step log: pinocchio's CRBA and RNEA, a linear solve, no ABA), and u-bar
is put in words as joint angles and rates."""

from __future__ import annotations

import numpy as np
import pytest

from rns_viz.live.loop.session import Session
from tests.support.logs import independent_reaction, log_row


@pytest.mark.parametrize(
    ("model", "peak", "motion"),
    [("trep", 0.8, "play_fast"), ("planar3r", 5.0, None)],
)
def test_reaction_readout_is_eq1_at_its_step(model: str, peak: float, motion: str | None) -> None:
    s = Session(model, realtime=False)
    try:
        assert s.wait_background()
        if motion is not None:
            getattr(s, motion)()
        s.advance(0.05)
        s.kick(peak)
        worst, biggest = 0.0, 0.0
        for _ in range(12):  # during the kick (f_ext != 0) and after it
            s.advance(0.021)
            r = s.snapshot().readouts
            assert np.isfinite(r.reaction_t)
            expected = independent_reaction(s.state.runs.sim.model, log_row(s, r.reaction_t))
            worst = max(worst, abs(r.reaction - expected))
            biggest = max(biggest, abs(expected))
        assert biggest > 1e-3  # N: the arm does push on the base here
        assert worst < 1e-9, f"readout differs from Eq. (1) by {worst:.3g} N (largest force {biggest:.3g} N)"
    finally:
        s.stop()


@pytest.mark.parametrize("model", ["trep", "boom7"])
def test_path_words_turn_ubar_into_joint_angles_and_rates(model: str) -> None:
    """TREP's two joints and boom7's seven (whose text had named its seventh joint "joint 2")."""
    from rns_viz.viz.panels.path_words import path_words

    s = Session(model, realtime=False)
    try:
        assert s.wait_background()
        s.play_slow()
        s.advance(1.0)
        snap = s.snapshot()
        text = path_words(snap)
        n = snap.readouts.n
        assert n is not None and snap.sigma is not None
        angles = ", ".join(f"{a:.1f}" for a in np.degrees(snap.q[snap.q.size - len(n) :]))
        assert f"θ = **({angles})°**" in text  # every joint of the arm, in order
        # theta' = n u-bar (Eq. 27): the last joint's rate at the chosen u-bar, deg/s
        assert f"joint {len(n)} {np.degrees(abs(n[-1]) * snap.settings.ubar_speed):.0f}°/s" in text
    finally:
        s.stop()
