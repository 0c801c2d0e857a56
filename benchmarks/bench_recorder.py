"""Benchmark: what the always-on recorder costs the simulation loop, and its memory.

    python benchmarks/bench_recorder.py            # both models, 5 rounds of 3 s simulated each

For each model a session without its loop thread (``realtime=False``) runs the same seconds of
simulation (a kick, TREP also moving along its path) with the recorder on and, as the baseline in
the same run, with it switched off; rounds alternate so a busy machine slows both alike. Printed:
the median CPU time (of the stepping thread) per 1 ms step of both, their ratio, the cost
per step in µs and as % of one core at real time, and the append alone timed directly; then the
ring buffer's size for 60 s (target <= 50 MB), the bytes of one row, and the memory a 60 s
replay adds (its immutable copy) and a CSV / player export adds (the end-effector table).
"""

from __future__ import annotations

import statistics
import sys
import time
import tracemalloc
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from rns_viz.live.loop.session import Session  # noqa: E402
from rns_viz.live.outputs.recorder import Recorder  # noqa: E402

KICKS = {"trep": 0.8, "planar3r": 5.0}


def step_time(model: str, seconds: float, record: bool) -> float:
    """CPU seconds of this thread (the one stepping) per simulation step over ``seconds`` of simulated
    time: CPU time, not wall time, so other processes on a busy machine count less."""
    s = Session(model, realtime=False)
    try:
        s.wait_background()
        if not record:
            s.state.outputs.recorder.append = lambda *args: None  # type: ignore[method-assign]
        s.kick(KICKS[model])
        if model == "trep":
            s.cyclic(True)
        s.advance(0.2)
        t0 = time.thread_time()
        s.advance(seconds)
        return (time.thread_time() - t0) / round(seconds / s.dt)
    finally:
        s.stop()


def append_time(s: Session, calls: int = 20000) -> float:
    """CPU seconds of one ``Recorder.append`` (both runs' newest rows into the ring), the direct figure:
    a whole-step comparison on a busy machine varies by more than this."""
    rec, runs = s.state.outputs.recorder, s.state.runs
    t0 = time.thread_time()
    for _ in range(calls):
        rec.append(runs, True, s.state.outputs.reaction_wrench, True)
    return (time.thread_time() - t0) / calls


def memory(model: str) -> None:
    s = Session(model, realtime=False)
    try:
        s.wait_background()
        s.kick(KICKS[model])
        s.advance(60.5)
        rec: Recorder = s.state.outputs.recorder
        one = append_time(s)
        print(f"  Recorder.append alone  {one * 1e6:7.1f} µs per step = {one * 1e5:.2f} % of one core at real time")
        print(
            f"  ring buffer for 60 s   {rec.nbytes() / 1e6:6.1f} MB (target <= 50); "
            f"{len(rec.columns)} columns x 8 B = {8 * len(rec.columns)} B per 1 ms step"
        )
        tracemalloc.start()
        recording = s.recording(60.0)
        taken = tracemalloc.get_traced_memory()[0]
        assert recording is not None
        _ = recording.table
        tabled = tracemalloc.get_traced_memory()[0]
        tracemalloc.stop()
        copy, table = taken / 1e6, (tabled - taken) / 1e6
        print(f"  a 60 s replay          +{copy:5.1f} MB (its copy); exporting it +{table:5.1f} MB more")
    finally:
        s.stop()


def main() -> None:
    rounds, seconds = 5, 3.0
    load = Path("/proc/loadavg").read_text().split()[:3]
    print(f"recorder benchmark: {rounds} rounds of {seconds:g} s simulated per model; load {' '.join(load)}")
    for model in ("trep", "planar3r"):
        on, off = [], []
        for _ in range(rounds):
            off.append(step_time(model, seconds, False))
            on.append(step_time(model, seconds, True))
        m_on, m_off = statistics.median(on), statistics.median(off)
        print(f"\n== {model}")
        print(f"  step without recorder  {m_off * 1e6:7.1f} µs (median of {rounds})")
        print(f"  step with recorder     {m_on * 1e6:7.1f} µs   ratio {m_on / m_off:.3f}")
        cost = m_on - m_off
        print(f"  recorder per step      {cost * 1e6:7.1f} µs = {cost * 1e3 * 100:.2f} % of one core at real time")
        memory(model)
    print(f"\nload average after: {' '.join(Path('/proc/loadavg').read_text().split()[:3])}")


if __name__ == "__main__":
    main()
