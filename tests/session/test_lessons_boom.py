"""boom7's lessons: each check turns true when a scripted student does the task and stays false when
the student does something else (no kick felt, suppression off, a kick during the reactionless path,
a drag too short)."""

from __future__ import annotations

from collections.abc import Callable, Iterator

import numpy as np
import pytest

from rns_viz.live.loop.session import Session
from tests.support.app_helpers import run_lesson, stepped_session

SIDEWAYS = (0.0, 1.0, 0.0, 0.0, 0.0, 0.0)


@pytest.fixture(scope="module")
def boom7_session() -> Iterator[Session]:
    """One boom7 session for the module (each lesson restarts it from the lesson's start)."""
    yield from stepped_session("boom7")


def kick(s: Session, seconds: float = 2.5) -> None:
    s.kick(5.0, direction=SIDEWAYS)
    s.advance(seconds)


def test_a_kick_suppressed_in_six_modes(boom7_session: Session) -> None:
    done, message = run_lesson(boom7_session, "boom7", 1, kick)
    assert done, message
    assert "mrad" in message and "%" in message


def test_without_suppression_the_kick_lesson_is_not_done(boom7_session: Session) -> None:
    def student(s: Session) -> None:
        s.set_suppression(False)  # the operated run rings; the shadow (suppression on) is the one that stops
        kick(s)

    done, message = run_lesson(boom7_session, "boom7", 1, student)
    assert not done, message


def test_the_reactionless_path_keeps_the_boom_still(boom7_session: Session) -> None:
    def student(s: Session) -> None:
        lo, _ = s.snapshot().sigma_range  # type: ignore[misc]
        s.scrub(0.5 * lo)  # about 4 cm of hand motion
        s.advance(5.0)

    done, message = run_lesson(boom7_session, "boom7", 2, student)
    assert done, message


def test_a_kick_during_the_path_lesson_fails_it(boom7_session: Session) -> None:
    done, message = run_lesson(boom7_session, "boom7", 2, lambda s: kick(s, 0.5))
    assert not done and "too much" in message


def drag(offset: tuple[float, float, float]) -> Callable[[Session], None]:
    def student(s: Session) -> None:
        goal = np.asarray(s.snapshot().target) + np.array(offset)
        s.set_target(tuple(goal), final=True)
        s.advance(3.0)

    return student


def test_forces_only_tracking_keeps_the_force_rows_near_zero(boom7_session: Session) -> None:
    done, message = run_lesson(boom7_session, "boom7", 3, drag((0.04, -0.02, 0.02)))
    assert boom7_session.snapshot().settings.model == "boom7#S=111000"
    assert done, message


def test_a_short_drag_does_not_finish_the_forces_only_lesson(boom7_session: Session) -> None:
    done, message = run_lesson(boom7_session, "boom7", 3, drag((0.01, 0.0, 0.0)))
    assert not done and "Hand moved 1." in message
