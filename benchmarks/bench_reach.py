"""Benchmark: boom7's reactionless-reachable set, as the app computes it when S or the rest configuration
changes (the job process's ``reach_region``: the breadth-first sweep of the RNS distribution plus the
Lie-bracket rank at the start).

Run on demand:  python benchmarks/bench_reach.py [--rounds 5]

For each selection S with a multi-dimensional RNS the app operates (r = 3: forces only and moments only;
r = 4), from boom7's default configuration: median wall time of ``build_reach_region`` over the rounds,
split into the sweep and the bracket test, and the number of points drawn. The planar 3R's set (on the
level set of its potential) is timed in the same run as a baseline. Target: <= 1 s per selection.
The load average is printed alongside: the machine may be shared.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from rns_viz.integrability import bracket_rank
from rns_viz.live.reach.region import VOXELS_PER_REACH, arm_reach, build_reach_region
from rns_viz.model import FsmsModel
from rns_viz.paths import explore_rns

SELECTIONS = {
    "forces (x y z)": [1, 1, 1, 0, 0, 0],
    "moments (rx ry rz)": [0, 0, 0, 1, 1, 1],
    "x y z rx": [1, 1, 1, 1, 0, 0],
}


def _median(f, rounds: int) -> tuple[float, object]:  # type: ignore[no-untyped-def]
    times, out = [], None
    for _ in range(rounds):
        t = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t)
    return statistics.median(times), out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--rounds", type=int, default=5)
    rounds = parser.parse_args().rounds
    print(f"load average before: {os.getloadavg()}")
    base = FsmsModel.from_name("boom7")
    theta0 = base.spec.default_configuration
    print(f"{'boom7 S':<20} {'total s':>8} {'sweep s':>8} {'brackets s':>10} {'points':>7}  bracket rank")
    for label, flags in SELECTIONS.items():
        model = base.with_selection(flags)
        voxel = arm_reach(model) / VOXELS_PER_REACH
        total, region = _median(lambda m=model: build_reach_region(m, theta0), rounds)
        sweep, _ = _median(lambda m=model, v=voxel: explore_rns(m, theta0, v), rounds)
        brackets, rank = _median(lambda m=model: bracket_rank(lambda th: m.coupling_matrix(m.q(th)), theta0), rounds)
        n_points = len(region.points)  # type: ignore[attr-defined]
        print(f"{label:<20} {total:8.3f} {sweep:8.3f} {brackets:10.3f} {n_points:7d}  {rank.with_brackets} of 7")  # type: ignore[attr-defined]
    planar = FsmsModel.from_name("planar3r")
    baseline, region = _median(lambda: build_reach_region(planar, planar.spec.default_configuration), rounds)
    print(f"{'planar3r (baseline)':<20} {baseline:8.3f} {'':>8} {'':>10} {len(region.points):7d}")  # type: ignore[attr-defined]
    print(f"load average after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
