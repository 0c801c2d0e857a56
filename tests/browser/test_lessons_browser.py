"""Every lesson in a real headless Chromium, with a screenshot of each, of the ghost and of a replay.

For each lesson of TREP (6) and of the 3R (3) the page shows the lesson's panel and the scene after the
lesson's task has been started by the operator (a kick, a play along the path, a dragged target ...).
The default run walks one lesson per model; the walk through every lesson only makes the pictures, so it
is marked ``docs`` (deselected by default). Screenshots go to ``artifacts/screenshots/``; the ones in
``docs/screenshots/`` are made with

    RNS_VIZ_SCREENSHOTS=docs/screenshots python -m pytest -m docs tests/browser/test_lessons_browser.py
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from playwright.sync_api import Page

from rns_viz.defaults import defaults_for
from rns_viz.live.teaching.lessons import lessons_for
from rns_viz.viz.scene.fsms_scene import FsmsScene
from rns_viz.viz.scene.ghost import Ghost
from rns_viz.viz.server.app import RnsApp, start_app
from tests.support.browser import (
    ARTIFACTS,
    browser_page,
    dismiss_notifications,
    open_folder,
    settle_for_picture,
    wait_for_nodes,
    wait_until,
)

pytestmark = pytest.mark.slow
SHOTS = Path(os.environ.get("RNS_VIZ_SCREENSHOTS", ARTIFACTS / "screenshots"))


def lesson_number(app: RnsApp) -> int | None:
    status = app.session.snapshot().lesson
    return None if status is None else status.number


def _ee(app: RnsApp) -> np.ndarray:
    q = app.session.snapshot().q
    return app.model.ee_position(q[app.model.m :])[:2]


def _scrub_far(app: RnsApp) -> None:
    snap = app.session.snapshot()
    if snap.sigma_range is not None:
        app.session.scrub(0.8 * snap.sigma_range[1])


# What the operator does in each lesson before its picture is taken (the start of the lesson's task).
ACTIONS: dict[tuple[str, int], Callable[[RnsApp], None]] = {
    ("trep", 1): lambda app: app.session.kick(0.8),
    ("trep", 2): lambda app: app.session.point_to_point(),
    ("trep", 3): lambda app: app.session.play_slow(),
    ("trep", 4): lambda app: app.session.kick(0.8),
    ("trep", 5): _scrub_far,
    ("trep", 6): lambda app: (app.session.cyclic(True), time.sleep(1.0), app.session.kick(0.8)),
    ("planar3r", 1): lambda app: app.session.set_target(_ee(app) + np.array([0.0, 0.3]), True),
    ("planar3r", 2): lambda app: app.session.set_target(np.array([2.5, 2.0]), True),
    ("planar3r", 3): lambda app: app.session.kick(3.0),
    ("boom7", 1): lambda app: app.session.kick(5.0, direction=(0.0, 1.0, 0.0, 0.0, 0.0, 0.0)),
    ("boom7", 2): lambda app: app.session.scrub(0.5 * app.session.snapshot().sigma_range[0]),  # type: ignore[index]
    ("boom7", 3): lambda app: app.session.set_target(
        np.asarray(app.session.snapshot().target) + np.array([0.04, -0.02, 0.02]), True
    ),
}
GHOSTS = {("trep", 4): "ghost_trep", ("planar3r", 3): "ghost_planar3r"}


def shoot(page: Page, name: str) -> Path:
    SHOTS.mkdir(parents=True, exist_ok=True)
    page.mouse.move(5, 5)
    dismiss_notifications(page)
    settle_for_picture(page, 15)
    path = SHOTS / f"{name}.png"
    page.screenshot(path=str(path))
    Image.open(path).convert("RGB").quantize(256).save(path, optimize=True)  # a third of the bytes, for docs/
    return path


def walk(model: str, numbers: list[int]) -> None:
    """Open ``model``'s app at lesson 1 in the page, then start each lesson of ``numbers`` from the
    session: the page shows its panel, the operator's action runs, the scene (and the ghost, when the
    lesson shows the shadow run) is photographed; TREP's walk ends with a replay on the page's timeline."""
    app = start_app(model, port=0, verbose=False, lesson=1)
    try:
        s = app.session
        with browser_page(app.server, width=1400, height=900, timeout=60.0) as page:
            wait_for_nodes(page, {FsmsScene.BASE, Ghost.BASE}, timeout=60.0)
            count = len(lessons_for(model))
            for number in numbers:
                s.start_lesson(model, number)
                wait_until(
                    lambda n=number: (s.snapshot().lesson or object()).__dict__.get("number") == n, 20.0, "lesson"
                )
                page.get_by_text(f"Lesson {number} of {count}", exact=False).wait_for(timeout=30_000)
                wait_until(s.wait_background, 60.0, "the lesson's path or reachable set")
                if (model, number) in GHOSTS:
                    app.controls.show(app.gui.exaggeration, 50.0 if model == "trep" else 5.0)
                ACTIONS[(model, number)](app)
                time.sleep(2.5)  # let the task show in the scene and the plots
                page.get_by_text(f"Lesson {number} of {count}", exact=False).scroll_into_view_if_needed()
                assert shoot(page, f"{model}_lesson{number}").stat().st_size > 10_000
                if (model, number) in GHOSTS:
                    assert app.view.on("ghost")  # the lesson shows the shadow run
                    snap = s.snapshot()
                    assert snap.q_shadow is not None and np.all(np.isfinite(snap.q_shadow))
                    assert shoot(page, GHOSTS[(model, number)]).stat().st_size > 10_000
                    app.controls.show(app.gui.exaggeration, defaults_for(model).exaggeration)
            if model == "trep":  # the last lesson replayed: the simulation waits, the timeline runs
                s.start_replay(10.0)
                wait_until(lambda: s.snapshot().replay is not None, 10.0, "the replay")
                open_folder(page, "Record and replay")
                wait_until(lambda: not app.replay.timeline.disabled, 10.0, "the timeline")
                page.get_by_role("button", name="Back to live").scroll_into_view_if_needed()
                time.sleep(2.0)
                assert shoot(page, "replay_trep").stat().st_size > 10_000
                s.stop_replay()
    finally:
        app.stop()


# One lesson per model in the default run (every lesson's logic is checked headless in
# tests/session/test_lessons.py and tests/session/test_lessons_boom.py): the ones with a ghost, and boom7's lesson on a
# selected S (a model variant: boom7#S=111000) with a dragged target.
@pytest.mark.parametrize(("model", "number"), [("trep", 4), ("planar3r", 3), ("boom7", 3)])
def test_a_lesson_started_from_the_session_shows_in_the_page(model: str, number: int) -> None:
    walk(model, [number])


@pytest.mark.docs
@pytest.mark.parametrize("model", ["trep", "planar3r", "boom7"])
def test_walk_every_lesson_with_screenshots(model: str) -> None:
    walk(model, list(range(1, len(lessons_for(model)) + 1)))
