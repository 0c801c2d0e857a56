"""Deflection you can see: the auto factor draws µm and mm base motion both visibly (Fig. 11's 2.8 µm
reactionless run against the 1.3 mm joint-space run), without flicker, and the factor written beside
the base is, in every frame, the factor the base was drawn with."""

from __future__ import annotations

import time
from collections.abc import Iterator

import numpy as np
import pytest

from rns_viz.model import FsmsModel
from rns_viz.scenarios import run_scenario
from rns_viz.viz.scene.auto_scale import HIGH, LOW, MOST, AutoExaggeration, step_below
from rns_viz.viz.scene.fsms_scene import base_label
from rns_viz.viz.server.app import RnsApp
from tests.support.app_helpers import stepped_app

FRAME_STEPS = 17  # 1 ms steps between two drawn frames (the render thread's 60 Hz)


def test_steps_are_1_2_5_and_never_above_the_number() -> None:
    assert [step_below(x) for x in (1.0, 1.9, 2.0, 4.99, 5.0, 9.99, 10.0, 37.0, 7142.0)] == [
        1.0,
        1.0,
        2.0,
        2.0,
        5.0,
        5.0,
        10.0,
        20.0,
        5000.0,
    ]


def drawn_run(name: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """A preset's base deflection at the frames the app draws, the auto factor of each frame, the reach."""
    model = FsmsModel.from_name("trep")
    log = run_scenario(name).log
    t, x_b = log.column("t")[::FRAME_STEPS], log.column("xb_1")[::FRAME_STEPS]
    auto = AutoExaggeration(model.arm_reach, model.base_rotational, factor=10.0)
    factors = np.array([auto.observe(float(ti), (np.array([xi]),)) for ti, xi in zip(t, x_b, strict=True)])
    return t, x_b, factors, model.arm_reach


def test_fig11_contrast_is_drawn_visibly_and_written_in_the_factor() -> None:
    """At a fixed ×10 the reactionless run's 2.8 µm is drawn 28 µm, 0.014 % of TREP's 0.2 m reach: nothing
    moves on screen. The auto factor draws both runs' peaks at 3-30 % of the reach, and the factors written
    (×5000 against ×10) carry the contrast of 2.8 µm against 1.3 mm."""
    peaks, factor_at_peak = {}, {}
    for name in ("fig11-fast", "fig11-joint2"):
        _, x_b, factors, reach = drawn_run(name)
        k = int(np.argmax(np.abs(x_b)))
        peaks[name], factor_at_peak[name] = abs(x_b[k]), factors[k]
        drawn = np.abs(x_b) * factors / reach
        assert LOW <= drawn[k] <= HIGH, (name, drawn[k])
        assert np.max(drawn) <= HIGH + 1e-12  # never drawn beyond the band (the factor drops first)
        changes = int(np.count_nonzero(np.diff(factors)))
        assert changes <= 6, (name, changes, sorted(set(factors)))  # a few steps, no flicker
    assert peaks["fig11-fast"] < 5e-6 and peaks["fig11-joint2"] > 1e-3  # the paper's µm against mm
    assert 10.0 * peaks["fig11-fast"] / reach < 2e-4  # the old fixed ×10: invisible
    assert factor_at_peak["fig11-fast"] >= 100.0 * factor_at_peak["fig11-joint2"]


def test_the_factor_stays_within_its_bounds_and_a_still_base_gets_the_largest() -> None:
    auto = AutoExaggeration(0.2, (False,), factor=10.0)
    assert auto.observe(0.0, (np.zeros(1),)) == MOST  # nothing moves: the largest factor (noise is 1e-12 m)
    assert auto.observe(0.1, (np.array([0.5]),)) == 1.0  # half a metre: drawn as simulated, not smaller
    assert auto.observe(0.2, (np.array([np.nan]), None)) == 1.0  # a diverged run changes nothing


def test_a_rotational_base_coordinate_counts_its_arc_at_the_reach() -> None:
    auto = AutoExaggeration(2.0, (False, True), factor=10.0)
    factor = auto.observe(0.0, (np.array([0.0, 1e-3]),))  # 1 mrad at 2 m: a 2 mm arc
    assert factor == step_below(0.1 * 2.0 / 2e-3)


@pytest.fixture
def trep_app() -> Iterator[RnsApp]:
    yield from stepped_app("trep")


def test_the_factor_written_beside_the_base_is_the_factor_drawn(trep_app: RnsApp) -> None:
    """Frame by frame (the render thread stopped, its frames run here): after a kick the auto factor changes,
    and in every frame the base label's factor, the panel's box and the pose of the drawn base agree."""
    app, r = trep_app, trep_app.renderer
    r.stop()
    model = r.model
    rest = model.pin_model.jointPlacements[1].translation
    axis = model.pin_model.jointPlacements[1].rotation @ model.base_axes()[0]
    factors = set()
    app.session.kick(1.0)
    for _ in range(120):
        app.session.advance(FRAME_STEPS * 1e-3)
        r._frame(time.perf_counter())
        snap, scene = app.session.snapshot(), r.scene
        factor = scene.exaggeration
        factors.add(factor)
        assert scene.base_label.text == base_label(factor)
        assert app.gui.exaggeration.value == factor
        drawn = float(axis @ (r.scene.robot.base_placement().translation - rest))
        assert drawn == pytest.approx(factor * r._drawn(snap.q, factor)[0], abs=1e-12)
    assert len(factors) >= 2, factors  # the auto factor did change on the way
    # the operator fixes the factor: it stays through the next swing, and is still written
    app.controls.show(app.gui.auto_exaggeration, False)
    app.controls.show(app.gui.exaggeration, 20.0)
    app.session.kick(3.0)
    for _ in range(30):
        app.session.advance(FRAME_STEPS * 1e-3)
        r._frame(time.perf_counter())
        assert r.scene.exaggeration == 20.0 and r.scene.base_label.text == base_label(20.0)


def test_a_factor_the_operator_drags_fixes_it_and_a_watchers_is_refused(trep_app: RnsApp) -> None:
    """Dragging *Base deflection drawn ×* is a fixed factor: auto goes off and the base is drawn with it; a
    watcher's drag changes neither."""
    from tests.support.browser import wait_for_clients, wait_until
    from tests.support.protocol_client import ProtocolClient, gui_uuid

    app, g = trep_app, trep_app.gui
    operator = ProtocolClient(app.port, decode=True)
    wait_for_clients(app, 1, "the operator")
    watcher = ProtocolClient(app.port, decode=True)
    wait_for_clients(app, 2, "the watcher")
    assert g.auto_exaggeration.value
    watcher.set_value(gui_uuid(g.exaggeration.slider), 40.0)
    wait_until(lambda: any(t == "View only" for t, _ in watcher.notifications), 10.0, "the watcher told")
    assert app.good(g.auto_exaggeration) and app.good(g.exaggeration) != 40.0
    operator.set_value(gui_uuid(g.exaggeration.slider), 30.0)
    wait_until(lambda: not app.good(g.auto_exaggeration), 10.0, "auto off")
    app.session.kick(1.0)
    app.session.advance(0.5)
    wait_until(lambda: app.scene.exaggeration == 30.0, 10.0, "the base drawn ×30")
    assert app.scene.base_label.text == base_label(30.0) and not g.auto_exaggeration.value
