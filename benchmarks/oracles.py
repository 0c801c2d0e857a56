"""Benchmark-only models and reimplementations: the generated 7-DOF arm and the step written plainly.

Nothing here is product code: the straightforward step is a baseline and a check (its trajectory
must equal the simulator's), the 7-DOF URDF a larger model for the timings.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from rns_viz.control import AccelerationLaw
from rns_viz.model import FsmsModel

DT = 1e-3
X_B0 = {"trep": 2e-3, "planar3r": 1e-2, "arm7": 1e-2, "boom7": 1e-3}  # initial base deflection, m


def initial_state(model: FsmsModel) -> tuple[np.ndarray, np.ndarray]:
    """At rest at the default configuration, the base deflected along its first lateral coordinate
    (boom7: sideways, y; the others: their one coordinate)."""
    x_b = np.zeros(model.m)
    x_b[1 if model.m > 1 else 0] = X_B0[model.name]
    return model.q(model.spec.default_configuration, x_b), np.zeros(model.nv)


# -- a 7-DOF spatial arm on a translating elastic base, generated -----------------------------------
ARM7_AXES = ("0 0 1", "0 1 0", "0 0 1", "0 1 0", "0 0 1", "0 1 0", "0 0 1")
ARM7_LINK = 0.25  # m
ARM7_MASS = 1.0  # kg per link, at the link centre


def arm7_urdf() -> str:
    """URDF text: prismatic base_x (cart on a spring) then seven revolute joints, axes z, y, z, ..."""
    inertia = '<inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-3"/>'
    parts = [
        '<?xml version="1.0"?>\n<robot name="arm7">',
        '<link name="world"/>',
        f'<link name="cart"><inertial><origin xyz="0 0 0"/><mass value="2.0"/>{inertia}</inertial></link>',
        '<joint name="base_x" type="prismatic"><parent link="world"/><child link="cart"/>'
        '<axis xyz="1 0 0"/><limit lower="-1" upper="1" effort="100" velocity="10"/></joint>',
    ]
    parent, offset = "cart", 0.0
    for i, axis in enumerate(ARM7_AXES, start=1):
        parts.append(
            f'<link name="link{i}"><inertial><origin xyz="{ARM7_LINK / 2} 0 0"/><mass value="{ARM7_MASS}"/>'
            f"{inertia}</inertial></link>"
        )
        parts.append(
            f'<joint name="joint{i}" type="revolute"><parent link="{parent}"/><child link="link{i}"/>'
            f'<origin xyz="{offset} 0 0"/><axis xyz="{axis}"/>'
            '<limit lower="-6.2832" upper="6.2832" effort="100" velocity="10"/></joint>'
        )
        parent, offset = f"link{i}", ARM7_LINK
    parts.append('<link name="ee"/>')
    parts.append(
        f'<joint name="ee_fixed" type="fixed"><parent link="{parent}"/><child link="ee"/>'
        f'<origin xyz="{ARM7_LINK} 0 0"/></joint>'
    )
    parts.append("</robot>")
    return "\n".join(parts)


ARM7_TOML = """
[model]
name = "arm7"
urdf = "arm7.urdf"
ee_frame = "ee"
task_axes = ["x", "y", "z"]
default_configuration_deg = [20.0, 30.0, -20.0, 40.0, 10.0, -30.0, 15.0]
gravity_m_per_s2 = [0.0, 0.0, 0.0]

[base]
joints = ["base_x"]
stiffness = [[100.0]]
damping = [[0.1]]
selection = [1]

[arm]
joint_damping = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
"""


def arm7_model(directory: Path) -> FsmsModel:
    (directory / "arm7.urdf").write_text(arm7_urdf())
    (directory / "arm7.toml").write_text(ARM7_TOML)
    return FsmsModel.from_file(directory / "arm7.toml")


@dataclass
class Straightforward:
    """The same closed-loop step written the obvious way, as the code was before it was optimised.

    Law (15) with P_RNS formed and -G_m theta' split into its range and RNS parts, the damped
    inverse of the single coupling row in closed form, resolved acceleration; RK4 on (q, v) with
    four ABA calls; a log row with forward kinematics for the end effector at every step.
    """

    model: FsmsModel
    law: AccelerationLaw  # only for its gains and damping threshold

    def __post_init__(self) -> None:
        model = self.model
        self.pm = model.pin_model
        self.ctrl_data, self.plant_data, self.fk_data = (self.pm.createData() for _ in range(3))
        self.q, self.v = initial_state(model)
        self.t = 0.0
        self.u = np.zeros(model.nv)
        self.log = np.full((20000, 2 + 4 * model.m + 5 * model.n + 5 + len(model.task_rows)), np.nan)
        self.row = 0

    def control(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
        model, m, rows = self.model, self.model.m, self.model.selected
        g, threshold = self.law.gains, self.law.coupling.threshold
        M = pin.crba(self.pm, self.ctrl_data, q).copy()
        c = pin.nonLinearEffects(self.pm, self.ctrl_data, q, v).copy()
        H_bm = M[rows, m:]
        sigma = float(np.sqrt(H_bm[0] @ H_bm[0]))
        lam2 = 0.0 if sigma >= threshold else (1 - (sigma / threshold) ** 2) * threshold**2
        pinv = (H_bm[0] / (sigma * sigma + lam2))[:, None]
        P = np.eye(model.n) - pinv @ H_bm
        thetadot = v[m:]
        suppression = pinv @ (g.g_b * (M[np.ix_(rows, rows)] @ v[rows]) - c[:m][rows])
        thetaddot = suppression - g.g_m * (thetadot - P @ thetadot) - g.g_m * (P @ thetadot)
        rhs = -model.K_b @ q[:m] - model.D_b @ v[:m] - c[:m] - M[:m, m:] @ thetaddot
        xddot_b = rhs / M[0, 0]
        tau = M[:m, m:].T @ xddot_b + M[m:, m:] @ thetaddot + c[m:] + model.D_m @ v[m:]
        return tau, H_bm @ thetadot, sigma

    def acceleration(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        model, m, u = self.model, self.model.m, self.u
        u[:m] = -model.K_b @ q[:m] - model.D_b @ v[:m]
        u[m:] = tau - model.D_m @ v[m:]
        return pin.aba(self.pm, self.plant_data, q, v, u)

    def rk4(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        h = 0.5 * DT
        a1 = self.acceleration(q, v, tau)
        v2 = v + h * a1
        a2 = self.acceleration(q + h * v, v2, tau)
        v3 = v + h * a2
        a3 = self.acceleration(q + h * v2, v3, tau)
        v4 = v + DT * a3
        a4 = self.acceleration(q + DT * v3, v4, tau)
        s = DT / 6.0
        return q + s * (v + 2.0 * (v2 + v3) + v4), v + s * (a1 + 2.0 * (a2 + a3) + a4)

    def ee(self, q: np.ndarray) -> np.ndarray:
        model = self.model
        pin.forwardKinematics(self.pm, self.fk_data, q)
        pin.updateFramePlacement(self.pm, self.fk_data, model.ee_frame_id)
        base = self.fk_data.oMi[model.base_joint_id]
        return base.rotation.T @ (self.fk_data.oMf[model.ee_frame_id].translation - base.translation)

    def record(self, tau: np.ndarray, L: np.ndarray, sigma: float) -> None:
        q, v, m, n = self.q, self.v, self.model.m, self.model.n
        row = self.log[self.row]
        row[:] = np.nan
        row[0] = self.t
        row[1 : 1 + m], row[1 + m : 1 + 2 * m] = q[:m], v[:m]
        i = 1 + 2 * m
        row[i : i + n], row[i + n : i + 2 * n], row[i + 2 * n : i + 3 * n] = q[m:], v[m:], tau
        i += 3 * n
        row[i : i + m] = 0.0
        row[i + m : i + m + 3] = self.ee(q)
        i += m + 3
        row[i : i + len(L)] = L
        row[i + len(L)] = sigma
        self.row = (self.row + 1) % len(self.log)

    def step(self) -> None:
        tau, L, sigma = self.control(self.q, self.v)
        q_next, v_next = self.rk4(self.q, self.v, tau)
        if not (np.all(np.isfinite(q_next)) and np.all(np.isfinite(v_next)) and np.all(np.isfinite(tau))):
            raise FloatingPointError("diverged")
        self.record(tau, L, sigma)
        self.q, self.v, self.t = q_next, v_next, self.t + DT
