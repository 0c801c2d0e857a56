"""Any model in the running app: the model dropdown lists the bundled models and the parameter files
given to the app (``rns-viz serve --model FILE.toml``); switching among them keeps the server and
every client served; a file that has gone bad is refused with a message naming the element at
fault, and the app keeps the model it runs. A headless server driven by protocol-level clients.
"""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from rns_viz.cli import main
from rns_viz.live.loop import wall_clock
from rns_viz.live.runs.laws import LAW_LABELS
from rns_viz.params import ASSETS_DIR
from rns_viz.viz.panels.base_panel import BasePanel
from rns_viz.viz.panels.model_menu import label_of
from rns_viz.viz.server.app import RnsApp, start_app
from tests.support.app_helpers import user_model
from tests.support.browser import wait_for_clients, wait_until
from tests.support.protocol_client import ProtocolClient, gui_uuid


@pytest.fixture
def app_with_file(tmp_path: Path) -> Iterator[tuple[RnsApp, Path, ProtocolClient, ProtocolClient, list]]:
    path = user_model(tmp_path)
    app = start_app("trep", port=0, realtime=False, verbose=False, models=(str(path),))
    told: list[tuple[int | None, str, str]] = []
    original = app.connections.notify_by_id

    def record(client_id, title, body, level):  # type: ignore[no-untyped-def]
        told.append((client_id, title, body))
        original(client_id, title, body, level)

    app.connections.notify_by_id = record  # type: ignore[method-assign]
    operator = ProtocolClient(app.port)
    wait_for_clients(app, 1, "the operator")
    watcher = ProtocolClient(app.port)
    wait_for_clients(app, 2, "a watcher")
    yield app, path, operator, watcher, told
    operator.close()
    watcher.close()
    app.stop()


def choose(app: RnsApp, client: ProtocolClient, label: str) -> None:
    """Pick ``label`` in the model dropdown from a client, and let the loop apply it."""
    client.set_value(gui_uuid(app.gui.model), label)
    wait_until(lambda: "SwitchModel" in app.session.pending_commands(), 10.0, "the model switch to be queued")
    app.session.advance(0.05)


def test_the_dropdown_switches_among_bundled_models_and_a_file_and_every_client_stays_served(app_with_file) -> None:  # type: ignore[no-untyped-def]
    app, path, operator, watcher, _ = app_with_file
    labels = app.gui.model.options
    assert label_of("boom7") in labels and "file: my_arm.toml" in labels
    for label, key, m in (
        (label_of("boom7"), "boom7", 6),
        ("file: my_arm.toml", str(path.resolve()), 1),
        (label_of("trep"), "trep", 1),
        (label_of("boom7"), "boom7", 6),
    ):
        choose(app, operator, label)
        snap = app.session.snapshot()
        assert snap.settings.model == key and snap.q.shape == (app.session.state.model.nv,)
        assert app.session.state.model.m == m
        wait_until(lambda key=key: app.model_name == key, 20.0, f"the scene of {key}")
        before = watcher.messages
        app.session.advance(0.2)
        wait_until(lambda before=before: watcher.messages > before, 10.0, "the watcher to get updates")
        assert app.render_thread.is_alive() and not watcher.closed.is_set() and not operator.closed.is_set()
        panel: BasePanel = app.base_panel
        wait_until(lambda m=m, p=panel: p.folder.visible == (m > 1), 10.0, "the base panel (6-DOF bases only)")
    theta = app.session.state.model.spec.default_configuration
    assert np.all(np.isfinite(app.session.snapshot().q)) and len(theta) == 7


def test_a_bad_model_file_is_refused_naming_the_element_and_the_app_keeps_its_model(app_with_file) -> None:  # type: ignore[no-untyped-def]
    app, path, operator, watcher, told = app_with_file
    app.session.kick(0.8)
    app.session.advance(0.5)
    q_before = app.session.snapshot().q.copy()
    path.write_text(path.read_text().replace("stiffness = [[100.0]]", "stiffness = [[100.0, 1.0]]"))
    choose(app, operator, "file: my_arm.toml")
    wait_until(lambda: any("stiffness" in body for _, _, body in told), 10.0, "the refusal to reach the operator")
    client, _, body = next(t for t in told if "stiffness" in t[2])
    assert "my_arm.toml" in body and "[base] stiffness" in body and "shape" in body
    assert client == app.lock.operator  # told to the client who asked
    snap = app.session.snapshot()
    assert snap.settings.model == "trep" and snap.t > 0.5 and np.allclose(snap.q[1:], q_before[1:], atol=0.1)
    wait_until(lambda: app.gui.model.value == label_of("trep"), 10.0, "the dropdown to show TREP again")
    before = watcher.messages
    app.session.advance(0.2)  # the simulation runs on and the watcher is served
    wait_until(lambda: watcher.messages > before, 10.0, "the watcher to get updates")
    assert app.render_thread.is_alive() and app.model_name == "trep"


def test_serve_refuses_a_bad_model_file_naming_the_element(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    path = user_model(tmp_path)
    path.write_text(path.read_text().replace('joints = ["base_x"]', 'joints = ["base_q"]'))
    assert main(["serve", "--model", str(path), "--port", "0"]) == 2
    err = capsys.readouterr().err
    assert "[base] joints" in err and "base_q" in err and "my_arm.urdf" in err


MY_APP = """
[app]
label = "My TREP copy"
short_label = "Mine"
law = "acceleration"
kick_peak_N = 1.5
kick_range_N = 8.0
kick_duration_s = 0.05
target_speed_m_per_s = 0.3
presets = ["fig10-on", "fig11-slow"]
lessons = ["trep-spring"]

[app.gains.acceleration]
g_b_per_s = 7.0
g_m_per_s = 3.0

[app.scene]
exaggeration = 25.0
base = { kind = "double-beam", spacing_m = 0.12 }
camera_position_m = [1.0, 2.0, 3.0]
"""


def test_a_model_file_with_its_own_app_table_is_offered_with_its_label_presets_lessons_and_defaults(
    tmp_path: Path,
) -> None:
    """A new model is a URDF and a parameter file: a copy of TREP's under another name, with an [app] table of
    its own, served with no Python written: its label in the dropdown, its presets in their own row, its
    lesson in the chooser, and the app starting with its law, gains, kick, speed and drawing."""
    shutil.copy(ASSETS_DIR / "trep.urdf", tmp_path / "my_trep.urdf")
    text = (ASSETS_DIR / "trep.toml").read_text()
    text = text[: text.index("\n[app]")].replace('"trep.urdf"', '"my_trep.urdf"').replace('name = "trep"', "")
    path = tmp_path / "my_trep.toml"
    path.write_text(text + MY_APP)
    app = start_app(str(path), port=0, realtime=False, verbose=False)
    try:
        key = str(path.resolve())
        g = app.gui
        assert g.model.value == "My TREP copy" and "My TREP copy" in g.model.options
        assert label_of("trep") in g.model.options  # the bundled models stay offered
        assert g.presets[key].label == "My TREP copy" and g.presets[key].options == ("fig10-on", "fig11-slow")
        assert g.presets[key].visible and g.presets["trep"].visible  # a heading of its own: both rows shown
        assert app.lessons.choices["Mine 1. The base is a spring"] == (key, 1)
        snap = app.session.snapshot()
        st = snap.settings
        assert (st.model, st.law, st.gains.g_b, st.gains.g_m, st.target_speed) == (key, "acceleration", 7.0, 3.0, 0.3)
        wait_until(lambda: app.model_name == key, 20.0, "the scene of the file's model")
        assert (g.kick_peak.value, g.kick_peak.max, g.exaggeration.value) == (1.5, 8.0, 25.0)
        assert not g.auto_exaggeration.value  # a number in the file: a fixed factor
        assert g.law.value == LAW_LABELS["acceleration"] and g.gains["g_b"].value == 7.0
        style = app.renderer.scene.style
        assert style.camera_position == (1.0, 2.0, 3.0) and style.base.spacing == 0.12  # type: ignore[union-attr]
        assert "0.05 s" in g.kick_peak.hint  # the pulse this model's kick sends
        app.session.kick(1.5)
        app.session.advance(0.2)
        assert np.max(np.abs(app.session.plot_arrays()["xb_1"])) > 0.0
    finally:
        app.stop()


def test_a_new_models_time_runs_from_when_its_scene_is_drawn(monkeypatch: pytest.MonkeyPatch) -> None:
    """Building a model's scene takes the interpreter for a second or more, which the loop would then drop as
    a stall (the status line said SKIPPED 3.60 s after every switch): once built, the clock starts again."""
    monkeypatch.setattr(wall_clock, "SKIPPED_HOLD_S", 600.0)  # a skip is forgotten by the restart, not by age
    app = start_app("trep", port=0, verbose=False)
    try:
        pacer = app.session.pacer
        wait_until(lambda: app.session.snapshot().t > 0.2, 20.0, "TREP running")
        pacer.drop_backlog(app.session.snapshot().t)  # as after a stall: a skip reported ...
        app.session.switch_model("planar3r")
        wait_until(lambda: app.renderer.model_name == "planar3r", 30.0, "the 3R's scene built")
        wait_until(lambda: app.session.snapshot().t > 0.1, 20.0, "the 3R running")
        assert pacer.skipped() == 0.0  # ... forgotten once the new scene was drawn
    finally:
        app.stop()
