"""Benchmark: what drawing the Panda's meshes (boom-panda) costs against boom7's plain cylinders.

    python benchmarks/bench_robot_meshes.py             # server side only (no browser)
    python benchmarks/bench_robot_meshes.py --browser   # also one headless chromium page per model

boom-panda needs the rns-viz[panda] extra (example-robot-data); without it only boom7 is measured.
Server side: building the robot's scene nodes once (URDF and meshes read, sent to no client) and
posing them per frame (forward kinematics and the changed poses, median over random configurations);
the two models have the same joints, so a frame sends the same number of poses. Browser side (software
WebGL): the page's requestAnimationFrame rate and chromium's CPU per page frame over a few seconds
while the simulation runs, boom7 measured in the same run as the baseline. Prints `uptime` alongside.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np
import viser

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from bench_page import RAF_JS, chromium_cpu_s, load

from rns_viz.model import FsmsModel
from rns_viz.params import missing_extra
from rns_viz.viz.scene.robot import RobotMeshes


def server_side(name: str, frames: int = 2000) -> dict[str, float]:
    model = FsmsModel.from_name(name)
    server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    try:
        t0 = time.perf_counter()
        robot = RobotMeshes(server, model)
        build_s = time.perf_counter() - t0
        rng = np.random.default_rng(0)
        qs = [model.q(rng.uniform(model.lower, model.upper), rng.uniform(-1e-3, 1e-3, 6)) for _ in range(frames)]
        times = []
        for q in qs:
            t = time.perf_counter()
            robot.pose(q)
            times.append(time.perf_counter() - t)
        faces = sum(len(m.faces) for m in _meshes(model))
        return {
            "build_s": build_s,
            "pose_us": 1e6 * statistics.median(times),
            "nodes": len(robot.meshes),
            "faces": faces,
        }
    finally:
        server.stop()


def _meshes(model: FsmsModel) -> list:
    import yourdfpy

    path = model.spec.urdf_path
    urdf = yourdfpy.URDF.load(str(path), load_meshes=True)
    return list(urdf.scene.geometry.values())


def browser_side(name: str, seconds: float = 4.0) -> dict[str, float]:
    from playwright.sync_api import sync_playwright

    from rns_viz.viz.server.app import start_app
    from tests.support.browser import CHROMIUM, CHROMIUM_FLAGS

    app = start_app(name, port=0, verbose=False)
    try:
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_FLAGS, headless=True)
            try:
                page = browser.new_page(viewport={"width": 1400, "height": 900})
                t0 = time.monotonic()
                page.goto(f"http://127.0.0.1:{app.port}/", timeout=120_000)
                page.get_by_role("button", name="Kick the base").wait_for(timeout=120_000)
                time.sleep(3.0)  # meshes received and uploaded
                ready_s = time.monotonic() - t0
                app.session.kick(5.0)
                before = sum(chromium_cpu_s().values())
                raf = page.evaluate(RAF_JS, int(seconds * 1000))
                cpu = sum(chromium_cpu_s().values()) - before
                return {"ready_s": ready_s, "raf_hz": raf, "cpu_ms_per_frame": 1e3 * cpu / max(raf * seconds, 1.0)}
            finally:
                browser.close()
    finally:
        app.stop()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--browser", action="store_true", help="also measure one chromium page per model")
    args = parser.parse_args()
    names = ["boom7"] + (["boom-panda"] if missing_extra("boom-panda") is None else [])
    if len(names) == 1:
        print("boom-panda: not installed (pip install 'rns-viz[panda]'); boom7 only")
    print(f"load before: {load()}")
    base = None
    for name in names:
        s = server_side(name)
        base = base or s
        print(
            f"{name:11s} server: {s['nodes']:3d} mesh nodes, {s['faces']:7d} faces, build {s['build_s']:.2f} s, "
            f"pose per frame {s['pose_us']:.0f} us ({s['pose_us'] / base['pose_us']:.2f}x boom7)"
        )
    if args.browser:
        for name in names:
            b = browser_side(name)
            print(
                f"{name:11s} page: ready {b['ready_s']:.1f} s, rAF {b['raf_hz']:.1f} Hz, "
                f"chromium CPU {b['cpu_ms_per_frame']:.1f} ms per page frame"
            )
    print(f"load after: {load()}")


if __name__ == "__main__":
    main()
