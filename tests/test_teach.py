"""Issue 11, the app's teaching views: the ghost draws the shadow run, the reaction force is Eq. (1)'s.

The reaction is checked against an independent evaluation of Eq. (1) from the step log (pinocchio's
CRBA and RNEA, a linear solve, no ABA); the ghost against the shadow simulation's own state.
"""

from __future__ import annotations

import time

import numpy as np
import pinocchio as pin
import pytest

from rns_viz.live.session import Session
from rns_viz.model import FsmsModel
from rns_viz.viz.app import RnsApp, start_app
from tests.browser import wait_until


def independent_reaction(model: FsmsModel, row: dict[str, np.ndarray]) -> float:
    """−(H_bm θ'' + c_b) of Eq. (1) with θ'' from M a = u − c solved directly (not the plant's ABA)."""
    m, pm = model.m, model.pin_model
    data = pm.createData()
    q, v = row["q"], row["v"]
    M = pin.crba(pm, data, q)
    M = np.triu(M) + np.triu(M, 1).T
    c = pin.rnea(pm, data, q, v, np.zeros(model.nv))  # velocity terms (zero gravity)
    u = np.concatenate([-model.K_b @ q[:m] - model.D_b @ v[:m] + row["f"], row["tau"] - model.D_m @ v[m:]])
    a = np.linalg.solve(M, u - c)
    return float(-(M[:m, m:] @ a[m:] + c[:m])[model.selected[0]])


def log_row(s: Session, t: float) -> dict[str, np.ndarray]:
    sim = s.state.runs.sim
    m, n = sim.model.m, sim.model.n
    log = sim.log
    k = int(np.flatnonzero(log.column("t") == t)[0])
    arr = log.array()[k]
    col = log.index
    get = lambda prefix, count: np.array([arr[col[f"{prefix}_{i + 1}"]] for i in range(count)])  # noqa: E731
    return {
        "q": np.concatenate([get("xb", m), get("theta", n)]),
        "v": np.concatenate([get("xbdot", m), get("thetadot", n)]),
        "tau": get("tau", n),
        "f": get("fext", m),
    }


@pytest.mark.parametrize(
    ("model", "peak", "motion"),
    [("trep", 0.8, "play_fast"), ("planar3r", 5.0, None)],
)
def test_reaction_readout_is_eq1_at_its_step(model: str, peak: float, motion: str | None) -> None:
    s = Session(model, realtime=False)
    try:
        assert s.wait_background()
        if motion is not None:
            getattr(s, motion)()
        s.advance(0.05)
        s.kick(peak)
        worst, biggest = 0.0, 0.0
        for _ in range(12):  # during the kick (f_ext != 0) and after it
            s.advance(0.021)
            r = s.snapshot().readouts
            assert np.isfinite(r.reaction_t)
            expected = independent_reaction(s.state.runs.sim.model, log_row(s, r.reaction_t))
            worst = max(worst, abs(r.reaction - expected))
            biggest = max(biggest, abs(expected))
        assert biggest > 1e-3  # N: the arm does push on the base here
        assert worst < 1e-9, f"readout differs from Eq. (1) by {worst:.3g} N (largest force {biggest:.3g} N)"
    finally:
        s.stop()


def test_ghost_draws_the_shadow_run_not_the_operated_one(trep_app: RnsApp) -> None:
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
    drawing = FsmsModel.from_name("trep")
    base = pin.SE3(drawing.pin_model.jointPlacements[1])
    expected = base.translation + ex * shadow[0] * (base.rotation @ drawing.base_axes()[0])
    np.testing.assert_allclose(ghost.drawn_base_position(), expected, atol=2e-4 * ex)
    assert np.linalg.norm(ghost.drawn_base_position() - expected) < ex * abs(shadow[0] - operated[0])
    # Hidden with its checkbox.
    app.view.boxes["ghost"].value = False
    wait_until(lambda: not ghost.root.visible, 5.0, "the ghost to hide")


def test_drawn_n_and_force_are_the_models(trep_app: RnsApp) -> None:
    app, s = trep_app, trep_app.session
    s.play_fast()
    s.advance(0.4)
    snap = s.snapshot()
    teach = app.renderer.teach
    theta = np.round(snap.q[1:], 4)
    wait_until(lambda: teach._theta is not None and np.array_equal(teach._theta, theta), 5.0, "n to be drawn")
    model = FsmsModel.from_name("trep")
    H = model.coupling_matrix(model.q(theta))
    assert teach.n is not None and abs(float((H @ teach.n)[0])) < 1e-12  # kg m/s per unit u-bar: no coupling
    np.testing.assert_allclose(teach.n, [H[0, 1], -H[0, 0]], rtol=1e-12)  # Eq. (27)
    time.sleep(0.1)
    assert app.scene._force == s.snapshot().readouts.reaction  # the arrow is the readout, unrounded


def test_lesson_panel_starts_steps_and_shows_progress_through_the_protocol() -> None:
    from tests.browser import wait_for_clients
    from tests.protocol_client import ProtocolClient, gui_uuid

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


def test_cli_lesson_option_reaches_the_app(monkeypatch: pytest.MonkeyPatch) -> None:
    import rns_viz.viz.app as app_module
    from rns_viz import cli

    calls: list[dict[str, object]] = []
    monkeypatch.setattr(app_module, "serve", lambda **kw: calls.append(kw))
    assert cli.main(["--lesson", "2"]) == 0
    assert cli.main(["serve", "--model", "planar3r", "--lesson", "3", "--port", "0"]) == 0
    assert [(c["model"], c["lesson"]) for c in calls] == [("trep", 2), ("planar3r", 3)]
    assert cli.main(["serve", "--model", "planar3r", "--lesson", "4"]) == 2  # the 3R has three lessons


def test_path_words_turn_ubar_into_joint_angles_and_rates() -> None:
    from rns_viz.viz.path_words import path_words

    s = Session("trep", realtime=False)
    try:
        assert s.wait_background()
        s.play_slow()
        s.advance(1.0)
        snap = s.snapshot()
        text = path_words(snap)
        n = snap.readouts.n
        assert n is not None and snap.sigma is not None
        assert f"joint 2 at **{np.degrees(snap.q[-1]):.1f}°**" in text
        # theta' = n u-bar (Eq. 27): joint 2's rate at the chosen u-bar, deg/s
        assert f"joint 2 {np.degrees(abs(n[1]) * snap.settings.ubar_speed):.0f}°/s" in text
    finally:
        s.stop()


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
    from tests.browser import wait_for_clients
    from tests.protocol_client import ProtocolClient, gui_uuid

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
