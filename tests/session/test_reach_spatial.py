"""boom7's reactionless-reachable set live: the set is drawn, a target inside it is tracked without the
selected reactions, one outside is held at the set's nearest point and the operator is told, r = 4 is
operated, and r = 5 (a 2-D RNS) holds targets on its reachable surface."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from rns_viz.live.loop.session import Session
from rns_viz.rns import rns_projector

FORCES = (True, True, True, False, False, False)


def _reference_coupling(s: Session) -> float:
    """|S H_bm(theta_ref) theta_ref'| / (|S H_bm| |theta_ref'|) of the operator's reference now."""
    model, op = s.state.model, s.state.operator
    H = model.coupling_matrix(model.q(op.joint.theta))  # type: ignore[union-attr]
    rate = op.joint.thetadot  # type: ignore[union-attr]
    return float(np.linalg.norm(H @ rate) / (np.linalg.norm(H) * max(np.linalg.norm(rate), 1e-300)))


def test_live_reach_set_inside_tracked_outside_held_and_said(boom7_session: Session) -> None:
    s = boom7_session
    s.set_suppression(False)  # (15)'s suppression of the forces alone pumps the free torsion (docs/models.md)
    s.set_selection(FORCES)
    s.advance(0.01)
    assert s.wait_background(60.0)
    s.advance(0.01)
    ov = s.overlays()
    assert ov.reach is not None and len(ov.reach) > 100 and "is involutive" in ov.reach_note
    region = s.state.operator.reach  # type: ignore[union-attr]
    assert region is not None and region.dims == 3
    start = np.asarray(s.snapshot().target)
    inside = region.points[np.argmin(np.linalg.norm(region.points - (start + np.array([0.04, -0.03, 0.03])), axis=1))]
    s.set_target(tuple(inside), final=True)
    s.advance(0.01)
    assert not [n for n in s.pop_notices() if n.title == "Target moved"]
    worst = 0.0
    for _ in range(30):
        s.advance(0.1)
        worst = max(worst, _reference_coupling(s))
    model = s.state.model
    assert np.linalg.norm(model.ee_position(s.snapshot().q[6:]) - inside) < 2e-3  # m: reached
    assert worst <= 1e-9  # the reference moved in N(S H_bm) throughout
    log = s.state.runs.sim.log
    L = np.stack([log.column(f"L_{i}", last=3000) for i in (1, 2, 3)])
    assert np.abs(L).max() < 1e-2 * model.arm_mass * s.snapshot().settings.target_speed
    far = inside + np.array([0.0, 0.0, 2.0])  # 2 m above: beyond the arm's reach
    s.set_target(tuple(far), final=True)
    s.advance(0.01)
    told = [n for n in s.pop_notices() if n.title == "Target moved"]
    assert told and "outside the reactionless-reachable set" in told[0].body and "mm from it" in told[0].body
    assert "held at" in s.snapshot().mode
    held = np.asarray(s.snapshot().target)
    assert region.distance(held) <= region.radius + 1e-9 and held[2] < far[2] - 0.5
    s.advance(2.0)
    snap = s.snapshot()
    assert not snap.diverged and np.all(np.isfinite(snap.q))


def test_r4_tracks_a_target_and_r5_tracks_on_its_reachable_surface(boom7_session: Session) -> None:
    s = boom7_session
    s.set_suppression(False)
    s.set_selection((True, True, True, True, False, False))  # r = 4: a 3-D RNS, J-bar square
    s.advance(0.01)
    told = [n for n in s.pop_notices() if n.title == "Selection S"]
    assert told and "n − r = 3" in told[0].body
    assert s.wait_background(60.0)
    s.advance(0.01)
    start = np.asarray(s.snapshot().target)
    model, op = s.state.model, s.state.operator
    q = model.q(op.tracker.theta)  # type: ignore[union-attr]
    P = rns_projector(model.coupling_matrix(q))
    data = model.pin_model.createData()
    J = pin.computeFrameJacobian(model.pin_model, data, q, model.ee_frame_id, pin.LOCAL_WORLD_ALIGNED)
    U, sigma, _ = np.linalg.svd(data.oMi[model.base_joint_id].rotation.T @ J[:3, 6:] @ P)
    assert sigma[-1] > 1e-3  # J-bar is 3 x 7 of rank 3 here: a square task in a 3-D RNS
    reached = []
    for sign in (1.0, -1.0):  # 3 cm along J-bar's strongest direction, both ways: at least one is not at a fold
        goal = s.snapshot().target + sign * 0.03 * U[:, 0]
        s.set_target(tuple(goal), final=True)
        s.advance(1.5)
        gap = np.linalg.norm(model.ee_position(s.snapshot().q[6:]) - goal)
        reached.append(gap < 3e-3)
        assert gap < 3e-3 or "singularity of J-bar" in s.snapshot().mode  # reached, or said why not
        assert _reference_coupling(s) <= 1e-9 or np.linalg.norm(op.joint.thetadot) == 0.0  # type: ignore[union-attr]
    assert any(reached) and np.linalg.norm(s.snapshot().target - start) < 0.1
    s.set_selection((True, True, True, True, True, False))  # r = 5: a 2-D RNS, the reachable set is a surface
    s.advance(0.01)
    told = [n for n in s.pop_notices() if n.title == "Selection S"]
    assert told and "n − r = 2" in told[0].body and "surface" in told[0].body
    assert s.wait_background(60.0)
    s.advance(0.01)
    region = s.state.operator.reach  # type: ignore[union-attr]
    assert region is not None and region.surface and len(region.points) > 3
    start = np.asarray(s.snapshot().target)
    sample = region.points[np.argsort(np.linalg.norm(region.points - start, axis=1))[1]]  # the nearest other one
    s.set_target(tuple(sample + np.array([0.0, 0.0, 0.05])), final=True)  # 5 cm off: snapped onto the set
    s.advance(0.01)
    assert [n for n in s.pop_notices() if n.title == "Target moved"]
    held = np.asarray(s.snapshot().target)
    assert np.min(np.linalg.norm(region.points - held, axis=1)) < 1e-12
    worst = 0.0
    for _ in range(30):
        s.advance(0.1)
        worst = max(worst, _reference_coupling(s))
    assert worst <= 1e-9
    gap = np.linalg.norm(model.ee_position(s.snapshot().q[6:]) - held)
    assert gap < 3e-3  # m: on the surface (0.12 mm measured after 3 s)
    assert not s.snapshot().diverged
