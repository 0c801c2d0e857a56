"""The external force is sampled at the RK4 stage times t, t + dt/2, t + dt, not held over a step.

TREP on a base without spring or damper (K_b = D_b = 0, no gravity), its arm stretched along the
base axis (H_bm = 0) and kept still by law (15) with zero gains: the base row of Eq. (1) then says
d/dt (H_b x_b') = f_ext with H_b constant, so the base momentum is the force's running integral,
peak T/pi (1 - cos(pi (t - start)/T)) during a half-sine pulse and its impulse 2 peak T/pi after.
Stage sampling integrates it like Simpson's rule (exact but for the kinks where the pulse starts
and ends inside a step); holding f(t) over each step (the former scheme,
still what Plant.rk4_state_step does with a single force) is a Riemann sum, whose running integral
lags by half a step: an O(dt) error during the pulse.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from rns_viz.control import AccelerationLaw, DampNullMotion, Gains
from rns_viz.model import FsmsModel
from rns_viz.sim import ForcePulse, Simulator
from rns_viz.sim.disturbance import stage_forces
from tests.support.repo import ASSETS

DT = 1e-3
PULSE = ForcePulse(start=0.0203, duration=0.05, peak=(2.0,))  # starts 0.3 ms into a step


def free_trep(tmp_path: Path) -> FsmsModel:
    """TREP with the base spring and damper removed: a free mass along x carrying the arm."""
    (tmp_path / "trep.urdf").write_text((ASSETS / "trep.urdf").read_text())
    params = (ASSETS / "trep.toml").read_text()
    params = params.replace("stiffness = [[77.9218]]", "stiffness = [[0.0]]")  # D_b is 0 already
    assert "stiffness = [[0.0]]" in params
    (tmp_path / "trep.toml").write_text(params)
    return FsmsModel.from_file(tmp_path / "trep.toml")


def base_momentum(model: FsmsModel, x: np.ndarray) -> float:
    """H_b x_b' + H_bm theta': the base row of M(q) v, kg m/s."""
    return float((model.mass_matrix(x[: model.nv]) @ x[model.nv :])[0])


def running_impulse(t: float) -> float:
    """The closed-form integral of PULSE from 0 to t, N s."""
    phase = np.clip((t - PULSE.start) / PULSE.duration, 0.0, 1.0)
    return float(PULSE.peak[0] * PULSE.duration / np.pi * (1.0 - np.cos(np.pi * phase)))


def test_stage_sampling_only_where_rk4_evaluates() -> None:
    assert stage_forces(PULSE, 0.0, DT) is None  # the pulse is not on in [0, 1 ms]
    f0, f_mid, f1 = stage_forces(PULSE, 0.020, DT)  # type: ignore[misc]
    assert f0 is None and f_mid is not None and f1 is not None
    assert np.allclose(f_mid, 2.0 * np.sin(np.pi * 0.0002 / 0.05))
    assert np.allclose(f1, 2.0 * np.sin(np.pi * 0.0007 / 0.05))


@pytest.mark.parametrize("native", [False, True], ids=["python-step", "native-step-if-installed"])
def test_pulse_momentum_matches_its_closed_form(tmp_path: Path, native: bool) -> None:
    model = free_trep(tmp_path)
    impulse = float(PULSE.impulse[0])
    assert impulse == pytest.approx(2 * 2.0 * 0.05 / np.pi, rel=1e-15)
    law = AccelerationLaw(model, Gains(g_b=0.0, g_m=0.0), DampNullMotion(0.0))
    q0 = model.q(np.zeros(model.n))  # arm along the base axis: H_bm = 0
    assert not np.any(model.mass_matrix(q0)[0, 1:])
    sim = Simulator(model, law, dt=DT, force=PULSE, q0=q0, native=native)
    held = Simulator(model, law, dt=DT, q0=q0, native=False)  # stepped by hand with the force held
    sampled_errors, held_errors = [], []
    for _ in range(100):  # the pulse is over at 70.3 ms
        t = sim.t
        sim.step()
        x = held._x
        held._x = held.plant.rk4_state_step(x, law(t, x[: model.nv], x[model.nv :]).tau, PULSE(t), DT)
        sampled_errors.append(abs(base_momentum(model, sim._x) - running_impulse(t + DT)))
        held_errors.append(abs(base_momentum(model, held._x) - running_impulse(t + DT)))
    assert abs(sim.q[0]) > 1e-3  # the base really moved
    assert np.max(np.abs(sim.q[model.m :])) <= 1e-12  # and the arm did not

    print(
        f"impulse {impulse:.9f} N s; max |p - integral of f| during the pulse: stage-sampled "
        f"{max(sampled_errors):.2e}, held {max(held_errors):.2e}; after it: {sampled_errors[-1]:.2e}, "
        f"{held_errors[-1]:.2e}"
    )
    # What is left is the kinks where the pulse starts and ends inside a step (~6e-7 N s each).
    assert max(sampled_errors) <= 1e-4 * impulse
    assert max(held_errors) >= 1e-2 * impulse  # half a step late: peak dt / 2 at the pulse's peak
    assert 100 * max(sampled_errors) <= max(held_errors)
    assert sampled_errors[-1] < held_errors[-1]  # the impulse after the pulse, too
