"""The reaction's base rows in a recording: boom7's replay shows the same reaction (Eq. 1's
−(H_bm θ'' + c_b), all six rows) the live loop published at the same instants, and its CSV carries them
with units (the player file's arrows: tests/app/test_replay_wrench.py)."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import replace

import numpy as np
import pytest

from rns_viz.csvio import read_csv
from rns_viz.live.loop.replay_mode import replay_snapshot
from rns_viz.live.loop.session import Session
from rns_viz.live.published.snapshot import ReplayView
from tests.support.app_helpers import kicked_boom7


@pytest.fixture(scope="module")
def boom7_run() -> Iterator[tuple[Session, dict[float, object]]]:
    """boom7 kicked sideways with suppression on: the arm reacts in every row."""
    yield from kicked_boom7()


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


def test_csv_carries_the_wrench_with_units(boom7_run: tuple[Session, dict[float, object]]) -> None:
    s, _ = boom7_run
    rec = s.recording(0.2)
    assert rec is not None
    header = rec.csv().decode().splitlines()[0].split(",")
    for i in range(1, 4):
        assert f"reaction_{i} (N)" in header and f"reaction_{i + 3} (N m)" in header
    assert "xb_4 (rad)" in header and "xb_1 (m)" in header
    table = read_csv(rec.csv())
    assert table.columns == rec.columns
    assert np.array_equal(table.rows, rec.table, equal_nan=True)


def _replaying(live: object, rec: object, t: float) -> object:
    """``live`` with a paused replay of ``rec`` at ``t`` (what the loop publishes after a seek)."""
    return replace(live, replay=ReplayView(rec, t, 0.0, 1.0, False, 0, True))
