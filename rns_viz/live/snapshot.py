"""The immutable snapshot of a live session that readers (the GUI's render loop) take."""

from __future__ import annotations

import math
from dataclasses import replace
from typing import TYPE_CHECKING

from rns_viz.live.records import Snapshot

if TYPE_CHECKING:
    from rns_viz.live.state import LiveState


def make_snapshot(state: LiveState, realtime: bool) -> Snapshot:
    """The loop's state for readers: a new immutable record each time."""
    sim, op, out = state.runs.sim, state.operator, state.outputs
    table = op.table if op is not None and op.on_path else None
    mode, target = (op.mode, op.target) if op is not None else (f"preset {state.settings.preset}", None)
    readouts = replace(out.readouts, reaction=out.reaction)
    shadow_on = state.settings.shadow
    return Snapshot(
        epoch=state.epoch,
        settings=state.settings,
        settings_version=state.settings_version,
        steps=out.steps,
        t=sim.t,
        q=sim.q.copy(),
        q_shadow=state.runs.shadow.q.copy() if shadow_on else None,
        paused=state.paused,
        diverged=state.diverged,
        rtf=0.0 if state.paused else state.pacer.rtf() if realtime else math.nan,
        behind=realtime and not state.paused and state.pacer.behind(),
        mode="paused" if state.paused and not state.diverged else mode,
        target=None if target is None else target.copy(),
        target_version=state.target_version,
        sigma=op.sigma if op is not None else None,
        sigma_range=None
        if table is None
        else ((-0.5 * table.period, 0.5 * table.period) if table.closed else (table.lo, table.hi)),
        readouts=readouts,
        overlay_version=state.overlay_version,
        lesson=state.lesson.status() if state.lesson is not None else None,
    )
