"""The live path reference (PathFollower): RK4 knots along n(theta) (Eq. 27) and Hermite curves between them.

Checked against the path integrated in many small RK4 steps (:func:`along_path`), for reactionlessness of its
reference velocity (S H_bm theta_ref' = 0, Eq. 8), for going back the way it came, and for how often it
evaluates n(theta) at the simulation's step (the reason for the knots).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from rns_viz.control.reference import along_path
from rns_viz.live.operator.moving_references import PathFollower
from rns_viz.model import FsmsModel

DT = 1e-3  # s: the simulation's step
PATH_MODELS = ("trep", "boom7")


def joint_speed_sigma_rate(follower: PathFollower, speed: float) -> float:
    """u-bar (1/(kg m s)) that moves the joints at ``speed`` rad/s at the follower's configuration."""
    n = follower.n(follower.theta)
    return speed / float(np.linalg.norm(n))


def walk(follower: PathFollower, ubar: float, steps: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """``steps`` simulation steps at u-bar: the reference (theta_ref, theta_ref') after each."""
    out = []
    for _ in range(steps):
        follower.advance(ubar * DT)
        theta, rate, _ = follower.reference(ubar, DT)
        out.append((theta, rate))
    return out


@pytest.mark.parametrize("name", PATH_MODELS)
def test_the_reference_stays_on_the_finely_integrated_path(
    name: str, bundled_model: Callable[[str], FsmsModel]
) -> None:
    model = bundled_model(name)
    theta0 = model.spec.default_configuration
    follower = PathFollower(model, theta0)
    ubar = joint_speed_sigma_rate(follower, 0.5)  # rad/s: a brisk move along the path
    steps = 1500  # 0.75 rad of joint motion, many knots
    samples = walk(follower, ubar, steps)
    for k in (0, 37, 499, steps - 1):  # between knots and after many
        sigma = ubar * DT * (k + 1)
        fine = along_path(
            model, theta0, sigma, max(1, int(np.ceil(sigma / (1e-4 / np.linalg.norm(follower.n(theta0))))))
        )
        theta, rate = samples[k]
        assert np.max(np.abs(theta - fine)) < 1e-10, (
            f"{name}: step {k} off the path by {np.max(np.abs(theta - fine)):.2e} rad"
        )
        n = model.null_vector(theta)
        assert np.linalg.norm(rate - n * ubar) <= 1e-7 * np.linalg.norm(n * ubar), (
            f"{name}: step {k}: rate is not n u-bar"
        )


@pytest.mark.parametrize("name", PATH_MODELS)
def test_the_reference_velocity_is_reactionless(name: str, bundled_model: Callable[[str], FsmsModel]) -> None:
    model = bundled_model(name)
    follower = PathFollower(model, model.spec.default_configuration)
    ubar = joint_speed_sigma_rate(follower, 0.5)
    for theta, rate in walk(follower, ubar, 400)[::13]:
        H_bm = model.coupling_matrix(model.q(theta))
        L = H_bm @ rate  # S H_bm theta_ref' (Eq. 8): what the reference would push into the base
        assert np.linalg.norm(L) <= 1e-8 * np.linalg.norm(H_bm) * np.linalg.norm(rate)


@pytest.mark.parametrize("name", PATH_MODELS)
def test_back_the_way_it_came_is_the_same_path(name: str, bundled_model: Callable[[str], FsmsModel]) -> None:
    model = bundled_model(name)
    theta0 = np.asarray(model.spec.default_configuration, dtype=float)
    follower = PathFollower(model, theta0)
    ubar = joint_speed_sigma_rate(follower, 0.5)
    there = walk(follower, ubar, 300)
    back = walk(follower, -ubar, 300)
    # step k forward and step 298 - k back are at the same sigma: the same point of the curve
    for k in (0, 100, 250):
        assert np.max(np.abs(there[k][0] - back[298 - k][0])) < 1e-12
    assert np.max(np.abs(back[-1][0] - theta0)) < 1e-12


@pytest.mark.parametrize("name", PATH_MODELS)
def test_a_simulation_step_rarely_evaluates_n(
    name: str, bundled_model: Callable[[str], FsmsModel], monkeypatch: pytest.MonkeyPatch
) -> None:
    """n(theta) is evaluated per knot (each STEP rad of joint motion), not four times every step."""
    model = bundled_model(name)
    follower = PathFollower(model, model.spec.default_configuration)
    ubar = joint_speed_sigma_rate(follower, 0.5)
    calls = 0
    evaluate = follower.n

    def counted(theta: np.ndarray) -> np.ndarray:
        nonlocal calls
        calls += 1
        return evaluate(theta)

    monkeypatch.setattr(follower, "n", counted)
    steps = 1000  # 0.5 rad at 0.5 rad/s: about 50 knots of STEP = 0.01 rad
    walk(follower, ubar, steps)
    knots = 0.5 / PathFollower.STEP
    assert calls <= 5 * 1.2 * knots, f"{name}: {calls} evaluations of n in {steps} steps"
    assert calls < steps / 5
