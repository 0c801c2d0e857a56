"""The reactionless reference path of Eq. (30), theta_ref' = n(theta_ref) u-bar(t), as PathReference
integrates it: reactionless at every query, equal to an independent integration, its acceleration the
time derivative of its velocity, and the same whatever the order of the queries."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pinocchio as pin
import pytest
from scipy.integrate import solve_ivp

from rns_viz.control.reference import PathReference
from rns_viz.model import FsmsModel


def ubar(t: float) -> tuple[float, float]:
    """A speed along the path and its rate, rad-scaled (1/(kg m s)), smooth and varying."""
    return 0.4 + 0.3 * np.sin(3.0 * t), 0.9 * np.cos(3.0 * t)


def coupling(model: FsmsModel, theta: np.ndarray) -> np.ndarray:
    """S H_bm at theta, from a fresh pinocchio data (not the reference's)."""
    q = np.zeros(model.nv)
    q[model.m :] = theta
    M = pin.crba(model.pin_model, model.pin_model.createData(), q)
    return M[model.selected][:, model.m :]


@pytest.mark.parametrize("name", ["trep", "boom7"])
def test_the_reference_is_reactionless_and_matches_an_independent_integration(
    name: str, bundled_model: Callable[[str], FsmsModel]
) -> None:
    model = bundled_model(name)
    theta0 = np.linspace(0.3, 0.9, model.n)
    ref = PathReference(model, theta0, ubar)
    times = np.linspace(0.0, 0.6, 41)[1:]
    samples = [ref(t) for t in times]

    for (theta, thetadot, _), t in zip(samples, times, strict=True):
        H = coupling(model, theta)
        assert np.abs(H @ thetadot).max() <= 1e-12 * np.abs(H).max() * np.abs(thetadot).max()  # Eq. (27)
        # n is the generalised cross product of S H_bm's rows: orthogonal to them, with their volume
        n = thetadot / ubar(t)[0]
        assert np.linalg.norm(n) == pytest.approx(np.sqrt(np.linalg.det(H @ H.T)), rel=1e-9)

    def field(t: float, theta: np.ndarray) -> np.ndarray:  # the oracle: n from an SVD, scaled by the volume
        H = coupling(model, theta)
        n = np.linalg.svd(H)[2][-1]
        n *= np.sqrt(np.linalg.det(H @ H.T)) * np.sign(n @ ref.n(theta))
        return n * ubar(t)[0]

    oracle = solve_ivp(field, (0.0, times[-1]), theta0, method="DOP853", rtol=1e-11, atol=1e-13, t_eval=times)
    assert np.abs(oracle.y.T - [s[0] for s in samples]).max() < 1e-9

    # theta_ref'' (the law's feedforward) is the time derivative of theta_ref'
    t, h = 0.3, 1e-4
    fresh = PathReference(model, theta0, ubar)
    before, _, after = fresh(t - h)[1], fresh(t), fresh(t + h)[1]
    assert np.allclose(ref(t)[2], (after - before) / (2 * h), rtol=1e-5, atol=1e-9)


def test_queries_in_any_order_give_the_path_through_the_same_points(trep: FsmsModel) -> None:
    model = trep
    theta0 = np.array([0.5, 1.2])
    ref = PathReference(model, theta0, ubar)
    for t in (0.0103, 0.0105, 0.2, 0.05, 0.0, 0.31, 0.31, 0.3107):  # partial steps, repeats and restarts
        theta, thetadot, _ = ref(t)
        assert np.array_equal(thetadot, ref.n(theta) * ubar(t)[0])  # n at the point reached, never a stale one
        straight = PathReference(model, theta0, ubar)(t)[0]  # the same time asked for at once
        assert np.allclose(theta, straight, rtol=0.0, atol=1e-10)  # other step grids: RK4's error only
    ref.restart(theta0=np.array([0.1, 0.2]))
    theta, thetadot, _ = ref(0.0)
    assert np.array_equal(theta, [0.1, 0.2]) and np.array_equal(thetadot, ref.n(theta) * ubar(0.0)[0])
