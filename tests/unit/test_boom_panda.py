"""boom-panda: the Franka Panda of example-robot-data on boom7's boom (an optional extra, rns-viz[panda]).

Always run: composition from a stand-in package laid out as example-robot-data is (the arm block of the
mass matrix equals pinocchio's on the stand-in's own URDF, meshes resolved into the package), and the
"not installed" path (a refusal naming the install command). With the extra installed: the real Panda
against pinocchio on the package's own panda.urdf, boom7's base numbers and a suppressed kick. In the app
(its model kept without the extra, the meshes in the scene): tests/app/test_boom_panda.py.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from rns_viz import robots
from rns_viz.control import AccelerationLaw, FixedReference
from rns_viz.control.hold import JointServo
from rns_viz.model import FsmsModel
from rns_viz.params import ASSETS_DIR, ModelFileError, missing_extra, param_file_for
from rns_viz.rns import restricted_jacobian, rns_projector
from rns_viz.scenarios import BOOM7_GAINS, BOOM7_KICK, FORCES_ONLY
from rns_viz.sim import ForcePulse, Simulator
from rns_viz.viz.panels.model_menu import ModelMenu, label_of

PANDA = "example-robot-data/panda"
installed = pytest.mark.skipif(
    not robots.is_installed(PANDA), reason="example-robot-data is not installed (pip install 'rns-viz[panda]')"
)

# A stand-in for example-robot-data: two revolute links, a hand with a prismatic finger, mesh references.
STAND_IN = """<robot name="panda">
  <link name="panda_link0"><inertial><origin xyz="0 0 0.05"/><mass value="0.5"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    <visual><geometry><mesh filename="package://example-robot-data/robots/panda_description/meshes/visual/link0.stl"/>
    </geometry></visual></link>
  <joint name="panda_joint1" type="revolute"><parent link="panda_link0"/><child link="panda_link1"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="10" velocity="2"/></joint>
  <link name="panda_link1"><inertial><origin xyz="0.1 0.02 0"/><mass value="2.0"/>
    <inertia ixx="0.02" ixy="0.001" ixz="0" iyy="0.03" iyz="0" izz="0.04"/></inertial></link>
  <joint name="panda_joint2" type="revolute"><parent link="panda_link1"/><child link="panda_hand"/>
    <origin xyz="0.3 0 0" rpy="1.5707963267948966 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" effort="10" velocity="2"/></joint>
  <link name="panda_hand"><inertial><origin xyz="0.05 0 0.01"/><mass value="0.7"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.002"/></inertial></link>
  <joint name="panda_finger_joint1" type="prismatic"><parent link="panda_hand"/><child link="panda_leftfinger"/>
    <origin xyz="0.1 0 0"/><axis xyz="0 1 0"/><limit lower="0" upper="0.04" effort="10" velocity="0.2"/>
    <dynamics damping="0.3"/></joint>
  <link name="panda_leftfinger"><inertial><origin xyz="0 0.01 0"/><mass value="0.05"/>
    <inertia ixx="1e-5" ixy="0" ixz="0" iyy="1e-5" iyz="0" izz="1e-5"/></inertial></link>
</robot>
"""


def stand_in_package(root: Path) -> Path:
    """example-robot-data's layout under ``root``; returns its share directory."""
    share = root / "share" / "example-robot-data"
    description = share / "robots" / "panda_description"
    (description / "urdf").mkdir(parents=True)
    (description / "meshes" / "visual").mkdir(parents=True)
    (description / "urdf" / "panda.urdf").write_text(STAND_IN)
    (description / "meshes" / "visual" / "link0.stl").write_text("solid empty\nendsolid empty\n")
    return share


def arm_block_oracle(urdf: str | Path, thetas: np.ndarray, n: int) -> list[np.ndarray]:
    """pinocchio's mass matrix of an arm's own URDF (fixed base, fingers at zero), its first n joints."""
    model = pin.buildModelFromUrdf(str(urdf))
    data = model.createData()
    out = []
    for theta in thetas:
        q = np.zeros(model.nq)
        q[:n] = theta
        out.append(pin.crba(model, data, q)[:n, :n].copy())
    return out


def test_composition_hangs_the_packaged_arm_on_the_mount(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, boom7: FsmsModel
) -> None:
    """From a stand-in package: boom7's base kept, its arm gone, the finger fixed, meshes resolved, and
    the arm block of M equals the stand-in's own (the joint-space inertia of an arm does not depend on
    where its base is when nothing moves the base)."""
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    share = stand_in_package(tmp_path / "prefix")
    path = robots.composed_urdf(ASSETS_DIR / "boom7.urdf", PANDA, share=share)
    assert path.is_relative_to(tmp_path / "cache")
    model = pin.buildModelFromUrdf(str(path))
    assert list(model.names)[1:] == [*boom7.spec.base.joints, "panda_joint1", "panda_joint2"]
    root = ET.parse(path).getroot()
    links = {link.get("name") for link in root.iter("link")}
    assert "link1" not in links and "ee" not in links and "panda_leftfinger" in links
    (mesh,) = root.iter("mesh")
    assert Path(mesh.get("filename")).is_file() and Path(mesh.get("filename")).is_relative_to(share.parent)
    rng = np.random.default_rng(3)
    thetas = rng.uniform(-2.0, 2.0, (5, 2))
    data = model.createData()
    for theta, oracle in zip(thetas, arm_block_oracle(share / robots.packaged_arm(PANDA).urdf, thetas, 2), strict=True):
        x_b = rng.uniform(-1e-3, 1e-3, 6)
        M = pin.crba(model, data, np.concatenate([x_b, theta]))
        np.testing.assert_allclose(M[6:, 6:], oracle, rtol=1e-12, atol=1e-14)
    # the base's translation block at rest: boom7's tip (plate and condensed tube) plus the whole stand-in arm (3.25 kg)
    M = pin.crba(model, data, np.zeros(model.nq))
    tip = sum(link_mass(ASSETS_DIR / "boom7.urdf", link) for link in ("boom_tip", "boom_tube"))
    np.testing.assert_allclose(np.diag(M[:3, :3]), tip + 3.25, rtol=1e-12)


def test_a_parameter_file_extends_boom7_with_a_packaged_arm(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, boom7: FsmsModel
) -> None:
    """``extends`` takes boom7's tables key by key, ``[model] arm`` composes the URDF (stand-in package)."""
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    share = stand_in_package(tmp_path / "prefix")
    monkeypatch.setattr(robots, "share_dir", lambda arm: share)
    path = tmp_path / "two.toml"
    path.write_text(
        f'extends = "{ASSETS_DIR / "boom7.toml"}"\n[model]\nname = "two"\nurdf = "{ASSETS_DIR / "boom7.urdf"}"\n'
        f'arm = "{PANDA}"\nee_frame = "panda_hand"\ndefault_configuration_deg = [10.0, 20.0]\n'
        "[arm]\njoint_damping = [0.1, 0.2]\n"
    )
    model = FsmsModel.from_file(path)
    assert (model.m, model.n, model.name) == (6, 2, "two") and model.arm_joint_names == ("panda_joint1", "panda_joint2")
    np.testing.assert_array_equal(model.K_b, boom7.K_b)
    np.testing.assert_array_equal(model.D_b, boom7.D_b)
    np.testing.assert_array_equal(model.spec.task_axes, boom7.spec.task_axes)  # not in two.toml: boom7's
    np.testing.assert_array_equal(model.spec.joint_damping, [0.1, 0.2])
    path.write_text(path.read_text().replace(PANDA, "example-robot-data/nao"))
    with pytest.raises(ModelFileError, match="unknown packaged arm"):
        FsmsModel.from_file(path)


def link_mass(urdf: Path, name: str) -> float:
    """The mass of one link of a URDF, kg."""
    link = next(link for link in ET.parse(urdf).getroot().iter("link") if link.get("name") == name)
    return float(link.find("inertial/mass").get("value"))


def test_without_the_extra_the_model_is_refused_with_the_install_command(panda_not_installed: None) -> None:
    with pytest.raises(ModelFileError, match=r"pip install 'rns-viz\[panda\]'") as caught:
        FsmsModel.from_name("boom-panda")
    assert "boom-panda.toml" in str(caught.value) and "[model] arm" in str(caught.value)
    assert missing_extra("boom-panda") == "panda" and missing_extra("boom7") is None
    label = label_of("boom-panda")
    assert label.startswith(param_file_for("boom-panda").app.label) and "rns-viz[panda]" in label
    assert ModelMenu().key_of(label) == "boom-panda"


# ------------------------------------------------------------------ with example-robot-data installed
@installed
def test_the_arm_is_the_packages_panda(boom_panda: FsmsModel) -> None:
    """Arm block of M = pinocchio's on the package's own panda.urdf at the same joint values (fingers at 0)."""
    share = robots.share_dir(robots.packaged_arm(PANDA))
    assert boom_panda.arm_joint_names == tuple(f"panda_joint{i}" for i in range(1, 8))
    rng = np.random.default_rng(7)
    thetas = rng.uniform(boom_panda.lower, boom_panda.upper, (8, 7))
    for theta, oracle in zip(thetas, arm_block_oracle(share / robots.packaged_arm(PANDA).urdf, thetas, 7), strict=True):
        M = boom_panda.mass_matrix(boom_panda.q(theta, rng.uniform(-1e-3, 1e-3, 6)))
        np.testing.assert_allclose(M[6:, 6:], oracle, rtol=1e-12, atol=1e-14)
    own = pin.buildModelFromUrdf(str(share / robots.packaged_arm(PANDA).urdf))
    np.testing.assert_array_equal(boom_panda.lower, own.lowerPositionLimit[:7])
    np.testing.assert_array_equal(boom_panda.upper, own.upperPositionLimit[:7])
    assert not np.any(boom_panda.spec.gravity)


@installed
def test_the_boom_is_boom7s(boom_panda: FsmsModel, boom7: FsmsModel) -> None:
    """K_b, D_b, S and the tip's inertia are boom7's; the arm's first joint sits where boom7's does."""
    np.testing.assert_array_equal(boom_panda.K_b, boom7.K_b)
    np.testing.assert_array_equal(boom_panda.D_b, boom7.D_b)
    np.testing.assert_array_equal(boom_panda.spec.base.selection, boom7.spec.base.selection)
    assert tip_element(boom_panda.spec.urdf_path) == tip_element(boom7.spec.urdf_path)
    q = np.zeros(13)
    for m in (boom_panda, boom7):
        pin.forwardKinematics(m.pin_model, m.data, q)
    np.testing.assert_allclose(
        boom_panda.data.oMi[boom_panda.pin_model.getJointId("panda_joint1")].translation,
        boom7.data.oMi[boom7.pin_model.getJointId("joint1")].translation,
        atol=1e-12,
    )


def tip_element(urdf: Path) -> bytes:
    """The boom tip link (its inertia and visual) as XML text."""
    return ET.tostring(next(link for link in ET.parse(urdf).getroot().iter("link") if link.get("name") == "boom_tip"))


@installed
def test_default_configuration_keeps_forces_only_tracking_away_from_singularity(boom_panda: FsmsModel) -> None:
    """r = 3 (forces only): sigma_min(J-bar = J P_RNS) at theta_0 is 0.098 m/rad, as boom7's."""
    model = boom_panda.with_selection(FORCES_ONLY)
    theta0 = model.spec.default_configuration
    H = model.coupling_matrix(model.q(theta0))
    J_bar = restricted_jacobian(model.ee_jacobian(theta0), rns_projector(H, np.linalg.pinv(H)))
    assert np.linalg.svd(J_bar, compute_uv=False)[-1] > 0.09  # m/rad


@installed
def test_a_kick_is_suppressed_in_all_six_modes(boom_panda: FsmsModel) -> None:
    """boom7's six-direction kick: with (15) each deflection over 3-3.5 s is below 1 % of the joints-held run's."""
    theta0 = boom_panda.spec.default_configuration
    runs = []
    for law in (AccelerationLaw(boom_panda, BOOM7_GAINS), JointServo(boom_panda, BOOM7_GAINS, FixedReference(theta0))):
        sim = Simulator(boom_panda, law, force=ForcePulse(**BOOM7_KICK), q0=boom_panda.q(theta0))
        sim.run(3.5)
        x_b = np.column_stack([sim.log.column(f"xb_{i + 1}") for i in range(6)])
        assert np.all(np.isfinite(x_b)) and np.all(np.isfinite(sim.q))
        runs.append(np.abs(x_b[sim.log.column("t") >= 3.0]).max(axis=0))
    on, off = runs
    assert np.all(on <= 0.01 * off)
