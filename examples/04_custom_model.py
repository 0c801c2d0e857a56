"""Your own model: a URDF and a parameter file written here, loaded, checked and simulated.

The arm is a two-link planar arm (0.4 m and 0.3 m links of 1.0 kg and 0.6 kg) on a 3 kg platform
held by a spring of 200 N/m along x. The URDF holds geometry and mass; the parameter file says which
joint is the elastic base coordinate, its stiffness and damping, the selection S and the task. The
same files serve in the app: ``rns-viz serve --model two_link.toml``.

    python examples/04_custom_model.py [--out DIR]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from rns_viz.control import AccelerationLaw, Gains
from rns_viz.model import FsmsModel
from rns_viz.sim import ForcePulse, Simulator


def link(name: str, length: float, mass: float) -> str:
    """A slender link along x with its centre of mass at the middle (radius of gyration 1 cm)."""
    i = mass * 1e-4
    return f"""
  <link name="{name}">
    <inertial><origin xyz="{length / 2} 0 0"/><mass value="{mass}"/>
      <inertia ixx="{i}" ixy="0" ixz="0" iyy="{i}" iyz="0" izz="{i}"/></inertial>
    <visual><origin xyz="{length / 2} 0 0"/><geometry><box size="{length} 0.03 0.02"/></geometry></visual>
  </link>"""


def joint(name: str, kind: str, parent: str, child: str, x: float = 0.0, axis: str = "0 0 1") -> str:
    limit = '<limit lower="-0.5" upper="0.5" effort="100" velocity="10"/>' if kind == "prismatic" else ""
    if kind == "revolute":
        limit = '<limit lower="-6.2832" upper="6.2832" effort="20" velocity="10"/>'
    return f"""
  <joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>
    <origin xyz="{x} 0 0"/><axis xyz="{axis}"/>{limit}</joint>"""


URDF = f"""<?xml version="1.0"?>
<robot name="two_link">
  <link name="world"/>
  <link name="platform">
    <inertial><mass value="3.0"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    <visual><geometry><box size="0.2 0.2 0.05"/></geometry></visual>
  </link>
  {joint("base_x", "prismatic", "world", "platform", axis="1 0 0")}
  {link("link1", 0.4, 1.0)}{joint("joint1", "revolute", "platform", "link1")}
  {link("link2", 0.3, 0.6)}{joint("joint2", "revolute", "link1", "link2", x=0.4)}
  <link name="ee"/>{joint("ee_joint", "fixed", "link2", "ee", x=0.3)}
</robot>
"""

PARAMETERS = """
[model]
name = "two_link"
urdf = "two_link.urdf"
ee_frame = "ee"
task_axes = ["x", "y"]
default_configuration_deg = [60.0, 60.0]
gravity_m_per_s2 = [0.0, 0.0, 0.0]   # a horizontal plane

[base]
joints = ["base_x"]        # the elastic base coordinate x_b
stiffness = [[200.0]]      # K_b, N/m
damping = [[0.5]]          # D_b, N s/m
selection = [1]            # S: the reaction along x must vanish

[arm]
joint_damping = [0.0, 0.0] # D_m, N m s/rad
"""


def main(out: Path) -> Path:
    out.mkdir(parents=True, exist_ok=True)
    (out / "two_link.urdf").write_text(URDF)
    (out / "two_link.toml").write_text(PARAMETERS)
    model = FsmsModel.from_file(out / "two_link.toml")
    theta0 = model.spec.default_configuration
    H_b = model.mass_matrix(model.q(theta0))[0, 0]  # the base's inertia with the arm locked, kg
    print(f"{model.spec.name}: base {model.m} coordinate, arm {model.n} joints, H_b = {H_b:.2f} kg")
    print(f"locked-arm frequency {np.sqrt(200.0 / H_b) / (2 * np.pi):.2f} Hz")
    law = AccelerationLaw(model, Gains(g_b=10.0, g_m=2.0))  # Eq. (15), its default null-space damping
    sim = Simulator(model, law, force=ForcePulse(start=0.2, duration=0.1, peak=(5.0,)), q0=model.q(theta0))
    xb = sim.run(4.0).column("xb_1")
    print(f"a 5 N kick: peak {np.abs(xb).max() * 1e3:.1f} mm, after 4 s {np.abs(xb[-1]) * 1e3:.4f} mm")
    return out / "two_link.toml"


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("."), help="folder for the two files")
    main(parser.parse_args().out)
