"""The gain analysis against the simulator's own step map, the closed-form cubic of (15), and kicks."""

from __future__ import annotations

import contextlib
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from rns_viz.analysis import (
    ClosedLoop,
    authority,
    default_axes,
    fit_decay,
    gain_map,
    joined,
    linearise,
    loops_along,
    map_of,
    modes_of,
    root_locus,
)
from rns_viz.control import AccelerationLaw, FixedReference, Gains, TorqueLaw, VelocityLaw
from rns_viz.control.common import CouplingEvaluator
from rns_viz.csvio import read_csv
from rns_viz.model import FsmsModel
from rns_viz.paths import trace_paths
from rns_viz.scenarios import FIG12_GAINS, FIG12_KICK_AT_S, run_scenario
from rns_viz.sim import ForcePulse, SimulationDiverged, Simulator
from tests.support.repo import ASSETS

RNG = np.random.default_rng(10)


def _law(model: FsmsModel, kind: str, theta: np.ndarray, g_b: float, g_m: float):
    """Built here from rns_viz.control, not by the analysis' own factory."""
    gains = Gains(g_b=g_b, g_m=g_m)
    if kind == "velocity":
        return VelocityLaw(model, gains, FixedReference(theta))
    return (AccelerationLaw if kind == "acceleration" else TorqueLaw)(model, gains)


def _step_map_eigenvalues(model: FsmsModel, kind: str, theta: np.ndarray, g_b: float, g_m: float) -> np.ndarray:
    """Eigenvalues of the central-difference Jacobian of Simulator.step (Python, 1 ms, torque held)."""
    sim = Simulator(model, _law(model, kind, theta, g_b, g_m), native=False, log_capacity=2)
    x0 = np.concatenate((model.q(theta), np.zeros(model.nv)))
    nv, d, eps = model.nv, 2 * model.nv, 1e-6

    def step(x: np.ndarray) -> np.ndarray:
        sim.reset(x[:nv].copy(), x[nv:].copy())
        sim.step()
        return np.concatenate((sim.q, sim.v))

    J = np.column_stack([(step(x0 + eps * e) - step(x0 - eps * e)) / (2 * eps) for e in np.eye(d)])
    return np.linalg.eigvals(J)


def _matched_distance(a: np.ndarray, b: np.ndarray) -> float:
    """Largest distance from a point of either set to the nearest of the other (same sizes)."""
    D = np.abs(a[:, None] - b[None, :])
    return float(max(D.min(axis=1).max(), D.min(axis=0).max()))


CASES = [("trep", "velocity"), ("trep", "acceleration"), ("trep", "torque"), ("planar3r", "acceleration")]


@pytest.mark.parametrize(("name", "kind"), CASES)
def test_poles_match_the_simulators_step_map(name: str, kind: str, bundled_model: Callable[[str], FsmsModel]) -> None:
    model = bundled_model(name)
    theta = model.spec.default_configuration
    loop = linearise(model, kind, theta)  # the step map of dt = 1 ms, the simulator's default
    g_b_axis, g_m_axis = default_axes(kind)
    worst = 0.0
    for i, j in ((5, 50), (20, 20), (35, 10), (50, 40), (59, 59)):  # sampled grid points, stable or not
        g_b, g_m = g_b_axis[i], g_m_axis[j]
        mu = np.exp(modes_of(loop, g_b, g_m).poles * loop.dt)
        mu = np.concatenate((mu, np.ones(loop.neutral)))  # the dropped joint angles: mu = 1
        worst = max(worst, _matched_distance(mu, _step_map_eigenvalues(model, kind, theta, g_b, g_m)))
    assert worst < 1e-6


@pytest.mark.parametrize(("name", "kind"), [("trep", "velocity"), ("planar3r", "acceleration"), ("trep", "torque")])
@pytest.mark.parametrize("view", ["discrete", "continuous"])
def test_closed_loop_is_linear_in_the_gains(
    name: str, kind: str, view: str, bundled_model: Callable[[str], FsmsModel]
) -> None:
    model = bundled_model(name)
    theta = model.spec.default_configuration + RNG.uniform(-0.3, 0.3, model.n)
    loop = linearise(model, kind, theta, view=view)
    for g_b, g_m in np.exp(RNG.uniform(np.log(0.1), np.log(500.0), (3, 2))):
        direct = ClosedLoop(model, kind, theta, Gains(g_b=g_b, g_m=g_m)).jacobian(view)[np.ix_(loop.kept, loop.kept)]
        assert np.abs(loop.matrix(g_b, g_m) - direct).max() <= 1e-6 * np.abs(direct).max()


@pytest.mark.parametrize("name", ["trep", "planar3r"])
def test_acceleration_law_gives_the_cubic(name: str, bundled_model: Callable[[str], FsmsModel]) -> None:
    """Law (15), 1-DOF base, continuous time. With L = h theta' (Eq. 8) the linearised law gives
    L' = h theta'' = g_b H_b x_b' - G_m L (h h^+ = 1 away from singularities) and the base row of
    Eq. (1) H_b x_b'' + L' + d x_b' + k x_b = 0; eliminating L:
        H_b s^3 + (H_b (G_m + g_b) + d) s^2 + (k + d G_m) s + k G_m = 0.
    The other poles: the arm's motion in the RNS, u = -G_m theta', at -G_m (n - 1 of them)."""
    model = bundled_model(name)
    theta = model.spec.default_configuration
    H_b = model.mass_matrix(model.q(theta))[0, 0]
    k, d = model.K_b[0, 0], model.D_b[0, 0]
    loop = linearise(model, "acceleration", theta, view="continuous")
    worst = 0.0
    for g_b, g_m in np.exp(RNG.uniform(np.log(0.1), np.log(300.0), (8, 2))):
        cubic = np.roots([H_b, H_b * (g_m + g_b) + d, k + d * g_m, k * g_m])
        expected = np.concatenate((cubic, np.full(model.n - 1, -g_m)))
        poles = modes_of(loop, g_b, g_m).poles
        worst = max(worst, _matched_distance(poles, expected) / np.abs(expected).max())
    assert worst < 1e-6


def _kick_rate(
    model: FsmsModel, kind: str, g_b: float, g_m: float, duration: float, peak: float, start: float = 0.2
) -> float:
    """Decay rate (1/s) fitted to x_b after a half-sine kick of ``peak`` N for 0.05 s (from ``start`` s)."""
    theta = model.spec.default_configuration
    sim = Simulator(
        model,
        _law(model, kind, theta, g_b, g_m),
        native=False,
        q0=model.q(theta),
        force=ForcePulse(start=0.0, duration=0.05, peak=(peak,)),
        log_capacity=round(duration / 1e-3) + 2,
    )
    sim.run(duration)
    return fit_decay(sim.log.column("t"), sim.log.column("xb_1"), start=start).rate


# 3 x 3 subsets of the default 60 x 60 grid where the base swings often enough for the peak fit (at
# least three half periods in the simulated time): rows (g_b), columns (g_m), duration s, kick N, and
# when the fit starts, s (5 x 5 over the same ranges all measured within 10 % too). TREP: g_b 1.2-19,
# g_m 6.6-54 /s (the paper's 24, 20 among them). The 3R: g_b 0.4-3.3, g_m 6.6-110 /s, its base swinging
# at 1.3-1.8 rad/s; its fit starts at 1 s, once the real root of the cubic near -G_m (a large share of
# x_b, no swing) has died out.
SUBSETS = {
    ("trep", "velocity"): ((14, 22, 30), (24, 30, 36), 3.0, 0.05, 0.2),
    ("planar3r", "acceleration"): ((8, 14, 20), (24, 32, 40), 7.0, 0.5, 1.0),
}


@pytest.mark.parametrize(
    ("name", "kind"),
    [("trep", "velocity"), pytest.param("planar3r", "acceleration", marks=pytest.mark.slow)],  # 9 x 7 s simulated
)
def test_predicted_base_decay_matches_a_kick(name: str, kind: str, bundled_model: Callable[[str], FsmsModel]) -> None:
    model = bundled_model(name)
    rows, cols, duration, peak, start = SUBSETS[(name, kind)]
    grid = gain_map(model, kind)
    errors = []
    for i in rows:
        for j in cols:
            assert grid.stable[i, j]
            predicted = grid.base_decay_rate[i, j]
            measured = _kick_rate(model, kind, grid.g_b[i], grid.g_m[j], duration, peak, start)
            errors.append(measured / predicted - 1.0)
    assert np.abs(errors).max() < 0.10, np.round(errors, 3)


def _released(model: FsmsModel, g_b: float, g_m: float, duration: float) -> Simulator:
    """TREP under (30) at rest but for a 1 um/s nudge of the base and 1 urad/s of joint 1."""
    theta = model.spec.default_configuration
    sim = Simulator(
        model,
        _law(model, "velocity", theta, g_b, g_m),
        native=False,
        q0=model.q(theta),
        v0=np.r_[1e-6, 1e-6, np.zeros(model.n - 1)],
        log_capacity=round(duration / 1e-3) + 2,
    )
    with contextlib.suppress(SimulationDiverged):  # the log keeps the steps up to the last finite state
        sim.run(duration)
    return sim


def test_points_marked_unstable_diverge(trep: FsmsModel) -> None:
    model = trep
    grid = gain_map(model, "velocity")
    # g_b = 2500 /s, g_m = 8 /s: the base mode grows (g_b H_b times the 1 ms hold is too much).
    i, j = 58, 25
    assert not grid.stable[i, j] and grid.base_decay_rate[i, j] < -10.0
    log = _released(model, grid.g_b[i], grid.g_m[j], 0.4).log
    t, xb = log.column("t"), log.column("xb_1")
    assert np.abs(xb[-50:]).max() > 1e3 * np.abs(xb[:50]).max()
    fit = fit_decay(t, xb)
    assert fit.rate == pytest.approx(grid.base_decay_rate[i, j], rel=0.1)
    # g_b = 19 /s, g_m = 3000 /s: the joints' position loop outruns the hold, in the RNS where x_b never
    # sees it (an arm mode grows) and in a mode x_b shows little of at first (0.3 % of a kick's response)
    # but that grows faster and takes the base with it.
    i, j = 30, 59
    assert not grid.stable[i, j] and grid.base_decay_rate[i, j] < -10.0 and grid.arm_decay_rate[i, j] < -10.0
    log = _released(model, grid.g_b[i], grid.g_m[j], 0.3).log
    theta, t, xb = log.column("theta_1"), log.column("t"), log.column("xb_1")
    assert np.abs(theta[-50:] - theta[0]).max() > 1e3 * np.abs(theta[:50] - theta[0]).max()
    assert fit_decay(t[150:], xb[150:]).rate == pytest.approx(grid.base_decay_rate[i, j], rel=0.1)


def test_fit_decay_recovers_a_damped_oscillation_and_refuses_a_short_log() -> None:
    t = np.linspace(0.0, 4.0, 4001)
    fit = fit_decay(t, 3e-3 * np.exp(-0.7 * t) * np.cos(6.0 * t + 0.3))
    assert fit.method == "peaks"
    assert fit.rate == pytest.approx(0.7, rel=1e-2)
    assert fit_decay(t, np.exp(-2.0 * t) + np.exp(-5.0 * t)).method == "tail"
    with pytest.raises(ValueError):
        fit_decay(t[:300], np.cos(20.0 * t[:300]))  # 0.3 s: two swings only


def test_map_marks_the_papers_gains_and_locus_is_consistent(trep: FsmsModel) -> None:
    loop = linearise(trep, "velocity")
    grid = map_of(loop)
    assert grid.base_decay_rate.shape == (60, 60)
    assert grid.stable.any() and not grid.stable.all()
    # Fig. 10 (g_b = 24, g_m = 20): the base pole decays at 0.40 /s (the paper's Fig. 10(a) envelope); the kick
    # falls to 10 % of its peak 6.02 s after it ends (so does the 1 ms step map stepped sample by sample), a
    # mean rate ln 10 / 6.02 s = 0.383 /s.
    fig10 = modes_of(loop, 24.0, 20.0)
    assert -np.max(fig10.poles[fig10.is_base].real) == pytest.approx(0.40, abs=0.01)
    assert float(fig10.base_time_to_10pct) == pytest.approx(6.02, abs=0.01)
    assert float(fig10.base_decay_rate) == pytest.approx(0.383, abs=0.002)
    assert float(fig10.base_decay_rate) * float(fig10.base_time_to_10pct) == pytest.approx(np.log(10.0))
    locus = root_locus(loop, "g_b", fixed=20.0, values=np.array([24.0]))
    assert np.allclose(np.sort_complex(locus.poles[0]), np.sort_complex(modes_of(loop, 24.0, 20.0).poles))


def test_authority_fades_only_where_the_damped_inverse_engages(trep: FsmsModel) -> None:
    """Along theta_1 at theta_2 = 0 the coupling h_bm shrinks as the arm turns onto the base axis
    (Eq. 26: h_bm1 ~ sin theta_1). With the exact inverse h h^+ = 1 and the loop does not depend on
    |h|; once |h| falls below the damping threshold, h h^+ = |h|^2 / (|h|^2 + lambda^2) < 1 and the
    base decay that suppression buys fades with it."""
    thetas = np.column_stack((np.deg2rad([90.0, 30.0, 10.0, 4.0, 2.0, 1.0]), np.zeros(6)))
    rates = authority(loops_along(trep, "velocity", thetas), 24.0, 20.0)
    threshold = CouplingEvaluator(trep).threshold
    far = rates.coupling_norm > threshold
    assert far.sum() == 3
    assert np.ptp(rates.base_decay_rate[far]) < 1e-3 * rates.base_decay_rate[0]
    assert np.all(np.diff(rates.base_decay_rate[~far]) < 0)
    assert rates.base_decay_rate[-1] < 0.2 * rates.base_decay_rate[0]


def test_authority_in_runs_joined_is_the_authority_of_the_whole(trep: FsmsModel) -> None:
    """The app asks the helper for the authority a few configurations at a time and joins the runs."""
    thetas = np.column_stack((np.deg2rad([90.0, 60.0, 30.0, 10.0, 4.0]), np.deg2rad([0.0, 10.0, -20.0, 5.0, 0.0])))
    whole = authority(loops_along(trep, "velocity", thetas), 24.0, 20.0)
    runs = [authority(loops_along(trep, "velocity", thetas[a:b]), 24.0, 20.0) for a, b in ((0, 2), (2, 3), (3, 5))]
    both = joined(runs)
    for name in ("base_decay_rate", "arm_decay_rate", "base_damping_ratio", "stable", "coupling_norm"):
        np.testing.assert_array_equal(getattr(both, name), getattr(whole, name))
    with pytest.raises(ValueError, match="same gains"):
        joined([runs[0], authority(loops_along(trep, "velocity", thetas[:1]), 10.0, 20.0)])


def test_fig12_preset_decays_as_the_map_predicts_along_its_path(trep: FsmsModel) -> None:
    """Fig. 12's gain: on the cyclic reactionless path the map predicts one base decay everywhere,
    and the preset's kick decays at it, as Fig. 10(a) does at the same gains (0.40 /s)."""
    path = trace_paths(trep, np.deg2rad([[90.0, 0.0]]), ds=0.2)[0]
    along = authority(loops_along(trep, "velocity", path.theta), FIG12_GAINS.g_b, FIG12_GAINS.g_m)
    assert np.ptp(along.base_decay_rate) < 1e-3 * along.base_decay_rate.mean()
    log = run_scenario("fig12-on").log
    fit = fit_decay(log.column("t"), log.column("xb_1"), start=FIG12_KICK_AT_S + 0.2)
    assert fit.rate == pytest.approx(along.base_decay_rate.mean(), rel=0.05)
    assert fit.rate == pytest.approx(0.40, abs=0.02)


def _cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "rns_viz.cli", *args], capture_output=True, text=True, timeout=120)


def test_cli_gains_writes_the_map(tmp_path: Path, trep: FsmsModel) -> None:
    out = tmp_path / "map.csv"
    result = _cli("gains", "--model", "trep", "--law", "30", "--csv", str(out))
    assert result.returncode == 0, result.stderr
    table = read_csv(out)
    header, data = table.columns, table.rows
    assert header[:6] == ("g_b", "g_m", "base_decay_rate", "arm_decay_rate", "base_damping_ratio", "stable")
    assert table.units[:6] == ("1/s", "1/s", "1/s", "1/s", "1", "1 = stable")
    assert data.shape == (3600, len(header))
    stable = data[:, 5].astype(bool)
    assert stable.any() and not stable.all()
    assert np.all(data[stable, 2] > 0)
    # the same numbers as the library
    paper = np.argmin(np.abs(np.log(data[:, 0] / 24.0)) + np.abs(np.log(data[:, 1] / 20.0)))
    loop = linearise(trep, "velocity")
    expected = float(modes_of(loop, data[paper, 0], data[paper, 1]).base_decay_rate)
    assert data[paper, 2] == pytest.approx(expected, rel=1e-5)


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (["--law", "17"], "unknown law '17'"),
        (["--theta-deg", "1", "2", "3"], "needs 2 joint angles"),
        (["--model", "nosuch"], "invalid choice"),
        (["--size", "0"], "must be at least 1"),
    ],
)
def test_cli_gains_bad_arguments_give_one_line(args: list[str], fragment: str, tmp_path: Path) -> None:
    result = _cli("gains", "--csv", str(tmp_path / "x.csv"), *args)
    assert result.returncode == 2
    assert "Traceback" not in result.stderr and fragment in result.stderr
    assert not (tmp_path / "x.csv").exists()


def test_gain_map_figure_is_drawn(tmp_path: Path) -> None:
    from PIL import Image

    from rns_viz.figures import draw_all

    (path,) = draw_all(tmp_path, ["gain_map_trep"])
    assert path.name == "gain_map_trep.png"
    image = np.asarray(Image.open(path).convert("L"))
    assert min(image.shape) >= 350 and image.std() > 10


def test_a_state_that_is_not_at_rest_is_refused(tmp_path: Path) -> None:
    """Gravity along the base axis loads the spring: x_b = 0 is no equilibrium to linearise about."""
    assets = ASSETS
    text = (assets / "trep.toml").read_text()
    text = text.replace("gravity_m_per_s2 = [0.0, 0.0, 0.0]", "gravity_m_per_s2 = [-9.81, 0.0, 0.0]")
    text = text.replace('urdf = "trep.urdf"', f'urdf = "{(assets / "trep.urdf").as_posix()}"')
    (tmp_path / "tilted.toml").write_text(text)
    with pytest.raises(ValueError, match="not an equilibrium"):
        linearise(FsmsModel.from_file(tmp_path / "tilted.toml"), "velocity")
