"""The divergence guard's bounds: the base's URDF limit, the joints' speed, finite values."""

from __future__ import annotations

import numpy as np

from rns_viz.live.runs.divergence_guard import MAX_JOINT_SPEED, Bounds
from rns_viz.model import FsmsModel


def test_bounds_come_from_the_urdf(trep: FsmsModel) -> None:
    b = Bounds(trep)
    q, v = np.zeros(trep.nv), np.zeros(trep.nv)
    assert b.violation(q, v) is None
    assert "joint limits" in (b.violation(np.array([0.2, 0.0, 0.0]), v) or "")
    assert "rad/s" in (b.violation(q, np.array([0.0, 0.0, 2 * MAX_JOINT_SPEED])) or "")
    assert "finite" in (b.violation(np.array([np.nan, 0.0, 0.0]), v) or "")
    q[1:] = 50.0  # arm joints may wind up: no bound on their angles
    assert b.violation(q, v) is None
