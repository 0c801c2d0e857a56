"""Long runs: nothing grows per step or per frame (ring buffers everywhere), pacing does not drift."""

from __future__ import annotations

import json
import subprocess
import sys
import tracemalloc
from pathlib import Path

STACK_DEPTH = 12  # frames kept per allocation: enough to reach the rns_viz caller of numpy and pinocchio
GROWTH_LIMIT = 1_000_000  # bytes: 5 s more of a simulation's own allocations still alive afterwards


def measure_growth() -> dict[str, object]:
    """Bytes that rns_viz code allocated over 5 s more of a warmed-up TREP session and still holds, with the
    largest growths; plus the ring buffers' lengths."""
    import rns_viz
    from rns_viz.live.loop.session import Session

    s = Session("trep", realtime=False)
    try:
        assert s.wait_background()
        s.advance(10.0)  # fill the ring buffers (plots: a 10 s window; the log is preallocated)
        for k in range(2):
            s.kick(0.5)
            s.scrub(float(k))
            s.advance(1.0)
        # Each snapshot once the helper's jobs (a kick's re-anchored path) are in: on a busy machine a result asked
        # for before the first snapshot can land after it (a one-off, not growth).
        assert s.wait_background()
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
        return {
            "grown": sum(d.size_diff for d in after.compare_to(before, "filename")),
            "largest": [
                "\n".join(d.traceback.format()) + f"\n  {d.size_diff:+d} B in {d.count_diff:+d} blocks"
                for d in after.compare_to(before, "traceback")[:3]
            ],
            "latencies": len(s.latencies()),
            "plotted": len(s.plot_arrays()["t"]),
            "pulses": len(s.state.runs.kicks.pulses),
        }
    finally:
        s.stop()


def test_memory_stays_bounded_over_a_long_run() -> None:
    # Measured in an interpreter of its own: in the test command's worker, threads that earlier tests left
    # finishing (a stopped session's job in flight, whose reply is unpickled when it lands) allocate from
    # rns_viz code too, inside this test's window (1.9 MB in a busy CI run), which is not this session's growth.
    done = subprocess.run(
        [sys.executable, __file__], capture_output=True, text=True, timeout=300, cwd=Path(__file__).parent
    )
    assert done.returncode == 0, f"the measurement failed:\n{done.stderr[-4000:]}"
    found = json.loads(done.stdout.strip().splitlines()[-1])
    largest = "\n".join(found["largest"])
    assert found["grown"] < GROWTH_LIMIT, f"{found['grown']} bytes more after 5 s more of simulation:\n{largest}"
    assert found["latencies"] <= 2000 and found["plotted"] == 500
    assert found["pulses"] <= 1  # ended pulses are dropped


if __name__ == "__main__":
    print(json.dumps(measure_growth()))
