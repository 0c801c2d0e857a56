"""Benchmark: how many students one machine serves, and what each one costs.

Run on demand (the machine should be quiet: the load average is printed with every figure):

    python benchmarks/bench_visitors.py                      # both parts below
    python benchmarks/bench_visitors.py --only visitors --window 20 --max 10
    python benchmarks/bench_visitors.py --only student --profile

1. ``visitors``: ``rns-viz serve --each-visitor`` (TREP, shadow run on) in a child process; protocol-level
   websocket clients (tests/support/protocol_client.py) join one at a time and receive every update; every
   simulation is kicked every 5 s. After each join, over ``--window`` s: the real-time factor of every
   simulation (simulated s / wall s), the server's CPU (% of one core, all its threads) and resident memory.
   The ramp stops at the first count where a simulation falls below RTF 0.99 in two windows running; the
   answer is the count before.
   ``--profile`` samples the server with py-spy at the largest count that kept real time (where the time goes).
   ``--step python`` runs the servers with the pure-Python step even when the optional native step
   (``pip install ./native``) is installed; ``--step native`` requires it. The step used is printed.
2. ``student``: one ``rns-viz serve`` as jupyter-server-proxy starts it for a student (one simulation), its
   CPU and memory with nobody watching (idle) and with one page watching and kicking (active); and, if
   jupyter-server-proxy is installed, a Jupyter server's own memory with the extension loaded. These are
   the per-student figures docs/deploy/classroom.md sizes a JupyterHub with.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))  # tests/ holds the websocket client

from benchmarks.bench_app import load  # noqa: E402 (the load average, as the other benchmarks print it)

KICK_EVERY_S = 5.0  # wall s between kicks of each simulation
SCENE_HZ, PLOTS_HZ = 30.0, 10.0  # the app's targets for what a page is sent (benchmarks/bench_app.py)
SETTLE_S = 3.0  # wall s after a join before measuring (the new page's scene and GUI are sent)
SAMPLES_PER_S = 100  # py-spy's sampling rate


def rss_mb(pid: int | str = "self") -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024.0
    return float("nan")


# ---------------------------------------------------------------- server side (child processes)
def choose_step(step: str) -> bool:
    """Before rns_viz is imported: keep the native step out ("python"), or require it ("native"); whether the
    native step runs."""
    if step == "python":
        sys.modules["rns_viz_native"] = None  # type: ignore[assignment]  # an import of it now fails as not installed
    from rns_viz.sim import native

    if step == "native" and not native.available():
        raise SystemExit(f"--step native: {native.unavailable_reason()}")
    return native.available()


def serve_visitors(step: str) -> None:
    """The per-visitor server; answers 'stats' with every simulation's clock, CPU and memory."""
    native = choose_step(step)
    from rns_viz.viz.server.classroom import start_classroom

    out, sys.stdout = sys.stdout, sys.stderr
    room = start_classroom("trep", port=0, max_visitors=1000, verbose=False)
    threading.Thread(target=kick_forever, args=(lambda: list(room.apps().values()),), daemon=True).start()
    print(json.dumps({"port": room.port, "pid": os.getpid(), "native": native}), file=out, flush=True)
    for line in sys.stdin:
        if line.strip() == "quit":
            break
        apps = room.apps()
        sims = {
            str(cid): [app.session.snapshot().t, app.session.pacer.dropped, app.scene_updates, app.plot_updates]
            for cid, app in apps.items()
        }
        stats = {"wall": time.perf_counter(), "cpu": time.process_time(), "rss_mb": rss_mb(), "sims": sims}
        print(json.dumps(stats), file=out, flush=True)
    room.stop()


def serve_student(step: str) -> None:
    """One student's app, as the proxy starts it (paused while no page is open); answers 'stats' like
    :func:`serve_visitors`."""
    native = choose_step(step)
    from rns_viz.viz.server.app import start_app

    out, sys.stdout = sys.stdout, sys.stderr
    app = start_app("trep", port=0, verbose=False, pause_unwatched=True)
    watched = threading.Event()
    threading.Thread(target=kick_forever, args=(lambda: [app] if watched.is_set() else [],), daemon=True).start()
    print(json.dumps({"port": app.port, "pid": os.getpid(), "native": native}), file=out, flush=True)
    for line in sys.stdin:
        if line.strip() == "quit":
            break
        if line.strip() == "kick":
            watched.set()
        sims = {"0": [app.session.snapshot().t, app.session.pacer.dropped, app.scene_updates, app.plot_updates]}
        stats = {"wall": time.perf_counter(), "cpu": time.process_time(), "rss_mb": rss_mb(), "sims": sims}
        print(json.dumps(stats), file=out, flush=True)
    app.stop()


def kick_forever(apps: Any) -> None:
    """Kick every simulation every KICK_EVERY_S, staggered (the GUI's kick, with its default size)."""
    from rns_viz.defaults import defaults_for

    peak = defaults_for("trep").kick_peak_N
    while True:
        current = apps()
        gap = KICK_EVERY_S / max(1, len(current))
        for app in current:
            app.session.kick(peak)
            time.sleep(gap)
        if not current:
            time.sleep(0.5)


# ---------------------------------------------------------------- client side
class Child:
    step = "installed"  # --step, for every child

    def __init__(self, role: str) -> None:
        command = [sys.executable, __file__, "--serve", role, "--step", Child.step]
        self.proc = subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, cwd=ROOT)
        assert self.proc.stdout is not None
        info = json.loads(self.proc.stdout.readline())
        self.port, self.pid = int(info["port"]), int(info["pid"])
        print(f"  (the server runs the {'native' if info['native'] else 'pure-Python'} step)", flush=True)

    def ask(self, line: str = "stats") -> dict[str, Any]:
        assert self.proc.stdin is not None and self.proc.stdout is not None
        self.proc.stdin.write(line + "\n")
        self.proc.stdin.flush()
        return json.loads(self.proc.stdout.readline())

    def close(self) -> None:
        with_stdin = self.proc.stdin
        if with_stdin is not None:
            with_stdin.write("quit\n")
            with_stdin.close()
        self.proc.wait(timeout=30)


def window(child: Child, seconds: float) -> dict[str, Any]:
    """Every simulation's RTF, the CPU (% of one core) and memory over ``seconds``."""
    a = child.ask()
    time.sleep(seconds)
    b = child.ask()
    wall = b["wall"] - a["wall"]
    both = [k for k in b["sims"] if k in a["sims"]]
    rtfs = [(b["sims"][k][0] - a["sims"][k][0]) / wall for k in both]
    dropped = sum(b["sims"][k][1] - a["sims"][k][1] for k in both)
    scenes = [(b["sims"][k][2] - a["sims"][k][2]) / wall for k in both]  # Hz: frames sent to each visitor
    plots = [(b["sims"][k][3] - a["sims"][k][3]) / wall for k in both]
    cpu = 100.0 * (b["cpu"] - a["cpu"]) / wall
    return {"rtfs": rtfs, "cpu": cpu, "rss_mb": b["rss_mb"], "dropped": dropped, "scenes": scenes, "plots": plots}


def profile(pid: int, seconds: float) -> None:
    """Where the server's Python time goes: py-spy's samples of the thread holding the interpreter lock, by
    thread and by function (own time) over ``seconds``."""
    if shutil.which("py-spy") is None:
        print("  (py-spy not installed: no profile)")
        return
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "profile.txt"
        cmd = ["py-spy", "record", "--pid", str(pid), "--duration", str(int(seconds)), "--format", "raw"]
        # samples of the thread holding the interpreter lock: where the Python time goes
        cmd += ["--threads", "--gil", "--rate", str(SAMPLES_PER_S)]
        result = subprocess.run([*cmd, "--output", str(out), "--nonblocking"], capture_output=True, text=True)
        if result.returncode != 0 or not out.exists():
            print(f"  py-spy failed: {result.stderr.strip()[-300:]}")
            return
        own: dict[str, int] = {}
        by_thread: dict[str, int] = {}
        total = 0
        for line in out.read_text().splitlines():
            stack, _, count = line.rpartition(" ")
            frames = stack.split(";")
            n = int(count)
            total += n
            by_thread[frames[0]] = by_thread.get(frames[0], 0) + n
            leaf = frames[-1].split(" (")[0] + " (" + frames[-1].rsplit("/", 1)[-1]
            own[leaf] = own.get(leaf, 0) + n
    busy = total / (SAMPLES_PER_S * int(seconds))  # a sample is taken only while a thread holds the lock
    print(f"  py-spy, {total} samples: the interpreter lock held {100 * busy:.0f} % of the time; by thread")
    for name, n in sorted(by_thread.items(), key=lambda kv: -kv[1])[:6]:
        print(f"    {100 * n / total:5.1f} %  {name[:90]}")
    print("  own time, top 12")
    for name, n in sorted(own.items(), key=lambda kv: -kv[1])[:12]:
        print(f"    {100 * n / total:5.1f} %  {name[:110]}")


def bench_visitors(max_count: int, seconds: float, want_profile: bool) -> None:
    from tests.support.protocol_client import ProtocolClient

    print(f"# per-visitor capacity: TREP, shadow on, kicked every {KICK_EVERY_S:g} s, {seconds:g} s windows")
    print(
        f"{'n':>3} {'min RTF':>8} {'median':>7} {'scene Hz':>8} {'plots Hz':>8} {'CPU %':>7} {'CPU %/n':>8} "
        f"{'RSS MB':>7} {'MB/n':>6} dropped  load"
    )
    child = Child("visitors")
    clients: list[Any] = []
    base = window(child, 2.0)  # nobody yet: the server alone
    print(f"{0:>3} {'':>8} {'':>7} {'':>8} {'':>8} {base['cpu']:7.1f} {'':>8} {base['rss_mb']:7.0f}  {load()}")
    best = best_rtf = 0
    try:
        for n in range(1, max_count + 1):
            clients.append(ProtocolClient(child.port, timeout=60.0))
            deadline = time.monotonic() + 60.0
            while len(child.ask()["sims"]) < n and time.monotonic() < deadline:
                time.sleep(0.2)
            time.sleep(SETTLE_S)
            w = window(child, seconds)
            if min(w["rtfs"]) < 0.99:  # once more: on a shared machine a burst of other work is no verdict
                print(f"    (min RTF {min(w['rtfs']):.3f} at load {load()}: measured again)", flush=True)
                w = window(child, seconds)
            low, mid = min(w["rtfs"]), statistics.median(w["rtfs"])
            scene, plots = min(w["scenes"]), min(w["plots"])  # the slowest visitor's
            per_mb = (w["rss_mb"] - base["rss_mb"]) / n
            print(
                f"{n:>3} {low:8.3f} {mid:7.3f} {scene:8.1f} {plots:8.1f} {w['cpu']:7.1f} {w['cpu'] / n:8.1f} "
                f"{w['rss_mb']:7.0f} {per_mb:6.0f} {w['dropped']:>7}  {load()}",
                flush=True,
            )
            if low < 0.99:
                break
            best_rtf = n
            if scene >= SCENE_HZ and plots >= PLOTS_HZ and best == n - 1:
                best = n
        print(f"=> {best_rtf} concurrent visitors kept RTF >= 0.99 (target >= 6); {best} of them also got every")
        print(f"   visitor the scene at >= {SCENE_HZ:g} Hz and the plots at >= {PLOTS_HZ:g} Hz (the app's own targets)")
        if want_profile and best:
            while len(clients) > best:
                clients.pop().close()
            time.sleep(SETTLE_S)
            profile(child.pid, min(seconds, 15.0))
    finally:
        for c in clients:
            c.close()
        child.close()


def bench_student(seconds: float, want_profile: bool) -> None:
    from tests.support.protocol_client import ProtocolClient

    print("# one student's app (as jupyter-server-proxy starts it): TREP, shadow on")
    t0 = time.perf_counter()
    child = Child("student")
    print(f"  start-up (process start to serving): {time.perf_counter() - t0:.1f} s   load {load()}")
    try:
        time.sleep(SETTLE_S)
        idle = window(child, seconds)
        print(f"  idle (no page):  CPU {idle['cpu']:5.1f} % of a core, RSS {idle['rss_mb']:.0f} MB   load {load()}")
        page = ProtocolClient(child.port, timeout=60.0)
        child.ask("kick")
        time.sleep(SETTLE_S)
        active = window(child, seconds)
        rtf = min(active["rtfs"])
        print(
            f"  active (a page, a kick every {KICK_EVERY_S:g} s): CPU {active['cpu']:5.1f} %, "
            f"RSS {active['rss_mb']:.0f} MB, RTF {rtf:.3f}   load {load()}"
        )
        if want_profile:
            profile(child.pid, min(seconds, 15.0))
        page.close()
    finally:
        child.close()
    jupyter_memory()


def jupyter_memory() -> None:
    """A Jupyter server's own resident memory with jupyter-server-proxy loaded (what a student's server costs
    besides the app)."""
    try:
        import jupyter_server_proxy  # noqa: F401
    except ImportError:
        print("  (jupyter-server-proxy not installed: no Jupyter figure)")
        return
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    with tempfile.TemporaryDirectory() as tmp:
        env = {**os.environ, "JUPYTER_CONFIG_DIR": tmp, "JUPYTER_DATA_DIR": tmp, "JUPYTER_RUNTIME_DIR": tmp}
        cmd = [sys.executable, "-m", "jupyter_server", "--no-browser", "--ip=127.0.0.1", f"--port={port}"]
        cmd += ["--IdentityProvider.token=bench", f"--ServerApp.root_dir={tmp}"]
        if os.geteuid() == 0:
            cmd.append("--allow-root")
        proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            time.sleep(8.0)
            print(f"  a Jupyter server (jupyter-server-proxy loaded, no kernel): RSS {rss_mb(proc.pid):.0f} MB")
        finally:
            proc.terminate()
            proc.wait(timeout=20)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--serve", choices=("visitors", "student"), help=argparse.SUPPRESS)
    parser.add_argument("--only", choices=("visitors", "student"))
    parser.add_argument("--window", type=float, default=15.0, help="s measured per step (default 15)")
    parser.add_argument("--max", type=int, default=12, help="most visitors tried (default 12)")
    parser.add_argument("--profile", action="store_true", help="sample the server with py-spy")
    parser.add_argument(
        "--step",
        choices=("installed", "python", "native"),
        default="installed",
        help="the simulation step: the native one if installed (default), pure Python, or native (required)",
    )
    args = parser.parse_args()
    Child.step = args.step
    if args.serve == "visitors":
        serve_visitors(args.step)
        return
    if args.serve == "student":
        serve_student(args.step)
        return
    print(f"# {os.cpu_count()} cores; load average at start {load()}")
    if args.only in (None, "visitors"):
        bench_visitors(args.max, args.window, args.profile)
    if args.only in (None, "student"):
        bench_student(args.window, args.profile)


if __name__ == "__main__":
    main()
