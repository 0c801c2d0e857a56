"""Benchmark: the appends and reads of the three ring buffers, this tree against another checkout.

Run on demand:  python benchmarks/bench_ring.py [OTHER_TREE] [--rounds 7] [--calls 20000]

The three: the step log (``Simulator.log``, written every 1 ms step: ``next_row()`` is the simulator's
path, ``append(row)`` the public one), the recorder (``Recorder.append``, every step of a live session)
and the live plot buffers (``PlotBuffers.append``, every 20th step); and two reads: the step log's
whole 10 s (10 000 rows, ``array()``) and the recorder taking its newest 10 s (``take``). TREP, a session
without its loop thread, kicked and run 12 s first so every ring has wrapped. One fresh Python per tree
and round (rounds alternate which goes first); per call CPU time of the process (process_time).
Printed: the median over the rounds, µs, of both trees, and the ratio this / other.
"""

from __future__ import annotations

import json
import sys
import time
from collections.abc import Callable
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from tree_rounds import main


def measure(calls: int) -> None:
    """In a fresh process: print µs per call of each operation as one JSON line."""
    import numpy as np

    from rns_viz.live.loop.session import Session
    from rns_viz.live.published.plot_buffers import PLOT_SERIES, PlotBuffers

    s = Session("trep", realtime=False)
    try:
        s.wait_background()
        s.kick(0.8)
        s.advance(12.0)  # past the 10 s step log: every ring has wrapped
        log, runs = s.state.runs.sim.log, s.state.runs
        recorder, outputs = s.state.outputs.recorder, s.state.outputs
        plots = PlotBuffers(500)
        row = log.array(1)[0].copy()
        sample = tuple(float(x) for x in np.arange(len(PLOT_SERIES)))

        def per_call(op: Callable[[], object], n: int) -> float:
            t = time.process_time()
            for _ in range(n):
                op()
            return (time.process_time() - t) / n * 1e6

        # each op is timed on its own and the ring is filled with real rows (next_row's slot left as it was)
        figures = {
            "log.next_row": per_call(log.next_row, calls),
            "log.append": per_call(lambda: log.append(row), calls),
            "recorder.append": per_call(lambda: recorder.append(runs, True, outputs.reaction_wrench, True), calls),
            "plots.append": per_call(lambda: plots.append(sample), calls),
            "log.array (10 s)": per_call(log.array, 50),
            "recorder.take (10 s)": per_call(lambda: recorder.take(10.0, s.state.model), 20),
        }
    finally:
        s.stop()
    print(json.dumps(figures))


if __name__ == "__main__":
    main(__file__, __doc__ or "", measure, rounds=7, calls=20000, unit="µs per call", scale=1.0)
