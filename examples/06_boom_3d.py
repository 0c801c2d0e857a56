"""The 3-D boom in a thin viser app: boom7's kick, suppressed in all six tip coordinates, played back.

boom7 is a 7-DOF arm on the tip of a 4 m aluminium boom with six elastic coordinates (x, y, z and three
rotations). The ``boom7-kick-on`` preset kicks the tip in all six directions and suppresses the
vibration with law (15); this script simulates it headless, then draws the run in a browser with the
library's scene (:class:`rns_viz.viz.FsmsScene`), the deflection exaggerated, in a loop. It is the
smallest app built on rns_viz; ``rns-viz serve --model boom7`` is the full one.

    python examples/06_boom_3d.py [--port 8080] [--seconds S]   # then open http://127.0.0.1:8080
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import viser

from rns_viz.model import FsmsModel
from rns_viz.scenarios import run_scenario
from rns_viz.viz import FsmsScene

EXAGGERATION = 50.0  # the tip moves by millimetres on a 4 m boom
FRAME_S = 1.0 / 60.0  # one drawn frame, s


def main(port: int = 8080, seconds: float | None = None) -> int:
    """Serve the playback on ``port`` for ``seconds`` (None: until Ctrl+C); returns the frames drawn."""
    model = FsmsModel.from_name("boom7")
    log = run_scenario("boom7-kick-on", duration=3.0).log
    t = log.column("t")
    xb = np.stack([log.column(f"xb_{i + 1}") for i in range(model.m)], axis=1)
    theta = np.stack([log.column(f"theta_{j + 1}") for j in range(model.n)], axis=1)
    print(f"boom7-kick-on: peak tip deflection {np.abs(xb[:, :3]).max() * 1e3:.2f} mm over {t[-1]:.1f} s")

    server = viser.ViserServer(host="127.0.0.1", port=port)
    scene = FsmsScene(server, model)
    scene.set_initial_camera()
    start, frames = time.monotonic(), 0
    try:
        while seconds is None or time.monotonic() - start < seconds:
            k = int(((time.monotonic() - start) % t[-1]) / (t[1] - t[0]))  # the logged step shown now
            scene.update(model.q(theta[k], xb[k]), EXAGGERATION)
            frames += 1
            time.sleep(FRAME_S)
    except KeyboardInterrupt:
        pass
    finally:
        server.stop()
    return frames


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--port", type=int, default=8080)
    parser.add_argument("--seconds", type=float, default=None, help="stop after this long (default: Ctrl+C)")
    args = parser.parse_args()
    main(args.port, args.seconds)
