"""Validation of the MuJoCo replay oracle (tests/support/oracles/mujoco_replay.py) on its own.

The oracle must agree with a plain RK4 of the FSMS equations of motion written here with
pinocchio's ``aba`` (torques and base forces held over each step, springs and dampers evaluated at
every stage), and MuJoCo's output must satisfy closed-form facts: the total linear momentum along
the base axis changes only through the base spring and damper, and small free oscillations of the
TREP base (arm free, zero torque) have the period of the arm-free effective mass.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np
import pinocchio as pin
import pytest

from rns_viz.model import FsmsModel
from tests.support.oracles.mujoco_replay import INERTIA_FLOOR, MujocoPlant, build_model, replay, simulate
from tests.support.repo import REPO

DT = 1e-3
STEPS = 2000
TOL_XB = 1e-9  # m


@dataclass(frozen=True)
class Case:
    """Amplitudes of a random replay: torque in N m, base force in N, deflection in m."""

    torque_hold: float  # held over 100-step blocks
    torque_noise: float  # changes every step
    x_b0: float
    arm_speed: float  # rad/s


CASES = {
    "trep": Case(torque_hold=0.02, torque_noise=0.005, x_b0=0.01, arm_speed=0.5),
    "planar3r": Case(torque_hold=20.0, torque_noise=5.0, x_b0=0.05, arm_speed=0.3),
}


def reference_rk4(
    model: FsmsModel,
    K: np.ndarray,
    D: np.ndarray,
    D_m: np.ndarray,
    q0: np.ndarray,
    v0: np.ndarray,
    torques: np.ndarray,
    base_forces: np.ndarray,
    dt: float,
    springs_at_stages: bool = True,
) -> tuple[np.ndarray, np.ndarray]:
    """Classical RK4 of M v' + c = [-K x_b - D x_b' + f; tau - D_m theta'] by pin.aba, inputs held.

    springs_at_stages=False holds the base spring and damper force at its step-start value
    instead (a wrong variant, used to show that the comparison can tell the two apart).
    """
    pm, m = model.pin_model, model.m
    data = pm.createData()
    held_base_force = np.zeros(m)

    def accel(q: np.ndarray, v: np.ndarray, tau: np.ndarray, f: np.ndarray) -> np.ndarray:
        spring = -K @ q[:m] - D @ v[:m] if springs_at_stages else held_base_force
        total = np.concatenate([spring + f, tau - D_m @ v[m:]])
        return pin.aba(pm, data, q, v, total).copy()

    steps = torques.shape[0]
    q = np.empty((steps + 1, pm.nq))
    v = np.empty((steps + 1, pm.nv))
    q[0], v[0] = q0, v0
    for k in range(steps):
        qk, vk, tau, f = q[k], v[k], torques[k], base_forces[k]
        held_base_force[:] = -K @ qk[:m] - D @ vk[:m]
        a1 = accel(qk, vk, tau, f)
        q2, v2 = qk + 0.5 * dt * vk, vk + 0.5 * dt * a1
        a2 = accel(q2, v2, tau, f)
        q3, v3 = qk + 0.5 * dt * v2, vk + 0.5 * dt * a2
        a3 = accel(q3, v3, tau, f)
        q4, v4 = qk + dt * v3, vk + dt * a3
        a4 = accel(q4, v4, tau, f)
        q[k + 1] = qk + dt / 6.0 * (vk + 2.0 * v2 + 2.0 * v3 + v4)
        v[k + 1] = vk + dt / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
    return q, v


def random_inputs(model: FsmsModel, case: Case, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Initial state (deflected base, moving arm) and piecewise-constant random torques (STEPS, n)."""
    rng = np.random.default_rng(seed)
    theta0 = model.spec.default_configuration + rng.uniform(-0.3, 0.3, model.n)
    q0 = model.q(theta0, np.full(model.m, case.x_b0))
    v0 = np.concatenate([np.zeros(model.m), rng.uniform(-case.arm_speed, case.arm_speed, model.n)])
    blocks = rng.uniform(-case.torque_hold, case.torque_hold, (STEPS // 100 + 1, model.n))
    noise = rng.uniform(-case.torque_noise, case.torque_noise, (STEPS, model.n))
    torques = np.repeat(blocks, 100, axis=0)[:STEPS] + noise
    return q0, v0, torques


def plant_for(model: FsmsModel, K: np.ndarray, D: np.ndarray, D_m: np.ndarray, **kwargs: float) -> MujocoPlant:
    spec = model.spec
    return build_model(spec.urdf_path, spec.base.joints, K, D, D_m, DT, **kwargs)


@pytest.fixture(scope="module", params=["trep", "planar3r"])
def fsms(request: pytest.FixtureRequest) -> FsmsModel:
    return request.getfixturevalue(request.param)


# -- (1) agreement with a plain RK4 of the same ODE -----------------------------------------------
def test_replay_matches_reference_rk4_with_model_parameters(fsms: FsmsModel) -> None:
    """Parameters of the model's TOML file, arm free, random held torques, no base force."""
    spec = fsms.spec
    q0, v0, torques = random_inputs(fsms, CASES[fsms.name], seed=1)
    q_mj, v_mj = replay(
        spec.urdf_path, spec.base.joints, spec.base.stiffness, spec.base.damping, spec.joint_damping,
        q0, v0, torques, None, DT,
    )  # fmt: skip
    no_force = np.zeros((STEPS, fsms.m))
    q_ref, v_ref = reference_rk4(fsms, fsms.K_b, fsms.D_b, fsms.D_m, q0, v0, torques, no_force, DT)
    assert q_mj.shape == v_mj.shape == (STEPS + 1, fsms.nv)
    assert np.array_equal(q_mj[0], q0) and np.array_equal(v_mj[0], v0)
    # the run is not trivial: the arm moves and the base is deflected
    assert np.abs(q_ref[:, fsms.m :] - q0[fsms.m :]).max() > 0.3
    assert np.abs(q_ref[:, : fsms.m]).max() > 0.5 * CASES[fsms.name].x_b0
    err_xb = np.abs(q_mj[:, : fsms.m] - q_ref[:, : fsms.m]).max()
    assert err_xb < TOL_XB, f"{fsms.name}: max |x_b difference| = {err_xb:.3e} m"
    assert np.abs(q_mj - q_ref).max() < 1e-8
    assert np.abs(v_mj - v_ref).max() < 1e-7


def test_springs_are_evaluated_at_every_rk4_stage(trep: FsmsModel) -> None:
    """MuJoCo's passive spring/damper forces enter each RK4 stage: a variant of the reference that
    holds them over the step is 1e-4 m away, five orders of magnitude above the tolerance."""
    q0, v0, torques = random_inputs(trep, CASES["trep"], seed=1)
    no_force = np.zeros((STEPS, 1))
    plant = plant_for(trep, trep.K_b, trep.D_b, trep.D_m)
    q_mj, _ = simulate(plant, q0, v0, torques, None)
    q_held, _ = reference_rk4(
        trep, trep.K_b, trep.D_b, trep.D_m, q0, v0, torques, no_force, DT, springs_at_stages=False
    )
    assert np.abs(q_mj[:, 0] - q_held[:, 0]).max() > 1e-5


def test_replay_matches_reference_rk4_with_dampers_and_base_force(fsms: FsmsModel) -> None:
    """Every input path at once: base damper, arm joint dampers, held external base force."""
    case = CASES[fsms.name]
    rng = np.random.default_rng(2)
    K = fsms.K_b
    H_b = fsms.mass_matrix(fsms.q(fsms.spec.default_configuration))[0, 0]
    D = np.diag(np.full(fsms.m, 0.1 * np.sqrt(K[0, 0] * H_b)))  # 5 % of critical damping
    D_m = np.diag(rng.uniform(0.5, 1.0, fsms.n) * case.torque_hold / case.arm_speed)
    q0, v0, torques = random_inputs(fsms, case, seed=3)
    base_forces = np.repeat(rng.uniform(-1.0, 1.0, (STEPS // 250 + 1, fsms.m)), 250, axis=0)[:STEPS]
    base_forces *= 0.5 * K[0, 0] * case.x_b0
    q_mj, v_mj = replay(
        fsms.spec.urdf_path, fsms.spec.base.joints, K, D, np.diag(D_m), q0, v0, torques, base_forces, DT
    )
    q_ref, v_ref = reference_rk4(fsms, K, D, D_m, q0, v0, torques, base_forces, DT)
    err_xb = np.abs(q_mj[:, : fsms.m] - q_ref[:, : fsms.m]).max()
    assert err_xb < TOL_XB, f"{fsms.name}: max |x_b difference| = {err_xb:.3e} m"
    assert np.abs(q_mj - q_ref).max() < 1e-8
    assert np.abs(v_mj - v_ref).max() < 1e-7


def test_inertia_floor_does_not_change_results(planar3r: FsmsModel) -> None:
    """planar3r has point masses, so MuJoCo needs an inertia floor. Its effect on x_b is linear in
    the floor (about 4 m per kg m^2 in this run): the default floor changes nothing measurable, and
    even a floor 100 times larger stays below the 1e-9 m budget.
    """
    q0, v0, torques = random_inputs(planar3r, CASES["planar3r"], seed=4)
    args = (planar3r.K_b, planar3r.D_b, planar3r.D_m)
    x_b = {
        floor: simulate(plant_for(planar3r, *args, inertia_floor=floor), q0, v0, torques, None)[0][:, 0]
        for floor in (INERTIA_FLOOR, 100.0 * INERTIA_FLOOR, 0.01 * INERTIA_FLOOR)
    }
    assert np.abs(x_b[INERTIA_FLOOR] - x_b[0.01 * INERTIA_FLOOR]).max() < 0.01 * TOL_XB
    assert np.abs(x_b[100.0 * INERTIA_FLOOR] - x_b[0.01 * INERTIA_FLOOR]).max() < TOL_XB


def test_mass_matrix_and_joint_map_agree_with_pinocchio(fsms: FsmsModel) -> None:
    """The same URDF gives the same M(q) in both (up to the inertia floor), after the joint-name map."""
    plant = plant_for(fsms, fsms.K_b, fsms.D_b, fsms.D_m)
    assert plant.joint_names == (*fsms.spec.base.joints, *fsms.arm_joint_names)
    data = mujoco.MjData(plant.model)
    full = np.zeros((plant.model.nv, plant.model.nv))
    rng = np.random.default_rng(5)
    for _ in range(20):
        q = rng.uniform(-np.pi, np.pi, fsms.nv)
        data.qpos[plant.qpos_index] = q
        mujoco.mj_forward(plant.model, data)
        mujoco.mj_fullM(plant.model, data, full)
        M_mj = full[np.ix_(plant.dof_index, plant.dof_index)]
        assert np.abs(M_mj - fsms.mass_matrix(q)).max() < 1e-9


XY_BASE_URDF = """<?xml version="1.0"?>
<robot name="xy_base">
  <link name="world"/>
  <link name="sled"><inertial><mass value="1"/>
    <inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
  <link name="cart"><inertial><mass value="1"/>
    <inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-3"/></inertial></link>
  <link name="arm"><inertial><origin xyz="0.5 0 0"/><mass value="2"/>
    <inertia ixx="1e-2" ixy="0" ixz="0" iyy="1e-2" iyz="0" izz="1e-2"/></inertial>
    <visual><geometry><mesh filename="package://nowhere/arm.stl"/></geometry></visual></link>
  <joint name="bx" type="prismatic"><parent link="world"/><child link="sled"/><axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="by" type="prismatic"><parent link="sled"/><child link="cart"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="j1" type="revolute"><parent link="cart"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>
"""


def test_two_dof_base_diagonal_joint_springs_coupled_tendons(tmp_path: Path) -> None:
    """A 2-DOF base: diagonal K_b, D_b map to joint springs; coupled ones to tendons giving -K x - D x'."""
    urdf = tmp_path / "xy_base.urdf"
    urdf.write_text(XY_BASE_URDF)  # also: a mesh visual that MuJoCo could not load is stripped
    K = np.diag([50.0, 80.0])
    D = np.diag([0.1, 0.2])
    plant = build_model(urdf, ["bx", "by"], K, D, [0.01], DT)
    assert np.allclose(plant.model.jnt_stiffness[plant.qpos_index], [50.0, 80.0, 0.0])
    assert np.allclose(plant.model.dof_damping[plant.dof_index], [0.1, 0.2, 0.01])
    q, _ = simulate(plant, np.array([0.01, -0.02, 0.5]), np.zeros(3), np.zeros((10, 1)), np.ones((10, 2)))
    assert q.shape == (11, 3) and np.all(np.isfinite(q))
    K_c, D_c = np.array([[50.0, -30.0], [-30.0, 80.0]]), np.array([[0.1, 0.05], [0.05, 0.2]])
    coupled = build_model(urdf, ["bx", "by"], K_c, D_c, [0.01], DT)
    assert coupled.model.ntendon == 4 and not np.any(coupled.model.jnt_stiffness)
    data = mujoco.MjData(coupled.model)
    x, xdot = np.array([0.01, -0.02]), np.array([0.3, 0.7])
    data.qpos[coupled.qpos_index[:2]], data.qvel[coupled.dof_index[:2]] = x, xdot
    mujoco.mj_forward(coupled.model, data)
    passive = data.qfrc_passive[coupled.dof_index[:2]]
    assert np.allclose(passive, -K_c @ x - D_c @ xdot, rtol=1e-12, atol=1e-12)
    with pytest.raises(ValueError, match="symmetric"):
        build_model(urdf, ["bx", "by"], np.array([[50.0, 5.0], [4.0, 80.0]]), D, [0.01], DT)
    with pytest.raises(ValueError, match="semi-definite"):
        build_model(urdf, ["bx", "by"], np.array([[50.0, 90.0], [90.0, 80.0]]), D, [0.01], DT)
    with pytest.raises(ValueError, match="shape"):
        build_model(urdf, ["bx", "by"], np.eye(3), D, [0.01], DT)
    with pytest.raises(ValueError, match="first joints"):
        build_model(urdf, ["by", "bx"], K, D, [0.01], DT)
    with pytest.raises(ValueError, match="torques"):
        simulate(plant, np.zeros(3), np.zeros(3), np.zeros((10, 2)), None)


def test_divergence_raises_instead_of_silent_reset(
    planar3r: FsmsModel, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """An unstable step (absurd joint damping for dt) raises; MuJoCo neither resets nor logs to cwd."""
    monkeypatch.chdir(tmp_path)
    plant = plant_for(planar3r, planar3r.K_b, planar3r.D_b, np.full(3, 1e5))
    q0 = planar3r.q(planar3r.spec.default_configuration)
    with pytest.raises(FloatingPointError, match="diverged"):
        simulate(plant, q0, np.ones(4), np.zeros((100, 3)), None)
    assert not list(tmp_path.iterdir())


# -- (2) closed-form checks on MuJoCo's output -----------------------------------------------------
def total_momentum_x(plant: MujocoPlant, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Linear momentum of the whole system along world x at each state, from MuJoCo's kinematics."""
    model = plant.model
    data = mujoco.MjData(model)
    out = np.empty(len(q))
    for k in range(len(q)):
        data.qpos[plant.qpos_index] = q[k]
        data.qvel[plant.dof_index] = v[k]
        mujoco.mj_forward(model, data)
        mujoco.mj_subtreeVel(model, data)
        out[k] = model.body_subtreemass[0] * data.subtree_linvel[0, 0]
    return out


def test_total_momentum_changes_only_through_base_spring_and_damper(fsms: FsmsModel) -> None:
    """dp_x/dt = -K x_b - D x_b' with the arm free and zero torque (its joint forces are internal).

    Finite differences on MuJoCo's output: p[k+2] - p[k] against Simpson's rule of the force over
    the same two steps (error O(dt^5)); a plain central difference would leave an O(dt^2) error of
    about 1e-5 relative here, which hides nothing but is a weaker check.
    """
    assert fsms.m == 1 and np.array_equal(fsms.base_axes()[0], [1.0, 0.0, 0.0])
    case = CASES[fsms.name]
    q0, v0, _ = random_inputs(fsms, case, seed=6)
    K, D = fsms.K_b, fsms.D_b + 0.02 * np.sqrt(fsms.K_b)  # some base damping for both models
    plant = plant_for(fsms, K, D, fsms.D_m)
    q, v = simulate(plant, q0, v0, np.zeros((STEPS // 2, fsms.n)), None)
    p = total_momentum_x(plant, q, v)
    force = -K[0, 0] * q[:, 0] - D[0, 0] * v[:, 0]
    dp = p[2:] - p[:-2]
    impulse = DT / 3.0 * (force[:-2] + 4.0 * force[1:-1] + force[2:])
    assert np.abs(q[:, 1:] - q0[1:]).max() > 0.1  # the arm moves and exchanges momentum
    assert np.abs(dp - impulse).max() < 1e-9 * np.abs(impulse).max()


def test_trep_small_free_oscillation_period(trep: FsmsModel) -> None:
    """Arm free at rest at theta = (90 deg, 0), zero torque, x_b0 = 1 mm, no damping: the period is
    2 pi sqrt(m_eff / k_b), m_eff = H_b - H_bm H_m^-1 H_mb (the arm yields), not the locked-arm one.

    At x_b0 = 1 cm the arm is not "at rest": it drifts by about 2 rad within 6 s through the
    nonlinear coupling and the period grows from 0.640 to 0.75 s, so the linear check uses 1 mm.
    """
    k_b = trep.K_b[0, 0]
    plant = plant_for(trep, trep.K_b, np.zeros((1, 1)), np.zeros((2, 2)))
    q0 = trep.q(np.array([np.pi / 2, 0.0]), np.array([1e-3]))
    q, _ = simulate(plant, q0, np.zeros(3), np.zeros((3000, 2)), None)
    x = q[:, 0]
    i = np.flatnonzero((x[:-1] < 0.0) & (x[1:] >= 0.0))
    crossings = (i - x[i] / (x[i + 1] - x[i])) * DT
    periods = np.diff(crossings)
    assert len(periods) >= 3
    data = mujoco.MjData(plant.model)
    data.qpos[plant.qpos_index] = q0
    mujoco.mj_forward(plant.model, data)
    full = np.zeros((3, 3))
    mujoco.mj_fullM(plant.model, data, full)
    H = full[np.ix_(plant.dof_index, plant.dof_index)]
    m_eff = H[0, 0] - H[0, 1:] @ np.linalg.solve(H[1:, 1:], H[1:, 0])
    expected = 2.0 * np.pi * np.sqrt(m_eff / k_b)
    locked = 2.0 * np.pi * np.sqrt(H[0, 0] / k_b)
    assert np.abs(periods - expected).max() < 1e-4 * expected
    assert locked - expected > 0.1  # s: the free arm makes a visibly shorter period
    assert np.abs(q[:, 1:] - q0[1:]).max() < 0.05  # the arm indeed moves little


# -- hygiene ---------------------------------------------------------------------------------------
def test_library_never_imports_mujoco() -> None:
    package = REPO / "rns_viz"
    pattern = re.compile(r"^\s*(import|from)\s+mujoco\b", re.MULTILINE)
    offenders = [str(p) for p in package.rglob("*.py") if pattern.search(p.read_text())]
    assert not offenders, f"rns_viz must not import mujoco: {offenders}"
