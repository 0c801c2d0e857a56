"""Benchmark: a 60 x 60 gain map (issue 10) against one simulator step, measured in the same run.

Run on demand:  python benchmarks/bench_gains.py [--rounds 15] [--size 60]

Per model and law (TREP with (30), the 3R with (15), both with the other laws, and boom7 with (15)):
- "linearise": :func:`rns_viz.analysis.linearise`, three central-difference Jacobians of the 1 ms
  step map (done once per model, law and configuration);
- "map": :func:`rns_viz.analysis.map_of` on that loop, the part repeated when the grid changes (the
  poles, and each stable cell's response to the model's kick: peak, time to 10 %, arm swing);
- "map + linearise": :func:`rns_viz.analysis.gain_map`, what a view pays when the model, law or
  configuration changes; target <= 100 ms;
- "plain eig": ``np.linalg.eig`` of the full A(g_b, g_m) at every grid point, the obvious way to
  get eigenvectors for the grouping (baseline for the map's block split);
- "one step": ``Simulator.step()`` with the same law (native when built, else Python), the ratio's base.

Medians over interleaved rounds (the machine is shared and noisy), after a warm-up.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from rns_viz.analysis import build_law, default_axes, gain_map, linearise, map_of
from rns_viz.control import Gains
from rns_viz.model import FsmsModel
from rns_viz.sim import Simulator

CASES = (
    ("trep", "velocity"),
    ("planar3r", "acceleration"),
    ("trep", "acceleration"),
    ("planar3r", "velocity"),
    ("boom7", "acceleration"),
)


def _median_ms(fn: Callable[[], object], rounds: int) -> float:
    fn()  # warm-up
    times = []
    for _ in range(rounds):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return 1e3 * statistics.median(times)


def _step_us(model: FsmsModel, law: str, steps: int = 2000) -> tuple[float, bool]:
    theta = model.spec.default_configuration
    sim = Simulator(model, build_law(model, law, theta, Gains(g_b=24.0, g_m=20.0)), q0=model.q(theta))
    sim.v = np.r_[1e-3, np.zeros(model.nv - 1)]
    sim.run(0.1)  # warm-up
    samples = []
    for _ in range(steps):
        t0 = time.perf_counter()
        sim.step()
        samples.append(time.perf_counter() - t0)
    return 1e6 * statistics.median(samples), sim.native


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=15)
    parser.add_argument("--size", type=int, default=60)
    args = parser.parse_args()
    print(f"{args.size} x {args.size} grid, medians of {args.rounds} rounds")
    header = f"{'model':9} {'law':13} {'linearise':>10} {'map':>8} {'map+lin':>8} {'plain eig':>10} {'one step':>10}"
    print(header + "   map / step   map+lin / step")
    for name, law in CASES:
        model = FsmsModel.from_name(name)
        g_b, g_m = default_axes(law, args.size)
        loop = linearise(model, law)
        grid_b, grid_m = np.meshgrid(g_b, g_m, indexing="ij")
        t_lin = _median_ms(lambda: linearise(model, law), args.rounds)  # noqa: B023
        t_map = _median_ms(lambda: map_of(loop, g_b, g_m), args.rounds)  # noqa: B023
        t_all = _median_ms(lambda: gain_map(model, law, g_b=g_b, g_m=g_m), args.rounds)  # noqa: B023
        t_eig = _median_ms(lambda: np.linalg.eig(loop.matrix(grid_b, grid_m)), args.rounds)  # noqa: B023
        step_us, native = _step_us(model, law)
        kind = "native" if native else "Python"
        print(
            f"{name:9} {law:13} {t_lin:8.1f}ms {t_map:6.1f}ms {t_all:6.1f}ms {t_eig:8.1f}ms "
            f"{step_us:6.1f}us {kind:6}  {1e3 * t_map / step_us:8.0f}x {1e3 * t_all / step_us:12.0f}x"
        )


if __name__ == "__main__":
    main()
