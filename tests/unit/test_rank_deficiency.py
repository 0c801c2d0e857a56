"""Rank deficiency of S H_bm (Sec. III-B, the fourth case): where it is, and that it is reactionless there.

Oracle: for a translating base row and planar links, h_bm is the derivative of the arm's mass moment
along x (Eq. 26), a sum of sines of the links' absolute angles; it vanishes exactly where every
link lies along the x axis, i.e. where every absolute angle is 0 or pi.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable

import numpy as np
import pytest

from rns_viz.model import FsmsModel
from rns_viz.rank import kernel_coupling, rank_deficient_configurations, sigma_grid


def absolute_angles(theta: np.ndarray) -> np.ndarray:
    return np.cumsum(theta)


@pytest.mark.parametrize(("name", "points"), [("trep", 12), ("planar3r", 6)])
def test_rank_deficient_points_are_the_links_along_the_deflection_axis(
    name: str, points: int, bundled_model: Callable[[str], FsmsModel]
) -> None:
    model = bundled_model(name)
    loss = rank_deficient_configurations(model, points_per_joint=points)
    n = model.n
    expected = {tuple(c) for c in itertools.product((0, 1), repeat=n)}  # absolute angle 0 or pi per link
    found = {tuple(np.round(np.mod(absolute_angles(th), 2 * np.pi) / np.pi).astype(int) % 2) for th in loss.theta}
    assert len(loss.theta) == 2**n and found == expected
    for theta in loss.theta:
        assert np.allclose(np.sin(absolute_angles(theta)), 0.0, atol=1e-9)


@pytest.mark.parametrize(("name", "points"), [("trep", 12), ("planar3r", 6)])
def test_every_drawn_point_is_rank_deficient_and_reactionless_along_the_kernel(
    name: str, points: int, bundled_model: Callable[[str], FsmsModel]
) -> None:
    """sigma_min(S H_bm) <= 1e-9 |H_bm| at every point; a kernel velocity couples <= 1e-9 of the most coupled one."""
    model = bundled_model(name)
    loss = rank_deficient_configurations(model, points_per_joint=points)
    assert loss.scale > 0.01  # kg m: the grid's most coupled direction is a real coupling
    for theta, sigma, ee in zip(loss.theta, loss.sigma_min, loss.ee, strict=True):
        H = model.coupling_matrix(model.q(theta))
        assert np.linalg.svd(H, compute_uv=False)[-1] <= 1e-9 * loss.scale
        assert sigma <= 1e-9 * loss.scale
        along_kernel, _ = kernel_coupling(model, theta)
        assert along_kernel <= 1e-9 * loss.scale  # per rad/s, against the most coupled unit velocity
        assert np.allclose(ee, model.ee_position(theta))  # the drawn image is the configuration's
        assert abs(ee[1]) <= 1e-9  # every link along x: the end effector is on the deflection axis


def test_next_to_rank_loss_the_same_velocity_does_couple(trep: FsmsModel) -> None:
    """Reactionless only at the points: 0.1 rad away along joint 1, turning joint 1 couples in first order
    (|dh_1/dtheta_1| = |A cos + B cos| >= A - B = 0.031 kg m at every point, so >= 0.0031 kg m there)."""
    model = trep
    loss = rank_deficient_configurations(model)
    turn_joint_1 = np.array([1.0, 0.0])  # rad/s
    for theta in loss.theta:
        at = model.coupling_matrix(model.q(theta)) @ turn_joint_1
        near = model.coupling_matrix(model.q(theta + 0.1 * turn_joint_1)) @ turn_joint_1
        assert abs(at[0]) <= 1e-9 * loss.scale and abs(near[0]) >= 0.2 * 0.1 * loss.scale  # kg m/s


def test_compensator_alone_loses_rank_along_the_beam_axis(trep2: FsmsModel) -> None:
    """trep2's compensating arm: its own S H_bm,2 vanishes with both links along x, at any task-arm pose."""
    model = trep2
    comp = model.arm_groups["compensating"].index
    loss = rank_deficient_configurations(model, columns=comp, points_per_joint=8)
    assert len(loss.theta) == 4
    for theta in loss.theta:
        assert np.allclose(np.sin(absolute_angles(theta[comp])), 0.0, atol=1e-9)
        assert np.allclose(theta[model.arm_groups["task"].index], model.spec.default_configuration[2:])


def test_sigma_grid_has_its_zeros_at_the_rank_deficient_points(trep: FsmsModel) -> None:
    model = trep
    a, b, field = sigma_grid(model, [0, 1], points_per_joint=9)  # nodes at multiples of pi/4
    zeros = {(round(a[i] / np.pi, 6), round(b[j] / np.pi, 6)) for i, j in zip(*np.nonzero(field < 1e-12), strict=True)}
    assert zeros == {(x, y) for x in (-1.0, 0.0, 1.0) for y in (-1.0, 0.0, 1.0)}
    assert field.max() > 0.05  # kg m
