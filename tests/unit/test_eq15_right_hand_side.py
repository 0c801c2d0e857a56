"""Eq. (15)'s right-hand side, one function for both laws that use it (the composite law (15) and the
compensating arm's law, Sec. III-B): y = g_b S H_b x_b' - S H_bm' theta' - g_m L with S on the rows of H_b.

The law demands S H_bm theta'' = y, so the coupling momentum S L = S H_bm theta' obeys
d(S L)/dt = g_b S H_b x_b' - g_m S L. Checked here on the plant itself: the law's torque, pinocchio's
forward dynamics, and d(S L)/dt by central differences along the motion, on a compensating arm whose
base has two coordinates (x, and a turn about z) with S selecting x alone: the base inertia couples the
turn into x, which S H_b S^T S x_b' (the selected block) would drop.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from rns_viz.control import AccelerationLaw, ControlLaw, Gains, TaskSample
from rns_viz.control.acceleration import base_rows_demand
from rns_viz.control.compensation import CompensatingLaw
from rns_viz.model import FsmsModel
from rns_viz.sim import Plant
from tests.support.repo import REPO

G_B, G_M = 10.0, 2.0  # 1/s


@pytest.fixture(scope="module")
def turning_dual() -> FsmsModel:
    model = FsmsModel.from_file(REPO / "tests" / "support" / "models" / "dual_turning_base.toml")
    assert model.m == 2 and list(model.selected) == [0]  # x selected, the turn free
    return model


def _compensating(model: FsmsModel) -> ControlLaw:
    target = TaskSample.held(model.ee_position(model.spec.default_configuration)[:2])
    return CompensatingLaw(model, Gains(g_b=G_B, g_m=G_M), target)


def _composite(model: FsmsModel) -> ControlLaw:
    return AccelerationLaw(model, Gains(g_b=G_B, g_m=G_M))


def _coupling_momentum(model: FsmsModel, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """S L = S H_bm theta' (Eq. 8), kg m/s."""
    return model.coupling_matrix(q) @ v[model.m :]


@pytest.mark.parametrize("make_law", [_compensating, _composite], ids=["compensating", "composite-15"])
def test_the_coupling_momentum_obeys_eq15_with_every_base_velocity(
    turning_dual: FsmsModel, make_law: Callable[[FsmsModel], ControlLaw]
) -> None:
    model, m = turning_dual, turning_dual.m
    plant = Plant(model)
    rng = np.random.default_rng(11)
    h = 1e-5  # s: central differences along the motion
    for _ in range(5):
        law = make_law(model)
        theta = model.spec.default_configuration + rng.uniform(-0.2, 0.2, model.n)
        q = model.q(theta, rng.uniform(-2e-3, 2e-3, m))
        v = np.concatenate([[rng.uniform(-0.02, 0.02)], [rng.uniform(0.3, 0.6)], rng.uniform(-0.5, 0.5, model.n)])
        out = law(0.0, q, v)
        onset = law.threshold if isinstance(law, CompensatingLaw) else law.coupling.threshold  # type: ignore[attr-defined]
        assert out.sigma_hbm > onset  # the inverse is undamped here: S H_bm H_bm^+ = E
        a = plant.acceleration(q, v, out.tau, None)
        ahead = _coupling_momentum(model, q + h * v + 0.5 * h * h * a, v + h * a)
        behind = _coupling_momentum(model, q - h * v + 0.5 * h * h * a, v - h * a)
        rate = (ahead - behind) / (2.0 * h)
        M = model.mass_matrix(q)
        free_part = G_B * M[model.selected, 1] * v[1]  # what the turn couples into x's row
        expected = G_B * M[model.selected, :m] @ v[:m] - G_M * _coupling_momentum(model, q, v)
        assert np.abs(free_part).max() > 0.1 * np.abs(expected).max()  # the selected block alone is far off
        np.testing.assert_allclose(rate, expected, rtol=1e-6, atol=1e-9 * np.abs(free_part).max())


def test_one_base_row_in_floats_equals_the_array_form(trep: FsmsModel) -> None:
    """A 1-DOF base's row (the per-step fast path) gives the same y as the array form, to rounding."""
    law = AccelerationLaw(trep, Gains(g_b=G_B, g_m=G_M))
    rng = np.random.default_rng(5)
    for _ in range(20):
        q, v = trep.q(rng.uniform(-2, 2, 2), rng.normal(size=1) * 1e-3), rng.normal(size=3) * 0.2
        cp = law.coupling(q, v)
        assert cp.row is not None
        y_row = base_rows_demand(cp, G_B, G_M, in_floats=True)
        y = base_rows_demand(cp, G_B, G_M)  # the same coupling through the array form
        assert isinstance(y_row, float) and y.shape == (1,)
        assert y_row == pytest.approx(float(y[0]), rel=1e-14, abs=1e-18)
