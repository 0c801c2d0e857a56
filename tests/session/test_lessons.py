"""Each lesson's check turns true when a scripted student does the task, and stays false otherwise
(for instance, the joint-2-only motion fails the reactionless-path lesson: it moves the base 1.3 mm)."""

from __future__ import annotations

from collections.abc import Callable, Iterator

import numpy as np
import pytest

from rns_viz.live.loop.session import Session
from rns_viz.live.teaching.lessons import lessons_for
from tests.support.app_helpers import run_lesson


@pytest.fixture(scope="module")
def trep_session() -> Iterator[Session]:
    s = Session("trep", realtime=False)
    yield s
    s.stop()


@pytest.fixture(scope="module")
def planar_session() -> Iterator[Session]:
    s = Session("planar3r", realtime=False)
    yield s
    s.stop()


def kick_then(seconds: float, peak: float | None = None) -> Callable[[Session], None]:
    def student(s: Session) -> None:
        s.kick(peak if peak is not None else (0.8 if s.snapshot().settings.model == "trep" else 5.0))
        s.advance(seconds)

    return student


def wait(seconds: float) -> Callable[[Session], None]:
    return lambda s: s.advance(seconds)


def then(*steps: Callable[[Session], None]) -> Callable[[Session], None]:
    def student(s: Session) -> None:
        for step in steps:
            step(s)

    return student


def press(name: str, *args: object) -> Callable[[Session], None]:
    return lambda s: getattr(s, name)(*args)


TREP_CASES = [
    (1, kick_then(3.5), True),
    (1, wait(3.5), False),  # no kick: nothing to see
    (1, kick_then(3.5, peak=0.05), False),  # too small to see (0.3 mm): "kick harder"
    (1, then(press("set_suppression", True), kick_then(3.5)), False),  # suppression damps it: not undamped
    (2, then(press("point_to_point"), wait(4.0)), True),
    (2, then(press("play_slow"), wait(6.0)), False),  # reactionless: the base stays still
    (3, then(press("play_slow"), wait(6.0)), True),
    (3, then(press("point_to_point"), wait(4.0)), False),  # joint 2 alone: the base moves 1.3 mm
    (4, kick_then(9.0), True),
    (4, then(press("set_suppression", False), kick_then(9.0)), False),  # off: nothing decays
    (5, then(press("play_slow"), wait(6.0)), True),
    (5, wait(1.0), False),  # at the start sigma(H_bm) is at its largest
    (6, then(press("cyclic", True), wait(2.0), kick_then(9.0)), True),
    (6, then(press("cyclic", True), wait(4.0)), False),  # no kick
]


@pytest.mark.parametrize(("number", "student", "expected"), TREP_CASES)
def test_trep_lessons(trep_session: Session, number: int, student: Callable[[Session], None], expected: bool) -> None:
    done, progress = run_lesson(trep_session, "trep", number, student)
    assert done is expected, progress
    trep_session.stop_lesson()
    trep_session.reset()


def drag_by(dx: float, dy: float, seconds: float) -> Callable[[Session], None]:
    def student(s: Session) -> None:
        start = s.state.model.ee_position(s.state.runs.theta)[:2]
        s.set_target(start + np.array([dx, dy]), True)
        s.advance(seconds)

    return student


def drag_to(x: float, y: float, seconds: float) -> Callable[[Session], None]:
    def student(s: Session) -> None:
        s.set_target((x, y), True)
        s.advance(seconds)

    return student


PLANAR_CASES = [
    (1, drag_by(-0.15, 0.15, 4.0), True),
    (1, drag_by(-0.03, 0.03, 4.0), False),  # 4 cm is not 20
    (2, drag_to(10.0, 0.0, 5.0), True),
    (2, wait(4.0), False),  # no drag: nothing moved
    (3, kick_then(12.0), True),
    (3, kick_then(12.0, peak=0.2), False),  # too soft to count
]


@pytest.mark.parametrize(("number", "student", "expected"), PLANAR_CASES)
def test_planar3r_lessons(
    planar_session: Session, number: int, student: Callable[[Session], None], expected: bool
) -> None:
    done, progress = run_lesson(planar_session, "planar3r", number, student)
    assert done is expected, progress
    planar_session.stop_lesson()
    planar_session.reset()


def test_every_lesson_is_checked_here() -> None:
    assert {n for n, _, _ in TREP_CASES} == set(range(1, len(lessons_for("trep")) + 1))
    assert {n for n, _, _ in PLANAR_CASES} == set(range(1, len(lessons_for("planar3r")) + 1))


def test_bad_lesson_numbers_are_refused() -> None:
    s = Session("trep", realtime=False)
    try:
        for model, number in (("trep", 0), ("trep", 99), ("nope", 1), ("trep", True)):
            with pytest.raises(ValueError):
                s.start_lesson(model, number)  # type: ignore[arg-type]
    finally:
        s.stop()


@pytest.mark.parametrize(
    ("student", "advice"),
    [
        (kick_then(3.5, peak=0.05), "kick harder"),
        (then(press("set_suppression", True), kick_then(3.5)), "Untick *Vibration suppression*"),
    ],
)
def test_lesson_1_says_why_a_kick_does_not_count(
    trep_session: Session, student: Callable[[Session], None], advice: str
) -> None:
    done, progress = run_lesson(trep_session, "trep", 1, student)
    trep_session.stop_lesson()
    trep_session.reset()
    assert not done and advice in progress, progress
