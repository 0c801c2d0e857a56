"""Benchmark: the live app under load, as people would use it.

Run on demand (Debian chromium needed for the browser scenario):

    python benchmarks/bench_app.py                     # TREP, 60 s per scenario
    python benchmarks/bench_app.py --model planar3r --seconds 20
    python benchmarks/bench_app.py --teach --seconds 70  # teaching views and recording, vs off
    python benchmarks/bench_app.py --model trep2 --only browser     # dual arms
    python benchmarks/bench_app.py --model boom7 --only browser   # the 13-DOF spatial system

The app runs in its own process (its CPU time is measured there, with time.process_time over all
its threads); clients run in this process. Scenarios, each with the shadow run on:

1. one browser (Playwright + Debian chromium) connected; the arm moves (TREP: cyclic motion along
   its reactionless path; 3R: kicks; trep2: the task arm's target jumps between two points 5 cm
   apart every 2.5 s, server side, the compensator cancelling, the shadow's held; boom7: its r = 6
   reactionless path played to the other end every 5 s) and the base is kicked every 5 s from the
   page's button (boom7: sideways, along y, the direction control's default);
2. four protocol-level websocket clients (tests/support/protocol_client.py), decoding everything they receive;
3. latency: a websocket client sends target drags and gain-slider changes at 20 Hz; the app
   reports, for each, the time from its GUI callback to the start of the first step that used it.

Printed per scenario: real-time factor (target >= 0.99), scene update rate (frames sent, target
>= 30 Hz) and as received by a client, plot update rate (target >= 10 Hz), server CPU as % of
one core (target <= 60 %), and the latency median / 90th percentile (target median <= 5 ms), with
the machine's load average (the figures are only as good as the machine was quiet) and whether the
native closed-loop step runs.

``--teach`` runs the one-browser scenario twice in the same run: first a baseline with
every *Show in the scene* view off (no ghost, no arrows, trail or region) and the recorder switched
off, then with all of them on and the recorder recording (as the app always does). Printed for both:
the figures above and the server's resident memory; then the ring buffer's size for 60 s, the memory
it added over the baseline, and the memory a 60 s replay takes (the immutable copy it replays).
Use ``--seconds 60`` or more so the ring has filled once.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))  # tests/ holds the browser and websocket helpers


# ---------------------------------------------------------------- server side (a child process)
def rss_mb() -> float:
    """This process's resident memory, MB (Linux /proc)."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024.0
    return float("nan")


def serve(model: str, teach: str | None = None) -> None:
    """Start the app, print its handles as JSON, then answer 'stats' lines until 'quit'.
    ``teach``: "on" shows every teaching view; "off" hides them all and switches the recorder off."""
    from rns_viz.viz.scene.view_toggles import TOGGLES
    from rns_viz.viz.server.app import TARGET_HANDLE, start_app

    out, sys.stdout = sys.stdout, sys.stderr  # viser prints a banner: keep the protocol pipe clean
    if teach == "off":  # the baseline records nothing (its ring buffer is never even allocated)
        from rns_viz.live.outputs.recorder import Recorder

        Recorder.append = lambda *args: None  # type: ignore[method-assign]
    app = start_app(model, port=0, verbose=False)
    recorder = app.session.state.outputs.recorder
    if teach == "off":
        app.view.show_only(())
    elif teach == "on":
        app.view.show_only([name for name, *_ in TOGGLES])
    g = app.gui
    info = {
        "port": app.port,
        "plot": g.plot_xb._impl.uuid,
        "kick": g.kick._impl.uuid,
        "g_b": g.gains["g_b"].slider._impl.uuid,  # a NumberField: its slider carries the uuid
        "cyclic": g.cyclic._impl.uuid,
        "handle": TARGET_HANDLE,
    }
    print(json.dumps(info), file=out, flush=True)
    if model == "trep2":  # the task arm keeps moving: the target jumps 5 cm every 2.5 s
        threading.Thread(target=move_target, args=(app,), daemon=True).start()
    for line in sys.stdin:
        if line.strip() == "quit":
            break
        s = app.session
        if line.strip() == "replay":  # the newest 60 s replayed: what the immutable copy costs
            s.start_replay(60.0)
            time.sleep(2.0)
        snap = s.snapshot()
        stats = {
            "wall": time.perf_counter(),
            "cpu": time.process_time(),
            "sim_t": snap.t,
            "scene": app.scene_updates,
            "plots": app.plot_updates,
            "dropped": s.pacer.dropped,
            "latencies": s.latencies(),
            "ee": app.model.ee_position(snap.q[app.model.m :]).tolist(),
            "clients": len(app.server.get_clients()),
            "rss_mb": rss_mb(),
            "ring_mb": recorder.nbytes() / 1e6,
            "recorded_s": len(recorder) * s.dt,
            "native": "native C++ step" if s.state.runs.sim.native else "Python step",
        }
        s._latencies.clear()
        print(json.dumps(stats), file=out, flush=True)
    app.stop()


def move_target(app: Any, period: float = 2.5) -> None:
    """trep2: send the task arm's target back and forth between two points 5 cm apart (server side)."""
    s = app.session
    home = app.model.ee_position(app.model.spec.default_configuration)[:2]
    k = 0
    while not s.stopped:
        k += 1
        s.set_target(home + np.array([0.05 * (k % 2), 0.0]), final=True)
        time.sleep(period)


# ---------------------------------------------------------------- client side
class Server:
    """The app in a child process that prints its handles as JSON, then one JSON line per command.
    ``command``: another child (bench_page.py's) instead of this file's ``--serve``."""

    def __init__(self, model: str, teach: str | None = None, command: list[str] | None = None) -> None:
        self.proc = subprocess.Popen(
            command
            or [sys.executable, __file__, "--serve", "--model", model, *(["--teach-mode", teach] if teach else [])],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
            cwd=ROOT,
        )
        self.info: dict[str, Any] = json.loads(self._line())

    def _line(self) -> str:
        assert self.proc.stdout is not None
        line = self.proc.stdout.readline()
        if not line:
            raise RuntimeError("the app process ended early")
        return line

    def ask(self, command: str = "stats") -> dict[str, Any]:
        assert self.proc.stdin is not None
        self.proc.stdin.write(command + "\n")
        self.proc.stdin.flush()
        return json.loads(self._line())

    def stats(self) -> dict[str, Any]:
        return self.ask("stats")

    def close(self) -> None:
        try:
            assert self.proc.stdin is not None
            self.proc.stdin.write("quit\n")
            self.proc.stdin.flush()
            self.proc.wait(timeout=20)
        except Exception:
            self.proc.kill()


def summarize(name: str, a: dict[str, Any], b: dict[str, Any], client_rates: tuple[float, float] | None) -> None:
    wall = b["wall"] - a["wall"]
    rtf = (b["sim_t"] - a["sim_t"]) / wall
    cpu = 100.0 * (b["cpu"] - a["cpu"]) / wall
    scene = (b["scene"] - a["scene"]) / wall
    plots = (b["plots"] - a["plots"]) / wall
    print(f"\n== {name} ({wall:.0f} s, {b['clients']} client(s), shadow run on)")
    print(f"  real-time factor      {rtf:6.3f}   (target >= 0.99; backlog drops: {b['dropped'] - a['dropped']})")
    print(f"  scene updates sent    {scene:6.1f} Hz (target >= 30)")
    print(f"  plot updates sent     {plots:6.1f} Hz (target >= 10)")
    if client_rates is not None:
        scene_rx, plots_rx = client_rates
        print(f"  received by a client  {scene_rx:6.1f} Hz scene windows, {plots_rx:5.1f} Hz plot updates")
    print(f"  server CPU            {cpu:6.1f} % of one core (target <= 60)")
    print(f"  server memory         {b['rss_mb']:6.1f} MB resident; recorded {b['recorded_s']:.1f} s")
    per_sim = (b["cpu"] - a["cpu"]) / max(b["sim_t"] - a["sim_t"], 1e-9)
    print(f"  CPU per simulated s   {per_sim:6.3f} s (what real time costs on a free core: <= 0.6 meets the target)")
    print(f"  load average          {load()}  (simulator {b['native']})")


def load() -> str:
    """The machine's 1, 5 and 15 minute load averages (what `uptime` prints)."""
    return ", ".join(f"{x:.2f}" for x in os.getloadavg())


def kicker(ws: Any, uuid: str, stop: threading.Event, every: float = 5.0) -> None:
    while not stop.wait(every):
        ws.click(uuid)


def scenario_browser(model: str, seconds: float, teach: str | None = None) -> dict[str, Any] | None:
    from tests.support.browser import CHROMIUM, CHROMIUM_FLAGS, wait_until

    if not CHROMIUM.is_file():
        print(f"\n== one browser: skipped (no {CHROMIUM})")
        return None
    from playwright.sync_api import sync_playwright

    srv = Server(model, teach)
    try:
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_FLAGS, headless=True)
            page = browser.new_page(viewport={"width": 1400, "height": 900})
            page.goto(f"http://127.0.0.1:{srv.info['port']}/", timeout=60_000)
            wait_until(lambda: srv.ask()["clients"] >= 1, 60.0, "the browser to connect", poll=0.5)
            if model == "trep":
                page.get_by_role("button", name="Start cyclic motion").click()
            time.sleep(3.0)
            a = srv.ask()
            deadline = time.monotonic() + seconds
            while time.monotonic() < deadline:
                page.get_by_role("button", name="Kick the base").click()
                if model == "boom7":  # the arm moves too: along its reactionless path, to the other end and back
                    page.get_by_role("button", name="Play path slowly (5 s)").click()
                time.sleep(min(5.0, max(0.0, deadline - time.monotonic())))
            b = srv.ask()
            if teach == "on":
                b["replay_rss_mb"] = srv.ask("replay")["rss_mb"]
            browser.close()
        views = {None: "", "off": ", teaching views and recorder off", "on": ", ghost, all overlays and recorder on"}
        summarize(f"one browser (Playwright chromium, software rendering{views[teach]})", a, b, None)
        return b
    finally:
        srv.close()


def scenario_teach(model: str, seconds: float) -> None:
    """The browser scenario without and with the teaching views and the recorder."""
    off = scenario_browser(model, seconds, "off")
    on = scenario_browser(model, seconds, "on")
    if off is None or on is None:
        return
    print("\n== recording")
    print(f"  ring buffer for 60 s  {on['ring_mb']:6.1f} MB (target <= 50), holding {on['recorded_s']:.1f} s now")
    print(f"  resident memory       {on['rss_mb'] - off['rss_mb']:+6.1f} MB over the baseline (views + recorder)")
    print(f"  a 60 s replay         {on['replay_rss_mb'] - on['rss_mb']:+6.1f} MB more while it is shown")


def scenario_clients(model: str, seconds: float, count: int = 4) -> None:
    from tests.support.protocol_client import ProtocolClient

    srv = Server(model)
    clients: list[ProtocolClient] = []
    stop = threading.Event()
    try:
        clients = [ProtocolClient(srv.info["port"], decode=True) for _ in range(count)]
        time.sleep(2.0)
        if model == "trep":
            clients[0].click(srv.info["cyclic"])
        thread = threading.Thread(target=kicker, args=(clients[0], srv.info["kick"], stop), daemon=True)
        thread.start()
        time.sleep(2.0)
        a = srv.ask()
        since = time.perf_counter()
        time.sleep(seconds)
        b = srv.ask()
        probe = clients[-1]
        rates = (probe.rate(probe.pose_times, since), probe.rate(probe.gui_times.get(srv.info["plot"], []), since))
        summarize(f"{count} websocket clients", a, b, rates)
    finally:
        stop.set()
        for c in clients:
            c.close()
        srv.close()


def scenario_latency(model: str, seconds: float) -> None:
    from tests.support.protocol_client import ProtocolClient

    srv = Server(model)
    ws = None
    try:
        ws = ProtocolClient(srv.info["port"], decode=False)
        time.sleep(2.0)
        ee = srv.ask()["ee"]
        srv.ask()  # clear the latencies so far
        period, k = 0.05, 0
        ws.drag(srv.info["handle"], tuple(ee), "start")
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            k += 1
            if k % 2:  # a small target move (0.5 % of the arm's reach) and back
                dx = 0.015 if model == "planar3r" else 0.001
                ws.drag(srv.info["handle"], (ee[0] + dx * (k % 4 == 1), ee[1], ee[2]), "update")
            else:
                ws.set_value(srv.info["g_b"], 10.0 + 0.1 * (k % 4))
            time.sleep(period)
        ws.drag(srv.info["handle"], tuple(ee), "end")
        time.sleep(0.5)
        lat = sorted(1e3 * x for x in srv.ask()["latencies"])
        if not lat:
            print("\n== latency: no samples")
            return
        p90 = lat[int(0.9 * (len(lat) - 1))]
        print(f"\n== latency: GUI callback -> first simulation step using the input ({len(lat)} inputs at 20 Hz)")
        median = statistics.median(lat)
        print(f"  median {median:.2f} ms, 90th percentile {p90:.2f} ms, max {lat[-1]:.2f} ms (target median <= 5)")
    finally:
        if ws is not None:
            ws.close()
        srv.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", default="trep", help="a bundled model (trep, planar3r, boom7, trep2) or .toml file")
    parser.add_argument("--seconds", type=float, default=60.0, help="measured seconds per scenario")
    parser.add_argument("--only", choices=("browser", "clients", "latency"), help="run one scenario")
    parser.add_argument("--teach", action="store_true", help="one browser, teaching views off then on")
    parser.add_argument("--serve", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--teach-mode", choices=("on", "off"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.serve:
        serve(args.model, args.teach_mode)
        return
    print(f"rns_viz live app benchmark: model {args.model}, {args.seconds:g} s per scenario, {os.cpu_count()} cores")
    print(f"load average at start: {load()}")
    if args.teach:
        scenario_teach(args.model, args.seconds)
        print(f"\nload average after: {load()}")
        return
    if args.only in (None, "browser"):
        scenario_browser(args.model, args.seconds)
    if args.only in (None, "clients"):
        scenario_clients(args.model, args.seconds)
    if args.only in (None, "latency"):
        scenario_latency(args.model, min(args.seconds, 20.0))
    print(f"\nload average after: {' '.join(f'{x:.2f}' for x in os.getloadavg())} (1, 5, 15 min)")


if __name__ == "__main__":
    main()
