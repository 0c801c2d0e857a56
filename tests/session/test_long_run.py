"""Long runs: nothing grows per step or per frame (ring buffers everywhere), pacing does not drift."""

from __future__ import annotations

import tracemalloc
from pathlib import Path

import rns_viz
from rns_viz.live.loop.session import Session

STACK_DEPTH = 12  # frames kept per allocation: enough to reach the rns_viz caller of numpy and pinocchio


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
        # Only what this session's code allocates (rns_viz on the stack): in the test command's worker, threads of
        # earlier tests (a browser driver, a server shutting down) allocate too (4 MB in a busy CI run).
        ours = [tracemalloc.Filter(True, str(Path(rns_viz.__file__).parent / "*"), all_frames=True)]
        tracemalloc.start(STACK_DEPTH)
        before = tracemalloc.take_snapshot().filter_traces(ours)
        for k in range(5):
            s.kick(0.5 if k % 2 else -0.5)
            s.scrub(float(k % 5))
            s.advance(1.0)
            s.pop_notices()
        assert s.wait_background()
        after = tracemalloc.take_snapshot().filter_traces(ours)
        tracemalloc.stop()
        grown = sum(d.size_diff for d in after.compare_to(before, "filename"))
        where = [str(d) for d in after.compare_to(before, "traceback")[:3]]  # the largest growths, to look at
        assert grown < 1_000_000, f"{grown} bytes more after 5 s more of simulation; largest: {where}"
        assert len(s.latencies()) <= 2000 and len(s.plot_arrays()["t"]) == 500
        assert len(s.state.runs.kicks.pulses) <= 1  # ended pulses are dropped
    finally:
        s.stop()
