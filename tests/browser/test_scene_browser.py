"""The scene in a real headless Chromium: nodes mount, live updates arrive, the robot is on screen.

Screenshots go to ``artifacts/scene_<model>.png`` for a person to look at.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from rns_viz.live.reach.region import arm_reach
from rns_viz.model import FsmsModel
from rns_viz.paths import path_family, reactionless_reachable_set, trace_paths
from rns_viz.viz import FsmsScene
from tests.support.browser import (
    browser_page,
    dismiss_notifications,
    local_position,
    local_server,
    screenshot,
    settle_for_picture,
    wait_for_nodes,
    wait_until,
)

DEFLECTION = {"trep": 0.004, "planar3r": 0.1}  # m, x_b shown (times EXAGGERATION) in the screenshot
EXAGGERATION = {"trep": 10.0, "planar3r": 2.0}  # drawn deflection factor set for the screenshot
FORCE = {"trep": 0.3, "planar3r": 40.0}  # N


def _orange_pixels(png: bytes) -> int:
    """Pixels of the URDF's orange (link 2 of TREP, the 3R's link masses) in a screenshot."""
    image = pytest.importorskip("PIL.Image")
    import io

    rgb = np.asarray(image.open(io.BytesIO(png)).convert("RGB")).astype(int)
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    return int(np.count_nonzero((r > 170) & (g > 90) & (g < 190) & (b < 90) & (r - g > 40)))


@pytest.mark.parametrize("name", ["trep", "planar3r"])
def test_scene_renders_in_chromium(name: str, bundled_model: Callable[[str], FsmsModel]) -> None:
    model = bundled_model(name)
    theta0 = model.spec.default_configuration
    with local_server() as server:
        scene = FsmsScene(server, model)
        if name == "trep":
            current = trace_paths(model, theta0[None])[0]
            family = [*path_family(model, 24), current]
            scene.set_path_family(family, len(family) - 1)
            arm_motion = current.theta[:12]  # the arm moves a stretch along the highlighted path
            overlay = FsmsScene.PATHS
            base_drawing = "/beam/plates"
        else:
            scene.set_reachable_set(reactionless_reachable_set(model, theta0).ee)
            overlay = FsmsScene.REACHABLE
            base_drawing = "/spring/coil"
            arm_motion = theta0[None]
        scene.set_target(model.ee_position(theta0) + np.array([0.0, 0.1 * arm_reach(model), 0.0]))
        x_b, gain = DEFLECTION[name], EXAGGERATION[name]
        scene.update(model.q(theta0, [x_b]), gain)
        scene.set_reaction_force(FORCE[name])

        with browser_page(server, draw=True) as page:  # its pixels are read
            nodes = {FsmsScene.BASE, "/base/link1", overlay, base_drawing, FsmsScene.FORCE, FsmsScene.TRAIL}
            wait_for_nodes(page, nodes)
            rest = np.asarray(model.pin_model.jointPlacements[1].translation)
            shift = np.array([gain * x_b, 0.0, 0.0])

            def base_at(expected: np.ndarray) -> bool:
                position = local_position(page, FsmsScene.BASE)
                return position is not None and np.allclose(position, expected, atol=1e-6)

            wait_until(lambda: base_at(rest + shift), 10.0, "the drawn base at its exaggerated deflection")
            scene.update(model.q(theta0, [-x_b]), gain)  # a live update reaches the page
            wait_until(lambda: base_at(rest - shift), 10.0, "the base to follow a live update")
            scene.clear_trail()
            for theta in arm_motion:
                scene.update(model.q(theta, [x_b]), gain)
            dismiss_notifications(page)
            settle_for_picture(page, 20)
            path = screenshot(page, f"scene_{name}")
            assert _orange_pixels(path.read_bytes()) > 30, f"robot not visible in {path}"
