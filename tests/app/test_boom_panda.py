"""boom-panda in the app: without the extra the app keeps its model and tells the operator; with it, the
Panda's meshes are drawn in the scene (its model and physics: tests/unit/test_boom_panda.py)."""

from __future__ import annotations

import numpy as np
import pytest
import viser

from rns_viz import robots
from rns_viz.model import FsmsModel
from rns_viz.viz.panels.model_menu import label_of
from rns_viz.viz.scene.robot import RobotMeshes
from rns_viz.viz.server.app import start_app
from tests.support.browser import wait_for_clients, wait_until
from tests.support.protocol_client import ProtocolClient, gui_uuid

PANDA = "example-robot-data/panda"


installed = pytest.mark.skipif(
    not robots.is_installed(PANDA), reason="example-robot-data is not installed (pip install 'rns-viz[panda]')"
)


def test_choosing_it_without_the_extra_keeps_the_app_and_tells_the_operator(panda_not_installed: None) -> None:
    app = start_app("trep", port=0, realtime=False, verbose=False)
    operator = ProtocolClient(app.port)
    try:
        wait_for_clients(app, 1, "the operator")
        app.session.advance(0.2)
        operator.set_value(gui_uuid(app.gui.model), label_of("boom-panda"))
        refusal = lambda: any("rns-viz[panda]" in body for _, body in operator.notifications)  # noqa: E731
        wait_until(refusal, 10.0, "the operator's page to be told the install command")
        app.session.advance(0.05)  # refused before anything was queued: the session runs on as it was
        assert app.session.snapshot().settings.model == "trep" and app.render_thread.is_alive()
        wait_until(lambda: app.gui.model.value == label_of("trep"), 10.0, "the dropdown to show TREP again")
    finally:
        operator.close()
        app.stop()


# ------------------------------------------------------------------ with example-robot-data installed
@installed
def test_the_panda_is_drawn_with_its_meshes(boom_panda: FsmsModel) -> None:
    """Every visual .dae of the package's Panda is in the scene, under the joint node that moves it."""
    server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    try:
        robot = RobotMeshes(server, boom_panda)
        names = [mesh.name for mesh in robot.meshes]
        for part in ("link0", "link1", "link4", "link7", "hand", "finger"):
            assert any(f"{part}.dae" in name for name in names), part
        assert any(name.startswith("/base/") and "panda_link7" in name for name in names)
        robot.pose(boom_panda.q(boom_panda.spec.default_configuration))
        ee = robot.ee_position()
        np.testing.assert_allclose(
            ee - robot.base_placement().translation, boom_panda.ee_position(boom_panda.spec.default_configuration)
        )
    finally:
        server.stop()
