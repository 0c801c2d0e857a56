"""The reaction's base rows in a recording: boom7's replay and player file draw the same force and moment
arrows (Eq. 1's −(H_bm θ'' + c_b), all six rows) as the live scene did at the same instants."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from rns_viz.live.loop.replay_mode import replay_snapshot
from rns_viz.live.loop.session import Session
from rns_viz.live.published.recording import reaction_columns, read_csv
from rns_viz.live.published.snapshot import ReplayView
from rns_viz.viz.scene import player_export as player
from rns_viz.viz.scene.fsms_scene import FsmsScene

BOOM7_KICK_N = 5.0  # N: the app's kick, along the tip's y and z


@pytest.fixture(scope="module")
def boom7_run() -> tuple[Session, dict[float, object]]:
    """boom7 kicked sideways with suppression on: the arm reacts in every row."""
    s = Session("boom7", realtime=False)
    assert s.wait_background(120.0)
    s.kick(BOOM7_KICK_N, direction=(0.0, 1.0, 1.0, 0.0, 0.0, 0.0))
    snaps = {}
    for _ in range(60):
        s.advance(0.01)
        snap = s.snapshot()
        snaps[snap.t] = snap
    yield s, snaps
    s.stop()


def test_a_recording_keeps_every_row_of_the_reaction() -> None:
    assert reaction_columns(1) == ("reaction",)  # a 1-DOF base: one column, its name unchanged
    assert reaction_columns(6) == tuple(f"reaction_{i}" for i in range(1, 7))


def test_replay_shows_the_live_wrench_at_the_same_instants(boom7_run: tuple[Session, dict[float, object]]) -> None:
    s, snaps = boom7_run
    rec = s.recording(0.6)
    assert rec is not None
    t0, t1 = rec.span
    shown = [t for t in snaps if t0 <= t <= t1]
    assert len(shown) >= 50
    wrenches = []
    for t in shown:
        live = snaps[t]
        frame = replay_snapshot(_replaying(live, rec, t))
        assert frame.t == t
        assert frame.readouts.reaction_wrench == live.readouts.reaction_wrench  # the same floats
        assert frame.readouts.reaction == live.readouts.reaction
        wrenches.append(live.readouts.reaction_wrench)
    w = np.array([x for x in wrenches if x])
    assert w.shape[1] == 6 and len(w) >= 40
    assert np.all(np.abs(w).max(axis=0) > 1e-3)  # every row reacts to the kick (N, N m) ...
    assert np.all(np.ptp(w, axis=0) > 1e-4)  # ... and changes over the recording


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


def test_csv_carries_the_wrench_with_units(boom7_run: tuple[Session, dict[float, object]]) -> None:
    s, _ = boom7_run
    rec = s.recording(0.2)
    assert rec is not None
    header = rec.csv().decode().splitlines()[0].split(",")
    for i in range(1, 4):
        assert f"reaction_{i} (N)" in header and f"reaction_{i + 3} (N m)" in header
    assert "xb_4 (rad)" in header and "xb_1 (m)" in header
    names, rows = read_csv(rec.csv())
    assert tuple(names) == rec.columns
    assert np.array_equal(rows, rec.table, equal_nan=True)


def _replaying(live: object, rec: object, t: float) -> object:
    """``live`` with a paused replay of ``rec`` at ``t`` (what the loop publishes after a seek)."""
    return replace(live, replay=ReplayView(rec, t, 0.0, 1.0, False, 0, True))
