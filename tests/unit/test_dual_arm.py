"""Dynamic redundancy on trep2 (Sec. III-B): the compensating arm cancels the task arm's reaction.

Oracles: TREP's own model (the task arm is Table I's, unchanged), Eq. (26)'s closed form for the
compensator's coupling row, and MuJoCo replaying the logged torques on the same URDF tree.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from rns_viz.control import Gains, TaskSample
from rns_viz.control.compensation import CompensatingLaw, TaskCircle
from rns_viz.model import FsmsModel
from rns_viz.params import BUNDLED_MODELS, MODEL_NAMES
from rns_viz.scenarios import DUAL_SCENARIOS, TREP2_CIRCLE, TREP2_GAINS, run_scenario
from rns_viz.sim import Simulator
from tests.support.logs import columns
from tests.support.oracles.mujoco_replay import HeldOverEachStep, replay

TASK = ["joint1", "joint2"]
COMP = ["c_joint1", "c_joint2"]
M21, C21, L21, M22, C22 = 0.20, 0.08, 0.10, 0.15, 0.10  # compensator: kg, m (trep2.urdf)


@pytest.fixture(scope="module")
def runs() -> dict[str, Simulator]:
    return {name: run_scenario(name) for name in DUAL_SCENARIOS}


def ee_error(sim: Simulator) -> np.ndarray:
    log = sim.log
    ee = np.column_stack([log.column("ee_x"), log.column("ee_y")])
    ref = np.column_stack([log.column("ee_ref_x"), log.column("ee_ref_y")])
    return np.linalg.norm(ee - ref, axis=1)


# -- the model ----------------------------------------------------------------------------------
def test_trep2_groups_its_joints_by_name_whatever_pinocchios_order(trep2: FsmsModel, trep: FsmsModel) -> None:
    assert "trep2" in BUNDLED_MODELS and "trep2" in MODEL_NAMES  # served by the live app
    assert trep2.arm_joint_names == ("c_joint1", "c_joint2", "joint1", "joint2")  # the tree's branch order
    task, comp = trep2.arm_groups["task"], trep2.arm_groups["compensating"]
    assert [trep2.arm_joint_names[i] for i in task.index] == TASK and task.frame == "ee"
    assert [trep2.arm_joint_names[i] for i in comp.index] == COMP and comp.frame == "c_ee"
    assert trep.arm_groups == {}  # single-arm models are unchanged


def test_task_arm_is_treps_and_compensator_row_is_eq26(trep2: FsmsModel, trep: FsmsModel) -> None:
    """Same H_bm,1, J and end effector as TREP; H_b gains the compensator's 0.35 kg; h_bm,2 by Eq. (26)."""
    task, comp = trep2.arm_groups["task"].index, trep2.arm_groups["compensating"].index
    rng = np.random.default_rng(3)
    for _ in range(5):
        theta = rng.uniform(-np.pi, np.pi, 4)
        q2, q1 = trep2.q(theta), trep.q(theta[task])
        M2, M1 = trep2.mass_matrix(q2), trep.mass_matrix(q1)
        assert np.allclose(M2[0, 1 + task], M1[0, 1:], atol=1e-15)
        assert np.allclose(M2[np.ix_(1 + task, 1 + task)], M1[1:, 1:], atol=1e-15)
        assert M2[0, 0] == pytest.approx(M1[0, 0] + M21 + M22, abs=1e-12)
        assert np.allclose(trep2.ee_position(theta), trep.ee_position(theta[task]), atol=1e-15)
        assert np.allclose(trep2.ee_jacobian(theta)[:, task], trep.ee_jacobian(theta[task]), atol=1e-15)
        assert np.allclose(trep2.ee_jacobian(theta)[:, comp], 0.0)
        a, b = theta[comp]
        h21 = -(M21 * C21 + M22 * L21) * np.sin(a) - M22 * C22 * np.sin(a + b)
        h22 = -M22 * C22 * np.sin(a + b)
        assert np.allclose(M2[0, 1 + comp], [h21, h22], atol=1e-15)
        assert np.allclose(M2[np.ix_(1 + task, 1 + comp)], 0.0)  # two branches: no arm-arm inertia


def test_branch_points_follow_each_arm(trep2: FsmsModel) -> None:
    theta = trep2.spec.default_configuration
    comp = trep2.branch_points(theta, "compensating")
    assert np.allclose(comp[:, :2], [[0, 0], [0, -0.1], [0, -0.2]], atol=1e-12)  # stretched along -y
    assert np.allclose(comp[:, 2], -0.09)  # below the arm plane
    assert np.allclose(trep2.branch_points(theta, "task")[-1], trep2.ee_position(theta))


# -- the law ------------------------------------------------------------------------------------
def test_compensated_circle_keeps_the_base_below_one_percent_of_held(runs: dict[str, Simulator]) -> None:
    on, off = runs["trep2-circle-on"], runs["trep2-circle-off"]
    peak_on, peak_off = (np.abs(s.log.column("xb_1")).max() for s in (on, off))
    assert peak_off > 1e-3  # m: the task motion does shake the held-compensator system
    assert peak_on <= 0.01 * peak_off


def test_compensator_does_not_disturb_the_task(runs: dict[str, Simulator]) -> None:
    on, off = runs["trep2-circle-on"], runs["trep2-circle-off"]
    comp = on.model.arm_groups["compensating"].index
    err_on, err_off = ee_error(on), ee_error(off)
    assert np.abs(err_on - err_off).max() <= 1e-6  # m
    assert err_on.max() <= 1e-5  # m: and the task is tracked
    ref = np.column_stack([on.log.column("ee_ref_x"), on.log.column("ee_ref_y")])
    assert np.ptp(ref, axis=0).min() >= 2 * TREP2_CIRCLE["radius"] - 1e-6  # a whole circle was drawn (1 ms samples)
    assert np.ptp(columns(on, "theta", 4)[:, comp], axis=0).max() > 0.1  # rad: the compensator did move


def test_coupling_momentum_is_zero_to_1e9_of_the_task_arms() -> None:
    """Continuous-time control, no G_b term: L = S (H_bm,1 theta_1' + H_bm,2 theta_2') stays 0 (Eq. 10)."""
    sim = DUAL_SCENARIOS["trep2-circle-on"].build()
    law = sim.law
    continuous = Simulator(sim.model, law, hold_control=False)
    L, L_task = [], []
    for _ in range(round((TREP2_CIRCLE["t0"] + TREP2_CIRCLE["duration"]) / continuous.dt)):
        out = continuous.step()
        L.append(abs(out.coupling_momentum[0]))
        L_task.append(out.extra["L_task"])
    L, L_task = np.array(L), np.array(L_task)
    assert L_task.max() > 0.01  # kg m^2/s... kg m/s: the task arm alone would push the base
    moving = L_task >= 0.1 * L_task.max()
    assert np.all(L[moving] <= 1e-9 * L_task[moving])
    assert L.max() <= 1e-9 * L_task.max()


def test_commanded_acceleration_keeps_L_constant(trep2: FsmsModel) -> None:
    """At states with L = 0: S H_bm theta'' + S H_bm' theta' = 0 (Eq. 9) to 1e-9 of the task arm's part."""
    rng = np.random.default_rng(7)
    task, comp = trep2.arm_groups["task"].index, trep2.arm_groups["compensating"].index
    data = trep2.pin_model.createData()
    for _ in range(10):
        theta = trep2.spec.default_configuration + rng.uniform(-0.5, 0.5, 4)
        x_d = trep2.ee_position(theta)[:2] + rng.uniform(-0.01, 0.01, 2)
        law = CompensatingLaw(trep2, Gains(g_b=0.0, g_m=2.0), TaskSample(x_d, rng.normal(size=2), np.zeros(2)))
        q = trep2.q(theta)
        H = trep2.coupling_matrix(q)[0]
        v = np.zeros(5)
        v[1 + task] = rng.uniform(-1, 1, 2)
        h2 = H[comp]
        v[1 + comp] = -h2 * (H[task] @ v[1 + task]) / (h2 @ h2) + 0.3 * np.array([h2[1], -h2[0]])  # L = 0
        tau = law(0.0, q, v).tau
        a = pin.aba(trep2.pin_model, data, q, v, np.concatenate([[0.0], tau]))
        terms = trep2.terms(q, v)
        dL = H @ a[1:] + terms.hbm_dot_thetadot[0]
        assert abs(terms.coupling_momentum[0]) <= 1e-15
        assert abs(dL) <= 1e-9 * abs(H[task] @ a[1 + task])


def circle_from(model: FsmsModel, theta0: np.ndarray) -> CompensatingLaw:
    start = model.ee_position(theta0)[:2]
    radius = TREP2_CIRCLE["radius"]
    circle = TaskCircle(start - np.array([radius, 0.0]), **TREP2_CIRCLE)
    return CompensatingLaw(model, TREP2_GAINS, circle, suppress=False)


def test_at_a_compensator_singularity_every_signal_stays_finite(trep2: FsmsModel) -> None:
    """Compensator along x (S H_bm,2 = 0): the damped inverse keeps every logged signal finite."""
    theta0 = trep2.spec.default_configuration.copy()
    theta0[trep2.arm_groups["compensating"].index] = 0.0  # both links along +x
    law = circle_from(trep2, theta0)
    out = law(0.0, trep2.q(theta0), np.zeros(5))
    assert out.sigma_hbm == 0.0 and np.all(np.isfinite(out.tau))
    sim = Simulator(trep2, law, q0=trep2.q(theta0))
    log = sim.run(1.5).array()
    signals = [i for name, i in sim.log.index.items() if not name.startswith("theta_ref")]  # no joint reference
    assert np.all(np.isfinite(log[:, signals]))


def test_null_space_motion_takes_the_compensator_off_its_singularity(trep2: FsmsModel) -> None:
    """Started 0.02 rad from S H_bm,2 = 0, P_2 u_2 climbs sigma_2 back to most of its value at theta_0."""
    theta0 = trep2.spec.default_configuration.copy()
    theta0[trep2.arm_groups["compensating"].index] = (0.02, 0.0)
    law = circle_from(trep2, theta0)
    sim = Simulator(trep2, law, q0=trep2.q(theta0))
    sim.run(TREP2_CIRCLE["t0"] + TREP2_CIRCLE["duration"] + 0.2)
    t, sigma = sim.log.column("t"), sim.log.column("sigma_hbm")
    sigma0 = law.threshold / 0.1  # sigma_2 at the default configuration, kg m
    assert sigma[0] <= 0.025 * sigma0
    assert sigma[t >= 2.5].min() >= 0.5 * sigma0


def test_null_space_motion_leaves_a_joint_limit_without_shaking_the_base(trep2: FsmsModel) -> None:
    """c_joint2 10 deg from its 150 deg limit, task arm holding still: P_2 u_2 moves the compensator out of
    the 30 deg limit margin by self-motion, which the base does not feel (L stays 0)."""
    theta0 = trep2.spec.default_configuration.copy()
    theta0[trep2.arm_joint_names.index("c_joint2")] = np.radians(140.0)
    law = CompensatingLaw(trep2, TREP2_GAINS, TaskSample.held(trep2.ee_position(theta0)[:2]))
    sim = Simulator(trep2, law, q0=trep2.q(theta0))
    sim.run(1.5)
    c_joint2 = np.degrees(sim.log.column(f"theta_{trep2.arm_joint_names.index('c_joint2') + 1}"))
    assert c_joint2.max() <= 140.0 + 1e-9 and c_joint2[-1] <= 120.0  # deg: out of the margin
    assert np.abs(sim.log.column("xb_1")).max() <= 1e-6  # m, against mm for the task motions above
    assert np.abs(ee_error(sim)).max() <= 1e-9  # m: the task arm stays put


def test_kick_is_suppressed_through_the_compensator_alone(runs: dict[str, Simulator]) -> None:
    on, off = runs["trep2-kick-on"], runs["trep2-kick-off"]
    t = on.log.column("t")
    late = t >= 4.0
    xb_on, xb_off = on.log.column("xb_1"), off.log.column("xb_1")
    assert np.abs(xb_off[late]).max() > 1e-3  # m: without g_b the beam keeps ringing
    assert np.abs(xb_on[late]).max() <= 0.01 * np.abs(xb_off[late]).max()
    task = on.model.arm_groups["task"].index
    assert np.abs(columns(on, "theta", 4)[:, task] - on.model.spec.default_configuration[task]).max() <= 0.05  # rad


# -- independent engine -------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["trep2-circle-on", "trep2-kick-on"])
def test_mujoco_replays_the_dual_arm_run(runs: dict[str, Simulator], name: str) -> None:
    """MuJoCo, fed the same held torques and kick on the same URDF tree, gives the same x_b to 1e-9 m
    (the kick held over each step, as mj_step applies it). The circle is run with g_b on: a digital
    law, its torque held over each step (without g_b the law is evaluated at every RK4 stage)."""
    sim = runs[name]
    if name == "trep2-circle-on":
        sim = DUAL_SCENARIOS[name].build()
        sim.law.set_suppression(True)
        assert sim.law.sampled(0.0)
        sim.resize_log(round(DUAL_SCENARIOS[name].duration / sim.dt) + 1)
        sim.run(DUAL_SCENARIOS[name].duration)
    if name.startswith("trep2-kick"):
        duration = DUAL_SCENARIOS[name].duration
        sim = DUAL_SCENARIOS[name].build()
        sim.force = HeldOverEachStep(sim.force)
        sim.resize_log(round(duration / sim.dt) + 1)
        sim.run(duration)
    model, rows, col = sim.model, sim.log.array(), sim.log.index
    q0 = rows[0, [col["xb_1"], *(col[f"theta_{i + 1}"] for i in range(4))]]
    v0 = rows[0, [col["xbdot_1"], *(col[f"thetadot_{i + 1}"] for i in range(4))]]
    torques = columns(sim, "tau", 4)
    forces = rows[:, [col["fext_1"]]]
    q, _ = replay(
        model.spec.urdf_path, model.spec.base.joints, model.K_b, model.D_b, model.D_m, q0, v0, torques, forces, sim.dt
    )
    np.testing.assert_allclose(q[:-1, 0], rows[:, col["xb_1"]], atol=1e-9, rtol=0)
    assert np.abs(q[:, 0]).max() > 1e-6  # m: not comparing zeros


BOTH_ARMS = 'task = ["joint1", "joint2"]\ncompensating = ["c_joint1", "c_joint2"]'


BOTH_ARMS = 'task = ["joint1", "joint2"]\ncompensating = ["c_joint1", "c_joint2"]'


@pytest.mark.parametrize(
    ("arms", "message"),
    [
        ('task = ["joint1", "joint2"]\ncompensating = ["c_joint1"]', "every arm joint once"),
        ('task = ["joint1", "joint2"]\ncompensating = ["c_joint1", "joint2"]', "two arms"),
        (BOTH_ARMS + '\nee_frames = { compensating = "nope" }', "nope"),
        ('task = []\ncompensating = ["c_joint1", "c_joint2"]', "non-empty list"),
    ],
)
def test_bad_arms_tables_name_the_problem(tmp_path: Path, arms: str, message: str) -> None:
    from rns_viz.params import ASSETS_DIR, ModelFileError

    text = (ASSETS_DIR / "trep2.toml").read_text()
    text = text.replace('urdf = "trep2.urdf"', f'urdf = "{(ASSETS_DIR / "trep2.urdf").as_posix()}"')
    head, rest = text.split("[arms]\n")
    text = head + "[arms]\n" + arms + "\n\n[base]\n" + rest.split("[base]\n", 1)[1]
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(ModelFileError, match=message):
        FsmsModel.from_file(path)
