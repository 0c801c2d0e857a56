"""The model's blocks of Eq. (1) against the paper's closed forms and finite differences."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from rns_viz.model import FsmsModel
from rns_viz.params import ModelFileError, load_spec, param_path_for
from tests.support.oracles.closed_forms import r3_ee, r3_hbm, trep_ee, trep_hbm

RNG = np.random.default_rng(7)


def random_state(model: FsmsModel, rng: np.random.Generator = RNG) -> tuple[np.ndarray, np.ndarray]:
    q = np.concatenate([rng.uniform(-0.05, 0.05, model.m), rng.uniform(-np.pi, np.pi, model.n)])
    return q, rng.normal(size=model.nv)


def test_trep_hbm_matches_eq26(trep: FsmsModel) -> None:
    for _ in range(200):
        q, v = random_state(trep)
        terms = trep.terms(q, v)
        np.testing.assert_allclose(terms.H_bm[0], trep_hbm(q[1:]), atol=1e-12, rtol=0)


def test_planar3r_hbm_matches_closed_form(planar3r: FsmsModel) -> None:
    for _ in range(200):
        q, v = random_state(planar3r)
        np.testing.assert_allclose(planar3r.terms(q, v).H_bm[0], r3_hbm(q[1:]), atol=1e-10, rtol=0)


@pytest.mark.parametrize(("name", "total"), [("trep", 0.795 + 0.310 + 0.120), ("planar3r", 1.0 + 30.0)])
def test_base_inertia_is_base_plus_arm_mass(name: str, total: float, bundled_model: Callable[[str], FsmsModel]) -> None:
    model = bundled_model(name)
    for _ in range(20):
        q, v = random_state(model)
        np.testing.assert_allclose(model.terms(q, v).H_b, [[total]], rtol=1e-14)
    assert model.arm_mass + (total - model.arm_mass) == pytest.approx(total)


@pytest.mark.parametrize("name", ["trep", "planar3r"])
def test_velocity_terms_match_finite_differences(name: str, bundled_model: Callable[[str], FsmsModel]) -> None:
    """H_bm' theta' and J' theta' by central differences along the motion; c_b = H_bm' theta'."""
    model = bundled_model(name)
    eps = 1e-6
    for _ in range(20):
        q, v = random_state(model)
        terms = model.terms(q, v)
        plus, minus = model.terms(q + eps * v, v), model.terms(q - eps * v, v)
        thetadot = v[model.m :]
        hbm_dot = (plus.H_bm - minus.H_bm) / (2 * eps)
        np.testing.assert_allclose(terms.hbm_dot_thetadot, hbm_dot @ thetadot, atol=1e-7)
        J_dot = (plus.J - minus.J) / (2 * eps)
        np.testing.assert_allclose(terms.Jdot_thetadot, J_dot @ thetadot, atol=1e-7)
        # Translating base, zero gravity: the base rows of the velocity terms are exactly H_bm' theta'.
        np.testing.assert_allclose(terms.c_b, terms.hbm_dot_thetadot, atol=1e-12)
        np.testing.assert_allclose(terms.coupling_momentum, terms.H_bm @ thetadot, atol=1e-15)


@pytest.mark.parametrize("name", ["trep", "boom7"])
def test_step_dynamics_are_the_terms(name: str, bundled_model: Callable[[str], FsmsModel]) -> None:
    """dynamics(), which the laws call at every step, gives terms()'s M, c (pinocchio's RNEA) and H_bm' theta':
    on boom7 (a turning base without gravity) c is C v from the Coriolis matrix that gives M' = C + C^T."""
    model = bundled_model(name)
    m = model.m
    for _ in range(20):
        q, v = random_state(model)
        terms = model.terms(q, v)
        M, c, hbm_dot = model.dynamics(q, v)
        np.testing.assert_array_equal(M[:m, m:], terms.H_bm)
        np.testing.assert_array_equal(M[m:, m:], terms.H_m)
        c_rnea = np.concatenate([terms.c_b, terms.c_m])
        np.testing.assert_allclose(c, c_rnea, rtol=0, atol=1e-13 * np.abs(c_rnea).max())
        np.testing.assert_allclose(hbm_dot, terms.hbm_dot_thetadot, rtol=0, atol=1e-13 * np.abs(c_rnea).max())


def test_jacobian_and_ee_match_forward_kinematics(trep: FsmsModel, planar3r: FsmsModel) -> None:
    eps = 1e-7
    for model, fk in ((trep, trep_ee), (planar3r, r3_ee)):
        for _ in range(20):
            q, v = random_state(model)
            theta = q[model.m :]
            terms = model.terms(q, v)
            np.testing.assert_allclose(terms.ee, fk(theta), atol=1e-12)
            fd = np.column_stack([(fk(theta + eps * e) - fk(theta - eps * e))[:2] / (2 * eps) for e in np.eye(model.n)])
            np.testing.assert_allclose(terms.J, fd, atol=1e-7)


def test_ee_is_in_the_base_frame(trep: FsmsModel) -> None:
    """A deflected base carries the arm: the base-frame end effector does not change."""
    theta = np.array([0.4, -1.1])
    a = trep.terms(trep.q(theta, [0.0]), np.zeros(3)).ee
    b = trep.terms(trep.q(theta, [0.03]), np.zeros(3)).ee
    np.testing.assert_allclose(a, b, atol=1e-15)


def test_arm_mass_moment_is_the_potential_of_hbm(trep: FsmsModel) -> None:
    eps = 1e-6
    for _ in range(20):
        theta = RNG.uniform(-np.pi, np.pi, 2)
        grad = [
            (trep.arm_mass_moment(theta + eps * e)[0] - trep.arm_mass_moment(theta - eps * e)[0]) / (2 * eps)
            for e in np.eye(2)
        ]
        np.testing.assert_allclose(grad, trep_hbm(theta), atol=1e-9)


def test_parameter_file_errors_name_file_and_element(tmp_path) -> None:
    good = param_path_for("trep").read_text()
    bad = tmp_path / "bad.toml"
    bad.write_text(good.replace("stiffness = [[77.9218]]", "stiffness = [[77.9218, 1.0]]"))
    with pytest.raises(ModelFileError, match=r"bad\.toml.*\[base\] stiffness"):
        load_spec(bad)
    urdf_line = f'urdf = "{param_path_for("trep").parent / "trep.urdf"}"'
    bad.write_text(good.replace('joints = ["base_x"]', 'joints = ["joint1"]').replace('urdf = "trep.urdf"', urdf_line))
    with pytest.raises(ModelFileError, match="must be the first joints"):
        FsmsModel(load_spec(bad))
    bad.write_text("[model\nname=")
    with pytest.raises(ModelFileError, match="not valid TOML"):
        load_spec(bad)
    urdf = tmp_path / "broken.urdf"
    urdf.write_text("<robot name='x'><link name='a'></robot>")
    bad.write_text(good.replace('urdf = "trep.urdf"', f'urdf = "{urdf}"'))
    with pytest.raises(ModelFileError, match=r"broken\.urdf"):
        FsmsModel(load_spec(bad))
