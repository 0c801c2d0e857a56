"""Record and replay: the last minute is always recorded; a replay shows exactly the recorded
states while the simulation waits; exports read back exactly; bad replay input is refused.

Oracles: the simulation's own step log and the snapshots the loop published while it ran (the
recording must hold the same floats, not a recomputation), a CSV read back, and the simulation's time
and state before and after a replay.
"""

from __future__ import annotations

import math
import time
from collections.abc import Iterator

import numpy as np
import pytest

from rns_viz.csvio import read_csv
from rns_viz.live.loop import commands as c
from rns_viz.live.loop.replay_mode import replay_snapshot
from rns_viz.live.loop.session import Session
from rns_viz.live.outputs.recorder import MAX_RECORD_S
from tests.support.browser import wait_until

KICKS = {"trep": 0.8, "planar3r": 5.0}


def run_recording(model: str, seconds: float = 1.5) -> tuple[Session, dict[float, object]]:
    """A session kicked and (TREP) moved along its path, with every published snapshot by time."""
    s = Session(model, realtime=False)
    assert s.wait_background()
    s.kick(KICKS[model])
    if model == "trep":
        s.play_fast()
    snaps = {}
    for _ in range(round(seconds / 0.01)):
        s.advance(0.01)
        snap = s.snapshot()
        snaps[snap.t] = snap
    return s, snaps


@pytest.fixture(params=["trep", "planar3r"])
def recorded(request: pytest.FixtureRequest) -> Iterator[tuple[Session, dict[float, object]]]:
    s, snaps = run_recording(request.param)
    yield s, snaps
    s.stop()


def test_recording_holds_the_simulation_logs_floats(recorded: tuple[Session, dict[float, object]]) -> None:
    s, _ = recorded
    rec = s.recording(1.0)
    assert rec is not None and len(rec) == 1000  # the newest second, one row per 1 ms step
    log = s.state.runs.sim.log
    rows = log.array()  # the log fills its end-effector columns on reading; the recording's table likewise
    width = len(log.columns)
    assert rec.columns[:width] == tuple(log.columns)
    k = np.searchsorted(rows[:, 0], rec.t[0])
    assert np.array_equal(rec.table[:, :width], rows[k : k + len(rec)], equal_nan=True)
    assert rec.t[-1] == rows[-1, 0]  # up to the newest step


def test_replay_shows_bit_exactly_the_states_it_recorded(recorded: tuple[Session, dict[float, object]]) -> None:
    s, snaps = recorded
    s.start_replay(1.0)
    s.play_replay(False)  # paused: the playhead stays where it is sought
    s.advance(0.0)
    assert s.snapshot().replay is not None and s.snapshot().paused
    rec = s.snapshot().replay.recording
    t0, t1 = rec.span
    shown = [t for t in snaps if t0 <= t <= t1]  # the states published while it ran, inside the recording
    assert len(shown) >= 90
    for t in shown:
        s.seek_replay(t)
        s.advance(0.0)
        view = replay_snapshot(s.snapshot())
        live = snaps[t]
        assert view.t == t
        assert np.array_equal(view.q, live.q)  # bit-exact: the same floats the loop published
        assert live.q_shadow is not None and np.array_equal(view.q_shadow, live.q_shadow)
        k = rec.at(t)
        assert np.array_equal(rec.v(k), s.state.runs.sim.log.array()[-(len(rec) - k), rec._v])
    # The replayed plots: the live plot samples at the same times have the same x_b of both runs.
    live_plots, replayed = s.plot_arrays(), rec.plot_arrays(t1)
    common, a, b = np.intersect1d(live_plots["t"], replayed["t"], return_indices=True)
    assert len(common) >= 10
    for key in ("xb", "xb_shadow"):
        assert np.array_equal(live_plots[key][a], replayed[key][b])


def test_csv_reads_back_the_recording_with_units() -> None:
    s, _ = run_recording("trep", 0.5)
    try:
        rec = s.recording(0.5)
        assert rec is not None
        data = rec.csv()
        header = data.decode().splitlines()[0].split(",")
        for cell in ("t (s)", "xb_1 (m)", "theta_1 (rad)", "thetadot_1 (rad/s)", "tau_1 (N m)", "L_1 (kg m/s)"):
            assert cell in header
        assert "shadow_xb_1 (m)" in header and "reaction (N)" in header
        table = read_csv(data)
        assert table.columns == rec.columns and table.units == rec.units
        assert np.array_equal(table.rows, rec.table, equal_nan=True)  # 17 digits: every float back exactly
    finally:
        s.stop()


@pytest.mark.parametrize("model", ["trep", "planar3r"])
def test_sixty_seconds_fit_in_fifty_megabytes(model: str) -> None:
    s = Session(model, realtime=False)
    try:
        s.advance(0.01)
        recorder = s.state.outputs.recorder
        assert recorder.seconds == MAX_RECORD_S
        assert recorder.nbytes() <= 50e6  # the whole ring, allocated at the first step
        assert recorder.nbytes() >= MAX_RECORD_S / s.dt * len(recorder.columns) * 8
    finally:
        s.stop()


def test_bad_replay_input_is_refused_and_the_simulation_is_intact() -> None:
    s, _ = run_recording("trep", 0.5)
    try:
        for bad in (
            lambda: c.SetReplaySpeed(math.nan),
            lambda: c.SetReplaySpeed(10.0),
            lambda: c.SetReplaySpeed(0.0),
            lambda: c.SeekReplay(math.inf),
            lambda: c.SeekReplay(-1.0),
            lambda: c.StartReplay(0.0),
            lambda: c.StartReplay(61.0),
            lambda: c.StartReplay(math.nan),
            lambda: c.PlayReplay("yes"),  # type: ignore[arg-type]
        ):
            with pytest.raises(ValueError):
                bad()
        before = s.snapshot()
        s.seek_replay(0.1)  # no replay running
        s.advance(0.0)
        notices = s.pop_notices()
        assert any("no replay is running" in n.body for n in notices)
        s.pause()
        s.start_replay(0.3)
        s.advance(0.0)
        view = s.snapshot().replay
        assert view is not None
        s.seek_replay(view.recording.span[1] + 1.0)  # outside the recording
        s.advance(0.0)
        assert any("within the recording" in n.body for n in s.pop_notices())
        after = s.snapshot()
        assert after.replay == view  # the replay as it was
        assert after.t == before.t and np.array_equal(after.q, before.q)  # the simulation untouched
    finally:
        s.stop()


def test_back_to_live_resumes_the_simulation_where_it_was() -> None:
    s, _ = run_recording("trep", 0.5)
    try:
        before = s.snapshot()
        x = np.concatenate((s.state.runs.sim.q, s.state.runs.sim.v))
        s.start_replay(0.5)
        s.set_replay_speed(4.0)
        s.advance(0.3)  # the simulation waits
        assert s.snapshot().t == before.t
        s.stop_replay()
        s.advance(0.0)
        snap = s.snapshot()
        assert snap.replay is None and not snap.paused
        assert snap.t == before.t and np.array_equal(np.concatenate((s.state.runs.sim.q, s.state.runs.sim.v)), x)
        s.advance(0.1)
        assert s.snapshot().t == pytest.approx(before.t + 0.1, abs=1e-9)
        # Paused before: paused after. Any live input ends a replay first and is applied.
        s.pause()
        s.start_replay(0.2)
        s.kick(0.5)
        s.advance(0.0)
        assert s.snapshot().replay is None and s.snapshot().paused
        assert len(s.state.runs.kicks.pulses) >= 1
    finally:
        s.stop()


def test_realtime_loop_waits_during_a_replay_and_goes_on_after() -> None:
    s = Session("trep", realtime=True)
    try:
        wait_until(lambda: s.snapshot().t > 0.3, 10.0, "the simulation to run")
        s.start_replay(0.2)
        wait_until(lambda: s.snapshot().replay is not None, 5.0, "the replay")
        t = s.snapshot().t
        time.sleep(0.4)
        assert s.snapshot().t == t  # waits
        s.stop_replay()
        wait_until(lambda: s.snapshot().t > t + 0.1, 5.0, "the simulation to go on")
        assert s.snapshot().t < t + 2.0  # from where it was, not caught up over the replay's wall time
    finally:
        s.stop()
