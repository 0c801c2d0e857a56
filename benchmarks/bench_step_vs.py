"""Benchmark: the Python closed-loop step of this tree against another checkout of rns_viz, same minute.

Run on demand:  python benchmarks/bench_step_vs.py OTHER_TREE [--rounds 7] [--steps 3000] [--shadow]

OTHER_TREE is the root of another checkout (e.g. a git worktree of an older commit). The step timed
is ``Simulator.step()`` with ``native=False`` (law and RK4 in Python + pinocchio), law (15)
``AccelerationLaw`` with ``Gains(g_b=10, g_m=1)`` and its default null input, RK4 at 1 ms, logging
on, starting at the model's default configuration with v0 = (0.01, 0, ...), for TREP, the 3R and
the generated 7-DOF arm of ``benchmarks/oracles.py`` (arm7) and boom7 (13 DOF, six coupling rows).
``--shadow``: the law without its G_b term (``suppress=False``), as the app's shadow run of a suppressing
run steps; the law is then evaluated at every RK4 stage (four times per step).
Also printed: the largest relative difference between the two trees' states after each round's
steps (the same steps must give the same numbers: 0 for a pure speed-up).

One subprocess per tree (its own imports), warmed up; the rounds alternate between them (which goes
first alternating too), so both see the same machine load. A round builds a fresh simulator per model
and times ``--steps`` steps of it as one block. Reported: min and median over the rounds of the
per-step time, in µs, and the ratio this tree / other tree (below 1: this tree is faster); wall-clock
time (perf_counter) and the process's CPU time (process_time), which a loaded machine inflates less
(a waiting process is not charged; caches shared with other work still are).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

MODELS = ("trep", "planar3r", "arm7", "boom7")


def worker(steps: int, arm7_toml: str, models: tuple[str, ...], suppress: bool = True) -> None:
    """Serve rounds: for each line on stdin, time ``steps`` Python steps per model with the rns_viz found on
    sys.path (a fresh simulator each round) and print µs/step (wall, CPU) and the final state as one JSON line."""
    import numpy as np

    from rns_viz.control import AccelerationLaw, Gains
    from rns_viz.model import FsmsModel
    from rns_viz.sim import Simulator

    starts = {}
    for name in models:
        model = FsmsModel.from_file(arm7_toml) if name == "arm7" else FsmsModel.from_name(name)
        v0 = np.zeros(model.nv)
        v0[0] = 0.01
        starts[name] = (model, model.q(model.spec.default_configuration), v0)

    def simulator(name: str) -> Simulator:
        model, q0, v0 = starts[name]
        law = AccelerationLaw(model, Gains(g_b=10.0, g_m=1.0), suppress=suppress)
        return Simulator(model, law, q0=q0, v0=v0, log_capacity=steps + 1, native=False)

    for name in models:
        simulator(name).run(0.3)  # warm-up
    print("ready", flush=True)
    for _ in sys.stdin:
        result = {}
        for name in models:
            sim = simulator(name)
            step = sim.step
            t0, c0 = time.perf_counter(), time.process_time()
            for _ in range(steps):
                step()
            wall, cpu = 1e6 * (time.perf_counter() - t0) / steps, 1e6 * (time.process_time() - c0) / steps
            result[name] = (wall, cpu, [*sim.q.tolist(), *sim.v.tolist()])
        print(json.dumps(result), flush=True)


class Worker:
    """A subprocess running :func:`worker` with ``tree`` first on its path; :meth:`round` times one round."""

    def __init__(self, tree: Path, steps: int, arm7_toml: Path, models: tuple[str, ...], shadow: bool) -> None:
        env = {**os.environ, "PYTHONPATH": str(tree), "PYTHONDONTWRITEBYTECODE": "1"}  # leave the other tree as it is
        command = [sys.executable, str(Path(__file__).resolve()), str(tree), "--worker", str(arm7_toml)]
        self.tree = tree
        self.process = subprocess.Popen(
            [*command, "--steps", str(steps), "--models", ",".join(models), *(["--shadow"] if shadow else [])],
            cwd=tree,
            env=env,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
        )
        self._read()  # "ready"

    def _read(self) -> str:
        line = self.process.stdout.readline()  # type: ignore[union-attr]
        if not line:
            raise SystemExit(f"worker in {self.tree} failed (exit {self.process.wait()})")
        return line

    def round(self) -> dict[str, list[float]]:
        self.process.stdin.write("go\n")  # type: ignore[union-attr]
        self.process.stdin.flush()  # type: ignore[union-attr]
        return json.loads(self._read())

    def close(self) -> None:
        self.process.stdin.close()  # type: ignore[union-attr]
        self.process.wait(timeout=30)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("other", type=Path, help="root of the other checkout of rns_viz")
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--steps", type=int, default=3000, help="timed steps per model and round")
    parser.add_argument("--models", default=",".join(MODELS), help="comma-separated; an older checkout may lack boom7")
    parser.add_argument("--shadow", action="store_true", help="the law without G_b (the app's shadow run)")
    parser.add_argument("--worker", metavar="ARM7_TOML", help=argparse.SUPPRESS)
    args = parser.parse_args()
    models = tuple(args.models.split(","))
    if unknown := set(models) - set(MODELS):
        parser.error(f"unknown models {sorted(unknown)}; choose from {', '.join(MODELS)}")
    if args.worker:
        worker(args.steps, args.worker, models, suppress=not args.shadow)
        return

    here = Path(__file__).resolve().parent.parent
    sys.path.insert(0, str(here))
    from benchmarks.oracles import ARM7_TOML, arm7_urdf

    trees = {"this": here, "other": args.other.resolve()}
    clocks = ("wall", "cpu")
    times = {(tree, clock): {name: [] for name in models} for tree in trees for clock in clocks}
    states: dict[tuple[str, str], np.ndarray] = {}  # the state (q, v) after the last round's steps
    load_before = os.getloadavg()
    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "arm7.urdf").write_text(arm7_urdf())
        (Path(tmp) / "arm7.toml").write_text(ARM7_TOML)
        workers = {
            tree: Worker(path, args.steps, Path(tmp) / "arm7.toml", models, args.shadow) for tree, path in trees.items()
        }
        for r in range(args.rounds):
            order = list(trees) if r % 2 == 0 else list(reversed(trees))
            for tree in order:
                for name, (wall, cpu, state) in workers[tree].round().items():
                    times[tree, "wall"][name].append(wall)
                    times[tree, "cpu"][name].append(cpu)
                    states[tree, name] = np.array(state)
        for w in workers.values():
            w.close()

    load = ", ".join(f"{x:.2f}" for x in (*load_before, *os.getloadavg()))
    law = "law (15) g_m=1 without G_b (shadow run)" if args.shadow else "law (15) g_b=10 g_m=1"
    print(f"Python step (native=False), {law}, RK4 1 ms, {args.steps} steps x {args.rounds} rounds")
    print(f"this: {trees['this']}\nother: {trees['other']}")
    print(f"load average (1, 5, 15 min) before, after: {load}")
    header = ("model", "clock", "this min", "median", "other min", "median", "ratio min", "median")
    print("{:<10}{:<6}{:>10}{:>9}{:>11}{:>9}{:>11}{:>9}".format(*header))
    for name in models:
        for clock in clocks:
            a, b = times["this", clock][name], times["other", clock][name]
            med_a, med_b = statistics.median(a), statistics.median(b)
            print(
                f"{name:<10}{clock:<6}{min(a):>10.1f}{med_a:>9.1f}{min(b):>11.1f}{med_b:>9.1f}"
                f"{min(a) / min(b):>11.3f}{med_a / med_b:>9.3f}"
            )
    print("µs per step; ratio = this / other (below 1: this tree is faster)")
    for name in models:
        a, b = states["this", name], states["other", name]
        rel = np.max(np.abs(a - b)) / np.max(np.abs(b))
        print(f"{name:<10}final state, max |this - other| / max |other|: {rel:.1e}")


if __name__ == "__main__":
    main()
