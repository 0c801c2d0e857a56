"""The path table of the live app (TREP's 1-D reaction null space): a reactionless path tabulated over
sigma = integral of u-bar dt, Eq. (30). Checked against the physics: the arm's mass moment w x_cm is
the same all along it, d theta / d sigma = n(theta) (Eq. 27), and a closed path wraps with its period."""

from __future__ import annotations

import numpy as np
import pytest

from rns_viz.model import FsmsModel
from rns_viz.paths import PathTable, build_path_table
from rns_viz.rns import null_vector

SEEDS = {"default": None, "elsewhere": np.array([0.6, 1.9])}  # rad; the second off the zero level


@pytest.fixture(scope="module", params=list(SEEDS))
def table(request: pytest.FixtureRequest, trep: FsmsModel) -> PathTable:
    seed = SEEDS[request.param]
    return build_path_table(trep, trep.spec.default_configuration if seed is None else seed)


def theta_at(table: PathTable, sigma: float) -> np.ndarray:
    s = table.wrap(sigma)
    return np.array([np.interp(s, table.sigma, table.theta[:, i]) for i in range(table.theta.shape[1])])


def mass_moment(model: FsmsModel, theta: np.ndarray) -> float:
    """w x_cm along the base axis, kg m: a potential of H_bm (Eq. 26)."""
    return float(model.arm_mass_moment(theta) @ model.base_axes()[0])


def test_sigma_increases_from_zero_at_the_seed(table: PathTable) -> None:
    assert np.all(np.diff(table.sigma) > 0)
    seed_row = int(np.argmin(np.linalg.norm((table.theta - table.seed + np.pi) % (2 * np.pi) - np.pi, axis=1)))
    assert table.sigma[seed_row] == 0.0
    assert table.sigma_nearest_theta(table.seed) == 0.0


def test_the_path_keeps_the_arm_mass_moment_of_its_seed(table: PathTable, trep: FsmsModel) -> None:
    level = mass_moment(trep, table.seed)
    along = np.array([mass_moment(trep, th) for th in table.theta])
    scale = trep.arm_mass * 0.1  # kg m: the arm's mass times a tenth of a metre
    assert np.max(np.abs(along - level)) < 1e-6 * scale
    for sigma in np.linspace(table.lo, table.hi, 37):  # between the rows too (linear interpolation)
        assert abs(mass_moment(trep, theta_at(table, sigma)) - level) < 1e-4 * scale


def test_theta_moves_along_n_at_unit_rate_of_sigma(table: PathTable, trep: FsmsModel) -> None:
    dtheta = np.diff(table.theta, axis=0) / np.diff(table.sigma)[:, None]
    middle = 0.5 * (table.theta[1:] + table.theta[:-1])
    n = np.array([null_vector(trep.coupling_matrix(trep.q(th))) for th in middle])
    error = np.linalg.norm(dtheta - n, axis=1) / np.linalg.norm(n, axis=1)
    assert np.max(error) < 1e-3, np.max(error)


def test_end_effector_points_lie_on_the_arm(table: PathTable, trep: FsmsModel) -> None:
    for sigma in np.linspace(table.lo, table.hi, 23):
        drawn, arm = table.ee_at(sigma), trep.ee_position(theta_at(table, sigma))
        assert np.linalg.norm(drawn - arm) < 1e-4  # m: chord error of the tabulation
    rows = np.linspace(0, len(table.sigma) - 1, 9).astype(int)
    for k in rows:
        assert np.allclose(table.ee[k], trep.ee_position(table.theta[k]), atol=1e-12)


def test_nearest_point_inverts_ee_at(table: PathTable) -> None:
    for sigma in np.linspace(table.lo, table.hi, 29)[1:-1]:
        found = table.sigma_nearest_point(table.ee_at(sigma) + np.array([0.0, 0.0, 0.3]))  # z is ignored
        assert np.allclose(table.ee_at(found), table.ee_at(sigma), atol=1e-9)


def test_a_closed_path_wraps_with_its_period(table: PathTable) -> None:
    assert table.closed and table.period == pytest.approx(table.hi - table.lo)
    p = table.period
    for sigma in (0.1 * p, 0.5 * p, 0.9 * p):
        assert table.wrap(sigma + 3 * p) == pytest.approx(sigma)
        assert table.wrap(sigma - p) == pytest.approx(sigma)
        assert np.allclose(table.ee_at(sigma + p), table.ee_at(sigma), atol=1e-12)
        centred = table.centred(sigma)
        assert -p / 2 <= centred < p / 2 and (centred - sigma) / p == pytest.approx(round((centred - sigma) / p))
        copy = table.nearest_copy(sigma, 10 * p + sigma + 0.3 * p)
        assert copy == pytest.approx(sigma + 10 * p)
    assert np.allclose(table.ee_at(table.lo), table.ee_at(table.hi), atol=1e-9)  # the ends meet


def test_an_open_path_clips_instead_of_wrapping() -> None:
    theta = np.stack([np.linspace(0.0, 1.0, 5), np.zeros(5)], axis=1)
    ee = np.stack([np.linspace(0.0, 0.4, 5), np.zeros(5), np.zeros(5)], axis=1)
    table = PathTable(theta, np.linspace(-2.0, 2.0, 5), ee, False, np.zeros(1), theta[2])
    assert np.isnan(table.period)
    assert table.wrap(5.0) == 2.0 and table.wrap(-5.0) == -2.0
    assert table.centred(3.0) == 2.0 and table.nearest_copy(1.5, 100.0) == 1.5
    assert np.allclose(table.ee_at(1.0), [0.3, 0.0, 0.0]) and np.allclose(table.ee_at(9.0), [0.4, 0.0, 0.0])
    assert table.sigma_nearest_point(np.array([0.25, 0.1])) == pytest.approx(0.5)
    assert table.sigma_nearest_point(np.array([-1.0, 0.0])) == -2.0  # beyond the end: the end
