"""trep2 in the live session (Sec. III-B, dynamic redundancy): the task arm follows the dragged target,
the compensating arm cancels its reaction; the shadow run does the same task with the compensator held.

Oracles: the shadow run itself (same task, compensator held), the task arm's workspace annulus
(link lengths from the model), and the compensator's coupling row sigma_min(S H_bm,2) recomputed.
"""

from __future__ import annotations

import numpy as np
import pytest

from rns_viz.live.loop.session import Session
from rns_viz.live.operator.dual_arm import TaskWorkspace
from rns_viz.model import FsmsModel
from rns_viz.scenarios import DUAL_SCENARIOS, LIVE_SCENARIOS

STEP_S = 0.01  # s between samples of both runs


def drag_and_sample(session: Session, target: tuple[float, float], seconds: float) -> dict[str, np.ndarray]:
    """Drag the target, run ``seconds``, sample x_b and both end effectors (base frame) every STEP_S."""
    model = session.state.model
    session.set_target(target, final=True)
    rows = []
    for _ in range(round(seconds / STEP_S)):
        session.advance(STEP_S)
        snap = session.snapshot()
        assert snap.q_shadow is not None
        m = model.m
        rows.append(
            np.concatenate(
                [[snap.q[0], snap.q_shadow[0]], model.ee_position(snap.q[m:])[:2], model.ee_position(snap.q_shadow[m:])]
            )
        )
    a = np.array(rows)
    return {"xb": a[:, 0], "xb_shadow": a[:, 1], "ee": a[:, 2:4], "ee_shadow": a[:, 4:6]}


def test_drag_compensated_base_stays_still_and_task_is_the_shadows() -> None:
    """Drag across the workspace: peak |x_b| <= 1 % of the shadow's (compensator held), the task arm's
    end effector (so its error against the common reference) equal in both runs to 1e-6 m, also in the
    second drag, which starts with the shadow's beam ringing at mm amplitude (D_b = 0): the held
    compensator is a servo evaluated at every RK4 stage, so the swing does not reach the task arm.
    """
    session = Session("trep2", realtime=False)
    session.advance(0.1)
    first = drag_and_sample(session, (0.06, 0.16), 3.0)
    second = drag_and_sample(session, (-0.08, 0.10), 3.0)
    for run in (first, second):
        assert np.abs(run["xb_shadow"]).max() > 1e-3  # the held compensator lets the task arm shake the beam (mm)
        assert np.abs(run["xb"]).max() <= 0.01 * np.abs(run["xb_shadow"]).max()
    for run in (first, second):
        assert np.linalg.norm(run["ee"] - run["ee_shadow"], axis=1).max() <= 1e-6  # m
    assert np.linalg.norm(second["ee"][-1] - (-0.08, 0.10)) < 1e-4  # arrived (no reactionless restriction)
    snap = session.snapshot()
    assert snap.readouts.dual and snap.readouts.cancel is None
    session.stop()


def test_readouts_are_the_compensators_coupling_and_the_task_arms_jacobian(trep2: FsmsModel) -> None:
    session = Session("trep2", realtime=False)
    session.advance(0.2)
    r = session.snapshot().readouts
    theta = session.snapshot().q[trep2.m :]
    H = trep2.coupling_matrix(trep2.q(theta))
    comp, task = trep2.arm_groups["compensating"].index, trep2.arm_groups["task"].index
    assert r.sigma_hbm == pytest.approx(np.linalg.svd(H[:, comp], compute_uv=False)[-1], rel=1e-12)
    assert r.sigma_jbar == pytest.approx(np.linalg.svd(trep2.ee_jacobian(theta)[:, task], compute_uv=False)[-1])
    session.stop()


def test_target_outside_the_workspace_is_moved_onto_its_edge(trep2: FsmsModel) -> None:
    ws = TaskWorkspace(trep2)
    center = ws.center
    assert ws.outer < 0.2 and ws.outer > 0.19  # Table I: two 0.1 m links from the beam tip
    session = Session("trep2", realtime=False)
    session.set_target((center[0] + 0.5, center[1]), final=True)
    session.advance(0.05)
    notices = session.pop_notices()
    assert any("task arm's workspace" in n.body for n in notices)
    target = session.snapshot().target
    assert target is not None
    assert np.linalg.norm(target[:2] - center) == pytest.approx(ws.outer, abs=1e-12)
    session.stop()


@pytest.mark.parametrize("bad", [(np.nan, 0.1), (np.inf, 0.0), (1e9, 0.0)])
def test_bad_targets_and_laws_are_refused_and_the_run_goes_on(bad: tuple[float, float]) -> None:
    session = Session("trep2", realtime=False)
    session.advance(0.05)
    with pytest.raises(ValueError, match="target must be"):
        session.set_target(bad, final=True)  # refused when the command is made: nothing queued
    assert session.pending_commands() == []
    session.set_law("velocity")
    session.advance(0.1)
    snap = session.snapshot()
    assert snap.settings.law == "acceleration"
    assert any("compensating law" in n.body for n in session.pop_notices())
    assert not snap.diverged and np.all(np.isfinite(snap.q)) and abs(snap.q[0]) < 1e-6
    session.stop()


def test_dual_presets_are_offered_and_the_shadow_flips_compensation() -> None:
    assert set(DUAL_SCENARIOS) <= set(LIVE_SCENARIOS)
    session = Session("trep", realtime=False)
    session.load_preset("trep2-circle-off")
    session.advance(0.001)  # the loop applies the command: the preset is being built from now on
    assert session.wait_background(60.0)
    peaks = np.zeros(2)  # m: peak |x_b| of the operated run (held) and of the shadow (compensating)
    for _ in range(50):
        session.advance(0.05)
        snap = session.snapshot()
        assert snap.q_shadow is not None
        peaks = np.maximum(peaks, np.abs([snap.q[0], snap.q_shadow[0]]))
    assert snap.settings.model == "trep2" and snap.settings.preset == "trep2-circle-off"
    runs = session.state.runs
    assert not runs.sim.law.compensate and runs.shadow.law.compensate
    assert peaks[0] > 1e-4 and peaks[1] <= 0.01 * peaks[0]
    assert snap.readouts.cancel is not None and "held" in snap.readouts.cancel
    session.stop()
