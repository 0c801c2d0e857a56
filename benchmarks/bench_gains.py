"""Benchmark: a 60 x 60 gain map and one simulator step, this tree against another checkout.

Run on demand:  python benchmarks/bench_gains.py [OTHER_TREE] [--rounds 5] [--calls 7]

e.g. against an older commit:
    git worktree add /tmp/f9ec097 f9ec097 && python benchmarks/bench_gains.py /tmp/f9ec097

Per model and law (TREP with (30), the 3R with (15), both with the other laws, and boom7 with (15)):
- "map": :func:`rns_viz.analysis.map_of` on a linearised loop, the part repeated when the grid changes
  (the poles, and each stable cell's response to the model's kick: peak, time to 10 %, arm swing);
- "map+lin": :func:`rns_viz.analysis.gain_map`, what a view pays when the model, law or configuration
  changes (three central-difference Jacobians of the 1 ms step map first); target <= 100 ms;
- "step": ``Simulator.step()`` with the same law (native when built, else Python), printed in µs (in the
  ms column: a map of 50 ms against a step of 20 µs is 2500 steps).

Each round starts a fresh Python per tree (rounds alternate which tree goes first); a figure is the median
CPU time (process_time: the machine is shared) of ``--calls`` calls after a warm-up. Printed: the median
over the rounds, ms, for both trees, and the ratio this / other.
"""

from __future__ import annotations

import json
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from tree_rounds import main

CASES = (
    ("trep", "velocity"),
    ("planar3r", "acceleration"),
    ("trep", "acceleration"),
    ("planar3r", "velocity"),
    ("boom7", "acceleration"),
)
EQUATION = {"acceleration": "(15)", "torque": "(16)", "velocity": "(30)"}


def _median_s(fn: Callable[[], object], calls: int) -> float:
    fn()  # warm-up
    samples = []
    for _ in range(calls):
        t0 = time.process_time()
        fn()
        samples.append(time.process_time() - t0)
    return statistics.median(samples)


def measure(calls: int) -> None:
    """In a fresh process: print every case's figures (s) as one JSON line."""
    import numpy as np

    from rns_viz.analysis import build_law, default_axes, gain_map, linearise, map_of
    from rns_viz.control import Gains
    from rns_viz.model import FsmsModel
    from rns_viz.sim import Simulator

    figures = {}
    for name, law in CASES:
        model = FsmsModel.from_name(name)
        g_b, g_m = default_axes(law, 60)
        loop = linearise(model, law)
        case = f"{name} {EQUATION[law]}"
        figures[f"map {case}"] = _median_s(lambda: map_of(loop, g_b, g_m), calls)  # noqa: B023
        figures[f"map+lin {case}"] = _median_s(lambda: gain_map(model, law, g_b=g_b, g_m=g_m), calls)  # noqa: B023
        theta = model.spec.default_configuration
        sim = Simulator(model, build_law(model, law, theta, Gains(g_b=24.0, g_m=20.0)), q0=model.q(theta))
        sim.v = np.r_[1e-3, np.zeros(model.nv - 1)]
        sim.run(0.1)
        figures[f"step {case}"] = 1e3 * _median_s(sim.step, 200 * calls)  # printed in µs
    print(json.dumps(figures))


if __name__ == "__main__":
    main(__file__, __doc__ or "", measure, rounds=5, calls=7, unit="ms", scale=1e3)
