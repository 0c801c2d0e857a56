"""Reactionless paths: w x_cm invariant along every path, FK agreement, tangency to n, closure."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from rns_viz.model import FsmsModel
from rns_viz.paths import default_seeds, path_family, reactionless_reachable_set, trace_paths
from tests.support.oracles.closed_forms import TREP_A, TREP_B, r3_ee, r3_wxcm, trep_ee, trep_hbm, trep_wxcm

TREP_RANGE = 2 * (TREP_A + TREP_B)  # max - min of w x_cm over the workspace


@pytest.fixture(scope="module")
def family(trep: FsmsModel) -> list:
    return path_family(trep, 40)


def test_family_has_requested_count_and_full_length(family: list) -> None:
    assert len(family) == 40
    # Away from the separatrix every TREP level set is a closed curve on the torus.
    assert all(p.end == "closed" for p in family)
    for p in family:
        gap = (p.theta[-1] - p.theta[0] + np.pi) % (2 * np.pi) - np.pi
        np.testing.assert_allclose(gap, 0.0, atol=1e-12)


def test_wxcm_constant_along_every_path(family: list) -> None:
    for p in family:
        values = np.array([trep_wxcm(th) for th in p.theta])
        assert np.ptp(values) <= 1e-9 * TREP_RANGE


def test_levels_spread_over_the_workspace(family: list) -> None:
    levels = np.array([trep_wxcm(p.theta[0]) for p in family])
    assert np.all(np.diff(levels) > 0)
    assert levels[0] < -0.9 * TREP_RANGE / 2 and levels[-1] > 0.9 * TREP_RANGE / 2


def test_exported_ee_matches_forward_kinematics(family: list) -> None:
    for p in family:
        expected = np.array([trep_ee(th) for th in p.theta])
        np.testing.assert_allclose(p.ee, expected, atol=1e-13)


def test_paths_follow_n(family: list) -> None:
    """Each chord is parallel to n at its midpoint (Eq. 27) up to the curve's bending."""
    for p in family:
        chords = np.diff(p.theta, axis=0)
        mids = 0.5 * (p.theta[1:] + p.theta[:-1])
        for chord, mid in zip(chords, mids, strict=True):
            h = trep_hbm(mid)
            n = np.array([h[1], -h[0]])
            cos = abs(chord @ n) / (np.linalg.norm(chord) * np.linalg.norm(n))
            assert cos > 0.999
        np.testing.assert_allclose(np.diff(p.s), np.linalg.norm(chords, axis=1))


def test_open_path_stops_near_singularity(trep: FsmsModel) -> None:
    """The separatrix level through the saddle theta = (0, pi), where H_bm = 0, ends in singularities."""
    level = trep_wxcm(np.array([0.0, np.pi]))  # A - B
    # A seed on that level with theta_2 = pi/2: w x_cm = A cos t1 + B cos(t1 + pi/2).
    t1 = brentq(lambda t: TREP_A * np.cos(t) + TREP_B * np.cos(t + np.pi / 2) - level, 0.0, np.pi / 2)
    seed = np.array([t1, np.pi / 2])
    (path,) = trace_paths(trep, seed[None, :])
    assert "singularity" in path.end
    assert np.all(np.isfinite(path.theta))


def test_seeds_lie_on_distinct_levels(trep: FsmsModel) -> None:
    seeds = default_seeds(trep, 7)
    levels = [trep_wxcm(s) for s in seeds]
    np.testing.assert_allclose(np.diff(levels), np.diff(levels)[0], rtol=1e-6)


def test_path_family_refuses_a_2d_rns(planar3r: FsmsModel) -> None:
    with pytest.raises(ValueError, match="1-D RNS"):
        path_family(planar3r, 3)


def test_planar3r_reachable_set(planar3r: FsmsModel) -> None:
    theta0 = planar3r.spec.default_configuration
    reach = reactionless_reachable_set(planar3r, theta0, spacing=0.2)
    assert reach.complete and len(reach.theta) > 500
    level = r3_wxcm(theta0)
    values = np.array([r3_wxcm(th) for th in reach.theta])
    np.testing.assert_allclose(values, level, atol=1e-9 * 60.0)
    np.testing.assert_allclose(reach.ee, np.array([r3_ee(th) for th in reach.theta]), atol=1e-12)
    # It is a 2-D set of end-effector points: it spans an area, not a curve.
    assert np.ptp(reach.ee[:, 0]) > 0.5 and np.ptp(reach.ee[:, 1]) > 2.0
    # Keeping x_cm fixed forbids some of the workspace: e.g. the arm stretched along -x.
    assert np.min(reach.ee[:, 0]) > -3.0 + 0.5
