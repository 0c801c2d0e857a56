"""The reactionless-reachable set of boom7 (a base that turns) and the Lie-bracket rank of its RNS
distribution; the set clamps a far target to its nearest point (live: tests/session/test_reach_spatial.py).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pinocchio as pin
import pytest

from rns_viz.integrability import bracket_rank
from rns_viz.live.reach.region import arm_reach, build_reach_region
from rns_viz.model import FsmsModel
from rns_viz.paths import explore_rns


@pytest.fixture(scope="module")
def forces_only(boom7: FsmsModel) -> FsmsModel:
    return boom7.with_selection([1, 1, 1, 0, 0, 0])


def test_forces_only_reactionless_motion_keeps_the_centre_of_mass(forces_only: FsmsModel) -> None:
    # Closed form: the force rows of H_bm are M d(x_cm)/d theta, so every reactionless motion keeps the
    # system's centre of mass where it was in the base frame.
    m = forces_only
    theta0 = m.spec.default_configuration
    found = explore_rns(m, theta0, voxel=arm_reach(m) / 20)
    data = m.pin_model.createData()
    com = np.array([pin.centerOfMass(m.pin_model, data, m.q(th)) for th in found.thetas])
    assert found.complete and len(found.points) > 100
    assert np.abs(com - com[0]).max() < 1e-4 * arm_reach(m)  # m: the RK4 moves' drift only (2e-5 m)
    assert np.ptp(found.points, axis=0).min() > 0.2  # a 3-D set of end-effector points, m
    assert np.all((found.thetas >= m.lower) & (found.thetas <= m.upper))
    assert np.allclose(m.ee_positions(found.thetas), found.points, atol=1e-12)


def _rank(coupling: Callable[[np.ndarray], np.ndarray]) -> int:
    return bracket_rank(coupling, np.array([0.3, -0.2, 0.5])).with_brackets


def test_bracket_rank_against_closed_forms(forces_only: FsmsModel, boom7: FsmsModel) -> None:
    # Heisenberg constraint dz - (x dy - y dx)/2 = 0 in R^3: [X, Y] = (0, 0, -1) leaves the plane: rank 3.
    assert _rank(lambda th: np.array([[th[1] / 2, -th[0] / 2, 1.0]])) == 3
    # dz = 0 (an integrable constraint, rows = a gradient): the brackets stay in it, rank 2.
    assert _rank(lambda th: np.array([[0.0, 0.0, 1.0]])) == 2
    assert _rank(lambda th: np.array([[np.cos(th[0]), np.sin(th[0]) * th[2], np.sin(th[0])]])) >= 2
    m = forces_only
    theta0 = m.spec.default_configuration
    forces = bracket_rank(lambda th: m.coupling_matrix(m.q(th)), theta0)
    assert forces.involutive and forces.rns_dim == 4 and "is involutive" in forces.words()
    moments = m.with_selection([0, 0, 0, 1, 1, 1])  # angular momentum is not a gradient
    turning = bracket_rank(lambda th: moments.coupling_matrix(moments.q(th)), theta0)
    assert not turning.involutive and turning.with_brackets > 4 and "not involutive" in turning.words()
    one = boom7  # S = E: a 1-D distribution is always involutive
    assert bracket_rank(lambda th: one.coupling_matrix(one.q(th)), theta0).with_brackets == 1


def test_region_clamps_a_far_target_to_its_nearest_reachable_point(forces_only: FsmsModel) -> None:
    region = build_reach_region(forces_only, forces_only.spec.default_configuration)
    inside = region.points[len(region.points) // 2]
    assert region.clamp(inside) == (pytest.approx(inside), False)
    far = inside + np.array([3.0, 0.0, 0.0])
    held, moved = region.clamp(far)
    assert moved and region.distance(held) <= region.radius + 1e-9
    nearest = region.points[np.argmin(np.linalg.norm(region.points - far, axis=1))]
    assert np.linalg.norm(held - far) <= np.linalg.norm(nearest - far) + 1e-12
