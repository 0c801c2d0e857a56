"""The CLI's --lesson option reaches the app's serve (serve itself stood in for)."""

from __future__ import annotations

import pytest


def test_cli_lesson_option_reaches_the_app(monkeypatch: pytest.MonkeyPatch) -> None:
    import rns_viz.viz.server.app as app_module
    from rns_viz import cli

    calls: list[dict[str, object]] = []
    monkeypatch.setattr(app_module, "serve", lambda **kw: calls.append(kw))
    assert cli.main(["--lesson", "2"]) == 0
    assert cli.main(["serve", "--model", "planar3r", "--lesson", "3", "--port", "0"]) == 0
    assert [(c["model"], c["lesson"]) for c in calls] == [("trep", 2), ("planar3r", 3)]
    assert cli.main(["serve", "--model", "planar3r", "--lesson", "4"]) == 2  # the 3R has three lessons
