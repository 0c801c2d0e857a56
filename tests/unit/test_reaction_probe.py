"""The arm's reaction on its base, -(H_bm theta'' + c_b) (Eq. 1), from the library (rns_viz.sim.ReactionProbe).

Oracle: the base rows of Eq. (1) themselves. With the motion the plant makes, H_b x_b'' + H_bm theta'' + c_b
+ D_b x_b' + K_b x_b = f_ext, so the reaction equals H_b x_b'' + D_b x_b' + K_b x_b - f_ext: what the
base's own inertia, damper and spring take, less the external force. x_b'' here comes from pinocchio's
forward dynamics with the generalised forces assembled in this test.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pinocchio as pin
import pytest

from rns_viz.model import FsmsModel
from rns_viz.sim import ReactionProbe

RNG = np.random.default_rng(23)


@pytest.mark.parametrize("name", ["trep", "boom7"])
def test_the_reaction_is_what_the_base_rows_of_eq1_take(name: str, bundled_model: Callable[[str], FsmsModel]) -> None:
    model = bundled_model(name)
    m = model.m
    probe = ReactionProbe(model)
    data = model.pin_model.createData()
    for _ in range(10):
        q = model.q(RNG.uniform(-2.0, 2.0, model.n), RNG.normal(size=m) * 1e-3)
        v = RNG.normal(size=model.nv) * 0.2
        tau, f_ext = RNG.normal(size=model.n), RNG.normal(size=m)
        force = probe.force(q, v, tau, f_ext)
        generalised = np.concatenate([f_ext - model.K_b @ q[:m] - model.D_b @ v[:m], tau - model.D_m @ v[m:]])
        a = pin.aba(model.pin_model, data, q, v, generalised)
        H_b = pin.crba(model.pin_model, data, q)[:m, :m]
        expected = H_b @ a[:m] + model.D_b @ v[:m] + model.K_b @ q[:m] - f_ext
        scale = np.abs(expected).max() + np.abs(f_ext).max()
        np.testing.assert_allclose(force, expected, atol=1e-10 * scale)
        assert force.shape == (m,)
