"""Benchmark: cost of one closed-loop simulation step, rns_viz versus baselines measured in the same run.

Run on demand:  python benchmarks/bench_sim.py [--samples 4000] [--rounds 20]

The step is ``Simulator.step()`` with the acceleration-based composite law (15) (AccelerationLaw,
default null input), RK4 with the torque held over a 1 ms step, logging on; with the native
extension built the law and RK4 run in C++ (rns_viz.sim.native). Baselines:

- "Python step": the same Simulator with ``native=False`` (law and RK4 in Python + pinocchio).
- "MuJoCo plant": the same AccelerationLaw object driving MuJoCo's ``mj_step`` (RK4, the same URDF
  loaded by ``tests.oracles.mujoco_replay.build_model``); no log.
- "straightforward": the same step written plainly (P_RNS formed, the paper's equations as printed,
  RK4 on separate q and v, a log row with forward kinematics each step). It is also a check: its
  trajectory must equal the simulator's.
- "pinocchio calls": crba + nonLinearEffects + 4 x aba alone, the floor of any step built on them.

Timing: every variant is timed per step with perf_counter, in interleaved rounds (the machine is
shared and noisy), after warm-up; medians in microseconds. "sustained" is a long ``Simulator.run``
divided by its steps. The real-time factor is simulated time / wall time at dt = 1 ms.
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import tempfile
import time
from collections.abc import Callable, Hashable
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np
import pinocchio as pin

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))  # for tests.oracles

from rns_viz.control import AccelerationLaw, Gains
from rns_viz.model import FsmsModel
from rns_viz.sim import Simulator
from rns_viz.sim import native as native_step
from tests.oracles.mujoco_replay import build_model

DT = 1e-3
GAINS = {"trep": Gains(g_b=24.0, g_m=20.0), "planar3r": Gains(g_b=10.0, g_m=1.0), "arm7": Gains(g_b=10.0, g_m=1.0)}
X_B0 = {"trep": 2e-3, "planar3r": 1e-2, "arm7": 1e-2}  # initial base deflection, m


# -- a 7-DOF spatial arm on a translating elastic base, generated -----------------------------------
ARM7_AXES = ("0 0 1", "0 1 0", "0 0 1", "0 1 0", "0 0 1", "0 1 0", "0 0 1")
ARM7_LINK = 0.25  # m
ARM7_MASS = 1.0  # kg per link, at the link centre


def arm7_urdf() -> str:
    """URDF text: prismatic base_x (cart on a spring) then seven revolute joints, axes z, y, z, ..."""
    inertia = '<inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-3"/>'
    parts = [
        '<?xml version="1.0"?>\n<robot name="arm7">',
        '<link name="world"/>',
        f'<link name="cart"><inertial><origin xyz="0 0 0"/><mass value="2.0"/>{inertia}</inertial></link>',
        '<joint name="base_x" type="prismatic"><parent link="world"/><child link="cart"/>'
        '<axis xyz="1 0 0"/><limit lower="-1" upper="1" effort="100" velocity="10"/></joint>',
    ]
    parent, offset = "cart", 0.0
    for i, axis in enumerate(ARM7_AXES, start=1):
        parts.append(
            f'<link name="link{i}"><inertial><origin xyz="{ARM7_LINK / 2} 0 0"/><mass value="{ARM7_MASS}"/>'
            f"{inertia}</inertial></link>"
        )
        parts.append(
            f'<joint name="joint{i}" type="revolute"><parent link="{parent}"/><child link="link{i}"/>'
            f'<origin xyz="{offset} 0 0"/><axis xyz="{axis}"/>'
            '<limit lower="-6.2832" upper="6.2832" effort="100" velocity="10"/></joint>'
        )
        parent, offset = f"link{i}", ARM7_LINK
    parts.append('<link name="ee"/>')
    parts.append(
        f'<joint name="ee_fixed" type="fixed"><parent link="{parent}"/><child link="ee"/>'
        f'<origin xyz="{ARM7_LINK} 0 0"/></joint>'
    )
    parts.append("</robot>")
    return "\n".join(parts)


ARM7_TOML = """
[model]
name = "arm7"
urdf = "arm7.urdf"
ee_frame = "ee"
task_axes = ["x", "y", "z"]
default_configuration_deg = [20.0, 30.0, -20.0, 40.0, 10.0, -30.0, 15.0]
gravity_m_per_s2 = [0.0, 0.0, 0.0]

[base]
joints = ["base_x"]
stiffness = [[100.0]]
damping = [[0.1]]
selection = [1]

[arm]
joint_damping = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
"""


def arm7_model(directory: Path) -> FsmsModel:
    (directory / "arm7.urdf").write_text(arm7_urdf())
    (directory / "arm7.toml").write_text(ARM7_TOML)
    return FsmsModel.from_file(directory / "arm7.toml")


# -- the variants -----------------------------------------------------------------------------------
def initial_state(model: FsmsModel) -> tuple[np.ndarray, np.ndarray]:
    return model.q(model.spec.default_configuration, [X_B0[model.name]]), np.zeros(model.nv)


def rns_viz_step(model: FsmsModel, log_ee: bool = True, native: bool = True) -> Simulator:
    q0, v0 = initial_state(model)
    law = AccelerationLaw(model, GAINS[model.name])
    return Simulator(model, law, dt=DT, q0=q0, v0=v0, log_capacity=20000, log_ee=log_ee, native=native)


class MujocoDriven:
    """The same AccelerationLaw, with MuJoCo's RK4 (``mj_step``) as the plant."""

    def __init__(self, model: FsmsModel) -> None:
        spec = model.spec
        self.plant = build_model(spec.urdf_path, spec.base.joints, model.K_b, model.D_b, model.D_m, DT)
        self.data = mujoco.MjData(self.plant.model)
        self.law = AccelerationLaw(model, GAINS[model.name])
        self.qadr = _as_slice(self.plant.qpos_index)
        self.dadr = _as_slice(self.plant.dof_index)
        self.arm = _as_slice(self.plant.dof_index[model.m :])
        q0, v0 = initial_state(model)
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


@dataclass
class Straightforward:
    """The same closed-loop step written the obvious way, as the code was before it was optimised.

    Law (15) with P_RNS formed and -G_m theta' split into its range and RNS parts, the damped
    inverse of the single coupling row in closed form, resolved acceleration; RK4 on (q, v) with
    four ABA calls; a log row with forward kinematics for the end effector at every step.
    """

    model: FsmsModel
    law: AccelerationLaw  # only for its gains and damping threshold

    def __post_init__(self) -> None:
        model = self.model
        self.pm = model.pin_model
        self.ctrl_data, self.plant_data, self.fk_data = (self.pm.createData() for _ in range(3))
        self.q, self.v = initial_state(model)
        self.t = 0.0
        self.u = np.zeros(model.nv)
        self.log = np.full((20000, 2 + 4 * model.m + 5 * model.n + 5 + len(model.task_rows)), np.nan)
        self.row = 0

    def control(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
        model, m, rows = self.model, self.model.m, self.model.selected
        g, threshold = self.law.gains, self.law.coupling.threshold
        M = pin.crba(self.pm, self.ctrl_data, q).copy()
        c = pin.nonLinearEffects(self.pm, self.ctrl_data, q, v).copy()
        H_bm = M[rows, m:]
        sigma = float(np.sqrt(H_bm[0] @ H_bm[0]))
        lam2 = 0.0 if sigma >= threshold else (1 - (sigma / threshold) ** 2) * threshold**2
        pinv = (H_bm[0] / (sigma * sigma + lam2))[:, None]
        P = np.eye(model.n) - pinv @ H_bm
        thetadot = v[m:]
        suppression = pinv @ (g.g_b * (M[np.ix_(rows, rows)] @ v[rows]) - c[:m][rows])
        thetaddot = suppression - g.g_m * (thetadot - P @ thetadot) - g.g_m * (P @ thetadot)
        rhs = -model.K_b @ q[:m] - model.D_b @ v[:m] - c[:m] - M[:m, m:] @ thetaddot
        xddot_b = rhs / M[0, 0]
        tau = M[:m, m:].T @ xddot_b + M[m:, m:] @ thetaddot + c[m:] + model.D_m @ v[m:]
        return tau, H_bm @ thetadot, sigma

    def acceleration(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        model, m, u = self.model, self.model.m, self.u
        u[:m] = -model.K_b @ q[:m] - model.D_b @ v[:m]
        u[m:] = tau - model.D_m @ v[m:]
        return pin.aba(self.pm, self.plant_data, q, v, u)

    def rk4(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        h = 0.5 * DT
        a1 = self.acceleration(q, v, tau)
        v2 = v + h * a1
        a2 = self.acceleration(q + h * v, v2, tau)
        v3 = v + h * a2
        a3 = self.acceleration(q + h * v2, v3, tau)
        v4 = v + DT * a3
        a4 = self.acceleration(q + DT * v3, v4, tau)
        s = DT / 6.0
        return q + s * (v + 2.0 * (v2 + v3) + v4), v + s * (a1 + 2.0 * (a2 + a3) + a4)

    def ee(self, q: np.ndarray) -> np.ndarray:
        model = self.model
        pin.forwardKinematics(self.pm, self.fk_data, q)
        pin.updateFramePlacement(self.pm, self.fk_data, model.ee_frame_id)
        base = self.fk_data.oMi[model.base_joint_id]
        return base.rotation.T @ (self.fk_data.oMf[model.ee_frame_id].translation - base.translation)

    def record(self, tau: np.ndarray, L: np.ndarray, sigma: float) -> None:
        q, v, m, n = self.q, self.v, self.model.m, self.model.n
        row = self.log[self.row]
        row[:] = np.nan
        row[0] = self.t
        row[1 : 1 + m], row[1 + m : 1 + 2 * m] = q[:m], v[:m]
        i = 1 + 2 * m
        row[i : i + n], row[i + n : i + 2 * n], row[i + 2 * n : i + 3 * n] = q[m:], v[m:], tau
        i += 3 * n
        row[i : i + m] = 0.0
        row[i + m : i + m + 3] = self.ee(q)
        i += m + 3
        row[i : i + len(L)] = L
        row[i + len(L)] = sigma
        self.row = (self.row + 1) % len(self.log)

    def step(self) -> None:
        tau, L, sigma = self.control(self.q, self.v)
        q_next, v_next = self.rk4(self.q, self.v, tau)
        if not (np.all(np.isfinite(q_next)) and np.all(np.isfinite(v_next)) and np.all(np.isfinite(tau))):
            raise FloatingPointError("diverged")
        self.record(tau, L, sigma)
        self.q, self.v, self.t = q_next, v_next, self.t + DT


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
    return {
        "step": sim.step,
        "Python step": rns_viz_step(model, native=False).step,
        "step, log_ee off": sim_no_ee.step,
        "MuJoCo plant": mj.step,
        "straightforward": Straightforward(model, AccelerationLaw(model, GAINS[model.name])).step,
        "pinocchio calls": PinocchioCalls(model),
        "law alone": lambda: law(0.0, q, v),
        "mj_step alone": mj.mj_step_only,
    }


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
    plain = Straightforward(model, AccelerationLaw(model, GAINS[model.name]))
    mj = MujocoDriven(model)
    worst_python = worst_plain = worst_mj = 0.0
    for _ in range(steps):
        sim.step()
        python.step()
        plain.step()
        mj.step()
        worst_python = max(worst_python, abs(sim.q[0] - python.q[0]))
        worst_plain = max(worst_plain, abs(sim.q[0] - plain.q[0]))
        worst_mj = max(worst_mj, abs(sim.q[0] - mj.data.qpos[mj.qadr][0]))
    return worst_python, worst_plain, worst_mj


# -- report -----------------------------------------------------------------------------------------
def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=4000, help="timed steps per variant and model")
    parser.add_argument("--rounds", type=int, default=20, help="interleaved rounds the samples are split into")
    args = parser.parse_args()

    with tempfile.TemporaryDirectory() as tmp:
        models = [FsmsModel.from_name("trep"), FsmsModel.from_name("planar3r"), arm7_model(Path(tmp))]
        variants = {(model.name, name): fn for model in models for name, fn in step_variants(model).items()}
        medians = median_us(variants, args.samples, args.rounds)
        results: dict[str, dict] = {model.name: {"n": model.n} for model in models}
        for (model_name, name), value in medians.items():
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
    print(f"({versions}, mujoco {mujoco.__version__})")
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
    print("Same trajectory? max |x_b difference| over 2 s against Simulator.step (m)")
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
        "pinocchio calls: crba + nonLinearEffects + 4 x aba, the floor under any step made of them."
    )
    if not math.isfinite(sum(r["step"] for r in results.values())):
        raise SystemExit("a timing was not finite")


if __name__ == "__main__":
    main()
