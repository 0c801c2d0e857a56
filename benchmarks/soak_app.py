"""Soak: the live app for N minutes with one client dragging the target and kicking the base.

Run on demand:  python benchmarks/soak_app.py [--seconds 600] [--model trep]

Prints, every --every seconds, the server's resident memory (RSS) and the real-time factor of
the simulation over that window; at the end the memory growth after warm-up (target <= 10 MB) and
the lowest windowed real-time factor (target >= 0.99). The client is a protocol-level websocket
client on 127.0.0.1 (tests/support/protocol_client.py), so the server does all its real work: callbacks,
scene and plot messages, the shadow run.
"""

from __future__ import annotations

import argparse
import gc
import math
import random
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from rns_viz.model import FsmsModel
from rns_viz.viz.server.app import TARGET_HANDLE, start_app
from tests.support.protocol_client import ProtocolClient, gui_uuid


def rss_mb() -> float:
    """Resident set size of this process, MB (Linux /proc)."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024.0
    return math.nan


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=600.0)
    parser.add_argument("--model", default="trep", choices=["trep", "planar3r"])
    parser.add_argument("--every", type=float, default=30.0, help="report period, s")
    parser.add_argument("--warmup", type=float, default=30.0, help="s before the memory baseline")
    args = parser.parse_args()

    app = start_app(args.model, port=0, verbose=False)
    rng = random.Random(1)
    client = ProtocolClient(app.port)
    kick = gui_uuid(app.gui.kick)
    model = FsmsModel.from_name(args.model)
    q0 = app.session.snapshot().q
    home = model.ee_position(q0[model.m :])  # drag around where the end effector starts
    reach = 0.15 if args.model == "trep" else 1.5
    start = time.monotonic()
    last_report, last_sim_t = start, app.session.snapshot().t
    baseline: float | None = None
    worst_rtf, rows = math.inf, []
    next_kick = start + 5.0
    try:
        while (now := time.monotonic()) - start < args.seconds:
            # Drag at 20 Hz around the starting target, like a hand on a mouse.
            phase = 2 * math.pi * (now - start) / 7.0
            x = home[0] + 0.5 * reach * math.sin(phase) + rng.uniform(-0.01, 0.01) * reach
            y = home[1] + 0.3 * reach * math.cos(1.3 * phase)
            client.drag(TARGET_HANDLE, (x, y, 0.0))
            if now >= next_kick:
                client.gui_update(kick, value=True)
                next_kick = now + 5.0
            if now - last_report >= args.every:
                snap = app.session.snapshot()
                rtf = (snap.t - last_sim_t) / (now - last_report)
                gc.collect()
                mem = rss_mb()
                if baseline is None and now - start >= args.warmup:
                    baseline = mem
                elif baseline is not None:
                    worst_rtf = min(worst_rtf, rtf)
                rows.append((now - start, mem, rtf, snap.paused, snap.diverged))
                print(
                    f"t={now - start:7.1f} s  RSS {mem:7.1f} MB  RTF {rtf:5.3f}  paused={snap.paused}  "
                    f"diverged={snap.diverged}",
                    flush=True,
                )
                last_report, last_sim_t = now, snap.t
            time.sleep(0.05)
    finally:
        client.close()
        app.stop()
    growth = rows[-1][1] - baseline if baseline is not None else math.nan
    print(
        f"\nsoak {args.seconds:.0f} s, model {args.model}: memory growth after warm-up {growth:+.1f} MB "
        f"(target <= 10), lowest windowed RTF {worst_rtf:.3f} (target >= 0.99)"
    )


if __name__ == "__main__":
    main()
