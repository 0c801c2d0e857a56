"""The gain map's kick simulated at one cell with the law the app runs, and measured from the log alone as
the map predicts it (rns_viz.analysis.measure_kick): the oracle of tests/unit/test_kick_predictions.py and
tests/unit/test_kick_response.py."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rns_viz.analysis import GainMap, measure_kick
from rns_viz.control import Gains, JointSample, LawKind, TaskSample
from rns_viz.live.runs.divergence_guard import Bounds
from rns_viz.live.runs.laws import build_law
from rns_viz.model import FsmsModel
from rns_viz.sim import ForcePulse, SimulationDiverged, Simulator

TOLERANCE = 0.2  # relative, on the peak, the time to 10 % and the rate
TIME_FLOOR_S = 0.01  # s: times to 10 % shorter than this are compared to this (1 ms log)


@dataclass(frozen=True)
class Kicked:
    """The simulated kick at one cell: predicted and measured."""

    cell: tuple[float, float]  # g_b, g_m (1/s)
    predicted: tuple[float, float, float]  # peak (m or rad), time to 10 % (s after the kick), decay rate (1/s)
    measured: tuple[float, float, float]
    stopped: str  # why the run stopped early ('' if it did not)

    def misses(self) -> list[str]:
        names = ("peak", "time to 10 %", "decay rate")
        out = []
        for k, (name, p, m) in enumerate(zip(names, self.predicted, self.measured, strict=True)):
            scale = max(abs(m), TIME_FLOOR_S) if k == 1 else abs(m)
            if not (math.isfinite(m) and abs(p - m) <= TOLERANCE * scale):
                out.append(f"{name} {p:.4g} vs {m:.4g}")
        return out

    def row(self) -> str:
        p, m = self.predicted, self.measured
        return (
            f"g_b {self.cell[0]:8.4g} g_m {self.cell[1]:8.4g} | rate {p[2]:8.4g} / {m[2]:8.4g} = {p[2] / m[2]:5.3f}"
            f" | 10 % {p[1]:7.4g} / {m[1]:7.4g} s | peak {p[0]:.3g} / {m[0]:.3g}"
        )


def app_law(model: FsmsModel, kind: LawKind, g_b: float, g_m: float):
    """The law the app runs with the arm at rest at its default configuration: the null-space input holds the
    joint reference, or on a multi-dimensional RNS (the 3R) the end effector with Eq. (24)."""
    theta = model.spec.default_configuration
    task = None
    if model.n - len(model.selected) > 1:
        ee = model.ee_kinematics(model.q(theta), np.zeros(model.n))[2]
        task = TaskSample.held(ee[model.task_rows][: len(model.spec.task_axes)])
    return build_law(model, kind, Gains(g_b=g_b, g_m=g_m), True, JointSample.held(theta), task).law


def kick_cell(model: FsmsModel, grid: GainMap, i: int, j: int, budget: float) -> Kicked:
    """Simulate the map's kick at cell (i, j) with the app's law; measure peak, time to 10 % and decay."""
    loop, m = grid.loop, grid.modes
    kick = loop.kick
    g_b, g_m = float(grid.g_b[i]), float(grid.g_m[j])
    predicted = (float(m.peak[i, j]), float(m.base_time_to_10pct[i, j]), float(m.base_decay_rate[i, j]))
    period = 2 * math.pi / max(float(m.base_frequency[i, j]), 1e-9)
    needed = kick.duration + 1.6 * predicted[1] + min(period, 1.0) + 0.3
    duration = min(needed, budget)
    theta = model.spec.default_configuration
    force = ForcePulse(start=0.0, duration=kick.duration, peak=tuple(kick.peak * kick.weights))
    steps = round(duration / 1e-3)
    sim = Simulator(model, app_law(model, loop.law, g_b, g_m), q0=model.q(theta), force=force, log_capacity=steps + 2)
    bounds, stopped = Bounds(model), ""
    try:
        for k in range(steps):
            sim.step()
            if k % 10 == 0 and (why := bounds.violation(sim.q, sim.v)):
                stopped = why
                break
    except SimulationDiverged as exc:
        stopped = str(exc)
    log = sim.log
    t = log.column("t")
    y = sum(w * log.column(f"xb_{c + 1}") for c, w in enumerate(kick.output) if w)
    got = measure_kick(t, y, kick.duration, quiet=max(0.2, 0.3 * predicted[1]))  # the log runs 1.6 times as long
    return Kicked((g_b, g_m), predicted, (got.peak, got.settle_time, got.decay_rate), stopped)
