"""Replay: a mode of the live session in which the simulation waits and a recording is shown instead.

The loop applies the replay commands (:func:`apply_replay`, called by
:meth:`rns_viz.live.loop.state.LiveState.apply`): *start* takes the newest N seconds from the recorder
(:mod:`rns_viz.live.outputs.recorder`) into an immutable
:class:`~rns_viz.live.published.snapshot.ReplayView` and pauses the simulation; *seek*, *speed* and
*play/pause* make a new view; *stop*, or any other input, goes back to live with the simulation as it
was (running again if it ran). Readers turn the view into the snapshot they draw with
:func:`replay_snapshot`, so the arm, ghost, overlays and plots are drawn by the same code as live, from
the recorded states.
"""

from __future__ import annotations

import time
from dataclasses import replace
from typing import Protocol

from rns_viz.live.loop import commands as c
from rns_viz.live.loop.wall_clock import Pacer
from rns_viz.live.operator.operator import InputRefused
from rns_viz.live.outputs.step_outputs import Outputs
from rns_viz.live.published.recording import Recording
from rns_viz.live.published.snapshot import ReplayView, Snapshot
from rns_viz.live.runs.run_pair import RunPair
from rns_viz.model import FsmsModel

SEEK_SLACK_S = 0.01  # s: a seek this close outside the recording goes to its end (the timeline's resolution)


class ReplayHost(Protocol):
    """What the replay touches of the loop's state (:class:`~rns_viz.live.loop.state.LiveState`)."""

    paused: bool
    replay: ReplayView | None
    pacer: Pacer
    runs: RunPair
    outputs: Outputs

    @property
    def model(self) -> FsmsModel: ...


def apply_replay(state: ReplayHost, cmd: c.Command) -> bool:
    """Apply ``cmd`` if it is a replay command (True). Any other input ends a replay first (back to
    live) and is left for the live simulation (False). Raises InputRefused with the reason."""
    view = state.replay
    if not isinstance(cmd, c.ReplayCommand):
        if view is not None:
            _back_to_live(state, view)
        return False
    now = time.perf_counter()
    if isinstance(cmd, c.StartReplay):
        recording = state.outputs.recorder.take(cmd.seconds, state.model)
        if recording is None:
            raise InputRefused("nothing is recorded yet: let the simulation run a moment first")
        was_paused = view.was_paused if view is not None else state.paused
        version = view.version + 1 if view is not None else 0
        state.paused = True
        state.replay = ReplayView(recording, recording.span[0], now, 1.0, True, version, was_paused)
        return True
    if view is None:
        raise InputRefused("no replay is running: press Replay first")
    here = view.position(now)
    match cmd:
        case c.SeekReplay(t=t):
            t0, t1 = view.recording.span
            if not t0 - SEEK_SLACK_S <= t <= t1 + SEEK_SLACK_S:
                raise InputRefused(f"replay time must be within the recording, {t0:.3f} s to {t1:.3f} s; got {t:g} s")
            view = replace(view, start=min(max(t, t0), t1))
        case c.SetReplaySpeed(speed=speed):
            view = replace(view, start=here, speed=speed)
        case c.PlayReplay(on=on):
            at_end = here >= view.recording.span[1]
            view = replace(view, start=view.recording.span[0] if on and at_end else here, playing=on)
        case c.StopReplay():
            _back_to_live(state, view)
            return True
    state.replay = replace(view, wall=now, version=view.version + 1)
    return True


def _back_to_live(state: ReplayHost, view: ReplayView) -> None:
    """The live simulation as it was before the replay, running on from its own time if it ran."""
    state.replay = None
    state.paused = view.was_paused
    if not state.paused:
        state.pacer.reanchor(state.runs.t)


def readout_row(rec: Recording) -> int:
    """The base row the reaction readout shows: the first selected one (as rns_viz.live.outputs.step_outputs)."""
    return int(rec.model.selected[0])


def replay_snapshot(live: Snapshot, now: float | None = None) -> Snapshot:
    """What to draw at wall time ``now``: the live snapshot, or during a replay the recorded step at the
    playhead in its place (t, q, the shadow's q, L, the reaction, suppression on or off)."""
    view = live.replay
    if view is None:
        return live
    rec = view.recording
    position = view.position(time.perf_counter() if now is None else now)
    k = rec.at(position)
    q_shadow = rec.q_shadow(k)
    wrench = rec.wrench(k)  # every base row of the reaction, as the live scene draws it
    reaction = wrench[readout_row(rec)] if wrench else 0.0
    readouts = replace(
        live.readouts,
        L=rec.value(k, "L_1"),
        reaction=reaction,
        reaction_wrench=wrench,
        reaction_t=rec.value(k, "t"),
        sigma_hbm=rec.value(k, "sigma_hbm"),
    )
    t0, t1 = rec.span
    state = f"{view.speed:g}×" if view.playing and position < t1 else "paused"
    return replace(
        live,
        t=rec.value(k, "t"),
        q=rec.q(k).copy(),
        q_shadow=None if q_shadow is None else q_shadow.copy(),
        settings=replace(live.settings, suppress=rec.value(k, "suppress") > 0.5, shadow=q_shadow is not None),
        mode=f"replay {position - t0:.1f} of {t1 - t0:.1f} s, {state}",
        target=None,
        readouts=readouts,
    )
