"""boom7, the spatial FSMS (m = 6 tip coordinates, n = 7 joints): Secs. II-V in general form, in 3-D.

Oracles: the cantilever's tip compliance (closed form), the SVD null space, MuJoCo loaded from the
same URDF, and the momentum balance of the whole system with the boom's spring and damper wrench as
the only external load.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import scipy.linalg

from rns_viz.control import AccelerationLaw, Gains, JointQuintic, JointServo, TaskQuintic, TrackEndEffector
from rns_viz.control.common import CouplingEvaluator
from rns_viz.defaults import defaults_for
from rns_viz.integrability import check_integrability
from rns_viz.model import FsmsModel
from rns_viz.params import BUNDLED_MODELS, MODEL_NAMES, ModelFileError
from rns_viz.paths import nearby_seeds, path_family, trace_paths
from rns_viz.rns import null_vector, rns_projector, singularity_distance
from rns_viz.scenarios import (
    ALL_SCENARIOS,
    BOOM7_DISPLACEMENT,
    BOOM7_GAINS,
    BOOM7_MOVE_S,
    BOOM7_START_S,
    DUAL_SCENARIOS,
    FORCES_ONLY,
    PANDA_SCENARIOS,
    SCENARIOS,
    SPATIAL_SCENARIOS,
    boom7_path_reference,
    boom7_track,
)
from rns_viz.sim import Simulator
from rns_viz.sim.plant import Plant
from tests.support.logs import columns
from tests.support.oracles.mujoco_replay import HeldOverEachStep, replay

RUN_S = BOOM7_START_S + BOOM7_MOVE_S + 0.1  # s: every motion is over by then
# The boom of boom7.toml: aluminium tube, E, G in Pa, length, outer diameter and wall in m.
E, G, L, D_OUT, WALL = 68.9e9, 26.0e9, 4.0, 0.100, 0.002


def energy_norm_peak(sim: Simulator) -> float:
    """Peak over time of sqrt(x_S^T K_SS x_S): the selected deflections in one unit-consistent norm (J^0.5)."""
    rows = sim.model.selected
    x = columns(sim, "xb", sim.model.m)[:, rows]
    return float(np.sqrt(np.einsum("ti,ij,tj->t", x, sim.model.K_b[np.ix_(rows, rows)], x)).max())


def test_boom_stiffness_is_the_cantilever_tip_stiffness(boom7: FsmsModel) -> None:
    """K_b is the inverse of a clamped tube's tip compliance; D_b = beta K_b gives 0.5 % in the first mode."""
    inner = D_OUT - 2 * WALL
    area, second_moment = np.pi / 4 * (D_OUT**2 - inner**2), np.pi / 64 * (D_OUT**4 - inner**4)
    EI, GJ, EA = E * second_moment, G * 2 * second_moment, E * area
    C = np.diag([L / EA, L**3 / (3 * EI), L**3 / (3 * EI), L / GJ, L / EI, L / EI])
    C[1, 5] = C[5, 1] = L**2 / (2 * EI)  # a force along +y turns the tip about +z
    C[2, 4] = C[4, 2] = -(L**2) / (2 * EI)  # a force along +z turns it about -y
    assert np.allclose(boom7.K_b, np.linalg.inv(C), rtol=1e-5, atol=0)
    H_b = boom7.mass_matrix(boom7.q(boom7.spec.default_configuration))[:6, :6]
    omega2, modes = scipy.linalg.eigh(boom7.K_b, H_b)
    damping_ratio = np.einsum("im,ij,jm->m", modes, boom7.D_b, modes) / (2 * np.sqrt(omega2))
    assert np.sqrt(omega2[0]) / (2 * np.pi) == pytest.approx(1.620, abs=0.005)  # Hz, as the file says
    assert damping_ratio[0] == pytest.approx(0.005, rel=1e-4)
    assert np.allclose(boom7.D_b, boom7.D_b[0, 0] / boom7.K_b[0, 0] * boom7.K_b, rtol=1e-5, atol=0)


def test_boom7_is_bundled_and_served(boom7: FsmsModel) -> None:
    assert "boom7" in BUNDLED_MODELS and "boom7" in MODEL_NAMES
    assert (boom7.m, boom7.n, boom7.nv) == (6, 7, 13)
    assert not np.any(boom7.spec.gravity)
    assert boom7.arm_mass == pytest.approx(16.792132)  # links 1-7 and hand, kg (link 0 is part of the tip)


def test_with_selection_rebuilds_the_model_with_another_S(boom7: FsmsModel) -> None:
    forces = boom7.with_selection([1, 1, 1, 0, 0, 0])
    q = boom7.q(boom7.spec.default_configuration)
    assert list(forces.selected) == [0, 1, 2] and list(boom7.selected) == list(range(6))
    assert np.array_equal(forces.coupling_matrix(q), boom7.coupling_matrix(q)[:3])
    for bad in ([1, 1, 1], [0] * 6, [2, 0, 0, 0, 0, 0]):
        with pytest.raises(ModelFileError, match="selection"):
            boom7.with_selection(bad)


def test_the_default_configuration_keeps_forces_only_tracking_away_from_singularity(boom7: FsmsModel) -> None:
    """sigma_min(J-bar = J P_RNS) with forces only (r = 3): 0.098 m/rad at theta_0, 0.003 at the Panda's ready pose."""
    forces = boom7.with_selection(FORCES_ONLY)

    def sigma_jbar(theta: np.ndarray) -> float:
        H = forces.coupling_matrix(forces.q(theta))
        return float(np.linalg.svd(forces.ee_jacobian(theta) @ rns_projector(H), compute_uv=False)[-1])

    assert sigma_jbar(forces.spec.default_configuration) == pytest.approx(0.098, abs=5e-4)  # m/rad
    ready = np.array([0.0, -np.pi / 4, 0.0, -3 * np.pi / 4, 0.0, np.pi / 2, np.pi / 4])
    assert sigma_jbar(ready) < 0.005


def test_traced_r6_path_tangent_lies_in_the_reaction_null_space(boom7: FsmsModel) -> None:
    """|S H_bm t| <= 1e-9 |S H_bm| |t| at every point; t agrees with the SVD null space (an independent oracle)."""
    (path,) = trace_paths(boom7, boom7.spec.default_configuration[None], ds=0.1, max_length=2.0)
    assert path.s[-1] >= 1.5 and len(path.theta) >= 20  # rad: a real curve, not a stub
    for theta in path.theta:
        H = boom7.coupling_matrix(boom7.q(theta))
        t = null_vector(H)
        assert np.linalg.norm(H @ t) <= 1e-9 * np.linalg.norm(H, 2) * np.linalg.norm(t)
        svd_null = np.linalg.svd(H)[2][-1]
        assert abs(abs(svd_null @ t) / np.linalg.norm(t) - 1.0) <= 1e-9
    chords = np.diff(path.theta, axis=0)  # the traced points themselves follow the tangent
    midpoints = 0.5 * (path.theta[1:] + path.theta[:-1])
    for chord, mid in zip(chords, midpoints, strict=True):
        t = null_vector(boom7.coupling_matrix(boom7.q(mid)))
        assert abs(chord @ t) / (np.linalg.norm(chord) * np.linalg.norm(t)) >= 1 - 1e-6


def test_r6_path_excites_the_base_below_one_percent_of_a_joint_quintic(boom7: FsmsModel) -> None:
    """Fig. 11 in 3-D: law (15) along the r = 6 path versus a joint-space quintic between its end points."""
    path = SPATIAL_SCENARIOS["boom7-path"].build()
    path.run(RUN_S)
    theta0 = boom7.spec.default_configuration
    theta_end = boom7_path_reference(boom7)(BOOM7_START_S + BOOM7_MOVE_S)[0]
    assert np.linalg.norm(theta_end - theta0) >= 1.4  # rad
    assert np.abs(path.q[6:] - theta_end).max() <= 1e-4  # rad: the arm got there
    quintic = JointServo(boom7, BOOM7_GAINS, JointQuintic(theta0, theta_end, BOOM7_MOVE_S, t0=BOOM7_START_S))
    p2p = Simulator(boom7, quintic)
    p2p.run(RUN_S)
    assert energy_norm_peak(path) <= 0.01 * energy_norm_peak(p2p)
    peaks_path, peaks_p2p = (np.abs(columns(s, "xb", 6)).max(axis=0) for s in (path, p2p))
    assert np.all(peaks_path <= 0.01 * peaks_p2p)  # and each of the six deflections alone


@pytest.mark.parametrize("suppress", [True, False], ids=["as shipped", "g_b off"])
def test_forces_only_tracking_is_reactionless_in_force(boom7: FsmsModel, suppress: bool) -> None:
    """r = 3 (S = x, y, z), Eq. (24), the boom7-track preset: the end effector reaches its target; against a
    joint quintic between the same end points, the force reactions (the coupling momentum L = S H_bm
    theta', Eq. 8) stay below 1e-6 of the quintic's without the g_b term (a law without g_b runs at every
    RK4 stage: ControlLaw.sampled). As shipped, with suppression on, they do not: (15) makes
    d(S L)/dt = g_b S H_b x_b' - g_m S L, answering the deflection that the free moments cause with
    coupling momentum (a third of the quintic's in z).

    The tip's translations move either way: the moments are left free, and a moment M at a cantilever's
    tip deflects it by M L^2/(2 EI) (docs/modelling.md); see the next test for a boom tip
    that cannot turn, where forces-only tracking leaves the selected deflections at rest too.
    """
    track = boom7_track()
    track.law.set_suppression(suppress)
    track.run(RUN_S)
    x_d = track.law.null_input.target(RUN_S)[0]
    assert np.linalg.norm(track.model.ee_position(track.q[6:]) - x_d) <= 1e-4  # m
    theta0, theta_end = track.model.spec.default_configuration, track.q[6:].copy()
    quintic = JointQuintic(theta0, theta_end, BOOM7_MOVE_S, t0=BOOM7_START_S)
    p2p = Simulator(track.model, JointServo(track.model, BOOM7_GAINS, quintic))
    p2p.run(RUN_S)
    L_track, L_p2p = (np.abs(columns(s, "L", 3)).max(axis=0) for s in (track, p2p))
    if suppress:
        assert 0.1 <= (L_track / L_p2p).max() <= 0.5  # measured 0.36 (z)
    else:
        assert np.all(L_track <= 1e-6 * L_p2p)  # measured 5e-11
    assert energy_norm_peak(track) >= 0.05 * energy_norm_peak(p2p)  # the free moments bend the boom


def clamped_rotation_boom(model: FsmsModel, where: Path) -> FsmsModel:
    """boom7 whose tip cannot turn (rx, ry, rz rigid): m = 3, K_b = the 3x3 translational block."""
    urdf = model.spec.urdf_path.read_text()
    for joint in ("base_rx", "base_ry", "base_rz"):
        urdf = urdf.replace(f'<joint name="{joint}" type="revolute">', f'<joint name="{joint}" type="fixed">')
    (where / "boom3.urdf").write_text(urdf)
    block = np.ix_(range(3), range(3))

    def rows(matrix: np.ndarray) -> str:
        return "[" + ", ".join("[" + ", ".join(repr(float(x)) for x in row) + "]" for row in matrix) + "]"

    theta0 = ", ".join(repr(float(x)) for x in np.rad2deg(model.spec.default_configuration))
    (where / "boom3.toml").write_text(
        f'[model]\nname = "boom3"\nurdf = "boom3.urdf"\nee_frame = "ee"\ntask_axes = ["x", "y", "z"]\n'
        f"default_configuration_deg = [{theta0}]\n"
        f'[base]\njoints = ["base_x", "base_y", "base_z"]\nstiffness = {rows(model.K_b[block])}\n'
        f"damping = {rows(model.D_b[block])}\nselection = [1, 1, 1]\n"
    )
    return FsmsModel.from_file(where / "boom3.toml")


def test_forces_only_tracking_leaves_a_tip_that_cannot_turn_at_rest(boom7: FsmsModel, tmp_path: Path) -> None:
    """r = 3 on the same boom with its tip rotations clamped: deflections <= 1 % of the quintic's."""
    model = clamped_rotation_boom(boom7, tmp_path)
    start = model.ee_position(model.spec.default_configuration)
    task = TaskQuintic(start, start + BOOM7_DISPLACEMENT, BOOM7_MOVE_S, t0=BOOM7_START_S)
    g = BOOM7_GAINS
    track = Simulator(model, AccelerationLaw(model, g, null_input=TrackEndEffector(model, task, g.G_p, g.G_d)))
    track.run(RUN_S)
    assert np.linalg.norm(model.ee_position(track.q[3:]) - task(RUN_S)[0]) <= 1e-4  # m
    quintic = JointQuintic(model.spec.default_configuration, track.q[3:].copy(), BOOM7_MOVE_S, t0=BOOM7_START_S)
    p2p = Simulator(model, JointServo(model, g, quintic))
    p2p.run(RUN_S)
    peaks_track, peaks_p2p = (np.abs(columns(s, "xb", 3)).max(axis=0) for s in (track, p2p))
    assert np.all(peaks_track <= 0.01 * peaks_p2p)


@pytest.fixture(scope="module")
def kicked() -> Simulator:
    """boom7-kick-on: the six-direction kick suppressed by (15), first 3.5 s."""
    sim = SPATIAL_SCENARIOS["boom7-kick-on"].build()
    sim.run(3.5)
    return sim


def test_kick_is_suppressed_in_all_six_modes(kicked: Simulator) -> None:
    """Each deflection over 3-3.5 s is below 1 % of the joints-held run's, with the arm inside its limits."""
    held = SPATIAL_SCENARIOS["boom7-kick-off"].build()
    held.run(3.5)
    late = kicked.log.column("t") >= 3.0
    on, off = (np.abs(columns(s, "xb", 6)[late]).max(axis=0) for s in (kicked, held))
    assert np.all(on <= 0.01 * off)
    theta = columns(kicked, "theta", 7)
    assert np.all((theta >= kicked.model.lower) & (theta <= kicked.model.upper))


def test_mujoco_replay_of_the_3d_kick_reproduces_all_six_deflections(boom7: FsmsModel) -> None:
    """MuJoCo from the same URDF (coupled K_b, D_b as tendons), the logged torques and kick held per step."""
    sim = SPATIAL_SCENARIOS["boom7-kick-on"].build()
    sim.force = HeldOverEachStep(sim.force)
    sim.run(3.5)
    x_b = np.vstack([columns(sim, "xb", 6), sim.q[None, :6]])
    theta = np.vstack([columns(sim, "theta", 7), sim.q[None, 6:]])
    q0 = np.concatenate([x_b[0], theta[0]])
    v0 = np.concatenate([columns(sim, "xbdot", 6)[0], columns(sim, "thetadot", 7)[0]])
    spec = boom7.spec
    q_mj, _ = replay(
        spec.urdf_path, spec.base.joints, boom7.K_b, boom7.D_b, spec.joint_damping,
        q0, v0, columns(sim, "tau", 7), columns(sim, "fext", 6), sim.dt,
    )  # fmt: skip
    peak = np.abs(x_b).max(axis=0)
    assert np.all(peak[1:] > 1e-4) and peak[0] > 1e-7  # all six modes were kicked (m, rad; axial is stiff)
    assert np.all(np.abs(q_mj[:, :6] - x_b).max(axis=0) <= 1e-6 * peak)
    assert np.abs(theta[-1] - theta[0]).max() >= 0.1  # rad: the arm really absorbed the kick


def test_spatial_presets_are_apart_from_the_apps(boom7: FsmsModel) -> None:
    """boom7's presets, named apart from the paper's; run_scenario and the CLI take ALL_SCENARIOS."""
    assert set(SPATIAL_SCENARIOS) == {"boom7-kick-on", "boom7-kick-off", "boom7-path", "boom7-track", "boom7-p2p"}
    assert not set(SPATIAL_SCENARIOS) & set(SCENARIOS)
    sources = {**SCENARIOS, **SPATIAL_SCENARIOS, **PANDA_SCENARIOS, **DUAL_SCENARIOS}
    assert {name: replace(s, look="") for name, s in ALL_SCENARIOS.items()} == {  # ALL adds what to look at
        name: replace(s, look="") for name, s in sources.items()
    }
    assert all(s.model == "boom7" for s in SPATIAL_SCENARIOS.values())
    gains = defaults_for("boom7").gains_for("acceleration")  # what the app will start with
    assert (gains.g_b, gains.g_m) == (BOOM7_GAINS.g_b, BOOM7_GAINS.g_m)


def test_damping_threshold_follows_the_distance_to_singularity(boom7: FsmsModel, trep: FsmsModel) -> None:
    """10 % of sigma_min(W S H_bm(theta_0)), the moment rows divided by the arm's reach: for one row that
    is |h| (TREP as before); boom7 is not damped there (the norm would have damped it at every step)."""
    h = trep.coupling_matrix(trep.q(trep.spec.default_configuration))
    assert trep.coupling_weights is None
    assert CouplingEvaluator(trep).threshold == pytest.approx(0.1 * np.linalg.norm(h), rel=1e-12)
    H = boom7.coupling_matrix(boom7.q(boom7.spec.default_configuration))
    W = np.diag(boom7.coupling_weights)
    assert np.allclose(np.diag(W), [1, 1, 1, *[1 / boom7.arm_reach] * 3])
    sigma = np.linalg.svd(W @ H, compute_uv=False)
    assert CouplingEvaluator(boom7).threshold == pytest.approx(0.1 * sigma[-1], rel=1e-12)
    assert 0.1 * sigma[-1] < 0.01 * np.linalg.norm(W @ H)  # what the norm would have given: 100x more


def test_the_distance_to_singularity_is_in_kg_m_whatever_the_unit_of_length(boom7: FsmsModel) -> None:
    """Restated in millimetres, S H_bm's force rows (kg m) grow 1e3 times, its moment rows (kg m^2) 1e6
    times and the reach 1e3 times: the weighted distance grows exactly 1e3 times (kg m -> kg mm), the
    unweighted sigma_min of the mixed rows does not (its value depended on the unit chosen)."""
    H = boom7.coupling_matrix(boom7.q(boom7.spec.default_configuration))
    c = 1e3  # mm per m
    H_mm = H * np.array([c, c, c, c * c, c * c, c * c])[:, None]
    w_mm = np.array([1.0, 1.0, 1.0, *[1 / (c * boom7.arm_reach)] * 3])
    assert singularity_distance(H_mm, w_mm) == pytest.approx(c * singularity_distance(H, boom7.coupling_weights))
    unweighted = singularity_distance(H_mm) / singularity_distance(H)
    assert abs(unweighted / c - 1) > 0.2


def test_momentum_balance_with_the_boom_wrench_as_the_only_external_load(boom7: FsmsModel) -> None:
    """d/dt (linear, angular momentum about the clamp) = boom wrench W, W = J_tip^-T (-K_b x_b - D_b x_b').

    The five links between the tip coordinates are massless, so W (the spring and damper forces
    mapped through the tip's 6x6 Jacobian) is the whole external load. Law (15) from a deflected tip,
    gravity off. W is integrated per step by the corrected trapezoid h/2 (W_0 + W_1) + h^2/12 (W_0' - W_1'),
    W' from the held torque's accelerations; dt is small enough to resolve the 168 Hz axial mode.
    """
    dt, steps = 3e-5, 4000
    x0 = np.array([0.0, 2e-3, -3e-3, 1e-3, 1e-3, -1e-3])  # m and rad
    theta0 = boom7.spec.default_configuration
    sim = Simulator(boom7, AccelerationLaw(boom7, Gains(g_b=10.0, g_m=2.0)), dt=dt, q0=boom7.q(theta0, x0))
    sim.resize_log(steps)
    sim.run(steps * dt)
    q = np.vstack([np.hstack([columns(sim, "xb", 6), columns(sim, "theta", 7)]), sim.q])
    v = np.vstack([np.hstack([columns(sim, "xbdot", 6), columns(sim, "thetadot", 7)]), sim.v])
    tau = columns(sim, "tau", 7)
    model, data, plant = boom7.pin_model, boom7.pin_model.createData(), Plant(boom7)

    def momentum(qk: np.ndarray, vk: np.ndarray) -> np.ndarray:
        h = pin.computeCentroidalMomentum(model, data, qk, vk)
        return np.concatenate([h.linear, h.angular + np.cross(data.com[0], h.linear)])  # about the origin

    def wrench(qk: np.ndarray, vk: np.ndarray) -> np.ndarray:
        pin.computeJointJacobians(model, data, qk)
        J = pin.getJointJacobian(model, data, boom7.m, pin.WORLD)[:, :6]
        return np.linalg.solve(J.T, -boom7.K_b @ qk[:6] - boom7.D_b @ vk[:6])

    def wrench_rate(qk: np.ndarray, vk: np.ndarray, ak: np.ndarray, eps: float = 1e-6) -> np.ndarray:
        return (wrench(qk + eps * vk, vk + eps * ak) - wrench(qk - eps * vk, vk - eps * ak)) / (2 * eps)

    h = np.array([momentum(qk, vk) for qk, vk in zip(q, v, strict=True)])
    impulse = np.zeros_like(h)
    for k in range(steps):
        a0 = plant.acceleration(q[k], v[k], tau[k], None).copy()
        a1 = plant.acceleration(q[k + 1], v[k + 1], tau[k], None).copy()
        trapezoid = 0.5 * dt * (wrench(q[k], v[k]) + wrench(q[k + 1], v[k + 1]))
        correction = dt**2 / 12 * (wrench_rate(q[k], v[k], a0) - wrench_rate(q[k + 1], v[k + 1], a1))
        impulse[k + 1] = impulse[k] + trapezoid + correction
    error = h - h[0] - impulse
    for part in (slice(0, 3), slice(3, 6)):  # linear (N s), angular (N m s)
        peak = np.linalg.norm(h[:, part], axis=1).max()
        assert peak > 0.05
        assert np.abs(error[:, part]).max() <= 1e-9 * peak


def test_batched_null_vectors_and_the_3d_path_family(boom7: FsmsModel) -> None:
    """null_vector of a stack is the stack of null vectors; path_family works without a coupling potential."""
    thetas = nearby_seeds(boom7, boom7.spec.default_configuration, 5)
    H = np.array([boom7.coupling_matrix(boom7.q(theta)) for theta in thetas])
    assert np.allclose(null_vector(H), [null_vector(h) for h in H], rtol=1e-12, atol=0)
    assert np.allclose(np.linalg.norm(thetas - boom7.spec.default_configuration, axis=1), 0.3)
    family = path_family(boom7, count=6, max_length=1.0)
    assert len(family) == 6 and all(p.ee.shape == (len(p.s), 3) for p in family)
    for path in family:
        H = boom7.coupling_matrix(boom7.q(path.theta[len(path.s) // 2]))
        t = null_vector(H)
        assert np.linalg.norm(H @ t) <= 1e-9 * np.linalg.norm(H, 2) * np.linalg.norm(t)


def test_forces_only_rns_is_integrable_moments_only_is_not(boom7: FsmsModel) -> None:
    """Sec. III-A, Frobenius: zero force reaction keeps the arm's centre of mass fixed on the tip, a
    holonomic constraint (integrable RNS); zero moment reaction is angular momentum, which is not."""
    samples = boom7.spec.default_configuration + np.random.default_rng(0).uniform(-0.3, 0.3, (3, 7))
    results = {}
    for name, selection in (("forces", [1, 1, 1, 0, 0, 0]), ("moments", [0, 0, 0, 1, 1, 1])):
        model = boom7.with_selection(selection)
        results[name] = check_integrability(lambda th, model=model: model.coupling_matrix(model.q(th)), samples)
    assert results["forces"].integrable and results["forces"].rns_dim == 4
    assert results["forces"].max_residual <= 1e-6
    assert not results["moments"].integrable and results["moments"].max_residual >= 0.01
