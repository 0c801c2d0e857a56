"""Benchmark: the dual-arm step (trep2, compensating law) against TREP's step in the same run.

Run on demand:  python benchmarks/bench_dual.py [--steps 300] [--rounds 15]

``Simulator.step()`` with RK4 at 1 ms, the torque held over the step, logging on. Cases, interleaved
round by round (the machine is shared and noisy), medians in microseconds per step:
- trep2, CompensatingLaw tracking the preset's circle, compensating (Python; no native step yet);
- trep2, the same with the compensator held (the shadow run of the comparison);
- TREP, law (15) with the default null input, in Python and, where built, in C++.
The real-time factor at 1 kHz is 1000 us / step; a live dual-arm view with its shadow steps both.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from benchmarks.step_timing import interleaved, load_line, step_round
from rns_viz.control import AccelerationLaw, Gains
from rns_viz.model import FsmsModel
from rns_viz.scenarios import trep2_circle
from rns_viz.sim import Simulator


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=300, help="steps per timed round")
    parser.add_argument("--rounds", type=int, default=15)
    args = parser.parse_args()

    cases: dict[str, Callable[[], float]] = {}
    for compensate in (True, False):
        sim = trep2_circle(compensate)
        q0 = sim.q.copy()
        label = f"trep2 (5 DOF), {'compensating' if compensate else 'held'}, Python"
        cases[label] = lambda sim=sim, q0=q0: step_round(sim, q0, args.steps, t0=0.5)  # the circle is moving
    trep = FsmsModel.from_name("trep")
    q_trep = trep.q(trep.spec.default_configuration, np.array([2e-3]))
    for native in (False, True):
        sim = Simulator(trep, AccelerationLaw(trep, Gains(g_b=10.0, g_m=2.0)), q0=q_trep, native=native)
        if native and not sim.native:
            print("trep: native step not built; Python only")
            continue
        cases[f"trep (3 DOF), law (15), {'C++' if native else 'Python'}"] = lambda sim=sim: step_round(
            sim, q_trep, args.steps
        )

    medians = interleaved(cases, args.rounds)
    print(f"closed-loop step, RK4 1 ms (median of {args.rounds} rounds x {args.steps} steps; {load_line()})")
    for label, us in medians.items():
        print(f"  {label:<42} {us:8.1f} us   real-time factor at 1 kHz {1e3 / us:5.2f}")
    dual = medians["trep2 (5 DOF), compensating, Python"]
    trep_py = medians["trep (3 DOF), law (15), Python"]
    print(f"  ratio trep2 compensating / TREP (Python): {dual / trep_py:.2f}")
    both = dual + medians["trep2 (5 DOF), held, Python"]
    print(f"  trep2 with its shadow run: {both:.1f} us per 1 ms step (real-time factor {1e3 / both:.2f})")


if __name__ == "__main__":
    main()
