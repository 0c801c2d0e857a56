"""Reaction null-space maths: projector, null vector, damped inverse, integrability."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from rns_viz import rns
from rns_viz.integrability import check_integrability
from rns_viz.model import FsmsModel
from rns_viz.rns import (
    damped_pinv,
    null_vector,
    project_onto_rns,
    restricted_jacobian,
    rns_projector,
    singularity_distance,
    weighted_damped_pinv,
)

RNG = np.random.default_rng(3)


@pytest.mark.parametrize("name", ["trep", "planar3r"])
def test_projector_is_orthogonal_and_annihilates_hbm(name: str, bundled_model: Callable[[str], FsmsModel]) -> None:
    model = bundled_model(name)
    for _ in range(100):
        theta = RNG.uniform(-np.pi, np.pi, model.n)
        H = model.coupling_matrix(model.q(theta))
        P = rns_projector(H)
        np.testing.assert_allclose(P, P.T, atol=1e-15)
        np.testing.assert_allclose(P @ P, P, atol=1e-14)
        np.testing.assert_allclose(H @ P, 0.0, atol=1e-15 * max(1.0, np.abs(H).max()))
        assert np.trace(P) == pytest.approx(model.n - 1)


def test_null_vector_is_eq27_and_orthogonal(trep: FsmsModel) -> None:
    for _ in range(100):
        theta = RNG.uniform(-np.pi, np.pi, 2)
        h = trep.coupling_matrix(trep.q(theta))
        n = null_vector(h)
        np.testing.assert_array_equal(n, [h[0, 1], -h[0, 0]])
        assert abs(h[0] @ n) < 1e-18


def test_generalised_null_vector_for_two_rows() -> None:
    for _ in range(50):
        H = RNG.normal(size=(2, 3))
        n = null_vector(H)
        np.testing.assert_allclose(H @ n, 0.0, atol=1e-14)
        np.testing.assert_allclose(n, np.cross(H[0], H[1]), atol=1e-14)


def test_damped_pinv_matches_pinv_away_from_singularity() -> None:
    for rows in (1, 2):
        A = RNG.normal(size=(rows, 3))
        inv = damped_pinv(A)
        np.testing.assert_allclose(inv.inverse, np.linalg.pinv(A), atol=1e-13)
        assert inv.damping == 0.0
        assert inv.sigma_min == pytest.approx(np.linalg.svd(A, compute_uv=False)[-1])


@pytest.mark.parametrize("offset", [0.0, 1e-12, 1e-8, 1e-5, 1e-3])
@pytest.mark.parametrize("theta2", [0.0, np.pi])
def test_damped_pinv_stays_finite_at_trep_singularity(trep: FsmsModel, offset: float, theta2: float) -> None:
    """Arm stretched or folded along x: H_bm = 0 there, and the inverse must stay bounded."""
    theta = np.array([offset, theta2])
    h = trep.coupling_matrix(trep.q(theta))
    inv = damped_pinv(h)
    assert np.all(np.isfinite(inv.inverse))
    bound = 1.0 / (2 * inv.damping) if inv.damping > 0 else 1.0 / inv.sigma_min
    assert np.abs(inv.inverse).max() <= bound * (1 + 1e-12)
    assert inv.sigma_min == pytest.approx(np.linalg.norm(h), abs=1e-18)
    assert inv.sigma_min < 1e-3 * 0.06  # the reported distance to singularity is small here


def test_damped_pinv_bound() -> None:
    """|A^+| <= 1 / (2 lambda) for the damped inverse, whatever sigma."""
    for sigma in (0.0, 1e-9, 1e-6, 5e-4):
        A = np.array([[sigma, 0.0]])
        inv = damped_pinv(A)
        assert np.all(np.isfinite(inv.inverse))
        assert np.abs(inv.inverse).max() <= 1.0 / (2 * inv.damping) + 1e-12


def test_restricted_jacobian_lies_in_rns(planar3r: FsmsModel) -> None:
    theta = planar3r.spec.default_configuration
    terms = planar3r.terms(planar3r.q(theta), np.zeros(4))
    P = rns_projector(terms.H_bm)
    Jbar = restricted_jacobian(terms.J, P)
    np.testing.assert_allclose(terms.H_bm @ np.linalg.pinv(Jbar), 0.0, atol=1e-12)  # J-bar^+ eta in N(H_bm)
    assert np.linalg.matrix_rank(Jbar) == 2


def test_integrability(trep: FsmsModel, planar3r: FsmsModel) -> None:
    samples2 = RNG.uniform(-np.pi, np.pi, (10, 2))
    samples3 = RNG.uniform(-np.pi, np.pi, (10, 3))
    trep_result = check_integrability(lambda th: trep.coupling_matrix(trep.q(th)), samples2)
    assert trep_result.integrable and trep_result.rns_dim == 1
    r3 = check_integrability(lambda th: planar3r.coupling_matrix(planar3r.q(th)), samples3)
    # Translating base: the RNS is tangent to the level sets of w x_cm, hence involutive.
    assert r3.integrable and r3.rns_dim == 2 and r3.max_residual < 1e-6


def test_integrability_detects_a_nonholonomic_distribution() -> None:
    """ker(dz - y dx) is the textbook non-involutive distribution: [X, Y] leaves it."""
    result = check_integrability(lambda th: np.array([[-th[1], 0.0, 1.0]]), RNG.normal(size=(5, 3)))
    assert not result.integrable
    assert result.max_residual > 0.1


def near_singular(rows: int, cols: int, sigma: float) -> np.ndarray:
    """A random rows x cols matrix whose smallest singular value is ``sigma`` (the others ~1)."""
    U, _ = np.linalg.qr(RNG.normal(size=(rows, rows)))
    V, _ = np.linalg.qr(RNG.normal(size=(cols, cols)))
    s = np.r_[RNG.uniform(0.5, 2.0, rows - 1), sigma]
    return U @ np.diag(s) @ V[:rows]


@pytest.mark.parametrize("rows", [1, 2])
@pytest.mark.parametrize("sigma", [1.0, 0.3, 0.051, 0.049, 1e-2, 1e-4, 1e-8, 0.0])
def test_closed_form_branches_equal_the_svd_branch(rows: int, sigma: float) -> None:
    """The one- and two-row closed forms of damped_pinv against its SVD branch, near and at rank loss."""
    threshold = 0.05
    for cols in (2, 3, 7):
        for _ in range(20):
            A = near_singular(rows, cols, sigma) if rows == 2 else RNG.normal(size=(1, cols))
            if rows == 1:
                A *= sigma / np.linalg.norm(A) if sigma > 0 else 0.0
            closed = damped_pinv(A, threshold, threshold)
            svd = rns._any_rows(A, threshold, threshold)
            scale = np.abs(svd.inverse).max()
            np.testing.assert_allclose(closed.inverse, svd.inverse, rtol=0, atol=1e-12 * max(scale, 1.0))
            assert closed.sigma_min == pytest.approx(svd.sigma_min, rel=1e-9, abs=1e-12)
            assert closed.damping == pytest.approx(svd.damping, rel=1e-9, abs=1e-12)


def test_damped_projector_applied_equals_formed() -> None:
    """P_RNS u without forming P equals the formed (damped) P_RNS times u, Eq. (9)."""
    for rows in (1, 2):
        for sigma in (1.0, 1e-4):
            H = near_singular(rows, rows + 2, sigma)
            inverse = damped_pinv(H, 1e-2, 1e-2).inverse
            u = RNG.normal(size=rows + 2)
            np.testing.assert_allclose(project_onto_rns(u, H, inverse), rns_projector(H, inverse) @ u, atol=1e-14)
            if sigma == 1.0:  # undamped: the damped projector is the exact one
                np.testing.assert_allclose(rns_projector(H, inverse), rns_projector(H), atol=1e-14)


def test_null_vector_of_a_stack_is_the_stack_of_null_vectors() -> None:
    for rows in (1, 2, 3):
        H = RNG.normal(size=(6, rows, rows + 1))
        stacked = null_vector(H)
        assert stacked.shape == (6, rows + 1)
        for Hk, nk in zip(H, stacked, strict=True):
            np.testing.assert_array_equal(nk, null_vector(Hk))
            np.testing.assert_allclose(Hk @ nk, 0.0, atol=1e-13)


def test_one_row_inverse_does_not_depend_on_the_matrix_after_the_call() -> None:
    """The one-row inverse is formed on first use; changing A afterwards must not change it."""
    A = np.array([[0.3, -0.4, 1.2]])
    inverse = damped_pinv(A, 1e-3, 1e-3)
    expected = np.linalg.pinv(A)
    A[:] = 7.0
    np.testing.assert_allclose(inverse.inverse, expected, rtol=1e-14)
    matrix, sigma, damping = inverse  # unpacks like the tuple it was
    assert matrix is inverse.inverse and sigma == pytest.approx(np.sqrt(0.09 + 0.16 + 1.44)) and damping == 0.0


def test_multi_row_damped_inverse_equals_its_formula(boom7: FsmsModel) -> None:
    """The multi-row damped inverse of Eq. (15), A^T (A A^T + lambda^2 E)^-1, on boom7's six coupling
    rows (the shared identity E must not leak between calls)."""
    model = boom7
    m = model.m
    for _ in range(20):
        q = model.q(RNG.uniform(-np.pi, np.pi, model.n))
        H_bm = model.mass_matrix(q)[:m, m:]
        damped = damped_pinv(H_bm, 1e3, 0.1)  # damped everywhere: lambda > 0
        E = np.eye(m)
        plain = H_bm.T @ np.linalg.solve(H_bm @ H_bm.T + damped.damping**2 * E, E)
        # (G^-1 A)^T vs A^T G^-1 E: equal up to rounding, which grows with cond(G)
        G = H_bm @ H_bm.T + damped.damping**2 * E
        tolerance = 1e-15 * np.linalg.cond(G)
        np.testing.assert_allclose(damped.inverse, plain, rtol=tolerance, atol=tolerance * np.abs(plain).max())
        assert damped.sigma_min == np.linalg.svd(H_bm, compute_uv=False)[-1]


@pytest.mark.parametrize("rows", [1, 2, 6])
def test_weighted_inverse_is_the_plain_one_undamped_and_damps_in_the_weighted_unit(rows: int) -> None:
    """(W A)^+ W: away from rank loss A's own right inverse (row weights change no right inverse of full row
    rank); sigma_min and lambda are W A's, and damped it is (W A)^T (W A (W A)^T + lambda^2 E)^-1 W."""
    A = RNG.normal(size=(rows, 7))
    weights = RNG.uniform(0.2, 3.0, rows)
    free = weighted_damped_pinv(A, weights, 1e-6, 1e-6)
    assert free.damping == 0.0
    np.testing.assert_allclose(free.inverse, np.linalg.pinv(A), rtol=1e-10, atol=1e-12)
    WA = weights[:, None] * A
    assert free.sigma_min == pytest.approx(singularity_distance(A, weights), rel=1e-12)
    assert singularity_distance(A, weights) == pytest.approx(np.linalg.svd(WA, compute_uv=False)[-1], rel=1e-12)
    damped = weighted_damped_pinv(A, weights, 1e3, 0.5)
    E = np.eye(rows)
    expected = WA.T @ np.linalg.solve(WA @ WA.T + damped.damping**2 * E, E) * weights
    assert damped.damping > 0
    np.testing.assert_allclose(damped.inverse, expected, rtol=1e-10, atol=1e-14)
