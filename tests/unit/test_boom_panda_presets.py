"""boom-panda's own presets (boom7's five experiments with the Franka Panda): headless runs that stay
reactionless where they claim to, and the CLI (the app: tests/app/test_boom_panda_presets.py).

Skipped without example-robot-data (pip install 'rns-viz[panda]').
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from rns_viz import robots
from rns_viz.control import JointQuintic
from rns_viz.control.hold import JointServo
from rns_viz.csvio import read_csv
from rns_viz.scenarios import (
    BOOM7_GAINS,
    BOOM7_MOVE_S,
    BOOM7_START_S,
    PANDA_SCENARIOS,
    SPATIAL_SCENARIOS,
    boom7_path_reference,
    boom7_track_end,
    presets_for,
    run_scenario,
)
from rns_viz.sim import Simulator
from tests.support.logs import columns

pytestmark = pytest.mark.skipif(
    not robots.is_installed("example-robot-data/panda"),
    reason="example-robot-data is not installed (pip install 'rns-viz[panda]')",
)
RUN_S = BOOM7_START_S + BOOM7_MOVE_S + 0.1  # s: every motion is over by then


def coupling_momentum(sim: Simulator) -> np.ndarray:
    """|S H_bm theta'| at every 5th logged step, recomputed from the logged q and theta' (Eq. 8's L)."""
    model, m, n = sim.model, sim.model.m, sim.model.n
    q = np.column_stack([columns(sim, "xb", m), columns(sim, "theta", n)])[::5]
    rates = columns(sim, "thetadot", n)[::5]
    rows = model.selected
    return np.array([np.linalg.norm(model.coupling_matrix(qk)[rows] @ w) for qk, w in zip(q, rates, strict=True)])


def test_the_panda_has_boom7s_five_experiments_under_its_own_name() -> None:
    assert [s.removeprefix("boom-panda-") for s in PANDA_SCENARIOS] == [
        s.removeprefix("boom7-") for s in SPATIAL_SCENARIOS
    ]
    assert all(s.model == "boom-panda" for s in PANDA_SCENARIOS.values())
    panda, boom7 = presets_for("boom-panda"), presets_for("boom7")
    assert tuple(PANDA_SCENARIOS) == panda and not set(panda) & set(boom7)


@pytest.mark.parametrize("name", list(PANDA_SCENARIOS))
def test_each_preset_runs_on_the_panda_inside_its_joint_limits(name: str) -> None:
    sim = run_scenario(name, RUN_S)
    assert sim.model.name.startswith("boom-panda") and sim.model.n == 7
    theta = columns(sim, "theta", 7)
    assert np.all(np.isfinite(theta)) and np.all(np.isfinite(columns(sim, "xb", 6)))
    assert np.all(theta >= sim.model.lower + 0.1) and np.all(theta <= sim.model.upper - 0.1)  # rad of margin


def test_the_r6_path_leaves_the_boom_below_one_percent_of_a_joint_quintic() -> None:
    """Fig. 11 on the Panda: every deflection and |S H_bm theta'| <= 1 % of a quintic between the same ends."""
    path = run_scenario("boom-panda-path", RUN_S)
    model = path.model
    theta0 = model.spec.default_configuration
    theta_end = boom7_path_reference(model)(BOOM7_START_S + BOOM7_MOVE_S)[0]
    assert np.linalg.norm(theta_end - theta0) >= 1.4  # rad: a real motion
    assert np.abs(path.q[6:] - theta_end).max() <= 1e-4  # rad: the arm got there
    p2p = Simulator(model, JointServo(model, BOOM7_GAINS, JointQuintic(theta0, theta_end, BOOM7_MOVE_S, BOOM7_START_S)))
    p2p.run(RUN_S)
    peaks_path, peaks_p2p = (np.abs(columns(s, "xb", 6)).max(axis=0) for s in (path, p2p))
    assert np.all(peaks_path <= 0.01 * peaks_p2p)
    assert coupling_momentum(path).max() <= 0.01 * coupling_momentum(p2p).max()


def test_forces_only_tracking_is_reactionless_in_force_against_the_p2p_preset() -> None:
    """boom-panda-track (24), r = 3: the target is reached and, in continuous time without the g_b term
    (which answers a deflection with coupling momentum on purpose), the force rows S H_bm theta' stay
    below 1e-6 of the boom-panda-p2p preset's, which joins the same end points."""
    built = PANDA_SCENARIOS["boom-panda-track"].build()
    built.law.set_suppression(False)
    track = Simulator(built.model, built.law, hold_control=False)
    track.run(RUN_S)
    assert np.linalg.norm(track.model.ee_position(track.q[6:]) - track.law.null_input.target(RUN_S)[0]) <= 1e-4
    p2p = run_scenario("boom-panda-p2p", RUN_S)
    assert list(p2p.model.selected) == list(track.model.selected) == [0, 1, 2]
    assert np.abs(p2p.q[6:] - boom7_track_end("boom-panda")).max() <= 1e-3  # rad: where the preset's tracking ends
    assert np.abs(p2p.q[6:] - track.q[6:]).max() <= 1e-2  # rad: and this continuous-time run, nearly
    L_track, L_p2p = (np.abs(columns(s, "L", 3)).max(axis=0) for s in (track, p2p))
    assert np.all(L_track <= 1e-6 * L_p2p)


def test_the_kick_preset_suppresses_all_six_modes() -> None:
    """boom-panda-kick-on: each deflection over 3-3.5 s is below 1 % of boom-panda-kick-off's."""
    late = []
    for name in ("boom-panda-kick-on", "boom-panda-kick-off"):
        sim = run_scenario(name, 3.5)
        late.append(np.abs(columns(sim, "xb", 6)[sim.log.column("t") >= 3.0]).max(axis=0))
    on, off = late
    assert np.all(off > 0) and np.all(on <= 0.01 * off)


def test_the_cli_runs_a_panda_preset_headless(tmp_path: Path) -> None:
    out = tmp_path / "panda.csv"
    result = subprocess.run(
        [sys.executable, "-m", "rns_viz.cli", "run", "boom-panda-path", "--csv", str(out), "--duration", "0.5"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert result.returncode == 0, result.stderr
    steps = int(result.stdout.removeprefix("boom-panda-path: ").split(" steps")[0])
    table = read_csv(out)
    assert steps >= 500 and len(table.rows) == steps  # 1 ms steps over 0.5 s
    assert "xb_6" in table.columns and "theta_7" in table.columns
