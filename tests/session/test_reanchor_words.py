"""After law (15) absorbs a kick the arm rests on another reactionless path, and the loop moves the reference
there (rns_viz.live.loop.settle): the hand's miss then falls to about zero although the hand did not move.
The arm's mode on the status line says so."""

from __future__ import annotations

from rns_viz.live.loop.session import Session


def test_the_status_says_the_reference_moved_to_where_the_arm_came_to_rest() -> None:
    s = Session("boom7", realtime=False)
    try:
        assert s.wait_background()
        s.kick(5.0)
        before = None
        for _ in range(60):  # up to 12 s simulated
            s.advance(0.2)
            snap = s.snapshot()
            if "came to rest" in snap.mode:
                break
            before = snap.readouts.ee_error
        else:
            raise AssertionError(f"no re-anchoring within 12 s; mode {snap.mode!r}")
        assert "the reference moved there" in snap.mode and "the hand's miss restarts from 0" in snap.mode
        # what the words explain: the miss measured from the new reference is far below the one before it
        s.advance(0.5)
        after = s.snapshot().readouts.ee_error
        assert before is not None and after < 0.1 * before, (before, after)
    finally:
        s.stop()
