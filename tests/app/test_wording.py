"""Words on screen that must be true: controls named by the lessons exist under those names and are not
disabled when a lesson names them, and one quantity has one notation everywhere it is shown.

Lessons name a control in *italics*, exactly as the panel labels it (a folder or tab may be named without
its parenthesis: *Live plots* for the tab 'Live plots (last 10 s)')."""

from __future__ import annotations

import ast
import re
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest
import viser

import rns_viz
from rns_viz.live.published.snapshot import LessonStatus
from rns_viz.live.teaching import lessons, lessons_boom
from rns_viz.live.teaching.lessons import lessons_for, models_with_lessons
from rns_viz.viz.panels import lesson_panel
from rns_viz.viz.server.app import RnsApp, start_app

ROOT = Path(rns_viz.__file__).resolve().parent
ITALIC = re.compile(r"(?<![*\w])\*(?!\*)([^*\n]+?)\*(?![*\w])")  # *name*, not **bold**
# Any notation of a singular value of H_bm, and the one the app uses (with words first where it is named:
# "distance to singularity"): the rows weighted into one unit by W (rns.singularity_distance);
# sigma_min(...) in ASCII where a docstring names it.
SIGMA_OF_HBM = re.compile(r"(σ|sigma)\S{0,20}?\(\s*(W\s*)?(S\s*)?H(_|<sub>)?bm")
NOTATIONS = ("σ_min(W S H_bm", "σ<sub>min</sub>(W S H<sub>bm", "sigma_min(W S H_bm")


@pytest.fixture(scope="module")
def app() -> Iterator[RnsApp]:
    app = start_app("trep", port=0, realtime=False, verbose=False)
    yield app
    app.stop()


def controls(app: RnsApp) -> dict[str, list[Any]]:
    """Every name a person can find in the panels -> the controls of that name: labels of buttons, boxes,
    dropdowns, folders and tabs (also without a trailing parenthesis), and the options of button groups."""
    gui = app.server.gui
    names: dict[str, list[Any]] = {}
    handles = [*gui._gui_input_handle_from_uuid.values(), *gui._container_handle_from_uuid.values()]  # (viser's)
    for handle in handles:
        label = getattr(handle, "label", None) or getattr(handle, "_label", None)  # a tab's is private (viser's)
        for name in (label, re.sub(r" \([^()]*\)$", "", label or "")):
            if name:
                names.setdefault(name, []).append(handle)
        if isinstance(handle, viser.GuiButtonGroupHandle):
            for option in handle.options:
                names.setdefault(option, []).append(handle)
    return names


def progress_texts() -> list[str]:
    """The constant parts of every Progress(...) message of the lessons (formatted values as {})."""
    out = []
    for module in (lessons, lessons_boom):
        for node in ast.walk(ast.parse(Path(module.__file__).read_text())):
            if isinstance(node, ast.Call) and getattr(node.func, "id", "") == "Progress":
                for arg in node.args:
                    if isinstance(arg, ast.Constant) and isinstance(arg.value, str):
                        out.append(arg.value)
                    elif isinstance(arg, ast.JoinedStr):
                        out.append("".join(v.value if isinstance(v, ast.Constant) else "{}" for v in arg.values))
    assert len(out) > 10
    return out


def lesson_texts() -> list[str]:
    lessons = [lesson for model in models_with_lessons() for lesson in lessons_for(model)]
    texts = [part for lesson in lessons for part in (lesson.text, lesson.task)]
    return [*texts, *progress_texts(), lesson_panel.NO_LESSON, lesson_panel.LAST_DONE]


def test_every_control_a_lesson_names_is_in_the_panel_under_that_name(app: RnsApp) -> None:
    names = controls(app)
    named = {name for text in lesson_texts() for name in ITALIC.findall(text)}
    assert {"Kick the base", "Same end points, joint space", "Start cyclic motion", "Next"} <= named
    missing = sorted(name for name in named if name not in names)
    assert not missing, f"lessons name controls the panel does not have: {missing}"


def test_no_lesson_asks_for_a_disabled_control(app: RnsApp) -> None:
    """Every lesson's text, done or not, as the panel shows it: each button it names is enabled."""
    names = controls(app)
    snap = app.session.snapshot()
    states = [None] + [
        LessonStatus(model, k, len(ls), lesson.title, lesson.equation, lesson.text, lesson.task, done, "…")
        for model in models_with_lessons()
        for ls in (lessons_for(model),)
        for k, lesson in enumerate(ls, start=1)
        for done in (False, True)
    ]
    for status in states:
        app.lessons.refresh(replace(snap, lesson=status))
        text = app.lessons.text.content
        for name in ITALIC.findall(text):
            for handle in names.get(name, []):
                if isinstance(handle, viser.GuiButtonHandle):
                    assert not handle.disabled, f"{status}: the text asks for {name!r}, which is disabled"
    last = lessons_for("trep")[-1]
    done = LessonStatus("trep", 6, 6, last.title, last.equation, last.text, last.task, True, "")
    app.lessons.refresh(replace(snap, lesson=done))
    assert app.lessons.next.disabled and "*Next*" not in app.lessons.text.content


def shown_strings() -> Iterator[tuple[str, str]]:
    """(where, text) of every string the app's panel, scene and lessons can show (the viz and live layers'
    string constants) and of the docs."""
    for path in sorted([*(ROOT / "viz").rglob("*.py"), *(ROOT / "live").rglob("*.py")]):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Constant) and isinstance(node.value, str):
                yield f"{path.name}:{node.lineno}", node.value
    for path in (ROOT.parent / "README.md", *sorted((ROOT.parent / "docs").rglob("*.md"))):
        yield path.name, path.read_text()


def test_the_distance_to_singularity_has_one_notation() -> None:
    found = [(where, text[m.start() : m.end()]) for where, text in shown_strings() for m in SIGMA_OF_HBM.finditer(text)]
    assert len(found) >= 5
    other = [(where, s) for where, s in found if not s.startswith(NOTATIONS)]
    assert not other, f"other notations of sigma_min(W S H_bm): {other}"


def test_the_readout_names_it_in_words_first(app: RnsApp) -> None:
    from rns_viz.viz.panels.panel_text import readouts_html

    html = readouts_html(app.session.snapshot())
    assert "distance to singularity σ<sub>min</sub>(W S H<sub>bm</sub>)" in html


def test_the_status_line_says_a_slow_rate_and_a_skip_apart(app: RnsApp) -> None:
    """After a stall the rate may be back at (or over) the speed while the skipped time is still said: the
    line never shows "falling behind" beside a rate at the speed."""
    from rns_viz.viz.panels.panel_text import status_html

    snap = replace(app.session.snapshot(), paused=False, diverged=None)
    caught_up = status_html(replace(snap, rtf=1.14, behind=False, skipped=0.31))
    assert "SKIPPED 0.31 s" in caught_up and "FALLING BEHIND" not in caught_up and "1.14× real time" in caught_up
    assert 'title="The processor was busy elsewhere' in caught_up  # what it means, on hovering it
    slow = status_html(replace(snap, rtf=0.7, behind=True, skipped=0.0))
    assert "FALLING BEHIND" in slow and "SKIPPED" not in slow
    steady = status_html(replace(snap, rtf=1.0, behind=False, skipped=0.0))
    assert "FALLING BEHIND" not in steady and "SKIPPED" not in steady


def test_the_status_line_marks_a_preset_changed_since_it_loaded(app: RnsApp) -> None:
    """The preset's name stays (its scene and forces run on), with what no longer holds of its description."""
    from rns_viz.viz.panels.panel_text import status_html

    s = app.session
    s.load_preset("fig10-on")
    s.advance(0.0)  # the command taken: the preset is built off the loop ...
    assert s.wait_background()  # ... and adopted
    st = s.snapshot().settings
    assert st.preset == "fig10-on" and "changed since" not in status_html(s.snapshot())
    g_b = st.gains.g_b
    s.set_gains(g_b=2 * g_b)
    s.set_suppression(False)
    s.advance(0.01)
    assert "fig10-on</b> <i>(gains, suppression changed since)</i>" in status_html(s.snapshot())
    s.set_gains(g_b=g_b)
    s.set_suppression(True)
    s.advance(0.01)
    assert "changed since" not in status_html(s.snapshot())  # back to the preset's own
    s.reset()
    s.advance(0.01)


def test_g_m_is_named_for_what_it_does_under_the_law(app: RnsApp) -> None:
    """g_m damps joint motion in (15)/(16) and pulls the joints to their reference in (30): its label says which."""
    from tests.support.browser import wait_until

    s, box = app.session, app.gui.gains["g_m"].slider
    for law, label in (("acceleration", "Joint damping g_m (1/s)"), ("velocity", "Joint hold g_m (1/s)")):
        s.set_law(law)
        s.advance(0.01)
        wait_until(lambda label=label: box.label == label, 5.0, f"g_m labelled {label!r} under law {law}")
