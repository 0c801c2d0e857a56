"""Benchmark: does the page stay live on a weak machine and after a hidden tab?

Run on demand (Debian chromium, software WebGL, as on a machine without a GPU):

    python benchmarks/bench_page.py                 # 5 min per browser run, 2 min hidden tab
    python benchmarks/bench_page.py --minutes 1 --hidden-minutes 0.5   # shortened

Each scenario runs twice in the same run: with the per-client pacing of rns_viz.viz.server.page_pacing
("paced") and without it ("unpaced", every page gets every update). The app
runs in a child process (its real-time factor is not disturbed by the clients); TREP, default app.

1. One software-rendered page, the base kicked from the page's Kick button every 10 s. Printed at
   the start and at the end of the run: the delay from pressing Kick to the page showing a state
   at or after the kick (its status line "t = ..." reaching the simulated time at which the
   server applied the kick), the page's requestAnimationFrame rate, the browser's memory (RSS of
   all chromium processes and the page's JS heap), and the page's answer time as the server
   measures it.
2. One software-rendered page plus 3 protocol-level clients (tests/support/protocol_client.py) with the
   arm in cyclic motion: server real-time factor, scene updates a second received by the fast
   clients, and by the page.
3. A hidden tab: the page is marked hidden and its main thread stopped (CDP Debugger.pause, as
   a frozen background tab) for --hidden-minutes, then shown: time until the page answers a
   script at all ("live") and until it shows the server's current time, then Kick -> visible.

What one frame costs, group by group: benchmarks/bench_frame_cost.py (uses this file's app).
The lead re-runs this on a quiet machine; `uptime` load is printed with the figures.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))  # tests/ holds the browser and websocket helpers
from bench_app import Server  # noqa: E402 (this folder is on the path when the script runs)

KICK_EVERY_S = 10.0


# ---------------------------------------------------------------- the app (a child process)
def serve(pace: bool) -> None:
    """Start the app, print its port, then answer 'stats' lines until 'quit'."""
    from rns_viz.viz.server.app import start_app

    out, sys.stdout = sys.stdout, sys.stderr  # viser prints a banner: keep the protocol pipe clean
    app = start_app("trep", port=0, verbose=False, pace=pace)
    s = app.session
    kicks: list[float] = []  # simulated times at which kicks were applied
    kick = s.kick

    def recorded_kick(*args: Any, **kwargs: Any) -> None:
        kicks.append(s.snapshot().t)
        kick(*args, **kwargs)

    s.kick = recorded_kick  # type: ignore[method-assign]
    print(json.dumps({"port": app.port}), file=out, flush=True)
    for line in sys.stdin:
        command = line.strip()
        if command == "quit":
            break
        if command == "cyclic":
            s.cyclic(True)
        if command.startswith(("hide:", "show:")):
            from bench_frame_cost import drawing_group

            for handle in drawing_group(app, command[5:]):
                handle.visible = command.startswith("show:")
        clients = sorted(app.server.get_clients())
        stats = {
            "wall": time.perf_counter(),
            "sim_t": s.snapshot().t,
            "scene": app.scene_updates,
            "kicks": kicks[-1:],
            "pace": {str(c): app.pace.state(c) for c in clients},
        }
        print(json.dumps(stats), file=out, flush=True)
    app.stop()


class App(Server):
    """The default TREP app in a child process (this file's ``--serve``), paced or not."""

    def __init__(self, pace: bool) -> None:
        super().__init__("trep", command=[sys.executable, __file__, "--serve", "--pace" if pace else "--no-pace"])
        self.port = int(self.info["port"])


# ---------------------------------------------------------------- the page
WATCH_STATUS_JS = """() => {
    window.__statusLog = [];
    const read = () => {
        const m = /t = +(-?[0-9.]+) s/.exec(document.body.innerText.slice(0, 4000));
        if (m) {
            const t = parseFloat(m[1]);
            const log = window.__statusLog;
            if (!log.length || log[log.length - 1][1] !== t) log.push([Date.now() / 1000, t]);
            if (log.length > 400) log.splice(0, 200);
        }
    };
    new MutationObserver(read).observe(document.body, {subtree: true, childList: true, characterData: true});
}"""
RAF_JS = """(ms) => new Promise((done) => {
    let n = 0; const t0 = performance.now();
    const step = () => {
        n++;
        if (performance.now() - t0 < ms) requestAnimationFrame(step);
        else done((n / (performance.now() - t0)) * 1000);
    };
    requestAnimationFrame(step);
})"""
HEAP_JS = "() => (performance.memory ? performance.memory.usedJSHeapSize / 1048576 : -1)"
HIDE_JS = """(hidden) => {
    Object.defineProperty(document, 'hidden', {configurable: true, get: () => hidden});
    const state = hidden ? 'hidden' : 'visible';
    Object.defineProperty(document, 'visibilityState', {configurable: true, get: () => state});
    document.dispatchEvent(new Event('visibilitychange'));
}"""


def _descendants() -> list[int]:
    """Process ids of everything this benchmark started (browsers, the Playwright driver, the app)."""
    children: dict[int, list[int]] = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                ppid = int(Path(f"/proc/{entry}/stat").read_text().rsplit(")", 1)[1].split()[1])
            except (OSError, IndexError, ValueError):
                continue
            children.setdefault(ppid, []).append(int(entry))
    found, todo = [], list(children.get(os.getpid(), []))
    while todo:
        pid = todo.pop()
        found.append(pid)
        todo += children.get(pid, [])
    return found


def chromium_rss_mb() -> float:
    """Resident memory of every chromium process started by this benchmark (MB)."""
    total = 0.0
    for pid in _descendants():
        try:
            if "chrom" in Path(f"/proc/{pid}/comm").read_text():
                for line in Path(f"/proc/{pid}/status").read_text().splitlines():
                    if line.startswith("VmRSS:"):
                        total += float(line.split()[1]) / 1024.0
        except OSError:
            continue
    return total


def chromium_cpu_s() -> dict[str, float]:
    """CPU seconds used so far by this benchmark's chromium processes, by kind (renderer, gpu, other)."""
    ticks = os.sysconf("SC_CLK_TCK")
    out = {"renderer": 0.0, "gpu": 0.0, "other": 0.0}
    for pid in _descendants():
        try:
            if "chrom" not in Path(f"/proc/{pid}/comm").read_text():
                continue
            cmd = Path(f"/proc/{pid}/cmdline").read_bytes()
            fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        kind = "renderer" if b"--type=renderer" in cmd else "gpu" if b"--type=gpu-process" in cmd else "other"
        out[kind] += (int(fields[11]) + int(fields[12])) / ticks
    return out


def kick_to_visible(page: Any, app: App, timeout: float = 120.0) -> float:
    """Press Kick on the page (a mouse click where the button is, as a person's press: no waiting for
    the page to confirm the button first); seconds until the page shows a state at or after the
    kick (nan on timeout)."""
    button = page.get_by_role("button", name="Kick the base")
    box = button.bounding_box(timeout=timeout * 1000)
    before = app.ask()["kicks"]
    pressed = time.time()
    page.mouse.click(box["x"] + 0.5 * box["width"], box["y"] + 0.5 * box["height"])
    deadline = time.monotonic() + timeout
    kick_t = None
    while kick_t is None and time.monotonic() < deadline:
        kicks = app.ask()["kicks"]
        if kicks and kicks != before:
            kick_t = kicks[0]
        else:
            time.sleep(0.05)
    if kick_t is None:
        return float("nan")
    while time.monotonic() < deadline:
        log = page.evaluate("() => window.__statusLog")
        shown = [wall for wall, t in log if t >= kick_t]
        if shown:
            return shown[0] - pressed
        time.sleep(0.1)
    return float("nan")


def page_figures(page: Any, app: App) -> dict[str, float]:
    t0 = time.monotonic()
    raf = page.evaluate(RAF_JS, 3000)
    figures = {"raf_hz": raf, "script_s": time.monotonic() - t0 - 3.0}
    figures["heap_mb"] = page.evaluate(HEAP_JS)
    figures["rss_mb"] = chromium_rss_mb()
    pace = list(app.ask()["pace"].values())
    figures["pace_hz"] = pace[0]["hz"] if pace and pace[0] else float("nan")
    figures["answer_s"] = pace[0]["answer_s"] if pace and pace[0] else float("nan")
    return figures


@contextmanager
def app_and_page(pace: bool) -> Iterator[tuple[App, Any]]:
    """The app (paced or not) and one software-rendered page showing it, its status line watched."""
    from playwright.sync_api import sync_playwright

    from tests.support.browser import CHROMIUM, CHROMIUM_FLAGS

    app = App(pace)
    try:
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_FLAGS, headless=True)
            try:
                page = browser.new_page(viewport={"width": 1400, "height": 900})
                page.goto(f"http://127.0.0.1:{app.port}/", timeout=120_000)
                page.get_by_role("button", name="Kick the base").wait_for(timeout=120_000)
                page.evaluate(WATCH_STATUS_JS)
                yield app, page
            finally:
                browser.close()
    finally:
        app.close()


# ---------------------------------------------------------------- scenarios
def scenario_one_page(pace: bool, minutes: float) -> dict[str, Any]:
    with app_and_page(pace) as (app, page):
        time.sleep(3.0)
        delays: list[float] = []
        start = page_figures(page, app)
        cpu0, wall0 = chromium_cpu_s(), time.monotonic()
        t_end = time.monotonic() + 60.0 * minutes
        while time.monotonic() < t_end:
            t0 = time.monotonic()
            delays.append(kick_to_visible(page, app))
            time.sleep(max(0.0, KICK_EVERY_S - (time.monotonic() - t0)))
        cpu1, wall1 = chromium_cpu_s(), time.monotonic()
        end = page_figures(page, app)
    k = max(1, min(3, len(delays) // 3))
    cpu = {kind: 100.0 * (cpu1[kind] - cpu0[kind]) / (wall1 - wall0) for kind in cpu0}
    return {"start": start, "end": end, "kick_start": delays[:k], "kick_end": delays[-k:], "kicks": len(delays)} | {
        "cpu": cpu
    }


def scenario_crowd(pace: bool, seconds: float) -> dict[str, Any]:
    from tests.support.protocol_client import ProtocolClient

    with app_and_page(pace) as (app, page):
        clients = [ProtocolClient(app.port, decode=True, watch_node="/base/link1") for _ in range(3)]
        try:
            app.ask("cyclic")
            time.sleep(5.0)
            a, since = app.ask(), time.perf_counter()
            time.sleep(seconds)
            b = app.ask()
            fast = [c.rate(c.pose_times, since) for c in clients]
            figures = page_figures(page, app)
        finally:
            for c in clients:
                c.close()
    wall = b["wall"] - a["wall"]
    return {
        "rtf": (b["sim_t"] - a["sim_t"]) / wall,
        "scene_sent_hz": (b["scene"] - a["scene"]) / wall,
        "fast_hz": fast,
        "page_pace_hz": figures["pace_hz"],
        "page_raf_hz": figures["raf_hz"],
    }


def scenario_hidden(pace: bool, minutes: float) -> dict[str, Any]:
    with app_and_page(pace) as (app, page):
        time.sleep(5.0)
        cdp = page.context.new_cdp_session(page)
        cdp.send("Debugger.enable")
        page.evaluate(HIDE_JS, True)
        cdp.send("Debugger.pause")  # the main thread stops, as in a frozen background tab
        time.sleep(60.0 * minutes)
        shown = time.monotonic()
        cdp.send("Debugger.resume")
        cdp.send("Debugger.disable")
        page.evaluate(HIDE_JS, False)
        live_s = time.monotonic() - shown
        server_t = app.ask()["sim_t"]
        current_s = float("nan")
        while time.monotonic() - shown < 600.0:
            log = page.evaluate("() => window.__statusLog")
            if log and log[-1][1] >= server_t:
                current_s = time.monotonic() - shown
                break
            time.sleep(0.05)
        kick_s = kick_to_visible(page, app)
    return {"live_s": live_s, "current_s": current_s, "kick_s": kick_s}


# ---------------------------------------------------------------- report
def load() -> str:
    return subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()


def med(xs: list[float]) -> float:
    return statistics.median(xs) if xs else float("nan")


def row(name: str, paced: float, unpaced: float, unit: str, target: str = "") -> None:
    print(f"  {name:<44} {paced:>9.2f} {unpaced:>9.2f}  {unit:<5} {target}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=5.0, help="minutes of the one-page run (each mode)")
    parser.add_argument("--crowd-seconds", type=float, default=60.0, help="seconds of the page + 3 clients run")
    parser.add_argument("--hidden-minutes", type=float, default=2.0, help="minutes the tab stays hidden")
    parser.add_argument("--only", choices=("page", "crowd", "hidden"), help="run one scenario")
    parser.add_argument("--serve", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--pace", action=argparse.BooleanOptionalAction, default=True, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.serve:
        serve(args.pace)
        return
    print(f"rns_viz page benchmark (TREP, software-rendered chromium). load at start: {load()}")
    header = f"  {'':<44} {'paced':>9} {'unpaced':>9}"
    if args.only in (None, "page"):
        runs = {p: scenario_one_page(p, args.minutes) for p in (True, False)}
        on, off = runs[True], runs[False]
        print(f"\n== one page, {args.minutes:g} min, Kick every {KICK_EVERY_S:g} s ({on['kicks']} kicks)  [{load()}]")
        print(header)
        row("Kick -> visible, first kicks (median)", med(on["kick_start"]), med(off["kick_start"]), "s", "target <= 1")
        row("Kick -> visible, last kicks (median)", med(on["kick_end"]), med(off["kick_end"]), "s", "target <= 1")
        for when in ("start", "end"):
            a, b = on[when], off[when]
            row(f"page rAF rate at the {when}", a["raf_hz"], b["raf_hz"], "Hz")
            row(f"page script delay at the {when}", a["script_s"], b["script_s"], "s")
            row(f"chromium RSS at the {when}", a["rss_mb"], b["rss_mb"], "MB")
            row(f"page JS heap at the {when}", a["heap_mb"], b["heap_mb"], "MB")
            row(f"page answer time at the {when} (paced only)", a["answer_s"], float("nan"), "s")
            row(f"page rate chosen at the {when} (paced only)", a["pace_hz"], float("nan"), "Hz")
        for kind in ("renderer", "gpu"):
            row(f"chromium {kind} CPU over the run", on["cpu"][kind], off["cpu"][kind], "%", "of one core")
    if args.only in (None, "crowd"):
        runs = {p: scenario_crowd(p, args.crowd_seconds) for p in (True, False)}
        on, off = runs[True], runs[False]
        print(f"\n== one page + 3 protocol clients, cyclic motion, {args.crowd_seconds:g} s  [{load()}]")
        print(header)
        row("server real-time factor", on["rtf"], off["rtf"], "", "target >= 0.99")
        row("scene frames sent by the render thread", on["scene_sent_hz"], off["scene_sent_hz"], "Hz")
        row("scene Hz at the fast clients (slowest)", min(on["fast_hz"]), min(off["fast_hz"]), "Hz", "target >= 30")
        row("page rate chosen by the server", on["page_pace_hz"], off["page_pace_hz"], "Hz")
        row("page rAF rate", on["page_raf_hz"], off["page_raf_hz"], "Hz")
    if args.only in (None, "hidden"):
        runs = {p: scenario_hidden(p, args.hidden_minutes) for p in (True, False)}
        on, off = runs[True], runs[False]
        print(f"\n== hidden tab for {args.hidden_minutes:g} min, then shown  [{load()}]")
        print(header)
        row("shown -> page answers a script", on["live_s"], off["live_s"], "s", "target <= 2")
        row("shown -> page shows the current time", on["current_s"], off["current_s"], "s", "target <= 2")
        row("then Kick -> visible", on["kick_s"], off["kick_s"], "s", "target <= 1")


if __name__ == "__main__":
    main()
