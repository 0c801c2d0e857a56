"""Timing helpers shared by the step benchmarks (bench_dual, bench_spatial): one timed round of a
simulator's steps, cases interleaved round by round on a shared, noisy machine, and the load."""

from __future__ import annotations

import os
import statistics
import time
from collections.abc import Callable

import numpy as np

from rns_viz.sim import Simulator


def step_round(sim: Simulator, q0: np.ndarray, steps: int, t0: float = 0.0) -> float:
    """Microseconds per step over one round of ``steps`` steps, restarting from q0 at time t0 (s)."""
    sim.reset(q0, t0=t0)
    start = time.perf_counter()
    for _ in range(steps):
        sim.step()
    return (time.perf_counter() - start) / steps * 1e6


def interleaved(cases: dict[str, Callable[[], float]], rounds: int) -> dict[str, float]:
    """Median of each case over ``rounds`` rounds, the cases taking turns within a round (after one warm-up)."""
    samples: dict[str, list[float]] = {name: [] for name in cases}
    for run in cases.values():  # warm-up
        run()
    for _ in range(rounds):
        for name, run in cases.items():
            samples[name].append(run())
    return {name: statistics.median(values) for name, values in samples.items()}


def load_line() -> str:
    """The 1, 5 and 15 minute load averages, to print beside any timing."""
    return "load average " + ", ".join(f"{x:.2f}" for x in os.getloadavg())
