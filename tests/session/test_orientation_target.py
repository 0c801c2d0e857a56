"""Orientation targets on boom7 in a session: the simulated arm reaches a pose target with r = 1 and bad
quaternions are refused while it runs; at r = 5 sigma(J-bar) is the second singular value and orientation
is not offered (the reference on its own: tests/unit/test_orientation_target.py)."""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pinocchio as pin
import pytest

from rns_viz.live.loop.session import Session
from rns_viz.rns import rns_projector
from tests.support.poses import angle_deg, coupling, rns_walk

R1 = (True, False, False, False, False, False)


@pytest.fixture
def live() -> Iterator[Session]:
    s = Session("boom7", realtime=False)
    assert s.wait_background(120.0)
    yield s
    s.stop()


def test_live_pose_target_the_arm_follows_and_bad_quaternions_are_refused(live: Session) -> None:
    s = live
    s.set_selection(R1)
    s.advance(0.01)
    view = s.snapshot().orientation
    assert view is not None and view.on and view.offered and "3 of 3" in view.note
    model = s.state.model
    theta0 = s.snapshot().q[6:]
    goal = rns_walk(model, theta0, seed=4, steps=200)
    rr = s.state.operator.tracker  # type: ignore[union-attr]
    x_goal, R_goal = rr.ee(goal), rr.ee_rotation(goal)
    wxyz = pin.Quaternion(R_goal)
    for bad in ((np.nan, 0.0, 0.0, 1.0), (0.0, 0.0, 0.0, 0.0), (1.0, 0.0, 0.0)):
        with pytest.raises(ValueError, match="quaternion"):
            s.set_target(tuple(x_goal), True, wxyz=bad)
    s.set_target(tuple(x_goal), True, wxyz=(wxyz.w, wxyz.x, wxyz.y, wxyz.z))
    s.advance(4.0)
    snap = s.snapshot()
    assert not snap.paused and snap.diverged is None and snap.t > 4.0  # the bad inputs left it running
    theta = snap.q[6:]
    assert np.linalg.norm(rr.ee(theta) - x_goal) < 2e-3  # the simulated arm, not only the reference
    assert angle_deg(rr.ee_rotation(theta), R_goal) < 1.0
    # only the axial force (S1) is selected: that coordinate stays still, the free ones are excited
    assert abs(snap.q[0]) < 1e-5 < np.abs(snap.q[1:6]).max()  # m, rad
    s.track_orientation(False)
    s.advance(0.01)
    assert s.snapshot().orientation.on is False  # type: ignore[union-attr]


def test_at_r_5_sigma_jbar_is_the_second_singular_value_and_orientation_is_refused(live: Session) -> None:
    s = live
    s.set_selection((True,) * 5 + (False,))
    s.advance(0.01)
    s.pop_notices()
    snap = s.snapshot()
    model = s.state.model
    theta = snap.q[6:]
    sv = np.linalg.svd(model.ee_jacobian(theta) @ rns_projector(coupling(model, theta)), compute_uv=False)
    assert sv[2] < 1e-9 * sv[0]  # rank n - r = 2 < 3 task rows
    assert snap.readouts.sigma_jbar == pytest.approx(sv[1], rel=1e-9) and sv[1] > 0.0
    assert snap.orientation is not None and not snap.orientation.offered and "not offered" in snap.orientation.note
    s.track_orientation(True)
    s.advance(0.01)
    refused = [n for n in s.pop_notices() if n.title == "Input not applied"]
    assert refused and "not offered" in refused[0].body
    assert not s.snapshot().paused
