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

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path


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


def run(tree: Path, calls: int) -> dict[str, float]:
    env = {**os.environ, "PYTHONPATH": str(tree), "PYTHONDONTWRITEBYTECODE": "1"}
    out = subprocess.run(
        [sys.executable, str(Path(__file__).resolve()), "--measure", "--calls", str(calls)],
        cwd=tree,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
        check=True,
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("other", type=Path, nargs="?", help="root of another checkout of rns_viz")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--calls", type=int, default=200)
    parser.add_argument("--measure", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.measure:
        measure(args.calls)
        return
    trees = {"this": Path(__file__).resolve().parent.parent}
    if args.other is not None:
        trees["other"] = args.other.resolve()
    figures = ("import", "first", "round_trip", "cached")
    found: dict[str, dict[str, list[float]]] = {tree: {f: [] for f in figures} for tree in trees}
    load = os.getloadavg()
    for r in range(args.rounds):
        for tree in list(trees) if r % 2 == 0 else list(reversed(trees)):
            for figure, value in run(trees[tree], args.calls).items():
                found[tree][figure].append(value)
    after = os.getloadavg()[0]
    print(f"job helper, {args.rounds} rounds, {args.calls} calls each; load before {load[0]:.2f}, after {after:.2f}")
    for tree, path in trees.items():
        print(f"{tree}: {path}")
    print(
        f"{'ms (median of rounds)':<24}"
        + "".join(f"{t:>10}" for t in trees)
        + ("     ratio" if len(trees) == 2 else "")
    )
    for figure in figures:
        values = [statistics.median(found[t][figure]) * 1e3 for t in trees]
        ratio = f"{values[0] / values[1]:>10.3f}" if len(values) == 2 else ""
        print(f"{figure:<24}" + "".join(f"{v:>10.3f}" for v in values) + ratio)


if __name__ == "__main__":
    main()
