"""Every control law, at random configurations, velocities and gains (singular ones included):
the output is finite and is what the physics says it is, checked against pinocchio directly.

- L = S H_bm theta' (Eq. 8) and sigma_hbm = the smallest singular value of S H_bm;
- the damped inverse stays bounded by 1 / threshold, 10 / |H_bm(theta_0)|, even at rank loss;
- away from rank loss, law (15) applied to the plant gives L' = H_b g_b x_b' - g_m L, and law (16)
  gives M^ x_b'' + (D_b + H_b g_b) x_b' + K_b x_b = g_m L (the closed loops the laws are built for).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pinocchio as pin
import pytest

from rns_viz.control import (
    AccelerationLaw,
    FixedReference,
    Gains,
    JointServo,
    TaskSample,
    TorqueLaw,
    TrackEndEffector,
    VelocityLaw,
)
from rns_viz.control.common import CouplingEvaluator
from rns_viz.model import FsmsModel

SAMPLES = 10_000  # law evaluations per model
RTOL = 1e-8  # of the largest term of an identity


def random_gains(rng: np.random.Generator) -> Gains:
    scale = 10.0 ** rng.uniform(-3, 4, size=7)
    values = scale * rng.random(7)
    values[rng.random(7) < 0.1] = 0.0  # zero gains too
    g_b, g_m, G_p, G_d, k_p, k_d, servo = values
    return Gains(g_b=g_b, g_m=g_m, G_p=G_p, G_d=G_d, k_p=k_p, k_d=k_d, servo_bandwidth=max(servo, 1e-3))


def special_configurations(model: FsmsModel) -> list[np.ndarray]:
    """Rank loss of H_bm (arm along x) and of J (arm stretched) for both models."""
    n = model.n
    out = [np.zeros(n), np.full(n, np.pi), np.r_[np.pi, np.zeros(n - 1)], np.r_[0.0, np.pi, np.zeros(n - 2)]]
    out.append(np.r_[np.pi / 2, np.zeros(n - 1)])
    return out


class Plant:
    """Eq. (1) straight from pinocchio (its own data): M, c, H_bm' theta' and the accelerations."""

    def __init__(self, model: FsmsModel) -> None:
        self.model, self.pm = model, model.pin_model
        self.data = self.pm.createData()
        self.m = model.m

    def at(self, q: np.ndarray, v: np.ndarray) -> None:
        m = self.m
        self.M = pin.crba(self.pm, self.data, q).copy()
        self.c = pin.nonLinearEffects(self.pm, self.data, q, v).copy()
        C = pin.computeCoriolisMatrix(self.pm, self.data, q, v)
        self.hbm_dot_thetadot = (C + C.T)[:m, m:] @ v[m:]  # H_bm' theta', from M' = C + C^T
        self.H_b, self.H_bm = self.M[:m, :m], self.M[:m, m:]

    def accelerations(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """(x_b'', theta'') of the plant under torques tau, no external force."""
        m, model = self.m, self.model
        generalised = np.concatenate([-model.K_b @ q[:m] - model.D_b @ v[:m], tau - model.D_m @ v[m:]])
        return np.linalg.solve(self.M, generalised - self.c)


def assert_close(residual: np.ndarray, *terms: np.ndarray | float, what: str) -> None:
    scale = max(float(np.max(np.abs(t))) for t in terms)
    assert float(np.max(np.abs(residual))) <= RTOL * scale + 1e-12, (what, residual, scale)


@pytest.mark.parametrize("name", ["trep", "planar3r"])
def test_every_law_stays_finite_and_physical(name: str, bundled_model: Callable[[str], FsmsModel]) -> None:
    model = bundled_model(name)
    plant = Plant(model)
    evaluator = CouplingEvaluator(model)
    inverse_bound = 1.0 / evaluator.threshold
    q0 = model.q(model.spec.default_configuration)
    assert inverse_bound == pytest.approx(10.0 / np.linalg.norm(model.coupling_matrix(q0)))
    rng = np.random.default_rng(2026)
    special = special_configurations(model)
    m, selected = model.m, model.selected
    undamped = {"15": 0, "16": 0}
    for k in range(SAMPLES // 5):
        gains = random_gains(rng)
        theta = special[k % len(special)] if k % 7 == 0 else rng.uniform(-2 * np.pi, 2 * np.pi, model.n)
        q = np.concatenate([rng.uniform(-0.1, 0.1, m), theta])
        v = rng.normal(scale=10.0 ** rng.uniform(-3, 1.5), size=model.nv)
        target = TaskSample.held(rng.uniform(-5, 5, 2))
        reference = FixedReference(rng.uniform(-np.pi, np.pi, model.n))
        plant.at(q, v)
        H = plant.H_bm[selected]
        L = H @ v[m:]
        sigma = float(np.linalg.svd(H, compute_uv=False)[-1])
        assert np.linalg.norm(evaluator(q, v).H_bm_pinv, 2) <= inverse_bound * (1 + 1e-12)
        law_15 = AccelerationLaw(model, gains)
        laws = (
            law_15,
            AccelerationLaw(model, gains, null_input=TrackEndEffector(model, target, gains.G_p, gains.G_d)),
            TorqueLaw(model, gains),
            VelocityLaw(model, gains, reference),
            JointServo(model, gains, reference),
        )
        for law in laws:
            out = law(float(k) * 1e-3, q, v)
            assert np.all(np.isfinite(out.tau)), (type(law).__name__, q, v, gains)
            assert_close(out.coupling_momentum - L, L, np.abs(H) @ np.abs(v[m:]), what="L")
            assert out.sigma_hbm == pytest.approx(sigma, rel=1e-9, abs=1e-14)
            if sigma < evaluator.threshold:
                continue  # damped: the identities below hold only approximately
            a = plant.accelerations(q, v, out.tau)
            xddot_b, thetaddot = a[:m], a[m:]
            H_b_xdot = plant.H_b[np.ix_(selected, selected)] @ v[selected]
            if isinstance(law, AccelerationLaw):  # Eq. (15): L' = H_b g_b x_b' - g_m L
                L_dot = H @ thetaddot + plant.hbm_dot_thetadot[selected]
                wanted = gains.g_b * H_b_xdot - gains.g_m * L
                scale = (np.abs(H) @ np.abs(thetaddot), plant.hbm_dot_thetadot, wanted, gains.g_m * L)
                assert_close(L_dot - wanted, *scale, what="(15)")
                undamped["15"] += 1
            elif isinstance(law, TorqueLaw):  # Eq. (16): M^ x_b'' + (D_b + H_b g_b) x_b' + K_b x_b = g_m L
                M_hat = plant.H_b - plant.H_bm @ np.linalg.solve(plant.M[m:, m:], plant.H_bm.T)
                terms = (M_hat @ xddot_b, model.D_b @ v[:m], gains.g_b * H_b_xdot, model.K_b @ q[:m], gains.g_m * L)
                residual = terms[0] + terms[1] + terms[2] + terms[3] - terms[4]
                assert_close(residual, *terms, what="(16)")
                undamped["16"] += 1
    assert min(undamped.values()) > SAMPLES // 10, undamped  # the identities were checked, often
