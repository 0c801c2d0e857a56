"""The immutable snapshot of a live session that readers (the GUI's render loop) take."""

from __future__ import annotations

from dataclasses import replace

from rns_viz.live.operator.operator import Operator
from rns_viz.live.outputs.step_outputs import Outputs
from rns_viz.live.published.snapshot import LessonStatus, ReplayView, Settings, Snapshot
from rns_viz.live.runs.run_pair import RunPair


def make_snapshot(
    settings: Settings,
    versions: tuple[int, int, int, int],
    runs: RunPair,
    op: Operator | None,
    out: Outputs,
    flags: tuple[bool, str | None, float, bool, float],
    lesson: LessonStatus | None,
    replay: ReplayView | None = None,
) -> Snapshot:
    """The loop's state for readers, a new immutable record each time. ``versions`` = (epoch, settings,
    target, overlay) versions; ``flags`` = (paused, why it diverged or None, real-time factor, behind,
    simulated s skipped lately)."""
    sim = runs.sim
    epoch, settings_version, target_version, overlay_version = versions
    paused, diverged, rtf, behind, skipped = flags
    table = op.table if op is not None else None
    mode, target = (op.mode, op.target) if op is not None else (f"preset {settings.preset}", None)
    readouts = replace(
        out.readouts, reaction=out.reaction, reaction_t=out.reaction_t, reaction_wrench=out.reaction_wrench
    )
    shadow_on = settings.shadow
    return Snapshot(
        epoch=epoch,
        settings=settings,
        settings_version=settings_version,
        steps=out.steps,
        t=sim.t,
        q=sim.q.copy(),
        q_shadow=runs.shadow.q.copy() if shadow_on else None,
        paused=paused,
        diverged=diverged,
        rtf=rtf,
        behind=behind,
        skipped=skipped,
        mode="paused" if paused and not diverged else mode,
        target=None if target is None else target.copy(),
        target_version=target_version,
        orientation=op.orientation_view() if op is not None else None,
        sigma=op.sigma if op is not None else None,
        sigma_range=None
        if table is None
        else ((-0.5 * table.period, 0.5 * table.period) if table.closed else (table.lo, table.hi)),
        readouts=readouts,
        overlay_version=overlay_version,
        lesson=lesson,
        replay=replay,
    )
