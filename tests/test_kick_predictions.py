"""The gain map's predictions against the simulator: what the map promises after a kick is what a kick does.

Each bundled model's map, for every law the app's explorer offers, predicts at each stable cell the base
deflection after the model's default kick (rns_viz.analysis.kick): its peak, its time to 10 % of the peak
and the decay rate of the pole that carries it there, or says why the linear loop cannot (not predictable).
Here seeded random predictable cells of each map, and its fastest, are kicked in the simulator running the
law the app runs at rest (its null-space input holding the arm: the joint reference; the end effector on
the 3R, Eq. 24) and measured from the log alone (rns_viz.analysis.measure_kick, on the logged samples): the
peak, and from the envelope of the deflection along the kick (through the tops of its swings) the time to
10 % and the decay rate from 20 % to 5 %. Agreement: within 20 %.

The default run checks cells whose kick has died down to 5 % within a few simulated seconds (SIM_BUDGET_S);
``-m slow_oracle`` checks more cells of every map, up to a minute of simulated time each.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pytest

from rns_viz import robots
from rns_viz.analysis import GainMap, gain_map, measure_kick
from rns_viz.control import Gains, JointSample, LawKind, TaskSample
from rns_viz.live.guard import Bounds
from rns_viz.live.laws import build_law
from rns_viz.model import FsmsModel
from rns_viz.sim import ForcePulse, SimulationDiverged, Simulator

TOLERANCE = 0.2  # relative, on the peak, the time to 10 % and the rate
TIME_FLOOR_S = 0.01  # s: times to 10 % shorter than this are compared to this (1 ms log)
# The laws the app's explorer maps for each model (every law but a dual-arm model's: it maps none).
LAWS: dict[str, tuple[LawKind, ...]] = {
    "trep": ("velocity", "acceleration", "torque"),
    "planar3r": ("acceleration", "velocity", "torque"),
    "boom7": ("acceleration", "torque", "velocity"),
    "boom-panda": ("acceleration", "torque", "velocity"),
}
# Default run: cells per map (at least 20 per model with the fastest ones) and the simulated seconds a
# cell may take; boom's steps cost about 3 times TREP's.
CELLS = {"trep": 6, "planar3r": 6, "boom7": 6, "boom-panda": 6}
SIM_BUDGET_S = {"trep": 4.0, "planar3r": 12.0, "boom7": 2.5, "boom-panda": 2.5}
SLOW_CELLS, SLOW_BUDGET_S = 20, 60.0
PANDA = pytest.mark.skipif(not robots.is_installed("example-robot-data/panda"), reason="rns-viz[panda] not installed")


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


def cells_to_check(grid: GainMap, count: int, budget: float, seed: int) -> list[tuple[int, int]]:
    """``count`` seeded random predictable cells whose kick dies down within ``budget`` s, and the fastest
    predictable cell of the map."""
    m = grid.modes
    kick = grid.loop.kick
    with np.errstate(divide="ignore", invalid="ignore"):
        needed = kick.duration + 1.6 * m.base_time_to_10pct + 0.3
    fits = np.argwhere(m.predictable & (needed <= budget - 1.0))
    rng = np.random.default_rng(seed)
    picked = [tuple(int(v) for v in fits[k]) for k in rng.choice(len(fits), min(count, len(fits)), replace=False)]
    g_b, g_m, _ = grid.best()
    fastest = (int(np.argmin(np.abs(grid.g_b - g_b))), int(np.argmin(np.abs(grid.g_m - g_m))))
    return [fastest, *(c for c in picked if c != fastest)]


def check_map(name: str, law: LawKind, count: int, budget: float, seed: int) -> list[Kicked]:
    model = FsmsModel.from_name(name)
    grid = gain_map(model, law)
    kicked = [kick_cell(model, grid, i, j, max(budget, 1.0)) for i, j in cells_to_check(grid, count, budget, seed)]
    for k in kicked:
        print(f"{name} {law}: {k.row()} {k.stopped}")
    return kicked


def assert_kept(name: str, law: LawKind, kicked: list[Kicked]) -> None:
    missed = [f"({k.cell[0]:.4g}, {k.cell[1]:.4g}): {', '.join(k.misses())} {k.stopped}" for k in kicked if k.misses()]
    assert not missed, f"{name}, law {law}: predictions the simulation does not keep:\n" + "\n".join(missed)


MAPS = [pytest.param(name, law, marks=PANDA if name == "boom-panda" else ()) for name in LAWS for law in LAWS[name]]


@pytest.mark.parametrize(("name", "law"), MAPS)
def test_the_maps_predictions_hold_in_the_simulator(name: str, law: LawKind) -> None:
    seed = 1000 + sorted(LAWS).index(name) * 10 + LAWS[name].index(law)
    kicked = check_map(name, law, CELLS[name], SIM_BUDGET_S[name], seed)
    assert len(kicked) >= CELLS[name]
    assert_kept(name, law, kicked)


@pytest.mark.slow_oracle
@pytest.mark.parametrize(("name", "law"), MAPS)
def test_the_maps_predictions_hold_in_the_simulator_more_cells(name: str, law: LawKind) -> None:
    seed = 2000 + sorted(LAWS).index(name) * 10 + LAWS[name].index(law)
    assert_kept(name, law, check_map(name, law, SLOW_CELLS, SLOW_BUDGET_S, seed))
