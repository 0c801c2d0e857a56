"""Words on screen that must be true: controls named by the lessons exist under those names and are not
disabled when a lesson names them, and one quantity has one notation everywhere it is shown.

Lessons name a control in *italics*, exactly as the panel labels it (a folder or tab may be named without
its parenthesis: *Live plots* for the tab 'Live plots (last 10 s)')."""

from __future__ import annotations

import ast
import colorsys
import re
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest
import viser

import rns_viz
from rns_viz.defaults import defaults_for
from rns_viz.live.published.snapshot import LessonStatus
from rns_viz.live.teaching import lessons, lessons_boom
from rns_viz.live.teaching.lessons import lessons_for, models_with_lessons
from rns_viz.viz.panels import lesson_panel, live_plots
from rns_viz.viz.panels.glossary import GLOSSARY
from rns_viz.viz.panels.live_plots import E_TITLE, L_TITLE, XB_TITLE
from rns_viz.viz.scene.fsms_scene import (
    FORCE_COLOUR,
    PATH_COLOUR,
    PATH_HIGHLIGHT,
    REACH_COLOUR,
    TARGET_COLOUR,
    TRAIL_COLOUR,
    base_label,
)
from rns_viz.viz.scene.ghost import GHOST_OFF_COLOUR
from rns_viz.viz.scene.quantities import BASE_VIBRATION, HAND_MISS, MOMENTUM, QUANTITIES, REACTION, Quantity
from rns_viz.viz.scene.rank_scene import RANK_COLOUR
from rns_viz.viz.scene.reaction_arrows import MOMENT_COLOUR
from rns_viz.viz.scene.teach_scene import L_COLOUR, N_COLOUR
from rns_viz.viz.server.app import RnsApp, start_app
from tests.support.browser import wait_until

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
    s.switch_model("trep")  # live again, no preset (a reset would load the preset again)
    s.advance(0.0)
    assert s.wait_background() and s.snapshot().settings.preset is None


def test_g_m_is_named_for_what_it_does_under_the_law(app: RnsApp) -> None:
    """g_m damps joint motion in (15)/(16) and pulls the joints to their reference in (30): its label says which."""
    from tests.support.browser import wait_until

    s, box = app.session, app.gui.gains["g_m"].slider
    for law, label in (("acceleration", "Joint damping g_m (1/s)"), ("velocity", "Joint hold g_m (1/s)")):
        s.set_law(law)
        s.advance(0.01)
        assert s.wait_background() and s.snapshot().settings.law == law
        wait_until(lambda label=label: box.label == label, 20.0, f"g_m labelled {label!r} under law {law}")


# What gives a label away as naming a quantity (its symbol, or words people use for it); a label so named
# must carry the quantity's one name (plain words, then symbol) and state its one unit.
TELLS = {
    BASE_VIBRATION: re.compile(r"x_b|x<sub>b</sub>|\bxb\b|vibration(?! suppression)|\bbend", re.I),
    MOMENTUM: re.compile(r"\bL\b|momentum", re.I),
    HAND_MISS: re.compile(r"\|e\||\bmiss\b|error", re.I),
    REACTION: re.compile(r"reaction(?!-free|less)|push on the base|F_b|F<sub>b</sub>", re.I),
}
UNIT_IN_LABEL = re.compile(r"\(([^()]*)\)$")  # a toggle's unit: "… (N·s)"
HELP_UNIT = re.compile(r"(?<![\w·/])(N·s|kg·m/s|N m|N|m)(?![\w·/])")
VALUE = re.compile(r"[-+]?\d[\d.]*(?:e[-+]?\d+)? (\S+)")  # "+1.2 µN·s": a number and its unit


def value_unit(text: str) -> str | None:
    """The SI unit of the first value in ``text``, its prefix taken off ("+1.2 µN·s" -> "N·s")."""
    found = VALUE.search(text)
    if found is None:
        return None
    unit = found[1].rstrip(",;")
    return unit[1:] if unit[0] in "pnµmkM" and unit[1:] in {q.unit for q in QUANTITIES} else unit


def named(label: str) -> list[Quantity]:
    return [q for q, tell in TELLS.items() if tell.search(label)]


def name_errors(where: str, label: str, unit: str | None) -> list[str]:
    """What is wrong with ``label`` (shown with ``unit``, None: the label states none) for each quantity it names."""
    errors = []
    for q in named(label):
        names = (q.name, q.html_name, f"{q.words} |{q.symbol}|")  # |x_b|: its size, as a peak row says
        if not any(name.lower() in label.lower() for name in names):
            errors.append(f"{where}: {label!r} names {q.name!r} otherwise")
        if unit is not None and unit != q.unit:
            errors.append(f"{where}: {label!r} gives {q.name!r} in {unit}, not {q.unit}")
    return errors


@contextmanager
def app_on(model: str) -> Iterator[RnsApp]:
    app = start_app(model, port=0, realtime=False, verbose=False)
    try:
        app.session.advance(0.05)
        yield app
    finally:
        app.stop()


@pytest.mark.parametrize("model", ["trep", "planar3r", "trep2"])
def test_each_quantity_has_one_name_and_unit_in_toggles_charts_scene_and_help(model: str) -> None:
    """The toggles, chart titles, peak rows, scene labels and Help of every model call x_b, L, |e| and F_b
    by one name each, in one unit (trep2 used to say "residual reaction", Help "arm's push on the base",
    the momentum toggle kg·m/s where everything else says N·s)."""
    with app_on(model) as app:
        labels: list[tuple[str, str, str | None]] = []
        for name, box in app.view.boxes.items():
            unit = UNIT_IN_LABEL.search(box.label)
            labels.append((f"toggle {name}", UNIT_IN_LABEL.sub("", box.label).strip(), unit and unit[1]))
        for title in (XB_TITLE, L_TITLE, E_TITLE):
            labels.append(("chart", title, None))
        for key, label, unit in live_plots._ROWS:
            labels.append((f"peak {key}", label, unit))
        for plain, symbol, what, _ in GLOSSARY:
            unit = HELP_UNIT.search(what)  # the first unit its description states
            labels.append(("help", f"{plain} {symbol}", unit and unit[1]))
        labels.append(("scene", base_label(3.0), None))
        app.view.show("reaction")
        app.view.show("coupling")
        app.session.kick(defaults_for(model).kick_peak_N)  # the arm's answer to a kick: L and a reaction
        teach = app.renderer.teach
        wait_until(lambda: (app.session.advance(0.02), bool(teach.coupling_label.text))[1], 20.0, "L's label")
        name, _, value = teach.coupling_label.text.partition(" = ")
        labels.append(("scene L", name, value_unit(value)))
        wait_until(lambda: (app.session.advance(0.02), bool(app.scene.force_label.text))[1], 20.0, "F_b's label")
        reaction = app.scene.force_label.text
        labels.append(("scene F_b", reaction.partition(" = ")[0], value_unit(reaction)))
        errors = [e for where, label, unit in labels for e in name_errors(where, label, unit)]
        assert {q for _, label, _ in labels for q in named(label)} == set(QUANTITIES)
        assert not errors, "\n".join(errors)


READOUT_ROW = re.compile(r'<td style="padding-right:8px">(.*?)</td><td>(.*?)</td>')


@pytest.mark.parametrize("model", ["trep", "trep2"])
def test_the_readouts_name_each_quantity_as_everywhere_else(model: str) -> None:
    from rns_viz.viz.panels.panel_text import readouts_html

    with app_on(model) as app:
        rows = READOUT_ROW.findall(readouts_html(app.session.snapshot()))
        assert len(rows) >= 6
        errors = [
            e for name, value in rows for e in name_errors("readout", name, value_unit(re.sub("<[^>]+>", "", value)))
        ]
        assert {q for name, _ in rows for q in named(name)} == set(QUANTITIES)
        assert not errors, "\n".join(errors)


COLOUR = r"(red|crimson|magenta|pink|purple|violet|lilac|blue|green|orange|amber|yellow|grey|gray)"
# Hue ranges (degrees, start to end going up through 360) each colour word may name; lilac is a pale purple.
HUES = {
    "red": (345, 15),
    "crimson": (330, 355),
    "magenta": (290, 335),
    "pink": (300, 355),
    "purple": (255, 300),
    "violet": (255, 300),
    "lilac": (240, 290),
    "blue": (195, 250),
    "green": (80, 165),
    "orange": (18, 45),
    "amber": (30, 50),
    "yellow": (45, 70),
}


def names_colour(word: str, rgb: tuple[float, ...]) -> bool:
    """Whether a person would call ``rgb`` (0-1 or 0-255) ``word``: grey is unsaturated, the rest a hue range."""
    scale = 255.0 if max(rgb) > 1.0 else 1.0
    hue, saturation, value = colorsys.rgb_to_hsv(*(c / scale for c in rgb))
    if word in ("grey", "gray"):
        return saturation < 0.15
    if word == "lilac" and not (0.1 < saturation < 0.45 and value > 0.75):
        return False
    if saturation < 0.15 and word != "lilac":
        return False
    lo, hi = HUES[word]
    degrees = 360.0 * hue
    return lo <= degrees <= hi if lo < hi else degrees >= lo or degrees <= hi


def test_the_hue_names_are_those_a_person_would_use() -> None:
    assert (
        names_colour("red", (255, 0, 0)) and names_colour("red", (180, 0, 0)) and not names_colour("red", (0, 0, 255))
    )
    assert names_colour("crimson", (0.90, 0.05, 0.30)) and not names_colour("red", (0.90, 0.05, 0.30))
    assert names_colour("grey", (128, 128, 128)) and not names_colour("grey", (0.62, 0.74, 0.88))
    assert names_colour("lilac", (196, 182, 236)) and not names_colour("lilac", (120, 40, 170))


# Each scene object, the colour it is drawn in and how the app's texts write its colour (one group: the word).
SCENE_COLOURS: dict[str, tuple[tuple[float, ...], tuple[str, ...]]] = {
    "current path": (
        PATH_HIGHLIGHT,
        (
            rf"\b{COLOUR} (?:reactionless )?(?:path|curve)\b",
            rf"(?:current one|reactionless path|current path) \({COLOUR}\b",
            rf"current path is always drawn in {COLOUR}",
        ),
    ),
    "other paths": (PATH_COLOUR, (rf"paths \({COLOUR}\)", rf"the {COLOUR} family")),
    "reaction force": (
        FORCE_COLOUR,
        (
            rf"{COLOUR} arrow: (?:the force|−)",
            rf"{COLOUR} arrow is the",
            rf"base \({COLOUR} arrow, −",
            rf"{COLOUR} force arrow",
        ),
    ),
    "reaction moment": (MOMENT_COLOUR, (rf"{COLOUR} moment arrow",)),
    "momentum L": (
        L_COLOUR,
        (rf"{COLOUR} arrow: the momentum", rf"\({COLOUR} arrow\), Eq\. \(8\)", rf"θ' \({COLOUR},"),
    ),
    "reaction-free direction n": (
        N_COLOUR,
        (rf"{COLOUR} arrow at the hand", rf"\({COLOUR} arrow: the hand", rf"produces \({COLOUR}"),
    ),
    "trail": (TRAIL_COLOUR, (rf"{COLOUR} line: where the hand",)),
    "reachable set": (REACH_COLOUR, (rf"(?<!-){COLOUR} dots",)),
    "rank-loss poses": (
        RANK_COLOUR,
        (rf"{COLOUR} (?:poses|links)", rf"(?:poses|configurations) (?:drawn )?in {COLOUR}"),
    ),
    # the ghost takes its run's colour in the plots (blue: suppression on, red: off); the texts name the off one
    "ghost, suppression off": (
        GHOST_OFF_COLOUR,
        (
            rf"{COLOUR} ghost \(suppression off\)",
            rf"{COLOUR} ghost is the shadow run, suppression off",
            rf"\(suppression off\) as a {COLOUR} ghost",
        ),
    ),
    "target": (TARGET_COLOUR, (rf"{COLOUR} target marker",)),
}
# A colour word right before one of these (or in brackets after it) is about a scene object: the table above
# must know every such phrase (not a colour map's ends, as in 'yellow-to-purple dots').
ABOUT_THE_SCENE = re.compile(
    rf"(?<![-\w]){COLOUR} (?:\w+ )?(?:arrow|path|curve|dots|poses|links|ghost|family|marker)s?\b", re.I
)


def test_every_colour_word_about_a_scene_object_names_the_colour_it_is_drawn_in() -> None:
    """The current path is drawn crimson, not red (red is the reaction arrow, and 'suppression off' in the
    plots), the path family grey, the ghost blue...: every phrase of the panel, Help, lessons and docs that
    gives a scene object's colour names its hue."""
    texts = list(shown_strings())
    wrong, counted, seen = [], dict.fromkeys(SCENE_COLOURS, 0), set()
    for obj, (rgb, patterns) in SCENE_COLOURS.items():
        for where, text in texts:
            for pattern in patterns:
                for m in re.finditer(pattern, text, re.I):
                    counted[obj] += 1
                    seen.add((where, m.start(1)))
                    if not names_colour(m[1].lower(), rgb):
                        wrong.append(f"{where}: {obj} said {m[1]!r} in {text[max(0, m.start() - 30) : m.end() + 10]!r}")
    assert all(counted.values()), f"phrases the table no longer finds: {[o for o, n in counted.items() if not n]}"
    unknown = [
        f"{where}: {m[0]!r}"
        for where, text in texts
        for m in ABOUT_THE_SCENE.finditer(text)
        if (where, m.start(1)) not in seen
    ]
    assert not unknown, f"colour words about the scene the table does not know: {unknown}"
    assert not wrong, "\n".join(wrong)
