"""Benchmark: the spatial model boom7 (m = 6, n = 7: a 13-DOF system) against TREP in the same run.

Run on demand:  python benchmarks/bench_spatial.py [--steps 300] [--rounds 15] [--family-rounds 7]

- Closed-loop step: ``Simulator.step()`` with law (15) (AccelerationLaw, default null input), RK4
  with the torque held over a 1 ms step, logging on, in Python (``native=False``) and, where the
  native step is built and covers the model, in C++. Timed per round of ``--steps`` steps, rounds
  interleaved between the models (the machine is shared and noisy); medians in microseconds.
  The real-time factor at 1 kHz is 1000 us / step.
- Path family: ``path_family(model, 40)``, the 40 reactionless curves the app overlays (boom7: r = 6,
  a 1-D RNS, seeds around the default configuration; TREP: seeds on levels of its potential).
  Target for boom7: <= 200 ms.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from benchmarks.step_timing import interleaved, load_line, step_round
from rns_viz.control import AccelerationLaw, Gains
from rns_viz.model import FsmsModel
from rns_viz.paths import path_family
from rns_viz.sim import Simulator

GAINS = {"trep": Gains(g_b=10.0, g_m=2.0), "boom7": Gains(g_b=10.0, g_m=2.0)}  # defaults of (15)
X_B0 = {"trep": np.array([2e-3]), "boom7": np.array([0.0, 2e-3, -3e-3, 1e-3, 1e-3, -1e-3])}  # m, rad
FAMILY_TARGET_MS = 200.0


def initial_state(model: FsmsModel) -> np.ndarray:
    return model.q(model.spec.default_configuration, X_B0[model.name])


def family_ms(model: FsmsModel) -> float:
    start = time.perf_counter()
    path_family(model, 40)
    return (time.perf_counter() - start) * 1e3


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=300, help="steps per timed round")
    parser.add_argument("--rounds", type=int, default=15)
    parser.add_argument("--family-rounds", type=int, default=7)
    args = parser.parse_args()

    models = {name: FsmsModel.from_name(name) for name in ("trep", "boom7")}
    step_cases: dict[str, Callable[[], float]] = {}
    for name, model in models.items():
        for native in (False, True):
            law = AccelerationLaw(model, GAINS[name])
            sim = Simulator(model, law, q0=initial_state(model), native=native)
            if native and not sim.native:
                print(f"{name}: native step not built or not covering this model; Python only")
                continue
            label = f"{name} ({model.nv} DOF), {'C++' if native else 'Python'} step"
            q0 = initial_state(model)
            step_cases[label] = lambda sim=sim, q0=q0: step_round(sim, q0, args.steps)
    steps = interleaved(step_cases, args.rounds)
    rounds = f"median of {args.rounds} rounds x {args.steps} steps"
    print(f"\nclosed-loop step, law (15), RK4 1 ms ({rounds}; {load_line()})")
    for label, us in steps.items():
        print(f"  {label:<34} {us:8.1f} us   real-time factor at 1 kHz {1e3 / us:5.2f}")
    trep_py = steps["trep (3 DOF), Python step"]
    boom_py = steps["boom7 (13 DOF), Python step"]
    print(f"  ratio boom7 / TREP (Python): {boom_py / trep_py:.2f}")

    families = interleaved({name: lambda m=m: family_ms(m) for name, m in models.items()}, args.family_rounds)
    print(f"\npath family of 40 curves (median of {args.family_rounds} rounds; {load_line()})")
    for name, ms in families.items():
        print(f"  {name:<8} {ms:8.1f} ms")
    verdict = "meets" if families["boom7"] <= FAMILY_TARGET_MS else "misses"
    ratio = families["boom7"] / families["trep"]
    print(f"  boom7 {verdict} the {FAMILY_TARGET_MS:.0f} ms target; ratio boom7 / TREP {ratio:.2f}")


if __name__ == "__main__":
    main()
