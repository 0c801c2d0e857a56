"""Scene preview: the FSMS drawn at its default configuration, no simulation.

Shows the model's reactionless path family (TREP) or reactionless reachable set (planar 3R),
moves the arm along the reactionless path through the default configuration (so the trail and
the highlighted path are visible), and swings the base deflection x_b sinusoidally at the
locked-arm natural frequency so the bending beam or the spring is visible. The drawn deflection
is multiplied by the exaggeration slider.

    python apps/scene_preview.py --model trep
    python apps/scene_preview.py --model planar3r --port 8081
"""

from __future__ import annotations

import time

import numpy as np
import tyro
import viser

from rns_viz.model import FsmsModel
from rns_viz.paths import path_family, reactionless_reachable_set, trace_paths
from rns_viz.viz import FsmsScene

AMPLITUDE = {"trep": 0.004, "planar3r": 0.15}  # m, swing of x_b before exaggeration
EXAGGERATION = {"trep": 10.0, "planar3r": 1.0}


def main(model: str = "trep", port: int = 8080, host: str = "127.0.0.1") -> None:
    """Serve the scene preview for ``model`` ("trep" or "planar3r") at http://host:port."""
    fsms = FsmsModel.from_name(model)
    server = viser.ViserServer(host=host, port=port)
    scene = FsmsScene(server, fsms, trail_frame="base")  # the fake base swing would zig-zag a world trail
    theta0 = fsms.spec.default_configuration
    rns_dim = fsms.n - len(fsms.selected)
    if rns_dim == 1:
        through_default = trace_paths(fsms, theta0[None])[0]
        family = [*path_family(fsms, 24), through_default]
        scene.set_path_family(family, len(family) - 1)
        arm_path = through_default.theta
    else:
        scene.set_reachable_set(reactionless_reachable_set(fsms, theta0).ee)
        arm_path = theta0[None]
    scene.set_target(fsms.ee_position(theta0))

    exaggeration = server.gui.add_slider(
        "Deflection ×", min=1.0, max=50.0, step=1.0, initial_value=EXAGGERATION.get(model, 1.0)
    )
    f_max = scene.style.force_arrow_max / scene.style.force_scale  # N at the longest arrow
    force = server.gui.add_slider(
        "Reaction force (N)", min=-f_max, max=f_max, step=f_max / 100, initial_value=f_max / 4
    )
    H_b = fsms.mass_matrix(fsms.q(theta0))[0, 0]
    omega = float(np.sqrt(fsms.K_b[0, 0] / H_b))  # locked-arm natural frequency, rad/s
    amplitude = AMPLITUDE.get(model, 0.01)
    start = time.monotonic()
    while True:
        t = time.monotonic() - start
        k = int(t * 20.0) % len(arm_path)  # 20 path points per second
        x_b = amplitude * np.sin(omega * t)
        scene.update(fsms.q(arm_path[k], np.array([x_b])), exaggeration.value)
        scene.set_reaction_force(force.value)
        time.sleep(1.0 / 60.0)


if __name__ == "__main__":
    tyro.cli(main)
