"""No non-finite output from any control law, whatever the configuration and gains (issue: robustness)."""

from __future__ import annotations

import numpy as np
import pytest

from rns_viz.control import (
    AccelerationLaw,
    FixedReference,
    Gains,
    JointServo,
    MovableTarget,
    TorqueLaw,
    TrackEndEffector,
    VelocityLaw,
)
from rns_viz.model import FsmsModel

SAMPLES = 10_000


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


@pytest.mark.parametrize("name", ["trep", "planar3r"])
def test_every_law_stays_finite(name: str) -> None:
    model = FsmsModel.from_name(name)
    rng = np.random.default_rng(2026)
    special = special_configurations(model)
    per_law = SAMPLES // 5
    checked = 0
    for k in range(per_law):
        gains = random_gains(rng)
        theta = special[k % len(special)] if k % 7 == 0 else rng.uniform(-2 * np.pi, 2 * np.pi, model.n)
        q = np.concatenate([rng.uniform(-0.1, 0.1, model.m), theta])
        v = rng.normal(scale=10.0 ** rng.uniform(-3, 1.5), size=model.nv)
        target = MovableTarget(rng.uniform(-5, 5, 2))
        reference = FixedReference(rng.uniform(-np.pi, np.pi, model.n))
        laws = (
            AccelerationLaw(model, gains),
            AccelerationLaw(model, gains, null_input=TrackEndEffector(model, target, gains.G_p, gains.G_d)),
            TorqueLaw(model, gains),
            VelocityLaw(model, gains, reference),
            JointServo(model, gains, reference),
        )
        for law in laws:
            out = law(float(k) * 1e-3, q, v)
            assert np.all(np.isfinite(out.tau)), (type(law).__name__, q, v, gains)
            assert np.all(np.isfinite(out.coupling_momentum))
            assert np.isfinite(out.sigma_hbm)
            checked += 1
    assert checked == SAMPLES
