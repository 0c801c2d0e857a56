"""The kick response the gain map predicts (rns_viz.analysis.kick), piece by piece, against independent oracles:
the pulse states against iterating the step map, the map's numbers against the linear step map stepped
1 ms at a time and read off sample by sample, the force input against the simulator, the measurement
against closed forms, and the marks on the map's picture."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pytest

from rns_viz.analysis import Kick, gain_map, linearise, measure_kick
from rns_viz.analysis.kick import KEPT, SWING, pulse_states, pulse_steps
from rns_viz.analysis.linear import build_law
from rns_viz.control import Gains
from rns_viz.model import FsmsModel
from rns_viz.sim import ForcePulse, Simulator
from tests.support.kick_oracle import kick_cell


def stepped(loop, g_b: float, g_m: float, seconds: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The linear step map x_{k+1} = A x_k + B f_k under the loop's kick, stepped for ``seconds``:
    times (s), the deflection along the kick, and the integral of L = S H_bm theta' (r,) at each step and,
    in a last row, for ever (the sum of the states after the last step is (E - A)^-1 x)."""
    A, kick, dt = loop.matrix(g_b, g_m), loop.kick, loop.dt
    b = loop.force_input @ kick.weights
    y_rows = kick.output @ np.eye(len(loop.kept))[np.flatnonzero(loop.kept < loop.m)]
    L_rows = loop.coupling @ loop.joint_rates
    n = round(seconds / dt)
    x = np.zeros(len(A))
    ys, integral, out_int = np.empty(n), np.zeros(len(L_rows)), np.empty((n, len(L_rows)))
    for k in range(n):
        ys[k], out_int[k] = y_rows @ x, integral
        t = (k + 0.5) * dt
        force = kick.peak * math.sin(math.pi * t / kick.duration) if t <= kick.duration else 0.0
        integral = integral + dt * (L_rows @ x)
        x = A @ x + b * force
    final = integral + dt * (L_rows @ np.linalg.solve(np.eye(len(A)) - A, x))
    return np.arange(n) * dt, ys, np.vstack([out_int, final])


def test_pulse_states_are_the_step_map_iterated_through_the_push() -> None:
    dt, duration = 1e-3, 0.1
    lam = np.array([[-4.45 + 1.46j, -236.8 - 128.8j, -0.05 + 8.0j, -3.0 + 0.0j, 40.0 + 900.0j]])
    mu = np.exp(lam * dt)
    steps = pulse_steps(Kick(1.0, duration, (1.0,)), dt)
    assert steps[-1] == 100 and len(steps) > 3
    xi = pulse_states(lam, mu, dt, duration, steps)
    x, want = np.zeros(lam.shape[1], dtype=complex), []
    for k in range(int(steps[-1])):
        x = mu[0] * x + math.sin(math.pi * (k + 0.5) * dt / duration)
        if k + 1 in steps:
            want.append(x.copy())
    assert np.abs(xi[0] - np.array(want).T).max() < 1e-9 * np.abs(xi).max()


def test_continuous_pulse_states_solve_the_pushed_mode() -> None:
    """Without a step map, xi' = lambda xi + sin(w t) from xi(0) = 0, checked by central differences."""
    duration, lam = 0.2, np.array([[-3.0 + 0.0j, -0.5 + 12.0j, -40.0 - 5.0j]])
    t, h = np.linspace(0.01, duration, 7), 1e-6
    xi, ahead, behind = (pulse_states(lam, None, 1.0, duration, t + d) for d in (0.0, h, -h))
    rate = (ahead - behind) / (2 * h)
    assert np.abs(rate - (lam[..., None] * xi + np.sin(math.pi * t / duration))).max() < 1e-6
    assert np.abs(pulse_states(lam, None, 1.0, duration, np.zeros(1))).max() < 1e-15


# boom7 under (15): cells whose deflection peaks inside the push, between its six samples (the map read the
# peak 2-6 % low and its time to 10 % up to 7 % off before the push's every step was read)
PEAK_IN_THE_PUSH = [(15.9, 1.15), (38.0, 0.482), (26.8, 0.201)]


@pytest.mark.parametrize(("g_b", "g_m"), PEAK_IN_THE_PUSH)
def test_a_peak_inside_the_push_is_read(g_b: float, g_m: float, boom7: FsmsModel) -> None:
    grid = gain_map(boom7, "acceleration")
    i, j = int(np.argmin(np.abs(grid.g_b - g_b))), int(np.argmin(np.abs(grid.g_m - g_m)))
    m, loop = grid.modes, grid.loop
    settle = float(m.base_time_to_10pct[i, j])
    t, y, _ = stepped(loop, grid.g_b[i], grid.g_m[j], loop.kick.duration + 1.6 * settle + 1.0)
    assert t[np.argmax(np.abs(y))] < loop.kick.duration  # the step map's peak is inside the push
    got = measure_kick(t, y, loop.kick.duration, quiet=0.3 * settle)
    assert m.peak[i, j] == pytest.approx(got.peak, rel=1e-3)
    assert settle == pytest.approx(got.settle_time, rel=0.01)


@pytest.mark.parametrize(("name", "law"), [("trep", "velocity"), ("planar3r", "acceleration"), ("boom7", "torque")])
def test_the_force_input_is_the_simulators(name: str, law: str, bundled_model: Callable[[str], FsmsModel]) -> None:
    """The linear step map driven by the kick follows the simulator's run of the same law at 1 % of the kick
    (its force sampled at RK4's stages, the torque held): what the map's numbers rest on."""
    model = bundled_model(name)
    loop = linearise(model, law)
    kick = loop.kick
    small = Kick(0.01 * kick.peak, kick.duration, kick.direction)
    g_b, g_m = (10.0, 2.0) if name != "trep" else (24.0, 20.0)
    theta = model.spec.default_configuration
    pulse = ForcePulse(start=0.0, duration=kick.duration, peak=tuple(small.peak * kick.weights))
    law_ = build_law(model, loop.law, theta, Gains(g_b=g_b, g_m=g_m))
    sim = Simulator(model, law_, native=False, q0=model.q(theta), force=pulse, log_capacity=1600)
    sim.run(1.5)
    y_sim = sum(w * sim.log.column(f"xb_{i + 1}") for i, w in enumerate(kick.output) if w)
    _, y_lin, _ = stepped(loop, g_b, g_m, 1.5)
    y_lin *= 0.01
    n = min(len(y_sim), len(y_lin))
    assert np.abs(y_sim[:n] - y_lin[:n]).max() < 2e-3 * np.abs(y_lin).max()


@pytest.mark.parametrize(("name", "law"), [("trep", "velocity"), ("trep", "torque"), ("planar3r", "acceleration"),
                                           ("boom7", "acceleration")])  # fmt: skip
def test_the_maps_numbers_are_the_linear_step_maps(
    name: str, law: str, bundled_model: Callable[[str], FsmsModel]
) -> None:
    """At random stable cells, peak, time to 10 % and rate agree with the linear step map stepped 1 ms at a
    time and read off sample by sample (independent of the modal machinery); the arm swing with its L
    integrated step by step."""
    model = bundled_model(name)
    grid = gain_map(model, law)
    m, loop = grid.modes, grid.loop
    cells = np.argwhere(m.stable & (m.base_time_to_10pct < 8.0))
    worst = np.zeros(4)
    rng = np.random.default_rng(31)  # each case its own draw: the cells must not depend on which tests ran first
    for i, j in cells[rng.choice(len(cells), 6, replace=False)]:
        settle = float(m.base_time_to_10pct[i, j])
        t, y, integral = stepped(loop, grid.g_b[i], grid.g_m[j], loop.kick.duration + 1.6 * settle + 1.0)
        got = measure_kick(t, y, loop.kick.duration, quiet=0.3 * settle)
        swing = np.abs(integral @ loop.swing_map.T).max()
        errors = (
            abs(m.peak[i, j] / got.peak - 1),
            abs(settle - got.settle_time) / max(got.settle_time, 0.01),
            abs(m.base_decay_rate[i, j] / got.decay_rate - 1),
            abs(m.swing[i, j] / swing - 1),
        )
        worst = np.maximum(worst, errors)
    assert np.all(worst < (0.01, 0.01, 0.01, 0.1)), worst


def test_measure_kick_reads_closed_forms() -> None:
    t = np.arange(0.0, 12.0, 1e-3)
    sigma, omega, end = 0.7, 6.0, 0.1
    y = np.where(t < end, 0.0, np.exp(-sigma * (t - end)) * np.cos(omega * (t - end)))
    got = measure_kick(t, y, end)
    # the last top of |y| at or above 0.1: tops at omega tau = n pi, e^(-sigma n pi / omega) >= 0.1
    n = math.floor(math.log(10.0) * omega / (sigma * math.pi))
    assert got.peak == pytest.approx(1.0)
    assert n * math.pi / omega <= got.settle_time < (n + 0.5) * math.pi / omega
    assert got.decay_rate == pytest.approx(math.log(10.0) / got.settle_time)
    early = measure_kick(t[t < end + got.settle_time + 0.5], y[t < end + got.settle_time + 0.5], end)
    assert math.isinf(early.settle_time) and math.isnan(early.decay_rate)  # not quiet long enough to tell


def test_map_image_marks_unpredictable_cells_apart_from_unstable_ones(planar3r: FsmsModel) -> None:
    from rns_viz.viz.scene.gain_scene import CELL_PIXELS, UNPREDICTABLE_HATCH, UNSTABLE_HATCH, UNSTABLE_RGB, map_image

    grid = gain_map(planar3r, "acceleration")
    odd = grid.stable & ~grid.predictable
    assert odd.sum() > 100 and (~grid.stable).sum() > 100
    image, _ = map_image(grid, "base")
    hatched = np.all(image == UNPREDICTABLE_HATCH, axis=-1).sum()
    assert hatched == CELL_PIXELS * odd.sum()  # one diagonal of pixels per marked cell
    grey = np.all(image == UNSTABLE_HATCH, axis=-1) | np.all(image == UNSTABLE_RGB, axis=-1)
    assert grey.sum() == CELL_PIXELS**2 * (~grid.stable).sum()  # the unstable cells as before


def test_the_3rs_fast_cells_are_marked_and_the_apps_run_leaves_the_linear_loop_there(planar3r: FsmsModel) -> None:
    """The 3R under (15): the cell the map used to call fastest (g_b 3.29, g_m 0.1 /s) and the fastest stable
    cell now both swing the arm by more than a radian to absorb the 5 N kick; they are marked, and the app's
    run (its end effector held, Eq. 24) does not keep the linear prediction there."""
    model = planar3r
    grid = gain_map(model, "acceleration")
    fastest = np.unravel_index(np.argmax(np.where(grid.stable, grid.base_decay_rate, -np.inf)), grid.stable.shape)
    reported = (int(np.argmin(np.abs(grid.g_b - 3.29))), int(np.argmin(np.abs(grid.g_m - 0.1))))
    for i, j in (reported, fastest):
        assert grid.modes.reason[i, j] == SWING and grid.modes.swing[i, j] > 1.0
        assert "swing" in grid.modes.why_not((i, j))
        kicked = kick_cell(model, grid, i, j, 12.0)
        assert kicked.stopped or kicked.misses(), kicked
    g_b, g_m, _ = grid.best()  # the fastest cell it does predict
    assert grid.modes.reason[np.argmin(np.abs(grid.g_b - g_b)), np.argmin(np.abs(grid.g_m - g_m))] == KEPT
