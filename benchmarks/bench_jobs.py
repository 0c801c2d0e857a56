"""Benchmark: what the job helper (rns_viz.live.jobs.helper) costs a caller, this tree against another checkout.

Run on demand:  python benchmarks/bench_jobs.py [OTHER_TREE] [--rounds 5] [--calls 200]

Each round starts a fresh Python per tree (rounds alternate which tree goes first) that imports the
helper module and measures, through the public ``jobs.call`` only:

- first call: the latency of the first job of the process, a trivial one (``family_curves`` of trep with
  count 0, which the job refuses at once): starting the helper process (its imports: pinocchio, rns_viz)
  and loading the model there;
- round trip: the median of ``--calls`` more of that trivial job, never cached (a failure is not): the
  transport alone;
- cached: the median of ``--calls`` repeats of a job answered before (``family_curves`` of trep, count 1).

Printed: the median over the rounds of each, in ms, for both trees, and the ratio this / other.
"""

from __future__ import annotations

import json
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from tree_rounds import main


def measure(calls: int) -> None:
    """In a fresh process: print the three figures (s) as one JSON line."""
    t0 = time.perf_counter()
    from rns_viz.live.jobs import helper as jobs

    imported = time.perf_counter() - t0

    def trivial() -> float:
        t = time.perf_counter()
        try:
            jobs.call("family_curves", "trep", 0)
        except jobs.JobError:
            return time.perf_counter() - t
        raise SystemExit("the trivial job did not fail as expected")

    first = trivial()
    round_trip = statistics.median(trivial() for _ in range(calls))
    jobs.call("family_curves", "trep", 1)
    cached = []
    for _ in range(calls):
        t = time.perf_counter()
        jobs.call("family_curves", "trep", 1)
        cached.append(time.perf_counter() - t)
    print(
        json.dumps({"import": imported, "first": first, "round_trip": round_trip, "cached": statistics.median(cached)})
    )


if __name__ == "__main__":
    main(__file__, __doc__ or "", measure, rounds=5, calls=200, unit="ms", scale=1e3)
