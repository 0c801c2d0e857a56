"""Benchmark: cost of one closed-loop simulation step, rns_viz versus baselines measured in the same run.

Run on demand:  python benchmarks/bench_sim.py [--samples 4000] [--rounds 20]

The step is ``Simulator.step()`` with the acceleration-based composite law (15) (AccelerationLaw,
default null input), RK4 with the torque held over a 1 ms step, logging on; with the native
extension built the law and RK4 run in C++ (rns_viz.sim.native). Baselines:

- "Python step": the same Simulator with ``native=False`` (law and RK4 in Python + pinocchio).
- "MuJoCo plant": the same AccelerationLaw object driving MuJoCo's ``mj_step`` (RK4, the same URDF
  loaded by ``tests.support.oracles.mujoco_replay.build_model``); no log.
- "straightforward": the same step written plainly (P_RNS formed, the paper's equations as printed,
  RK4 on separate q and v, a log row with forward kinematics each step; ``benchmarks/oracles.py``,
  with the generated 7-DOF arm). It is also a check: its trajectory must equal the simulator's.
- "pinocchio calls": crba + nonLinearEffects + 4 x aba alone, the floor of any step built on them.

The Python step against another commit (e.g. an older commit, checked out beside this one):
``python benchmarks/bench_step_vs.py OTHER_CHECKOUT`` (alternating subprocesses, wall and CPU time).

trep2 (TREP with a compensating second arm, Sec. III-B) runs its own law, the CompensatingLaw tracking
the trep2-circle preset's circle, in Python (no native step for it): its row gives the step with the
compensator cancelling, with it held (the live shadow run), their sum (what the live app steps per
1 ms), and the same law object driving MuJoCo's plant.

Timing: every variant is timed per step with perf_counter, in interleaved rounds (the machine is
shared and noisy), after warm-up; medians in microseconds. "sustained" is a long ``Simulator.run``
divided by its steps. The real-time factor is simulated time / wall time at dt = 1 ms.
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import sys
import tempfile
import time
from collections.abc import Callable, Hashable
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import pinocchio as pin

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))  # for tests.support.oracles

from benchmarks.oracles import DT, Straightforward, arm7_model, initial_state
from rns_viz.control import AccelerationLaw, Gains
from rns_viz.model import FsmsModel
from rns_viz.scenarios import trep2_circle
from rns_viz.sim import Simulator
from rns_viz.sim import native as native_step
from tests.support.oracles.mujoco_replay import build_model

GAINS = {
    "trep": Gains(g_b=24.0, g_m=20.0),
    "planar3r": Gains(g_b=10.0, g_m=1.0),
    "arm7": Gains(g_b=10.0, g_m=1.0),
    "boom7": Gains(g_b=10.0, g_m=2.0),  # the live app's default (rns_viz.defaults): 13 DOF, six base rows
}


def single_row(model: FsmsModel) -> bool:
    """The straightforward oracle inverts one coupling row in closed form: boom7's six rows are left out."""
    return len(model.selected) == 1


# -- the variants -----------------------------------------------------------------------------------
def rns_viz_step(model: FsmsModel, log_ee: bool = True, native: bool = True) -> Simulator:
    q0, v0 = initial_state(model)
    law = AccelerationLaw(model, GAINS[model.name])
    return Simulator(model, law, dt=DT, q0=q0, v0=v0, log_capacity=20000, log_ee=log_ee, native=native)


class MujocoDriven:
    """The same AccelerationLaw (or ``law``), with MuJoCo's RK4 (``mj_step``) as the plant."""

    def __init__(self, model: FsmsModel, law: Callable[..., Any] | None = None) -> None:
        spec = model.spec
        self.plant = build_model(spec.urdf_path, spec.base.joints, model.K_b, model.D_b, model.D_m, DT)
        self.data = mujoco.MjData(self.plant.model)
        self.law = law if law is not None else AccelerationLaw(model, GAINS[model.name])
        self.qadr = _as_slice(self.plant.qpos_index)
        self.dadr = _as_slice(self.plant.dof_index)
        self.arm = _as_slice(self.plant.dof_index[model.m :])
        at_rest = (model.q(model.spec.default_configuration), np.zeros(model.nv))
        q0, v0 = initial_state(model) if law is None else at_rest  # a given law's run sets its own state
        self.data.qpos[self.qadr] = q0
        self.data.qvel[self.dadr] = v0
        self.t = 0.0

    def step(self) -> None:
        data = self.data
        out = self.law(self.t, data.qpos[self.qadr], data.qvel[self.dadr])
        data.qfrc_applied[self.arm] = out.tau
        mujoco.mj_step(self.plant.model, data)
        self.t += DT

    def mj_step_only(self) -> None:
        mujoco.mj_step(self.plant.model, self.data)


def _as_slice(index: np.ndarray) -> slice | np.ndarray:
    """A contiguous increasing index array as a slice (cheaper to index with), else the array."""
    if len(index) and np.array_equal(index, np.arange(index[0], index[0] + len(index))):
        return slice(int(index[0]), int(index[0]) + len(index))
    return index


class PinocchioCalls:
    """crba + nonLinearEffects + four aba at a fixed state: the pinocchio work inside one step."""

    def __init__(self, model: FsmsModel) -> None:
        self.pm = model.pin_model
        self.data = self.pm.createData()
        q, _ = initial_state(model)
        self.q, self.v, self.u = q, np.full(model.nv, 0.1), np.full(model.nv, 0.01)

    def __call__(self) -> None:
        pm, d, q, v, u = self.pm, self.data, self.q, self.v, self.u
        pin.crba(pm, d, q)
        pin.nonLinearEffects(pm, d, q, v)
        for _ in range(4):
            pin.aba(pm, d, q, v, u)


# -- timing -----------------------------------------------------------------------------------------
def step_variants(model: FsmsModel) -> dict[str, Callable[[], None]]:
    """What is timed for one model, each a call that does one step (or one step's part)."""
    sim, sim_no_ee = rns_viz_step(model), rns_viz_step(model, log_ee=False)
    mj = MujocoDriven(model)
    law, q, v = sim.law, sim.q.copy(), sim.v.copy()
    variants = {
        "step": sim.step,
        "Python step": rns_viz_step(model, native=False).step,
        "step, log_ee off": sim_no_ee.step,
        "MuJoCo plant": mj.step,
        "pinocchio calls": PinocchioCalls(model),
        "law alone": lambda: law(0.0, q, v),
        "mj_step alone": mj.mj_step_only,
    }
    if single_row(model):
        variants["straightforward"] = Straightforward(model, AccelerationLaw(model, GAINS[model.name])).step
    return variants


def median_us(variants: dict[Hashable, Callable[[], None]], samples: int, rounds: int) -> dict[Hashable, float]:
    """Median µs per call of each variant, timed call by call in interleaved rounds after warm-up."""
    times: dict[Hashable, list[float]] = {name: [] for name in variants}
    per_round = max(1, samples // rounds)
    clock = time.perf_counter
    for _ in range(rounds):
        for name, fn in variants.items():
            for _ in range(50):
                fn()
            record = times[name].append
            for _ in range(per_round):
                t0 = clock()
                fn()
                record(clock() - t0)
    return {name: 1e6 * statistics.median(ts) for name, ts in times.items()}


def sustained_us(model: FsmsModel, steps: int) -> float:
    """Wall time of ``Simulator.run`` over ``steps`` steps, per step (no log reads)."""
    sim = rns_viz_step(model)
    sim.run(0.2)
    t0 = time.perf_counter()
    sim.run(steps * DT)
    return 1e6 * (time.perf_counter() - t0) / steps


def ee_fill_us(model: FsmsModel, steps: int = 5000) -> float:
    """End-effector columns filled on reading the log, per logged row (done once per row)."""
    sim = rns_viz_step(model)
    sim.run(steps * DT)
    t0 = time.perf_counter()
    sim.log.column("ee_x")
    filled = time.perf_counter() - t0
    t0 = time.perf_counter()
    sim.log.column("ee_x")  # the same read again: nothing left to fill
    plain = time.perf_counter() - t0
    return 1e6 * (filled - plain) / steps


def trajectories_agree(model: FsmsModel, steps: int = 2000) -> tuple[float, float, float]:
    """max |x_b| difference (m) of the Python step, the straightforward step and MuJoCo against the simulator."""
    sim, python = rns_viz_step(model), rns_viz_step(model, native=False)
    plain = Straightforward(model, AccelerationLaw(model, GAINS[model.name])) if single_row(model) else None
    mj = MujocoDriven(model)
    m = model.m
    worst_python = worst_mj = 0.0
    worst_plain = 0.0 if plain is not None else math.nan
    for _ in range(steps):
        sim.step()
        python.step()
        mj.step()
        worst_python = max(worst_python, float(np.abs(sim.q[:m] - python.q[:m]).max()))
        worst_mj = max(worst_mj, float(np.abs(sim.q[:m] - mj.data.qpos[mj.qadr][:m]).max()))
        if plain is not None:
            plain.step()
            worst_plain = max(worst_plain, abs(sim.q[0] - plain.q[0]))
    return worst_python, worst_plain, worst_mj


def dual_variants() -> dict[Hashable, Callable[[], None]]:
    """trep2's steps: compensating, held (the live shadow), and the compensating law on MuJoCo's plant."""
    on, held = trep2_circle(True), trep2_circle(False)
    for sim in (on, held):
        sim.run(0.5)  # the circle is under way
    mj = MujocoDriven(on.model, trep2_circle(True).law)
    mj.data.qpos[mj.qadr], mj.data.qvel[mj.dadr], mj.t = on.q, on.v, on.t
    return {("trep2", "step"): on.step, ("trep2", "held step"): held.step, ("trep2", "MuJoCo plant"): mj.step}


# -- report -----------------------------------------------------------------------------------------
def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=4000, help="timed steps per variant and model")
    parser.add_argument("--rounds", type=int, default=20, help="interleaved rounds the samples are split into")
    args = parser.parse_args()

    with tempfile.TemporaryDirectory() as tmp:
        models = [
            FsmsModel.from_name("trep"),
            FsmsModel.from_name("planar3r"),
            arm7_model(Path(tmp)),
            FsmsModel.from_name("boom7"),
        ]
        variants = {(model.name, name): fn for model in models for name, fn in step_variants(model).items()}
        variants.update(dual_variants())
        medians = median_us(variants, args.samples, args.rounds)
        results: dict[str, dict] = {model.name: {"n": model.n} for model in models}
        dual = {name: value for (model_name, name), value in medians.items() if model_name == "trep2"}
        for (model_name, name), value in medians.items():
            if model_name != "trep2":
                results[model_name][name] = value
        for model in models:
            results[model.name]["sustained"] = sustained_us(model, 5000)
            results[model.name]["ee fill"] = ee_fill_us(model)
            results[model.name]["agree"] = trajectories_agree(model)

    native = (
        "native (C++) step" if rns_viz_step(models[0]).native else f"NO native step: {native_step.unavailable_reason()}"
    )
    print(f"Closed-loop step, AccelerationLaw (15), RK4 with torque held over dt = {DT * 1e3:g} ms; medians in µs")
    print(f"step: {native}")
    versions = f"python {sys.version.split()[0]}, numpy {np.__version__}, pinocchio {pin.__version__}"
    print(f"({versions}, mujoco {mujoco.__version__}; load average {', '.join(f'{x:.2f}' for x in os.getloadavg())})")
    print()
    header = (
        "model",
        "arm DOF",
        "step",
        "RTF 1kHz",
        "sustained",
        "Python step",
        "MuJoCo plant",
        "ratio",
        "straightforward",
        "speed-up",
    )
    print("{:<10}{:>8}{:>8}{:>10}{:>11}{:>13}{:>14}{:>8}{:>17}{:>10}".format(*header))
    for name, r in results.items():
        r.setdefault("straightforward", math.nan)
        print(
            f"{name:<10}{r['n']:>8}{r['step']:>8.1f}{1e3 / r['step']:>9.1f}x{r['sustained']:>11.1f}"
            f"{r['Python step']:>13.1f}{r['MuJoCo plant']:>14.1f}{r['step'] / r['MuJoCo plant']:>8.2f}"
            f"{r['straightforward']:>17.1f}{r['straightforward'] / r['step']:>9.1f}x"
        )
    print()
    print("Where the time goes (medians, µs); log_ee: end-effector columns of the log")
    header = ("model", "pinocchio calls", "law alone", "mj_step alone", "log_ee off", "log_ee on", "ee fill/row")
    print("{:<10}{:>17}{:>11}{:>15}{:>12}{:>11}{:>13}".format(*header))
    for name, r in results.items():
        print(
            f"{name:<10}{r['pinocchio calls']:>17.1f}{r['law alone']:>11.1f}{r['mj_step alone']:>15.1f}"
            f"{r['step, log_ee off']:>12.1f}{r['step']:>11.1f}{r['ee fill']:>13.1f}"
        )
    print()
    both = dual["step"] + dual["held step"]
    print("trep2 (4 arm DOF), CompensatingLaw on the circle preset, Python step (medians, µs)")
    header = ("compensating", "RTF 1kHz", "held", "with shadow", "RTF", "MuJoCo plant", "ratio")
    print("{:<14}{:>9}{:>8}{:>13}{:>7}{:>14}{:>7}".format(*header))
    print(
        f"{dual['step']:<14.1f}{1e3 / dual['step']:>8.2f}x{dual['held step']:>8.1f}{both:>13.1f}{1e3 / both:>6.2f}x"
        f"{dual['MuJoCo plant']:>14.1f}{dual['step'] / dual['MuJoCo plant']:>7.2f}"
    )
    print()
    print("Same trajectory? max |x_b difference| over 2 s against Simulator.step (m; boom7: m or rad)")
    for name, r in results.items():
        python, plain, mj = r["agree"]
        print(f"{name:<10} Python step {python:.1e}   straightforward {plain:.1e}   MuJoCo plant {mj:.1e}")
    print()
    print(
        "step: Simulator.step() with logging (end-effector columns filled when the log is read: 'ee fill/row').\n"
        "RTF: simulated/wall time from the median; sustained: Simulator.run over 5000 steps, per step.\n"
        "Python step: the same Simulator with native=False.\n"
        "MuJoCo plant: the same law object, mj_step (RK4) as the plant, no log; ratio = step / MuJoCo plant.\n"
        "straightforward: the same step written plainly (see the class docstring); speed-up = it / step.\n"
        "pinocchio calls: crba + nonLinearEffects + 4 x aba, the floor under any step made of them.\n"
        "boom7: 7-DOF arm on a 6-DOF boom tip (13 DOF, S = all six rows); the straightforward oracle is\n"
        "single-row only (nan); x_b differences are the largest over its six coordinates (m or rad)."
    )
    if not math.isfinite(sum(r["step"] for r in results.values())):
        raise SystemExit("a timing was not finite")


if __name__ == "__main__":
    main()
