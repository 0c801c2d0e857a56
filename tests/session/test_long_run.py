"""Long runs: nothing grows per step or per frame (ring buffers everywhere), pacing does not drift."""

from __future__ import annotations

import tracemalloc

from rns_viz.live.loop.session import Session


def test_memory_stays_bounded_over_a_long_run() -> None:
    s = Session("trep", realtime=False)
    try:
        assert s.wait_background()
        s.advance(10.0)  # fill the ring buffers (plots: a 10 s window; the log is preallocated)
        for k in range(2):
            s.kick(0.5)
            s.scrub(float(k))
            s.advance(1.0)
        # Each snapshot once the helper's jobs (a kick's re-anchored path, the gain map) are in: on a busy machine
        # a result asked for before the first snapshot can land after it (a one-off 4 MB, not growth).
        assert s.wait_background()
        tracemalloc.start()
        before = tracemalloc.take_snapshot()
        for k in range(5):
            s.kick(0.5 if k % 2 else -0.5)
            s.scrub(float(k % 5))
            s.advance(1.0)
            s.pop_notices()
        assert s.wait_background()
        after = tracemalloc.take_snapshot()
        tracemalloc.stop()
        grown = sum(d.size_diff for d in after.compare_to(before, "filename"))
        assert grown < 1_000_000, f"{grown} bytes more after 5 s more of simulation"
        assert len(s.latencies()) <= 2000 and len(s.plot_arrays()["t"]) == 500
        assert len(s.state.runs.kicks.pulses) <= 1  # ended pulses are dropped
    finally:
        s.stop()
