"""The reaction's base rows in boom7's player file: the exported scene draws, frame by frame, the force and
moment arrows (Eq. 1's −(H_bm θ'' + c_b), all six rows) the live scene drew at the same instants."""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pytest

from rns_viz.live.loop.session import Session
from rns_viz.viz.scene import player_export as player
from rns_viz.viz.scene.fsms_scene import FsmsScene
from tests.support.app_helpers import kicked_boom7


@pytest.fixture(scope="module")
def boom7_run() -> Iterator[tuple[Session, dict[float, object]]]:
    """boom7 kicked sideways with suppression on: the arm reacts in every row."""
    yield from kicked_boom7()


def test_player_file_draws_the_live_wrench(
    boom7_run: tuple[Session, dict[float, object]], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The exported scene's arrows get, frame by frame, the wrench the live scene drew at that instant."""
    s, snaps = boom7_run
    rec = s.recording(0.6)
    assert rec is not None
    drawn: list[tuple[float, ...]] = []
    original = FsmsScene.set_reaction_force

    def spy(self: FsmsScene, f: float, label: str = "F", wrench: tuple[float, ...] = ()) -> None:
        drawn.append(tuple(wrench))
        original(self, f, label, wrench)

    monkeypatch.setattr(FsmsScene, "set_reaction_force", spy)
    data = player.scene_file(rec, s.snapshot())
    t0, t1 = rec.span
    times = np.arange(t0, t1 + 0.5 * rec.dt, player.FRAME_S)
    assert len(drawn) == len(times)
    live_times = np.array(sorted(snaps))
    matched = 0
    for t, wrench in zip(times, drawn, strict=True):
        assert wrench == rec.wrench(rec.at(float(t)))
        near = live_times[np.abs(live_times - t) < 0.25 * rec.dt]
        if len(near):  # a frame at an instant the live loop published: its wrench, exactly
            assert wrench == snaps[float(near[0])].readouts.reaction_wrench
            matched += 1
    assert sum(1 for w in drawn if len(w) == 6) >= len(drawn) - 2 and matched >= 1
    # a sane file: 30 frames per second of a few kB each
    assert len(data) <= 40_000 * len(times)
