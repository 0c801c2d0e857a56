"""boom7's lesson table: three lessons, the third on forces only (each lesson walked in a session:
tests/session/test_lessons_boom.py)."""

from __future__ import annotations

from rns_viz.live.teaching.lessons import lessons_for


def test_boom7_has_three_lessons() -> None:
    assert [lesson.start.model for lesson in lessons_for("boom7")] == ["boom7", "boom7", "boom7#S=111000"]
