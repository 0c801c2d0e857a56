"""Benchmark: what one frame of the app costs a software-rendered page, group by group.

    python benchmarks/bench_frame_cost.py                     # every group
    python benchmarks/bench_frame_cost.py --groups paths,grid  # some, e.g. twice: paths,grid,paths,grid

The default TREP app (unpaced: every frame is sent, so this is what drawing costs, not what
pacing saves) with the arm in cyclic motion, one headless chromium page with software WebGL.
For each group of scene nodes (or the plots), measured back to back with the group drawn and
hidden: the page's requestAnimationFrame rate, and chromium's CPU per page frame, split into the
page's own process (JS, layout) and the GPU process (SwiftShader rasterisation). CPU per frame
is what a busy machine distorts least; the rAF rate follows the machine's load.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_page import RAF_JS, app_and_page, chromium_cpu_s, load

# What the page draws, in groups that can be hidden one at a time to see what a frame costs.
COST_GROUPS = ("paths", "ghost", "labels", "grid", "beam", "robot", "arrows", "reach+trail", "plots", "all 3-D")


def drawing_group(app: Any, name: str) -> list[Any]:
    """Handles of one group of COST_GROUPS (scene nodes by name or kind; the plots' charts)."""
    if name == "plots":
        return [c for charts in app.gui.plots.charts.values() for c in charts.values() if c.visible] + [
            app.gui.plots.error
        ]
    nodes = app.server.scene._handle_from_node_name  # viser 1.1.1: name -> handle
    kinds = {"labels": "LabelHandle", "robot": "GlbHandle", "arrows": "ArrowsHandle"}
    names = {
        "paths": ("/base/paths", "/base/path_arrows"),
        "ghost": ("/ghost",),
        "grid": ("/grid",),
        "beam": ("/beam/edges", "/beam/plates"),
        "reach+trail": ("/base/reachable", "/base/reach_outline", "/base/trail"),
        "all 3-D": ("/base", "/beam", "/ghost", "/grid", "/gain_map"),
    }
    if name in kinds:
        return [h for h in nodes.values() if type(h).__name__ == kinds[name]]
    return [nodes[n] for n in names[name] if n in nodes]


def scenario_cost(
    seconds: float, groups: tuple[str, ...] = COST_GROUPS
) -> list[tuple[str, dict[str, float], dict[str, float]]]:
    """Per group of COST_GROUPS: the page's frames and chromium's CPU per frame with everything drawn
    and with that group hidden (measured back to back; the ratio is what the group costs)."""

    def measure(page: Any) -> dict[str, float]:
        cpu0 = chromium_cpu_s()
        raf_hz = page.evaluate(RAF_JS, int(1000 * seconds))
        cpu1 = chromium_cpu_s()
        frames = max(1.0, raf_hz * seconds)
        per = {k: 1e3 * (cpu1[k] - cpu0[k]) / frames for k in cpu0}
        return {"raf_hz": raf_hz, "renderer_ms": per["renderer"], "gpu_ms": per["gpu"]}

    rows = []
    with app_and_page(pace=False) as (app, page):  # every frame sent: what drawing costs, not what pacing saves
        app.ask("cyclic")
        time.sleep(8.0)  # the path family is computed and drawn
        for name in groups:
            with_it = measure(page)
            app.ask(f"hide:{name}")
            time.sleep(1.0)
            without = measure(page)
            app.ask(f"show:{name}")
            time.sleep(1.0)
            rows.append((name, with_it, without))
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--groups", help=f"comma-separated, of: {', '.join(COST_GROUPS)}")
    parser.add_argument("--seconds", type=float, default=4.0, help="seconds per measurement")
    args = parser.parse_args()
    groups = tuple(args.groups.split(",")) if args.groups else COST_GROUPS
    rows = scenario_cost(args.seconds, groups)
    print(f"== what a frame costs: each group hidden in turn (unpaced, cyclic motion)  [{load()}]")
    head = ("group", "rAF Hz with / without", "renderer CPU ms/frame", "GPU-process ms/frame")
    print(f"  {head[0]:<12} {head[1]:>22} {head[2]:>24} {head[3]:>22}")
    for name, a, b in rows:
        print(
            f"  {name:<12} {a['raf_hz']:>10.1f} / {b['raf_hz']:<9.1f} {a['renderer_ms']:>11.1f} / "
            f"{b['renderer_ms']:<10.1f} {a['gpu_ms']:>10.1f} / {b['gpu_ms']:<9.1f}"
        )


if __name__ == "__main__":
    main()
