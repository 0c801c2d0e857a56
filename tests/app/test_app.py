"""The live app, headless: a real viser server on 127.0.0.1, driven like a browser would drive it.

Inputs go through the app's own GUI handles and scene handle, either set on the server or sent by
a protocol-level websocket client (tests/support/protocol_client.py), so viser's real callback path runs. The
session is made with ``realtime=False`` and advanced faster than real time with ``advance()``;
one test runs the real-time loop, and one (marked ``perf``, not in the default run) checks its timing.
"""

from __future__ import annotations

import inspect
import math
import time

import numpy as np
import pytest

from rns_viz.csvio import read_csv
from rns_viz.live.loop.session import Session
from rns_viz.viz.scene.fsms_scene import FsmsScene
from rns_viz.viz.server.app import TARGET_HANDLE, RnsApp, serve, start_app
from tests.support.app_helpers import queued, uuid
from tests.support.browser import wait_for_clients, wait_until
from tests.support.protocol_client import ProtocolClient
from tests.unit.test_scenarios import PAPER_PRESETS


def peak_xb(session: Session, seconds: float) -> float:
    return float(np.abs(session.state.runs.sim.log.column("xb_1", last=round(seconds / session.dt))).max())


def envelope(session: Session, key: str, seconds: float) -> float:
    arrays = session.plot_arrays()
    t = arrays["t"]
    return float(np.abs(arrays[key][t >= t[-1] - seconds]).max())


def test_binds_localhost_by_default_and_reports_its_port(trep_app: RnsApp) -> None:
    assert inspect.signature(serve).parameters["host"].default == "127.0.0.1"
    assert inspect.signature(serve).parameters["port"].default == 8080
    assert trep_app.port > 0
    ws = ProtocolClient(trep_app.port, decode=True)
    wait_for_clients(trep_app, 1, "a client")
    ws.close()


@pytest.mark.parametrize("name", ["trep", "planar3r"])
def test_every_control_and_scene_node_exists(name: str) -> None:
    app = start_app(name, port=0, realtime=False, verbose=False)
    try:
        g = app.gui
        labels = {
            g.kick.label,
            g.kick_peak.label,
            g.suppression.label,
            g.pause.label,
            g.step.label,
            g.reset.label,
            g.speed.label,
            g.law.label,
            g.model.label,
            g.exaggeration.label,
            g.shadow.label,
            g.download.label,
            g.sigma.label,
            g.ubar_speed.label,
            g.target_speed.label,
        }
        assert {"Kick the base", "Vibration suppression", "Reset", "Speed", "Law", "Model"} <= labels
        assert set(g.gains) == {"g_b", "g_m", "G_p", "G_d", "k_p", "k_d"}
        assert all("(" in s.label for s in g.gains.values())  # units in every gain label
        assert g.speed.options == ("1/8×", "1/4×", "1/2×", "1×", "2×")
        assert set(g.presets["trep"].options) | set(g.presets["planar3r"].options) == PAPER_PRESETS
        assert g.path_folder.visible == (name == "trep") and g.target_folder.visible == (name == "planar3r")
        for node in (FsmsScene.BASE, FsmsScene.FORCE, FsmsScene.TARGET, TARGET_HANDLE):
            assert app.server.scene.get_handle_by_name(node) is not None, node
        assert tuple(app.handle.active_axes) == (True, True, False) and app.handle.disable_rotations
        assert app.session.wait_background()
        wait_until(lambda: app.scene.paths.visible or app.scene.reachable.visible, 10.0, "the path family or reach set")
    finally:
        app.stop()


@pytest.mark.parametrize("client", ["trep_app"], indirect=True)
def test_kick_button_deflects_the_base(trep_app: RnsApp, client: ProtocolClient) -> None:
    s = trep_app.session
    s.advance(0.2)
    assert abs(s.snapshot().q[0]) < 1e-9
    client.click(uuid(trep_app.gui.kick))
    queued(trep_app, "Kick")
    s.advance(0.15)
    assert abs(s.snapshot().q[0]) > 1e-3  # 0.8 N for 0.1 s: millimetres
    wait_until(lambda: trep_app.scene_updates > 0, 5.0, "a scene update")


@pytest.mark.parametrize("name", ["trep", "planar3r"])
def test_suppression_decays_faster_than_the_shadow_run(name: str) -> None:
    app = start_app(name, port=0, realtime=False, verbose=False)
    try:
        s = app.session
        assert app.gui.suppression.value and s.snapshot().settings.shadow
        app.gui.kick.value = True  # a click from the server side runs the same callback
        queued(app, "Kick")
        s.advance(4.0)
        on, off = envelope(s, "xb", 1.0), envelope(s, "xb_shadow", 1.0)
        first = float(np.abs(s.plot_arrays()["xb_shadow"]).max())
        assert off > 0.5 * first  # the shadow (suppression off) still rings
        assert on < 0.3 * off, (on, off)
        app.gui.suppression.value = False  # the roles swap: the operated run now rings
        queued(app, "SetSuppression")
        s.advance(0.01)
        assert not s.snapshot().settings.suppress
    finally:
        app.stop()


@pytest.mark.parametrize("client", ["planar_app"], indirect=True)
def test_target_drag_moves_the_3r_end_effector_without_reaction(planar_app: RnsApp, client: ProtocolClient) -> None:
    s, model = planar_app.session, planar_app.model
    start = model.ee_position(model.spec.default_configuration)
    goal = start + np.array([-0.4, -0.3, 0.0])
    for k, phase in enumerate(("start", "update", "update", "end")):
        point = start + (k + 1) / 4 * (goal - start)
        client.drag(TARGET_HANDLE, (point[0], point[1], point[2]), phase)
    wait_until(lambda: s.pending_commands().count("DragTarget") >= 5, 10.0, "the drag's target commands")
    s.advance(4.0)
    snap = s.snapshot()
    ee = model.ee_position(snap.q[model.m :])
    assert np.linalg.norm(ee[:2] - goal[:2]) < 5e-3, ee
    assert peak_xb(s, 4.0) <= 1e-4
    assert np.allclose(snap.target[:2], goal[:2])


@pytest.mark.parametrize("client", ["planar_app"], indirect=True)
def test_unreachable_3r_target_is_clamped_and_reported(planar_app: RnsApp, client: ProtocolClient) -> None:
    s = planar_app.session
    client.drag(TARGET_HANDLE, (4.0, 0.0, 0.0), "start")
    client.drag(TARGET_HANDLE, (4.0, 0.0, 0.0), "end")
    wait_until(lambda: s.pending_commands().count("DragTarget") >= 3, 10.0, "the target commands")
    s.advance(0.05)
    target = s.snapshot().target
    assert target is not None and target[0] < 2.5  # the 3R reaches 3 m, but not without reaction
    wait_until(lambda: client.types["NotificationShowMessage"] >= 1, 10.0, "the 'Target clamped' notification")
    s.advance(3.0)
    assert peak_xb(s, 3.0) <= 1e-4


@pytest.mark.parametrize("client", ["trep_app"], indirect=True)
def test_scrubbing_trep_along_its_path_keeps_the_base_still(trep_app: RnsApp, client: ProtocolClient) -> None:
    s = trep_app.session
    theta0 = s.snapshot().q[1:].copy()
    client.set_value(uuid(trep_app.gui.sigma.slider), 40.0)
    queued(trep_app, "Scrub")
    s.advance(4.0)
    snap = s.snapshot()
    assert np.linalg.norm(snap.q[1:] - theta0) > 0.5  # the arm moved a long way
    assert abs(snap.sigma - 40.0) < 0.5
    assert peak_xb(s, 4.0) <= 1e-4
    # A drag: the end effector goes to the point of the current path nearest the target.
    table = s.state.operator.table
    far = table.ee[len(table.ee) // 3] + np.array([0.01, 0.0, 0.0])
    client.drag(TARGET_HANDLE, tuple(far), "start")
    client.drag(TARGET_HANDLE, tuple(far), "end")
    wait_until(lambda: s.pending_commands().count("DragTarget") >= 3, 10.0, "the target commands")
    s.advance(5.0)
    ee = trep_app.model.ee_position(s.snapshot().q[1:])
    assert np.linalg.norm(ee[:2] - s.snapshot().target[:2]) < 2e-3
    assert np.min(np.linalg.norm(table.ee[:, :2] - ee[:2], axis=1)) < 2e-3  # on the path
    assert peak_xb(s, 5.0) <= 1e-4


def test_point_to_point_comparison_shakes_the_base_and_the_path_does_not(trep_app: RnsApp) -> None:
    s = trep_app.session
    trep_app.gui.play_fast.value = True
    queued(trep_app, "Play")
    s.advance(3.0)
    reactionless = peak_xb(s, 3.0)
    trep_app.gui.point_to_point.value = True
    queued(trep_app, "PointToPoint")
    s.advance(3.0)
    joint_space = peak_xb(s, 3.0)
    assert reactionless < 1e-4 < joint_space and joint_space > 20 * reactionless


def test_model_switch_resets_cleanly(trep_app: RnsApp) -> None:
    s = trep_app.session
    trep_app.gui.kick.value = True
    queued(trep_app, "Kick")
    s.advance(1.0)
    trep_app.gui.model.value = "planar 3R on a spring"
    queued(trep_app, "SwitchModel")
    s.advance(0.1)
    snap = s.snapshot()
    assert snap.settings.model == "planar3r" and snap.settings.preset is None
    assert snap.t == pytest.approx(0.1) and abs(snap.q[0]) < 1e-9
    assert np.allclose(snap.q[1:], s.state.model.spec.default_configuration)
    wait_until(lambda: trep_app.gui.target_folder.visible, 10.0, "the panel and scene to switch model")
    scene = trep_app.server.scene
    wait_until(lambda: scene.get_handle_by_name("/spring/coil") is not None, 10.0, "the spring")
    assert scene.get_handle_by_name("/beam/plates") is None
    assert trep_app.gui.target_folder.visible and not trep_app.gui.path_folder.visible
    assert len(s.plot_arrays()["t"]) == 5  # the plots restarted with the new run (50 Hz samples)
    trep_app.gui.model.value = "TREP (2R on a flexible beam)"
    queued(trep_app, "SwitchModel")
    s.advance(0.1)
    assert s.snapshot().settings.model == "trep" and s.snapshot().q.shape == (3,)


def test_pause_single_step_resume_and_speed(trep_app: RnsApp) -> None:
    s = trep_app.session
    s.advance(0.1)
    trep_app.gui.pause.value = True
    queued(trep_app, "Pause")
    s.advance(0.5)
    t = s.snapshot().t
    assert s.snapshot().paused and t == pytest.approx(0.1)
    trep_app.gui.step.value = True
    queued(trep_app, "SingleStep")
    s.advance(0.0)
    assert s.snapshot().t == pytest.approx(t + 0.001)
    s.resume()
    s.advance(0.2)
    assert s.snapshot().t == pytest.approx(t + 0.201)
    trep_app.gui.speed.value = "1/2×"
    queued(trep_app, "SetSpeed")
    s.advance(0.0)
    assert s.snapshot().settings.speed == 0.5


def test_presets_load_their_law_gains_and_kicks() -> None:
    app = start_app("trep", port=0, realtime=False, verbose=False)
    try:
        s = app.session
        app.gui.presets["trep"].value = "fig10-on"
        queued(app, "LoadPreset")
        s.advance(0.0)
        assert s.wait_background()
        snap = s.snapshot()
        assert snap.settings.preset == "fig10-on" and snap.settings.law == "velocity"
        assert snap.settings.gains.g_b == 24.0 and snap.settings.gains.g_m == 20.0 and snap.settings.suppress
        wait_until(lambda: app.gui.gains["g_m"].value == 20.0, 5.0, "the g_m slider to show the preset")
        assert snap.paused and snap.t == 0.0  # "Start presets paused": it waits for Resume
        s.resume()
        s.advance(1.0)  # the preset's kick comes at 0.5 s
        assert peak_xb(s, 1.0) > 1e-3
        app.gui.preset_paused.value = False  # this one starts at once
        app.gui.presets["planar3r"].value = "fig3"  # a 3R preset switches the model
        queued(app, "LoadPreset")
        s.advance(0.0)
        assert s.wait_background()
        assert s.snapshot().settings.model == "planar3r" and s.snapshot().settings.preset == "fig3"
        s.advance(2.0)  # kicked at 1 s
        assert peak_xb(s, 1.0) > 1e-3
        s.set_target((1.8, -0.2))  # operating during a preset continues live from the current state
        s.advance(0.01)
        assert s.snapshot().settings.preset is None
    finally:
        app.stop()


@pytest.mark.parametrize("client", ["trep_app"], indirect=True)
def test_log_download_has_the_step_log_columns(trep_app: RnsApp, client: ProtocolClient) -> None:
    s = trep_app.session
    s.advance(0.5)
    table = read_csv(s.log_csv())
    log = s.state.runs.sim.log
    assert list(table.columns) == log.columns and list(table.units) == log.units
    assert len(table.rows) == 500 and all(math.isfinite(x) for x in table.rows[-1, :5])
    client.click(uuid(trep_app.gui.download))
    wait_until(lambda: client.types["FileTransferStartDownload"] >= 1, 10.0, "the CSV download to start")


def test_real_time_loop_runs_applies_inputs_and_publishes() -> None:
    """The real-time loop, what it does (its timing is test_real_time_pacing_and_latency's, perf)."""
    app = start_app("trep", port=0, realtime=True, verbose=False)
    try:
        s = app.session
        wait_until(lambda: s.snapshot().t > 0.2, 10.0, "simulated time to advance")
        for k in range(5):
            s.scrub(float(k))
        wait_until(lambda: len(s.latencies()) >= 5, 10.0, "the scrubs to reach a step")
        s.set_speed(0.5)
        wait_until(lambda: s.snapshot().settings.speed == 0.5, 10.0, "the speed change")
        wait_until(lambda: app.scene_updates > 0 and app.plot_updates > 0, 10.0, "scene and plot updates")
        assert not s.snapshot().paused and s.snapshot().diverged is None
    finally:
        app.stop()


@pytest.mark.perf
def test_real_time_pacing_and_latency() -> None:
    app = start_app("trep", port=0, realtime=True, verbose=False)
    try:
        s = app.session
        time.sleep(1.5)
        snap = s.snapshot()
        assert 1.0 < snap.t < 2.0 and snap.rtf == pytest.approx(1.0, abs=0.05)
        for k in range(20):
            s.scrub(float(k))
            time.sleep(0.02)
        assert np.median(s.latencies()) < 0.02
        s.set_speed(0.5)
        time.sleep(1.5)
        assert s.snapshot().rtf == pytest.approx(0.5, abs=0.05)
        assert app.scene_updates > 30 and app.plot_updates > 10
    finally:
        app.stop()
