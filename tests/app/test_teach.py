"""The app's teaching views: the ghost draws the shadow run (against the shadow simulation's
own state), the drawn n and force are the model's, the lesson panel, the reachable region's outline,
the scene recording, and hostile values for the new controls (the reaction readout against Eq. (1) in a
session: tests/session/test_teach.py).
"""

from __future__ import annotations

import time

import numpy as np
import pinocchio as pin
import pytest

from rns_viz.model import FsmsModel
from rns_viz.viz.server.app import RnsApp, start_app
from tests.support.browser import wait_until


def _nearest(colour: tuple[int, int, int], legend: dict[str, str]) -> str:
    """The legend entry whose colour (#rrggbb) is nearest ``colour`` (RGB 0-255)."""
    rgb = {name: np.array([int(c[i : i + 2], 16) for i in (1, 3, 5)]) for name, c in legend.items()}
    return min(rgb, key=lambda name: float(np.linalg.norm(rgb[name] - np.array(colour))))


def test_the_ghost_takes_its_runs_colour_in_the_plots(trep_app: RnsApp) -> None:
    """Blue is suppression on and red off in every plot: the ghost, the shadow run, is drawn so, whichever way
    the operated run's suppression is set (it had been blue always, also as the suppression-off run)."""
    from rns_viz.viz.panels.live_plots import OFF_COLOUR, ON_COLOUR

    app, s = trep_app, trep_app.session
    ghost = app.renderer.teach.ghost
    legend = {"on": ON_COLOUR, "off": OFF_COLOUR}
    for suppress in (True, False, True):
        s.set_suppression(suppress)
        s.advance(0.05)
        shadow = "off" if suppress else "on"
        wait_until(lambda shadow=shadow: _nearest(ghost.colour, legend) == shadow, 5.0, f"a {shadow} ghost")
        assert ghost.label_text == f"ghost: suppression {shadow}"
        assert all(tuple(mesh.color) == ghost.colour for mesh in ghost.robot.meshes)


def test_ghost_draws_the_shadow_run_not_the_operated_one(trep_app: RnsApp, trep: FsmsModel) -> None:
    app, s = trep_app, trep_app.session
    assert s.snapshot().settings.suppress
    s.kick(0.8)
    s.advance(0.6)  # suppression on: the operated base settles, the shadow's keeps swinging
    shadow, operated = s.state.runs.shadow.q.copy(), s.state.runs.sim.q.copy()
    assert abs(shadow[0] - operated[0]) > 1e-4  # m: the two runs differ by more than the drawing's rounding
    ghost = app.renderer.teach.ghost
    wait_until(lambda: ghost.q is not None and abs(ghost.q[0] - shadow[0]) < 1e-5, 5.0, "the ghost to be drawn")
    assert ghost.q is not None
    np.testing.assert_allclose(ghost.q, shadow, atol=1e-4)
    # The drawn base node (exaggerated) sits where the shadow's x_b puts it, not the operated one's.
    ex = ghost.exaggeration
    drawing = trep
    base = pin.SE3(drawing.pin_model.jointPlacements[1])
    expected = base.translation + ex * shadow[0] * (base.rotation @ drawing.base_axes()[0])
    np.testing.assert_allclose(ghost.drawn_base_position(), expected, atol=2e-4 * ex)
    assert np.linalg.norm(ghost.drawn_base_position() - expected) < ex * abs(shadow[0] - operated[0])
    # Hidden with its checkbox.
    app.view.boxes["ghost"].value = False
    wait_until(lambda: not ghost.root.visible, 5.0, "the ghost to hide")


def test_drawn_n_and_force_are_the_models(trep_app: RnsApp, trep: FsmsModel) -> None:
    app, s = trep_app, trep_app.session
    app.view.show("null_vector")  # off in TREP's first look (defaults.py)
    s.play_fast()
    s.advance(0.4)
    snap = s.snapshot()
    teach = app.renderer.teach
    theta = np.round(snap.q[1:], 4)
    wait_until(lambda: teach._theta is not None and np.array_equal(teach._theta, theta), 5.0, "n to be drawn")
    model = trep
    H = model.coupling_matrix(model.q(theta))
    assert teach.n is not None and abs(float((H @ teach.n)[0])) < 1e-12  # kg m/s per unit u-bar: no coupling
    np.testing.assert_allclose(teach.n, [H[0, 1], -H[0, 0]], rtol=1e-12)  # Eq. (27)
    time.sleep(0.1)
    assert app.scene._force == s.snapshot().readouts.reaction  # the arrow is the readout, unrounded


def test_lesson_panel_starts_steps_and_shows_progress_through_the_protocol() -> None:
    from tests.support.browser import wait_for_clients
    from tests.support.protocol_client import ProtocolClient, gui_uuid

    app = start_app("trep", port=0, realtime=False, verbose=False, lesson=1)
    try:
        s = app.session
        s.advance(0.01)
        assert s.wait_background()
        wait_until(lambda: "Lesson 1 of 6" in app.lessons.text.content, 5.0, "lesson 1 in the panel")
        assert "✓" not in app.lessons.text.content and "Eq. (1)" in app.lessons.text.content
        # Lesson 1 draws only what it explains: no ghost yet (suppression is lesson 4's subject).
        assert not app.view.on("ghost") and not app.view.on("null_vector") and app.view.on("reaction")
        with ProtocolClient(app.port, decode=True) as ws:
            wait_for_clients(app, 1, "the websocket client to connect")
            s.kick(0.8)
            s.advance(3.5)  # the student's task of lesson 1: kick and watch it swing
            wait_until(lambda: "✓" in app.lessons.text.content, 5.0, "the tick of a finished lesson")
            ws.click(gui_uuid(app.lessons.next))
            wait_until(lambda: "StartLesson" in s.pending_commands(), 10.0, "Next to queue a lesson")
            s.advance(0.05)
            lesson = s.snapshot().lesson
            assert lesson is not None and lesson.number == 2 and not lesson.done
            wait_until(lambda: "Lesson 2 of 6" in app.lessons.text.content, 5.0, "lesson 2 in the panel")
            assert app.view.on("coupling") and not app.view.on("ghost")  # lesson 2 is about L
            ws.set_value(gui_uuid(app.lessons.chooser), "3R 2. The reactionless-reachable set")
            wait_until(lambda: app.lessons.chooser.value.startswith("3R 2"), 5.0, "the chooser's new value")
            ws.click(gui_uuid(app.lessons.start))
            wait_until(lambda: "StartLesson" in s.pending_commands(), 10.0, "Start to queue a lesson")
            s.advance(0.05)
            lesson = s.snapshot().lesson
            assert lesson is not None and (lesson.model, lesson.number) == ("planar3r", 2)
            assert s.snapshot().settings.model == "planar3r"
            ws.click(gui_uuid(app.lessons.stop))
            wait_until(lambda: "StopLesson" in s.pending_commands(), 10.0, "Stop to queue")
            s.advance(0.01)
            assert s.snapshot().lesson is None
    finally:
        app.stop()


def test_reachable_region_outline_is_its_edge() -> None:
    app = start_app("planar3r", port=0, realtime=False, verbose=False)
    try:
        assert app.session.wait_background()
        app.session.advance(0.01)
        teach = app.renderer.teach
        wait_until(lambda: teach.has_reach and teach.outline.visible, 10.0, "the region's outline")
        reach = app.session.overlays().reach
        assert reach is not None
        edge = np.asarray(teach.outline.points, dtype=float)
        d = np.sqrt(((edge[:, None, :2] - reach[None, :, :2]) ** 2).sum(axis=2))
        span = float(np.ptp(reach[:, :2], axis=0).max())
        assert d.min(axis=1).max() < 0.06 * span  # every outline point lies at the region
        # ... and the region's extreme samples lie on the outline (it goes all the way round).
        for k in (int(np.argmax(reach[:, 0])), int(np.argmin(reach[:, 0])), int(np.argmax(reach[:, 1]))):
            assert np.sqrt(((edge[:, :2] - reach[k, :2]) ** 2).sum(axis=1)).min() < 0.06 * span
        assert len(edge) < 0.1 * len(reach)  # an outline, not the region again
        app.view.boxes["reach"].value = False
        wait_until(lambda: not teach.outline.visible and not app.scene.reachable.visible, 5.0, "the region to hide")
    finally:
        app.stop()


def test_scene_recording_is_a_viser_file_of_the_moving_scene(trep_app: RnsApp) -> None:
    """The last second of a kicked TREP, exported for viser's player: the scene, the ghost and the arrows
    in the file, both bases moving over its time."""
    import msgspec
    import zstandard

    app, s = trep_app, trep_app.session
    s.kick(0.8)
    s.advance(1.0)
    recording = s.recording(1.0)
    assert recording is not None
    name, _ = app.replay.export(recording, "player", s.snapshot(), 20.0)
    assert name == "rns_trep_player.zip"
    data = app.replay.last_scene
    assert data is not None
    size = int.from_bytes(data[:8], "little")
    inner = zstandard.ZstdDecompressor().decompress(data[8:], max_output_size=size)
    n = int.from_bytes(inner[:8], "little")
    payload = msgspec.msgpack.decode(inner[8 : 8 + n])
    assert payload["durationSeconds"] == pytest.approx(1.0, abs=0.1)
    names = {m.get("name") for _, m in payload["messages"]}
    assert {"/ghost/base", "/base", "/base/reaction"} <= names  # the scene, the ghost and the arrows
    moved = {m.get("name") for t, m in payload["messages"] if t > 0.0}
    assert "/base" in moved and "/ghost/base" in moved  # both bases move during the recording


def test_hostile_values_for_the_new_controls_are_set_back_and_the_server_lives(trep_app: RnsApp) -> None:
    from tests.support.browser import wait_for_clients
    from tests.support.protocol_client import ProtocolClient, gui_uuid

    app = trep_app
    with ProtocolClient(app.port, decode=True) as ws:
        wait_for_clients(app, 1, "the websocket client to connect")
        box = app.view.boxes["ghost"]
        ws.set_value(gui_uuid(box), "not a bool")
        ws.set_value(gui_uuid(app.lessons.chooser), "no such lesson")
        ws.click(gui_uuid(app.lessons.start))
        ws.set_value(gui_uuid(app.replay.seconds.slider), 1e9)
        time.sleep(1.0)
        wait_until(lambda: box.value is True, 5.0, "the ghost box to be set back")
        assert app.session.snapshot().lesson is None  # nothing started from a name that is no lesson
        assert app.render_thread.is_alive()
        app.session.advance(0.05)
        assert np.all(np.isfinite(app.session.snapshot().q))
