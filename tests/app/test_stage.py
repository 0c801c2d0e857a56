"""The stage (layout, keys, overlays, seat) through the protocol: every keyboard command reaches the session
as its button's command and is refused for a watcher; overlay toggles hide and show their nodes; the
per-model first look is one table; on a server open to the network nobody operates by connecting first."""

from __future__ import annotations

import time
from typing import get_args

import numpy as np
import pytest

from rns_viz.defaults import defaults_for
from rns_viz.live.operator.kinds import operator_class
from rns_viz.live.reach.region import arm_reach
from rns_viz.model import FsmsModel
from rns_viz.param_file import Overlay
from rns_viz.params import MODEL_NAMES, missing_extra
from rns_viz.viz.panels.glossary import KEYS
from rns_viz.viz.panels.keys import jog_step
from rns_viz.viz.scene.framing import frame_points, is_narrow
from rns_viz.viz.scene.fsms_scene import REFRAME_SETTLE_S, FsmsScene
from rns_viz.viz.scene.view_toggles import TOGGLES, first_look
from rns_viz.viz.server.app import RnsApp, start_app
from tests.support.app_helpers import stepped_app
from tests.support.browser import wait_for_clients, wait_until
from tests.support.protocol_client import ProtocolClient


def uuid_of(app: RnsApp, label: str) -> str:
    return app.keys.commands[label]._impl.uuid


def settle(app: RnsApp, seconds: float = 0.05) -> None:
    app.session.advance(seconds)


def test_every_key_reaches_the_session_and_is_refused_for_a_watcher(trep_app: RnsApp) -> None:
    app, s = trep_app, trep_app.session
    operator = ProtocolClient(app.port, decode=True)
    wait_for_clients(app, 1, "the operator")
    watcher = ProtocolClient(app.port, decode=True)
    wait_for_clients(app, 2, "the watcher")
    try:
        assert app.lock.operator is not None and len(app.lock.clients()) == 2
        # suppression: the watcher's key is refused (the setting stays), the operator's toggles it
        before = s.snapshot().settings.suppress
        watcher.command(uuid_of(app, "Vibration suppression on/off"))
        wait_until(lambda: any(t == "View only" for t, _ in watcher.notifications), 10.0, "the watcher told")
        settle(app)
        assert s.snapshot().settings.suppress == before
        operator.command(uuid_of(app, "Vibration suppression on/off"))
        wait_until(lambda: (settle(app), s.snapshot().settings.suppress != before)[1], 10.0, "suppression toggled")

        # pause / resume
        paused = s.snapshot().paused
        watcher.command(uuid_of(app, "Pause / resume"))
        settle(app)
        assert s.snapshot().paused == paused
        operator.command(uuid_of(app, "Pause / resume"))
        wait_until(lambda: (settle(app), s.snapshot().paused != paused)[1], 10.0, "pause toggled")
        if s.snapshot().paused:
            operator.command(uuid_of(app, "Pause / resume"))
            wait_until(lambda: (settle(app), not s.snapshot().paused)[1], 10.0, "resumed")

        # kick: the base deflects only after the operator's key
        watcher.command(uuid_of(app, "Kick the base"))
        settle(app, 0.3)
        assert abs(s.snapshot().q[0]) < 1e-7
        operator.command(uuid_of(app, "Kick the base"))
        wait_until(lambda: (settle(app), abs(s.snapshot().q[0]) > 1e-5)[1], 10.0, "the kick to bend the base")

        # reset: back to t = 0
        epoch = s.snapshot().epoch
        watcher.command(uuid_of(app, "Reset"))
        settle(app)
        assert s.snapshot().epoch == epoch
        operator.command(uuid_of(app, "Reset"))
        wait_until(lambda: (settle(app, 0.0), s.snapshot().epoch != epoch)[1], 10.0, "the reset")

        # jogging: one step of the stated size per press, the operator's only
        step = jog_step(arm_reach(app.model))
        home = app.renderer.home(s.snapshot())
        watcher.command(uuid_of(app, "Jog target +x"))
        settle(app)
        assert s.snapshot().target is None or np.allclose(s.snapshot().target[:2], home[:2])
        operator.command(uuid_of(app, "Jog target +x"))
        wait_until(lambda: (settle(app), s.snapshot().target is not None)[1], 10.0, "the jogged target")
        moved = np.asarray(s.snapshot().target)[:2] - home[:2]  # TREP's target is the path's point nearest the step
        assert moved[0] > 0.9 * step and np.linalg.norm(moved) == pytest.approx(step, rel=0.05)
        operator.command(uuid_of(app, "Jog target −z"))  # a planar model refuses z with a message
        wait_until(lambda: any("plane" in b for _, b in operator.notifications), 10.0, "the z jog refused")
    finally:
        watcher.close()
        operator.close()


def test_keys_keep_clear_of_the_camera_keys_and_of_each_other() -> None:
    camera = set("WASDQE")
    bound = [(key, modifier) for _, key, modifier, _ in KEYS]
    assert len(bound) == len(set(bound))
    assert not {key for key, _ in bound} & camera


def test_jog_step_is_a_round_fraction_of_the_reach() -> None:
    assert jog_step(0.2) == pytest.approx(0.005)  # 0.2 m / 40
    assert jog_step(1.2) == pytest.approx(0.02)  # 0.03 rounded down to 2 cm
    assert jog_step(3.0) == pytest.approx(0.05)  # 0.075 -> 5 cm


def test_first_look_table_names_only_real_toggles_and_starts_calm() -> None:
    """The overlays a parameter file may name are exactly the app's toggles; every bundled model's first
    look (its ``[app.scene] shown``) leaves out the gain map and the path family."""
    assert set(get_args(Overlay)) == {name for name, *_ in TOGGLES}
    for model in MODEL_NAMES:
        if missing_extra(model) is None:
            shown = defaults_for(model).shown
            assert "gain_map" not in shown and "paths" not in shown, model  # the calm default
    assert defaults_for("trep").shown == {"ghost", "reaction", "trail", "labels", "path_arrows"}
    assert defaults_for("planar3r").shown == {"ghost", "reaction", "trail", "labels", "reach"}


@pytest.mark.parametrize(("key", "reach"), [("trep", False), ("boom7", False), ("boom7#S=111000", True)])
def test_the_first_look_shows_the_reachable_set_the_target_is_dragged_over(key: str, reach: bool) -> None:
    """An operator that drives a target over the reactionless-reachable set (boom7 holding forces only: a
    4-D reaction null space) shows that set from the first look; one that follows a path adds nothing."""
    model = FsmsModel.from_key(key)
    assert (operator_class(model).shows == "reachable set") == reach
    assert first_look(model) == (defaults_for(model).shown | ({"reach"} if reach else set()))
    assert ("reach" in first_look(model)) == (reach or "reach" in defaults_for(model).shown)


@pytest.mark.parametrize("model", ["trep", "boom7"])
def test_the_app_starts_with_its_models_row_and_toggles_hide_and_show_nodes(model: str) -> None:
    for app in stepped_app(model):
        check_first_look_and_toggles(app, model)


def check_first_look_and_toggles(app: RnsApp, model: str) -> None:
    view, server = app.view, app.server
    assert {n for n, box in view.boxes.items() if box.value} == defaults_for(model).shown
    label = server.scene.get_handle_by_name("/base/callout_base")
    assert label is not None
    settle(app)
    wait_until(lambda: label.visible, 5.0, "the base label shown")
    view.show("labels", False)
    wait_until(lambda: not label.visible, 5.0, "the label hidden by its toggle")
    view.show("labels", True)
    wait_until(lambda: label.visible, 5.0, "the label shown again")
    # the gain map: out of the scene until ticked
    explorer = app.renderer.explorer
    wait_until(lambda: explorer.scene is not None and explorer.scene.gain_map is not None, 60.0, "the map")
    assert explorer.scene is not None
    assert not explorer.scene.frame.visible
    view.show("gain_map")
    wait_until(lambda: explorer.scene.frame.visible, 5.0, "the map shown by its toggle")
    view.show("gain_map", False)
    wait_until(lambda: not explorer.scene.frame.visible, 5.0, "the map hidden again")


def test_toggles_that_draw_nothing_on_a_model_are_disabled_saying_why_and_come_back_on_switching(
    trep_app: RnsApp,
) -> None:
    """planar3r has no single reactionless path (a 2-D null space) and trep2 neither a path nor a gain map (a
    second arm compensates): their path toggles (and trep2's map) are disabled, unticked, a tick refused, the
    hint saying why; the region of a larger null space is disabled on the path models. Back on trep all
    path toggles work again."""
    app, s = trep_app, trep_app.session
    no_path = {"paths", "null_vector", "path_arrows"}
    expected = {"trep": {"reach"}, "planar3r": no_path, "trep2": no_path | {"reach", "gain_map"}, "boom7": {"reach"}}
    hints = {name: hint for name, _, _, hint in TOGGLES}
    for model in ("trep", "planar3r", "trep2", "trep"):
        if model != app.model_name:
            s.switch_model(model)
            settle(app)
            wait_until(lambda model=model: app.model_name == model, 30.0, f"the scene of {model}")
        disabled = {name for name, box in app.view.boxes.items() if box.disabled}
        assert disabled == expected[model], model
        for name, box in app.view.boxes.items():
            if name in disabled:
                assert not box.value and box.hint.startswith("Not for this model: "), (model, name)
                app.view.show(name)
                assert not box.value and not app.view.on(name)
            else:
                assert box.hint == hints[name], (model, name)
    app.view.show("path_arrows")
    assert app.view.on("path_arrows")


def test_labels_keep_off_the_gain_map_while_it_is_shown(trep_app: RnsApp) -> None:
    """The map, its title, ticks and legend are one solid of the callouts' layout while shown (no label
    covers a cell of it; the layout keeps labels off every solid: tests/unit/test_callouts.py), none hidden."""
    app, callouts = trep_app, trep_app.renderer.callouts
    explorer = app.renderer.explorer
    wait_until(lambda: explorer.scene is not None and explorer.scene.gain_map is not None, 60.0, "the map")
    assert explorer.scene is not None
    arm = callouts.solids()
    app.view.show("gain_map")
    wait_until(lambda: app.scene.also_framed is not None, 5.0, "the map framed beside the robot")
    with_map = callouts.solids()
    assert len(with_map) == len(arm) + 1
    assert {tuple(p) for p in with_map[-1]} == {tuple(p) for p in explorer.scene.framed_corners()}
    app.view.show("gain_map", False)
    wait_until(lambda: app.scene.also_framed is None, 5.0, "the map hidden")
    assert len(callouts.solids()) == len(arm)


def test_labels_keep_clear_of_a_paced_pages_slowed_line(trep_app: RnsApp) -> None:
    """A paced page's floating panel carries the "Display slowed" line: its box for the labels' layout grows."""
    from rns_viz.viz.scene.framing import NOTICE_HEIGHT_PX

    app = trep_app
    assert app.renderer.page_notice == app.pace.noticed  # the pace tells the labels' layout
    callouts = app.renderer.callouts
    with ProtocolClient(app.port) as ws:
        wait_for_clients(app, 1, "the page")
        ws.camera((1.0, 0.0, 0.0, 0.0), (5.0, 5.0, 5.0), size=(1200, 700))
        wait_until(lambda: bool(callouts.pages()), 10.0, "the page's camera")
        plain = callouts.pages()[0].covered
        app.renderer.page_notice = lambda client_id: True
        try:
            slowed = callouts.pages()[0].covered
        finally:
            app.renderer.page_notice = app.pace.noticed
        assert plain is not None and slowed is not None and slowed[3] == plain[3] + NOTICE_HEIGHT_PX


def test_other_paths_toggle_draws_the_family_or_only_the_current_path(trep_app: RnsApp) -> None:
    app = trep_app
    paths = app.server.scene.get_handle_by_name(FsmsScene.PATHS)
    assert paths is not None
    wait_until(lambda: (settle(app), app.scene.paths.visible)[1], 30.0, "the current path drawn")
    alone = len(app.scene.paths.points)
    app.view.show("paths")
    wait_until(lambda: (settle(app), len(app.scene.paths.points) > 3 * alone)[1], 30.0, "the family drawn")
    app.view.show("paths", False)
    wait_until(lambda: (settle(app), len(app.scene.paths.points) == alone)[1], 30.0, "only the current path again")


def test_on_a_network_server_the_first_visitor_watches_until_it_takes_control() -> None:
    app = start_app("trep", host="0.0.0.0", port=0, realtime=False, verbose=False)
    try:
        first = ProtocolClient(app.port, decode=True)
        wait_for_clients(app, 1, "the first visitor")
        assert app.lock.operator is None  # connecting first gives no seat
        second = ProtocolClient(app.port, decode=True)
        wait_for_clients(app, 2, "the second visitor")
        panel = app.connections.panels._panels[app.lock.clients()[0]]  # the first visitor's panel
        first.click(panel.take._impl.uuid)
        wait_until(lambda: app.lock.operator == app.lock.clients()[0], 10.0, "the seat taken by asking")
        first.close()
        wait_until(lambda: len(app.lock.clients()) == 1, 10.0, "the first visitor gone")
        app.lock.expire()
        assert app.lock.operator is None  # nor does the seat pass to whoever is left
        second.close()
    finally:
        app.stop()


def test_framing_puts_every_corner_inside_the_stated_fraction() -> None:
    rng = np.random.default_rng(3)
    points = rng.normal(size=(20, 3))
    direction = np.array([0.4, -1.0, 0.7])
    for aspect in (0.46, 1.0, 1.8):
        pose = frame_points(points, direction, fov=1.0, aspect=aspect, fill=0.7)
        forward = (pose.look_at - pose.position) / np.linalg.norm(pose.look_at - pose.position)
        right = np.cross(forward, [0.0, 0.0, 1.0])
        right /= np.linalg.norm(right)
        up = np.cross(right, forward)
        lo, hi = points.min(axis=0), points.max(axis=0)
        corners = np.array([[a, b, c] for a in (lo[0], hi[0]) for b in (lo[1], hi[1]) for c in (lo[2], hi[2])])
        rel = corners - pose.position
        depth = rel @ forward
        x = (rel @ right) / (depth * np.tan(0.5) * aspect)
        y = (rel @ up) / (depth * np.tan(0.5))
        assert np.all(np.abs(x) <= 0.7 + 1e-9) and np.all(np.abs(y) <= 0.7 + 1e-9)
        assert max(np.abs(x).max(), np.abs(y).max()) > 0.5  # and fills a good part of the view


def test_every_preset_and_lesson_says_what_to_look_at() -> None:
    """Each preset's panel text and each lesson's text carries a 'Look at:' line of its own."""
    from rns_viz.live.teaching.lessons import LESSON_LIBRARY
    from rns_viz.scenarios import LIVE_SCENARIOS
    from rns_viz.viz.panels.preset_rows import preset_description

    for name, preset in LIVE_SCENARIOS.items():
        assert len(preset.look) > 20, name
        assert f"**Look at:** {preset.look}" in preset_description(name)
    for name, lesson in LESSON_LIBRARY.items():
        assert len(lesson.look) > 20, name
    assert len({p.look for p in LIVE_SCENARIOS.values()}) >= 18  # their own words, not one line for all


def test_present_option_reaches_the_app_and_makes_the_projector_screen(monkeypatch: pytest.MonkeyPatch) -> None:
    """``rns-viz serve --present``: the CLI passes it on; the app hides the folders a demonstration does not
    need, widens the docked plots and raises the page's text size. Without it nothing is hidden."""
    import rns_viz.viz.server.app as app_module
    from rns_viz import cli
    from rns_viz.viz.panels import presentation

    calls: list[dict[str, object]] = []
    monkeypatch.setattr(app_module, "serve", lambda **kw: calls.append(kw))
    assert cli.main(["serve", "--present", "--port", "0"]) == 0 and cli.main(["serve", "--port", "0"]) == 0
    assert [c["present"] for c in calls] == [True, False]

    for present in (True, False):
        app = start_app("trep", port=0, realtime=False, verbose=False, present=present)
        try:
            g = app.gui
            folders = (app.renderer.explorer.folder, app.replay.folder, g.gains_folder, g.download)
            assert [f.visible for f in folders] == [not present] * 4
            style = app.present_style
            assert (style.content if style is not None else None) == (presentation.PRESENT_CSS if present else None)
            assert g.plots_panel.visible and g.readouts.visible and g.kick.visible  # what a demo needs stays
        finally:
            app.stop()


def test_a_page_is_framed_again_for_a_new_size_unless_its_view_was_moved(trep_app: RnsApp) -> None:
    """A page's camera messages carry its canvas size: a resize re-frames a view nobody moved; a moved view
    stays where the user put it, until the page turns narrow (a phone's panel sheet covers the lower part)."""
    scene, wxyz = trep_app.scene, (1.0, 0.0, 0.0, 0.0)

    def framed(size: tuple[int, int]) -> np.ndarray:  # where the app puts a camera of fov 1 rad for this canvas
        return scene.camera_pose(1.0, size[0] / size[1], is_narrow(*size)).position

    with ProtocolClient(trep_app.port) as ws:
        wait_for_clients(trep_app, 1, "the page")
        client = next(iter(trep_app.server.get_clients().values()))
        at = lambda size: np.allclose(client.camera.position, framed(size), atol=1e-6)  # noqa: E731
        # the page's first report (or, if the app saw the one sent on connecting, a resize just after it)
        ws.camera(wxyz, (5.0, 5.0, 5.0), size=(1200, 700))
        wait_until(lambda: at((1200, 700)), 10.0, "the first framing")
        time.sleep(REFRAME_SETTLE_S)  # the page settled
        ws.camera(wxyz, tuple(framed((1200, 700))), size=(1000, 720))  # resized, the view as framed
        wait_until(lambda: at((1000, 720)), 10.0, "the page framed for its new size")
        # the drawing density lowered (a slow page): the same shape in fewer px frames nothing again (the
        # framing follows the shape; re-framing at each density change kept a slow page from settling)
        framed_at = trep_app.scene.framed_pages[client.client_id][2]
        ws.camera(wxyz, tuple(framed((1000, 720))), size=(750, 540))
        wait_until(lambda: client.camera.image_width == 750, 10.0, "the lower density reported")
        assert trep_app.scene.framed_pages[client.client_id][2] == framed_at
        moved = (3.0, -2.0, 1.5)
        time.sleep(REFRAME_SETTLE_S)  # (a size reported within this of a framing is the page still settling)
        ws.camera(wxyz, moved, size=(1000, 720))  # the user orbits ...
        ws.camera(wxyz, moved, size=(900, 720))  # ... then resizes the window: the view is theirs
        wait_until(lambda: client.camera.image_width == 900, 10.0, "the resize reported")
        assert np.allclose(client.camera.position, moved)
        ws.camera(wxyz, moved, size=(390, 844))  # turned narrow: framed in the band above the sheet
        wait_until(lambda: at((390, 844)), 10.0, "the narrow page framed")
        assert not np.allclose(framed((390, 844)), framed((900, 720)))
