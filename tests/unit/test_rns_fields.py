"""The library's single functions for the RNS distribution: n(theta) (Eq. 27, generalised), the one RK4
step along a field (rns.rk4_along) and the reactionless path it integrates (control.reference.along_path),
P_RNS of one or many configurations (Eqs. 9, 10), and the distance to singularity in one unit.

Oracles: the SVD (null space, row space, singular values), scipy's adaptive solve_ivp, closed forms.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from rns_viz.control.reference import along_path
from rns_viz.model import FsmsModel
from rns_viz.rns import (
    null_vector,
    project_onto_rns,
    rk4_along,
    rns_basis,
    rns_projector,
    singularity_distance,
)

RNG = np.random.default_rng(29)


# -- n(theta) -----------------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["trep", "boom7"])
def test_n_spans_the_svd_null_space_with_the_rows_volume(name: str, bundled_model: Callable[[str], FsmsModel]) -> None:
    """n(theta) is the SVD's null-space direction of S H_bm, and |n| = sigma_1 ... sigma_m (the rows' volume,
    so n vanishes where S H_bm loses rank)."""
    model = bundled_model(name)
    for _ in range(20):
        theta = RNG.uniform(model.lower, model.upper) if name == "boom7" else RNG.uniform(-np.pi, np.pi, model.n)
        H = model.coupling_at(theta)
        n = model.null_vector(theta)
        _, s, Vt = np.linalg.svd(H)
        assert np.linalg.norm(n) == pytest.approx(np.prod(s), rel=1e-10)
        assert abs(abs(n @ Vt[-1]) - np.linalg.norm(n)) <= 1e-10 * np.linalg.norm(n)  # parallel to the null space
        np.testing.assert_array_equal(n, null_vector(H))  # the model evaluates the one formula
        data = model.pin_model.createData()
        np.testing.assert_array_equal(model.null_vector(theta, data), n)  # in any pinocchio data


# -- the one RK4 ----------------------------------------------------------------------------------
def test_rk4_is_fourth_order_on_a_time_dependent_field() -> None:
    """dx/ds = s x from x(0) = x0: x(s) = x0 exp(s^2 / 2). Halving the step divides the error by 2^4."""
    x0 = np.array([1.0, -0.5])

    def integrate(steps: int) -> np.ndarray:
        x, h = x0, 1.0 / steps
        for k in range(steps):
            x = rk4_along(lambda s, x: s * x, k * h, x, h)
        return x

    exact = x0 * np.exp(0.5)
    errors = [float(np.abs(integrate(steps) - exact).max()) for steps in (10, 20, 40)]
    assert errors[2] < 1e-7
    for coarse, fine in itertools.pairwise(errors):
        assert 14.0 < coarse / fine < 18.0


def test_rk4_along_n_matches_solve_ivp_and_keeps_the_potential(trep: FsmsModel) -> None:
    """d theta/d sigma = n(theta) on TREP: along_path (RK4) against solve_ivp at 1e-12, and w x_cm (Eq. 26)
    constant along it."""
    theta0 = np.array([1.0, 1.0])
    sigma = 20.0  # 1/(kg m): about 1 rad of joint motion
    end = along_path(trep, theta0, sigma, steps=100)
    oracle = solve_ivp(lambda _s, th: trep.null_vector(th), (0.0, sigma), theta0, rtol=1e-12, atol=1e-12).y[:, -1]
    np.testing.assert_allclose(end, oracle, atol=1e-9)
    assert np.linalg.norm(end - theta0) > 0.5
    moment = [trep.arm_mass_moment(th)[0] for th in (theta0, end)]
    assert moment[1] == pytest.approx(moment[0], abs=1e-12)


def test_rk4_steps_a_stack_of_curves_in_lock_step(trep: FsmsModel) -> None:
    """K configurations (K, n) with per-curve steps (K, 1) give each curve's own RK4 step."""
    thetas = RNG.uniform(-np.pi, np.pi, (5, 2))
    h = RNG.uniform(0.01, 0.1, (5, 1))

    def field(_s: object, th: np.ndarray) -> np.ndarray:
        return null_vector(np.array([trep.coupling_at(t) for t in np.atleast_2d(th)])).reshape(th.shape)

    stacked = rk4_along(field, 0.0, thetas, h)
    for k in range(5):
        np.testing.assert_allclose(stacked[k], rk4_along(field, 0.0, thetas[k], float(h[k, 0])), atol=1e-15)


# -- P_RNS of one or many -------------------------------------------------------------------------
def test_the_projector_of_a_stack_is_the_stack_of_projectors(boom7: FsmsModel) -> None:
    """boom7 with forces only (r = 3) at K configurations, and one rank-deficient member (a repeated row):
    each P of the stack is that configuration's own Moore-Penrose P_RNS, applied or formed, and the
    orthonormal bases of the RNS span it."""
    model = boom7.with_selection([1, 1, 1, 0, 0, 0])
    thetas = RNG.uniform(model.lower, model.upper, (6, model.n))
    H = np.array([model.coupling_at(th) for th in thetas])
    P = rns_projector(H)
    u = RNG.normal(size=(6, model.n))
    applied = project_onto_rns(u, H)
    for k in range(6):
        np.testing.assert_array_equal(P[k], rns_projector(H[k]))
        np.testing.assert_allclose(applied[k], project_onto_rns(u[k], H[k]), atol=1e-15)
        np.testing.assert_allclose(applied[k], P[k] @ u[k], atol=1e-13)
        np.testing.assert_allclose(H[k] @ applied[k], 0.0, atol=1e-12)
    basis = rns_basis(H)  # (K, n, n - r): orthonormal, in the RNS, spanning what P projects onto
    assert basis.shape == (6, model.n, model.n - 3)
    np.testing.assert_allclose(
        np.swapaxes(basis, 1, 2) @ basis, np.broadcast_to(np.eye(model.n - 3), (6, 4, 4)), atol=1e-14
    )
    np.testing.assert_allclose(basis @ np.swapaxes(basis, 1, 2), P, atol=1e-13)
    np.testing.assert_array_equal(basis[0], rns_basis(H[0]))
    deficient = H.copy()
    deficient[2, 2] = deficient[2, 1]  # rank 2: its P keeps one direction more
    P_def = rns_projector(deficient)
    assert round(float(np.trace(P_def[2]))) == model.n - 2 and round(float(np.trace(P_def[1]))) == model.n - 3
    np.testing.assert_allclose(P_def[2], rns_projector(deficient[2]), atol=1e-14)
    np.testing.assert_allclose(P_def[2] @ P_def[2], P_def[2], atol=1e-13)


# -- the distance to singularity ------------------------------------------------------------------
def test_the_distance_to_singularity_does_not_depend_on_the_unit_of_the_moment_rows(boom7: FsmsModel) -> None:
    """boom7's S H_bm has force rows (kg m) and moment rows (kg m^2); weighted by 1/reach the distance is in
    kg m. In millimetres every kg m entry is 1e3 times larger and every kg m^2 entry 1e6 times, the reach 1e3
    times: the weighted distance is then exactly 1e3 times (the same kg m), the unweighted one is not."""
    model = boom7
    rotational = np.array([model.base_rotational[i] for i in model.selected])
    assert rotational.any() and not rotational.all()
    for _ in range(10):
        H = model.coupling_at(RNG.uniform(model.lower, model.upper))
        in_mm = H * np.where(rotational, 1e6, 1e3)[:, None]
        weights_mm = np.where(rotational, 1.0 / (1e3 * model.arm_reach), 1.0)
        sigma = singularity_distance(H, model.coupling_weights)
        assert singularity_distance(in_mm, weights_mm) == pytest.approx(1e3 * sigma, rel=1e-9)
        assert singularity_distance(in_mm) != pytest.approx(1e3 * singularity_distance(H), rel=1e-2)
    stack = np.array([model.coupling_at(th) for th in RNG.uniform(model.lower, model.upper, (4, model.n))])
    np.testing.assert_allclose(
        singularity_distance(stack, model.coupling_weights),
        [singularity_distance(h, model.coupling_weights) for h in stack],
        rtol=1e-14,
    )
