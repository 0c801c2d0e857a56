"""boom7 (a 7-DOF arm on a 6-DOF flexible boom tip) in the live session, headless: the kick is
suppressed in all six modes with law (15) while the shadow run (suppression off) keeps swinging;
with S = all six the arm moves along its 1-D reactionless path (scrub and 3-D drags) leaving the
boom still; the selection S is chosen live: forces only (r = 3) tracks a 3-D target by Eq. (24),
an RNS the app does not operate is refused with the reason and the runs are left as they were.
"""

from __future__ import annotations

import numpy as np
import pytest

from rns_viz.live.loop.session import Session

SIDEWAYS = (0.0, 1.0, 0.0, 0.0, 0.0, 0.0)  # a kick along y: the boom's first bending mode


def test_a_kick_is_suppressed_in_all_six_modes_and_the_shadow_keeps_swinging(boom7_session: Session) -> None:
    s = boom7_session
    assert s.snapshot().settings.law == "acceleration" and s.snapshot().readouts.rns_dim == 1
    s.kick(5.0, direction=SIDEWAYS)
    s.advance(0.3)
    early = np.abs(s.snapshot().q[:6])
    early_shadow = np.abs(s.snapshot().q_shadow[:6])  # type: ignore[index]
    s.advance(2.7)
    snap = s.snapshot()
    late, late_shadow = np.abs(snap.q[:6]), np.abs(snap.q_shadow[:6])  # type: ignore[index]
    assert early_shadow[1] > 1e-4  # the kick bent the boom sideways (about 0.3 mm)
    assert late.max() < 1e-3 * early_shadow[1]  # all six coordinates of the operated run came to rest
    assert late_shadow[1] > 0.3 * early_shadow[1]  # the run without suppression still swings (zeta 0.5 %)
    assert early.max() < early_shadow.max()
    arrays = s.plot_arrays()  # the six coordinates are plotted (mm / mrad), the deflection as |translation|
    assert all(np.isfinite(arrays[f"xb_{i}"]).all() for i in range(1, 7))
    assert np.allclose(arrays["xb"], np.linalg.norm(np.stack([arrays[f"xb_{i}"] for i in (1, 2, 3)]), axis=0))


def test_scrubbing_the_reactionless_path_moves_the_hand_and_not_the_boom(boom7_session: Session) -> None:
    s = boom7_session
    ee0 = s.state.model.ee_position(s.snapshot().q[6:])
    lo, hi = s.snapshot().sigma_range  # type: ignore[misc]
    s.scrub(0.5 * lo)  # about 4 cm of hand motion along the path, at the default u-bar speed
    s.advance(5.0)
    snap = s.snapshot()
    moved = np.linalg.norm(s.state.model.ee_position(snap.q[6:]) - ee0)
    peak = np.abs(s.state.runs.sim.log.array(5000)[:, 1:7]).max(axis=0)  # x_b over the motion
    assert snap.sigma == pytest.approx(0.5 * lo, abs=1e-2) and moved > 0.03
    assert peak[:3].max() < 1e-6 and peak[3:].max() < 1e-6  # m, rad: the boom stays still
    # A 3-D drag off the path: the hand goes to the nearest point of its path, and the operator is told.
    far = s.state.operator.table.ee_at(0.5 * hi) + np.array([0.0, 0.0, 0.3])  # type: ignore[union-attr]
    s.set_target(tuple(far), final=True)
    s.advance(0.01)
    notes = [n for n in s.pop_notices() if n.title == "Target moved"]
    assert notes and "nearest point (" in notes[0].body and notes[0].body.count(",") >= 2


def test_forces_only_tracks_a_3d_target_and_an_unserved_selection_is_refused(boom7_session: Session) -> None:
    s = boom7_session
    s.set_selection((True, True, True, False, False, False))
    s.advance(0.01)
    told = [n for n in s.pop_notices() if n.title == "Selection S"]
    assert told and "n − r = 4" in told[0].body and "left free" in told[0].body
    # forces only: the rows are the linear momentum, the gradient of M x_cm (Eq. 26), so the RNS is integrable
    assert "the RNS distribution is integrable" in told[0].body
    snap = s.snapshot()
    assert snap.settings.model == "boom7#S=111000" and snap.readouts.rns_dim == 4 and len(snap.target) == 3  # type: ignore[arg-type]
    goal = np.asarray(snap.target) + np.array([0.03, -0.02, 0.02])
    s.set_target(tuple(goal), final=True)
    s.advance(3.0)
    model = s.state.model
    hand = model.ee_position(s.snapshot().q[6:])
    assert np.linalg.norm(hand - goal) < 2e-3  # m: tracked in 3-D by Eq. (24)
    log = s.state.runs.sim.log
    L = np.stack([log.column(f"L_{i}", last=3000) for i in (1, 2, 3)])  # kg m/s, the selected rows (Eq. 8)
    moving = model.arm_mass * s.snapshot().settings.target_speed  # kg m/s: the arm's momentum scale
    # the force reactions stay near zero while the hand moves (what is left comes from holding the torque
    # over each 1 ms step, and from the free modes' ringing moving the arm)
    assert np.abs(L).max() < 1e-2 * moving
    s.set_selection((False,) * 6)  # no reaction to cancel: nothing for the RNS to do
    s.advance(0.01)
    refused = [n for n in s.pop_notices() if n.title == "Input not applied"]
    assert refused and "at least one" in refused[0].body
    assert s.snapshot().settings.model == "boom7#S=111000"  # the runs kept their selection
