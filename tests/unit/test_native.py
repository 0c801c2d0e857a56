"""The native closed-loop step (C++, ``pip install ./native``) computes what the Python laws (15),
(30) and RK4 compute.

The C++ pinocchio model built from the URDF text gives the Python model's M and c of Eq. (1).
Trajectories with a kick (force at the RK4 stage times), suppression switching on and gains changed
mid-run agree to 1e-12, and so do the paper's presets run both ways; the laws alone agree at random
states, at the TREP singularity, for a 2-DOF base with one or both rows selected (the SVD branch)
and with gravity (the Coriolis branch of H_bm' theta'). Eq. (24) tracking is compared on the 3R (a
2-D RNS) and on the 2-DOF base; the path tracer's centre-of-mass kernels against pinocchio's Python
calls. Steps that evaluate the law at every RK4 stage (a joint servo, a law without g_b, continuous-time
control; g_b and the reference at the stage times) agree with Python's on the 3R and boom7, and the
damped inverse of boom7's weighted moment rows where it damps. Skipped when the module is not
installed, unless RNS_VIZ_REQUIRE_NATIVE=1 (CI's native job):
then a missing or unusable module fails.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from rns_viz import _native
from rns_viz.control import (
    AccelerationLaw,
    DampNullMotion,
    FixedReference,
    Gains,
    JointQuintic,
    JointServo,
    TorqueLaw,
    TrackEndEffector,
    TrackJointReference,
    VelocityLaw,
)
from rns_viz.control.common import Coupling
from rns_viz.control.null_input import NullOutput
from rns_viz.model import FsmsModel
from rns_viz.paths import CouplingField, path_family
from rns_viz.scenarios import SCENARIOS, run_scenario
from rns_viz.sim import ForcePulse, SimulationDiverged, Simulator, native
from tests.support.repo import ASSETS

if not native.available():
    if os.environ.get("RNS_VIZ_REQUIRE_NATIVE") == "1":
        raise RuntimeError(f"RNS_VIZ_REQUIRE_NATIVE=1 but {native.unavailable_reason()}")
    pytest.skip(f"native step not built: {native.unavailable_reason()}", allow_module_level=True)

RNG = np.random.default_rng(11)
NATIVE_LAW_TOLERANCE = 1e-12  # relative, per logged column and state entry


def pair(model: FsmsModel, law: AccelerationLaw, **kw: object) -> tuple[Simulator, Simulator]:
    """The same law and start in a native and a Python simulator."""
    sims = (Simulator(model, law, native=True, **kw), Simulator(model, law, native=False, **kw))  # type: ignore[arg-type]
    assert sims[0].native and not sims[1].native
    return sims


@pytest.mark.parametrize("name", ["trep", "planar3r"])
def test_trajectories_agree(name: str) -> None:
    model = FsmsModel.from_name(name)
    law = AccelerationLaw(model, Gains(g_b=20.0, g_m=5.0), suppress_after=0.5)
    kick = ForcePulse(0.1, 0.05, np.array([2.0 if name == "trep" else 20.0]))
    sims = pair(model, law, force=kick)
    for s in sims:
        s.q = s.q + np.r_[1e-3, np.zeros(model.n)]
        s.v = s.v + np.r_[0.0, np.full(model.n, 0.2)]
    for s in sims:
        s.run(1.0)
    law.gains = Gains(g_b=5.0, g_m=1.0)  # read at every step by both
    law.null_input = DampNullMotion(3.0)
    for s in sims:
        s.run(1.0)
    native_log, python_log = (s.log.array() for s in sims)
    assert abs(sims[0].q[0]) > 1e-6  # the base really moved
    assert np.array_equal(np.isnan(native_log), np.isnan(python_log))
    assert np.nanmax(np.abs(native_log - python_log)) <= 1e-12 * max(1.0, np.nanmax(np.abs(python_log)))
    assert np.max(np.abs(sims[0]._x - sims[1]._x)) <= 1e-12


def law_agrees(
    model: FsmsModel, law: AccelerationLaw | VelocityLaw | JointServo, q: np.ndarray, v: np.ndarray, t: float = 1.0
) -> None:
    step = native.NativeStep(model, law)
    got = step.control(t, np.concatenate((q, v)))
    want = law(t, q, v)
    scale = max(1.0, float(np.max(np.abs(want.tau))))
    assert np.allclose(got.tau, want.tau, rtol=0, atol=1e-10 * scale), (got.tau, want.tau)
    assert np.allclose(got.coupling_momentum, want.coupling_momentum, rtol=1e-12, atol=1e-14)
    assert math.isclose(got.sigma_hbm, want.sigma_hbm, rel_tol=1e-12, abs_tol=1e-14)
    if math.isnan(want.sigma_jbar):
        assert math.isnan(got.sigma_jbar)
    else:
        assert math.isclose(got.sigma_jbar, want.sigma_jbar, rel_tol=1e-9, abs_tol=1e-12)
    for name in ("theta_ref", "ee_ref"):
        expected = getattr(want, name)
        assert (getattr(got, name) is None) if expected is None else np.array_equal(getattr(got, name), expected)


def random_laws(model: FsmsModel) -> list[AccelerationLaw | VelocityLaw | JointServo]:
    """One law of each natively computed kind, random gains, random quintic joint and task references."""
    gains = Gains(
        g_b=RNG.uniform(0, 50),
        g_m=RNG.uniform(0, 30),
        k_p=RNG.uniform(0, 500),
        k_d=RNG.uniform(0, 50),
        servo_bandwidth=RNG.uniform(10, 500),
    )
    theta0 = model.spec.default_configuration
    reference = JointQuintic(theta0, theta0 + RNG.uniform(-1, 1, model.n), 2.0)
    damped = AccelerationLaw(model, gains, DampNullMotion(RNG.uniform(0, 30)))
    tracking = AccelerationLaw(model, gains, TrackJointReference(reference, gains.k_p, gains.k_d))
    velocity = VelocityLaw(model, gains, reference, feedforward=bool(RNG.integers(2)))
    servo = JointServo(model, gains, reference)
    laws: list[AccelerationLaw | VelocityLaw | JointServo] = [damped, tracking, velocity, servo]
    if model.n - len(model.selected) >= len(model.task_rows):  # an RNS wide enough for Eq. (24)
        ee0 = model.ee_position(theta0)[model.task_rows]
        target = JointQuintic(ee0, ee0 + RNG.uniform(-0.3, 0.3, len(ee0)), 2.0)
        G_p, G_d, threshold = RNG.uniform(0, 400), RNG.uniform(0, 40), RNG.uniform(1e-3, 0.1)
        laws.append(AccelerationLaw(model, gains, TrackEndEffector(model, target, G_p, G_d, threshold)))
    return laws


def models(tmp_path: Path) -> list[FsmsModel]:
    """The bundled models and the 2-DOF base with gravity (every branch of the C++ model build)."""
    return [FsmsModel.from_name("trep"), FsmsModel.from_name("planar3r"), xy_model(tmp_path, [1, 1], [0.0, -9.81, 0.0])]


def test_cpp_model_equals_the_python_model(tmp_path: Path) -> None:
    """crba and nonLinearEffects of the model built in C++ from the URDF text equal pinocchio's
    Python model (same parser, same gravity) to 1e-12, at random states."""
    for model in models(tmp_path):
        robot = _native.robot_model(model)
        assert robot is not None and robot.nv == model.nv
        data = model.pin_model.createData()
        worst = 0.0
        for _ in range(50):
            q = np.r_[RNG.normal(0, 1e-2, model.m), RNG.uniform(-math.pi, math.pi, model.n)]
            v = RNG.normal(0, 1.0, model.nv)
            M, c = model.mass_matrix(q), pin.nonLinearEffects(model.pin_model, data, q, v)
            assert np.any(c != 0.0)
            worst = max(
                worst,
                float(np.max(np.abs(robot.mass_matrix(q) - M))) / max(1.0, float(np.max(np.abs(M)))),
                float(np.max(np.abs(robot.nonlinear_effects(q, v) - c))) / max(1.0, float(np.max(np.abs(c)))),
            )
        assert worst <= NATIVE_LAW_TOLERANCE, (model.name, worst)


@pytest.mark.parametrize("name", ["trep", "planar3r", "boom7 forces only"])
def test_law_agrees_at_random_states(name: str) -> None:
    """boom7 with S = forces only: a 6-DOF base whose selected rows of H_b reach the free coordinates."""
    model = FsmsModel.from_name("boom7").with_selection((1, 1, 1, 0, 0, 0)) if name.startswith("boom7") else None
    model = model or FsmsModel.from_name(name)
    for _ in range(30):
        q = np.r_[RNG.normal(0, 1e-2, model.m), RNG.uniform(-math.pi, math.pi, model.n)]
        v = RNG.normal(0, 1.0, model.nv)
        for law in random_laws(model):
            law_agrees(model, law, q, v, t=RNG.uniform(0, 3))


@pytest.mark.parametrize("selection", [(1, 1, 1, 1, 1, 1), (0, 0, 0, 0, 1, 1), (0, 0, 0, 0, 0, 1)])
def test_law_agrees_with_weighted_moment_rows_where_it_damps(selection: tuple[int, ...]) -> None:
    """boom7's moment rows weighted by 1/reach (rns.weighted_damped_pinv): six, two and one selected rows,
    the damping threshold raised so that the damped inverse acts at every random state."""
    model = FsmsModel.from_name("boom7").with_selection(selection)
    assert model.coupling_weights is not None
    for _ in range(10):
        q = np.r_[RNG.normal(0, 1e-2, model.m), RNG.uniform(-math.pi, math.pi, model.n)]
        v = RNG.normal(0, 1.0, model.nv)
        for law in random_laws(model)[:3]:
            law.coupling.threshold = law.coupling.max_damping = 50.0  # kg m: beyond sigma_min everywhere
            assert law.coupling(q, v).inverse.damping > 0
            law_agrees(model, law, q, v, t=RNG.uniform(0, 3))


def test_law_agrees_at_the_trep_singularity() -> None:
    """Arm stretched along the base x axis: H_bm = 0, the damped inverse keeps both finite and equal."""
    model = FsmsModel.from_name("trep")
    for theta in ([0.0, 0.0], [math.pi, 0.0], [1e-9, -1e-9]):
        for law in random_laws(model):
            law_agrees(model, law, model.q(theta, [2e-3]), np.r_[0.05, 0.3, -0.2])


XY_PARAMS = """
[model]
name = "xy3r"
urdf = "xy3r.urdf"
ee_frame = "ee"
task_axes = ["x", "y"]
default_configuration_deg = [60.0, -60.0, -60.0]
gravity_m_per_s2 = {gravity}

[base]
joints = ["base_x", "base_y"]
stiffness = [[100.0, 0.0], [0.0, 150.0]]
damping = [[0.1, 0.0], [0.0, 0.2]]
selection = {selection}

[arm]
joint_damping = [0.01, 0.02, 0.03]
"""


def xy_model(tmp_path: Path, selection: list[int], gravity: list[float]) -> FsmsModel:
    """The bundled planar 3R on a cart that deflects along x and y (a 2-DOF base)."""
    urdf = (ASSETS / "planar3r.urdf").read_text()
    sled = (
        '<link name="sled"><inertial><mass value="0.5"/>'
        '<inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>\n'
        '  <joint name="base_x" type="prismatic"><parent link="world"/><child link="sled"/>'
        '<axis xyz="1 0 0"/><limit lower="-2" upper="2" effort="1000" velocity="10"/></joint>\n'
        '  <joint name="base_y" type="prismatic"><parent link="sled"/><child link="cart"/>'
        '<axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="1000" velocity="10"/></joint>'
    )
    start = urdf.index('<joint name="base_x"')
    end = urdf.index("</joint>", start) + len("</joint>")
    (tmp_path / "xy3r.urdf").write_text(urdf[:start] + sled + urdf[end:])
    params = tmp_path / "xy3r.toml"
    params.write_text(XY_PARAMS.format(selection=selection, gravity=gravity))
    return FsmsModel.from_file(params)


@pytest.mark.parametrize(
    ("selection", "gravity"),
    [([1, 1], [0.0, 0.0, 0.0]), ([1, 0], [0.0, 0.0, 0.0]), ([1, 1], [0.0, -9.81, 0.0])],
    ids=["both-rows", "x-row-only", "gravity"],
)
def test_two_dof_base(tmp_path: Path, selection: list[int], gravity: list[float]) -> None:
    model = xy_model(tmp_path, selection, gravity)
    assert model.m == 2 and len(model.selected) == sum(selection)
    assert model.cb_is_hbm_dot == (not any(gravity))
    for _ in range(20):
        q = np.r_[RNG.normal(0, 1e-2, 2), RNG.uniform(-math.pi, math.pi, 3)]
        v = RNG.normal(0, 1.0, model.nv)
        for law in random_laws(model):
            law_agrees(model, law, q, v)
    law = AccelerationLaw(model, Gains(g_b=10.0, g_m=2.0))
    sims = pair(model, law, force=ForcePulse(0.05, 0.05, np.array([10.0, -5.0])))
    for s in sims:
        s.run(0.5)
    assert np.max(np.abs(sims[0]._x - sims[1]._x)) <= 1e-11


class OwnArithmetic(TrackJointReference):
    """A subclass that changes the arithmetic: not in the registry, so computed in Python."""

    def __call__(self, t: float, cp: Coupling, q: np.ndarray, v: np.ndarray) -> NullOutput:
        out = super().__call__(t, cp, q, v)
        out.u = 0.5 * out.u  # type: ignore[operator]
        return out


def test_subclasses_run_their_own_python_body() -> None:
    """Only the registry's exact types run natively: a subclass (of TrackEndEffector, or one that
    changes the arithmetic) runs its Python body, natively simulated or not."""
    model = FsmsModel.from_name("planar3r")
    gains = Gains(g_b=10.0, g_m=1.0)
    ee0 = model.ee_position(model.spec.default_configuration)[model.task_rows]
    target = JointQuintic(ee0, ee0 + np.array([0.05, -0.05]), 1.0)

    class OwnTracker(TrackEndEffector):
        pass

    for null_input in (
        OwnTracker(model, target, 100.0, 20.0),
        OwnArithmetic(FixedReference(model.spec.default_configuration + 0.1), 4.0, 4.0),
    ):
        law = AccelerationLaw(model, gains, null_input)
        assert native.native_kind(law) is None and not Simulator(model, law).native
    assert native.native_kind(AccelerationLaw(model, gains, TrackEndEffector(model, target, 1.0, 1.0))) == "task"


def test_other_laws_stay_in_python() -> None:
    model = FsmsModel.from_name("planar3r")
    gains = Gains(g_b=10.0, g_m=1.0)
    law = AccelerationLaw(model, gains)
    sims = pair(model, law)
    for s in sims:
        s.run(0.2)
    # The null input changes in place to one computed in Python only: the native simulator falls
    # back to Python for those steps and both runs stay together.
    law.null_input = OwnArithmetic(FixedReference(model.spec.default_configuration), 4.0, 4.0)
    for s in sims:
        s.run(0.2)
    assert np.max(np.abs(sims[0]._x - sims[1]._x)) <= 1e-12
    sims[0].law = law  # re-checked when the law is set
    assert not sims[0].native
    assert not Simulator(model, TorqueLaw(model, gains)).native
    assert not Simulator(model, AccelerationLaw(model, gains), integrator="semi-implicit-euler").native


def staged_laws(model: FsmsModel) -> dict[str, tuple[object, dict[str, object]]]:
    """Each natively computed kind in a step that evaluates it at every RK4 stage (g_b and the reference
    at the stage times): unsampled (a held or moving joint servo, g_b = 0) or under continuous-time control."""
    gains = Gains(g_b=10.0, g_m=2.0, k_p=400.0, k_d=40.0)
    theta0 = model.spec.default_configuration
    quintic = JointQuintic(theta0, theta0 + 0.2, 0.6, t0=0.1)
    ee0 = model.ee_position(theta0)[model.task_rows]
    target = JointQuintic(ee0, ee0 + 0.02, 0.6, t0=0.1)
    return {
        "servo": (JointServo(model, gains, quintic), {}),
        "damp": (AccelerationLaw(model, gains, suppress=False), {}),
        "joint": (AccelerationLaw(model, gains, TrackJointReference(quintic, 400.0, 40.0), suppress=False), {}),
        "task": (AccelerationLaw(model, gains, TrackEndEffector(model, target, 400.0, 40.0), suppress=False), {}),
        "velocity": (VelocityLaw(model, gains, quintic, suppress=False, feedforward=True), {}),
        "switching on": (AccelerationLaw(model, gains, suppress_after=0.3005), {}),  # g_b on at a stage time
        "continuous": (VelocityLaw(model, gains, quintic), {"hold_control": False}),
    }


@pytest.mark.parametrize("name", ["planar3r", "boom7"])
@pytest.mark.parametrize("kind", ["servo", "damp", "joint", "task", "velocity", "switching on", "continuous"])
def test_steps_with_the_law_at_every_stage_agree(name: str, kind: str) -> None:
    """A joint servo holding or moving the arm, laws without g_b and continuous-time control: the native
    step evaluates the law at every stage as Python does, to 1e-12, through a kick."""
    model = FsmsModel.from_name(name)
    if name == "boom7" and kind == "task":
        model = model.with_selection([1, 1, 1, 0, 0, 0])  # forces only: Eq. (24) in a 4-D RNS, as boom7-track
    law, options = staged_laws(model)[kind]
    kick = ForcePulse(0.05, 0.1, np.full(model.m, 2.0))
    sims = pair(model, law, force=kick, q0=model.q(model.spec.default_configuration), **options)  # type: ignore[arg-type]
    for s in sims:
        s.run(0.6)
    assert not options or not sims[0].hold_control
    native_log, python_log = (s.log.array() for s in sims)
    assert np.abs(sims[0].q[: model.m]).max() > 1e-6  # the base really moved
    assert np.max(np.abs(sims[0]._x - sims[1]._x)) <= 1e-12 * max(1.0, np.max(np.abs(sims[1]._x)))
    if name == "boom7":  # per logged column, as test_spatial_presets_agree (13 DOF, a stiff axial mode)
        scale = np.maximum(1e-3, np.nanmax(np.abs(python_log), axis=0, initial=0.0))
        assert np.nanmax(np.abs(native_log - python_log) / scale) <= 1e-9
    else:
        assert np.nanmax(np.abs(native_log - python_log)) <= 1e-12 * max(1.0, np.nanmax(np.abs(python_log)))


@pytest.mark.parametrize("name", sorted(SCENARIOS))
def test_presets_agree(name: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """Every preset run natively and in Python gives the same log (laws not computed natively
    run in Python both times)."""
    duration = min(SCENARIOS[name].duration, 4.0)
    fast = run_scenario(name, duration)
    monkeypatch.setattr(native, "available", lambda: False)
    slow = run_scenario(name, duration)
    assert not slow.native
    a, b = fast.log.array(), slow.log.array()
    assert a.shape == b.shape
    assert np.array_equal(np.isnan(a), np.isnan(b))
    scale = np.maximum(1.0, np.nanmax(np.abs(b), axis=0, initial=0.0))  # per column
    worst = np.nanmax(np.abs(a - b) / scale, axis=0, initial=0.0)
    assert np.all(worst <= 1e-11), dict(zip(fast.log.columns, worst, strict=True))


@pytest.mark.parametrize("name", ["boom7-track", "boom7-kick-on", "boom7-kick-off", "boom7-p2p"])
def test_spatial_presets_agree(name: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """boom7 with S = forces only (law (15)'s S H_b G_b x_b' takes all six base velocities) and with all
    six rows: the native step and Python give the same log."""
    fast = run_scenario(name, 2.0)
    assert fast.native
    monkeypatch.setattr(native, "available", lambda: False)
    slow = run_scenario(name, 2.0)
    a, b = fast.log.array(), slow.log.array()
    scale = np.maximum(1e-3, np.nanmax(np.abs(b), axis=0, initial=0.0))  # per column (m, rad, N m ...)
    worst = np.nanmax(np.abs(a - b) / scale, axis=0, initial=0.0)
    assert np.all(worst <= 1e-9), dict(zip(fast.log.columns, worst, strict=True))


def test_divergence_keeps_the_last_finite_state() -> None:
    model = FsmsModel.from_name("trep")
    law = AccelerationLaw(model, Gains(g_b=24.0, g_m=20.0))
    sim = Simulator(model, law)
    sim.v = np.r_[0.0, 1e200, -1e200]  # the next step overflows
    x_before = sim._x.copy()
    with pytest.raises(SimulationDiverged, match="non-finite"):
        sim.step()
    assert np.array_equal(sim._x, x_before, equal_nan=True) and sim.t == 0.0


@pytest.mark.parametrize("name", ["trep", "planar3r"])
def test_centre_of_mass_kernels_agree(name: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """The path tracer's batch kernels give pinocchio's numbers: the same family, the same set."""
    model = FsmsModel.from_name(name)
    thetas = RNG.uniform(-math.pi, math.pi, (25, model.n))
    fast = CouplingField(model)
    assert fast.native is not None
    monkeypatch.setattr(_native, "core", None)
    slow = CouplingField(model)
    assert slow.native is None
    (H_fast, pot_fast), (H_slow, pot_slow) = fast.rows_at(thetas, True), slow.rows_at(thetas, True)
    assert np.allclose(H_fast, H_slow, rtol=0, atol=1e-14) and np.allclose(pot_fast, pot_slow, rtol=0, atol=1e-14)
    assert np.allclose(fast.rows_at(thetas)[0], H_slow, rtol=0, atol=1e-14)
    assert np.allclose(fast.potentials(thetas), slow.potentials(thetas), rtol=0, atol=1e-14)
    if name == "trep":
        python_family = path_family(model, 12)
        monkeypatch.undo()
        native_family = path_family(model, 12)
        assert [p.end for p in native_family] == [p.end for p in python_family]
        for a, b in zip(native_family, python_family, strict=True):
            assert a.theta.shape == b.theta.shape and np.allclose(a.theta, b.theta, rtol=0, atol=1e-12)


def test_a_cpp_model_that_differs_is_refused() -> None:
    """A model changed in Python after it was read (here its gravity) is not what the C++ side
    builds from the URDF: the native step refuses it, says so once, and the Python step runs."""
    model = FsmsModel.from_name("trep")
    model.pin_model.gravity.linear[:] = [0.0, -9.81, 0.0]  # changed in Python only
    with pytest.warns(RuntimeWarning, match="differs from pinocchio's Python model"):
        assert _native.robot_model(model) is None
    assert not Simulator(model, AccelerationLaw(model, Gains(g_b=20.0, g_m=5.0))).native
