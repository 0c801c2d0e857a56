"""boom-panda's presets in the app: serving boom-panda offers its presets and keeps the Panda when one is
chosen (the presets' physics headless: tests/unit/test_boom_panda_presets.py).

Skipped without example-robot-data (pip install 'rns-viz[panda]').
"""

from __future__ import annotations

import pytest

from rns_viz import robots
from rns_viz.viz.server.app import start_app
from tests.support.browser import wait_for_clients, wait_until
from tests.support.protocol_client import ProtocolClient, gui_uuid

pytestmark = pytest.mark.skipif(
    not robots.is_installed("example-robot-data/panda"),
    reason="example-robot-data is not installed (pip install 'rns-viz[panda]')",
)


def test_the_app_serving_boom_panda_shows_its_presets_and_keeps_the_panda() -> None:
    """The menu shows the Panda's presets instead of boom7's; clicking one loads it on boom-panda."""
    app = start_app("boom-panda", port=0, realtime=False, verbose=False)
    operator = ProtocolClient(app.port)
    try:
        wait_for_clients(app, 1, "the operator")
        app.session.advance(0.05)
        wait_until(lambda: app.gui.presets["boom-panda"].visible, 20.0, "the Panda's presets to be shown")
        assert not app.gui.presets["boom7"].visible
        operator.click(gui_uuid(app.gui.presets["boom-panda"]), "boom-panda-track")
        wait_until(lambda: "LoadPreset" in app.session.pending_commands(), 10.0, "the preset to be queued")
        app.session.advance(0.0)
        assert app.session.wait_background(120.0)
        snap = app.session.snapshot()
        assert snap.settings.model.startswith("boom-panda") and app.session.state.runs.sim.model.n == 7
        assert app.session.state.runs.sim.model.arm_joint_names[0] == "panda_joint1"
        assert app.gui.presets["boom-panda"].visible and not app.gui.presets["boom7"].visible
    finally:
        operator.close()
        app.stop()
