"""Benchmark: the live app with the gain explorer in use.

    python benchmarks/bench_gain_ui.py --model trep --seconds 20

The app runs in real time in this process with two protocol-level clients (the operator and a
watcher, decoding everything). The operator clicks a random stable cell of the gain map every
0.5 s (the explorer recomputes poles, loci and authority off the loop) and switches the law every
4 s (a whole new map). Printed: real-time factor (target >= 0.99), dropped backlogs, scene
updates sent per second (target >= 30), map redraws, clicks applied, and the render thread's time
in the explorer's per-frame update (median and max, ms).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

LAWS = {"trep": ("velocity", "acceleration"), "planar3r": ("acceleration", "torque")}


def main() -> None:
    from rns_viz.viz.scene.gain_scene import GainScene, axis_fraction
    from rns_viz.viz.server.app import start_app
    from tests.support.browser import wait_for_clients, wait_until
    from tests.support.protocol_client import ProtocolClient

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", choices=("trep", "planar3r"), default="trep")
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--law-every", type=float, default=4.0, help="s between law switches (0: none)")
    parser.add_argument("--no-explorer", action="store_true", help="baseline: the explorer's view not drawn")
    args = parser.parse_args()

    app = start_app(args.model, port=0, verbose=False)
    s = app.session
    ex = app.renderer.explorer
    frame_ms: list[float] = []
    inner = ex.frame

    def timed() -> None:
        t0 = time.perf_counter()
        inner()
        frame_ms.append(1e3 * (time.perf_counter() - t0))

    ex.frame = (lambda: None) if args.no_explorer else timed  # type: ignore[method-assign]
    redraws = [0]
    show_map = GainScene.show_map

    def counted(self: GainScene, *a: object) -> None:
        redraws[0] += 1
        show_map(self, *a)  # type: ignore[arg-type]

    GainScene.show_map = counted  # type: ignore[method-assign]
    operator = ProtocolClient(app.port, decode=True)
    wait_for_clients(app, 1, "the operator")
    watcher = ProtocolClient(app.port, decode=True)
    wait_for_clients(app, 2, "a watcher")
    wait_until(lambda: s.gain_view().map is not None, 60.0, "the map")
    if args.no_explorer:
        inner()  # drawn once, to have cells to click
    rng = np.random.default_rng(1)
    if args.model == "trep":
        s.cyclic(True, None)  # the arm moves: the scene has something to send
    snap0, wall0, scene0 = s.snapshot(), time.perf_counter(), app.scene_updates
    next_click, next_law, law = wall0, wall0 + 4.0, 0
    while time.perf_counter() - wall0 < args.seconds:
        now = time.perf_counter()
        sc = ex.scene
        if now >= next_click and sc is not None and sc.gain_map is not None:
            next_click += 0.5
            gm = sc.gain_map
            moderate = gm.stable & (gm.g_b[:, None] >= 1) & (gm.g_b[:, None] <= 100) & (gm.g_m[None, :] <= 100)
            i, j = rng.choice(np.argwhere(moderate & (gm.g_m[None, :] >= 1)))
            u, v = axis_fraction(gm.g_b, gm.g_b[i]), axis_fraction(gm.g_m, gm.g_m[j])
            hit = sc.centre + sc.rotation @ np.array([(u - 0.5) * sc.size, (v - 0.5) * sc.size, 0.0])
            operator.scene_click(GainScene.IMAGE, tuple(hit + sc.rotation[:, 2]), tuple(-sc.rotation[:, 2]))
        if args.law_every > 0 and now >= next_law:
            next_law += args.law_every
            law = 1 - law
            s.set_law(LAWS[args.model][law], None)
        time.sleep(0.02)
    snap1, wall1 = s.snapshot(), time.perf_counter()
    rtf = (snap1.t - snap0.t) / (wall1 - wall0)
    print(f"gain explorer in use: model {args.model}, {args.seconds:g} s, 2 clients, shadow run on")
    print(f"  real-time factor       {rtf:.3f}   (target >= 0.99; backlog drops: {s.pacer.dropped})")
    print(f"  scene updates sent     {(app.scene_updates - scene0) / (wall1 - wall0):5.1f} Hz (target >= 30)")
    print(f"  diverged               {snap1.diverged}")
    print(f"  map redraws            {redraws[0]}   clicks applied {ex.clicks_applied}")
    if frame_ms:
        print(f"  explorer frame update  median {statistics.median(frame_ms):.3f} ms, max {max(frame_ms):.1f} ms")
    operator.close()
    watcher.close()
    app.stop()


if __name__ == "__main__":
    main()
