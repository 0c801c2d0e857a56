"""MuJoCo replay oracle: integrate an FSMS URDF in MuJoCo under a logged torque sequence.

This is an independent check of our own simulator (pinocchio forward dynamics, RK4 with the joint
torque held over each step). It loads the *same* URDF into MuJoCo (PyPI ``mujoco`` 4.0) and
integrates

    M(q) v' + c(q, v) = [ -K_b x_b - D_b x_b' + f_ext ; tau - D_m theta' ]

with MuJoCo's own RK4 integrator, zero gravity, no contacts and no joint limits:

- K_b, D_b (diagonal) become the MuJoCo joint ``stiffness`` / ``damping`` of the base joints, with
  the spring at rest at x_b = 0 (``springref`` 0); D_m becomes the arm joints' ``damping``. They
  are passive forces, so MuJoCo evaluates them at every RK4 stage, like a plain RK4 of the ODE.
- A coupled (symmetric, positive semi-definite) K_b or D_b, such as a cantilever's tip stiffness,
  is split as sum_j lambda_j a_j a_j^T (eigen-decomposition) into fixed tendons of length
  l_j = a_j . x_b, stiffness (or damping) lambda_j and rest length 0: their passive force
  -lambda_j a_j (a_j . x_b) sums to -K_b x_b, again evaluated at every stage.
- tau and f_ext go through ``data.qfrc_applied``, which MuJoCo's RK4 keeps constant across the
  four stages of a step: the held-torque convention of our simulator.

Only tests import this module; ``rns_viz`` must never import MuJoCo.

MuJoCo adjustments needed to load the URDFs (see :func:`build_model`):

- ``<visual>`` and ``<collision>`` elements are stripped before loading (they do not affect
  dynamics, and meshes would need files); ``compiler.discardvisual`` is set as well.
- ``compiler.fusestatic = False`` so that massless fixed-joint links (``ee``) stay bodies.
- MuJoCo rejects moving bodies with zero rotational inertia ("mass and inertia of moving bodies
  must be larger than mjMINVAL"), which the point masses of planar3r.urdf have. Principal
  inertias of bodies with positive mass are raised to a floor of :data:`INERTIA_FLOOR` kg m^2
  (only where they are below it; TREP's inertias are untouched). The tests check that this
  changes the base deflection by far less than 1e-9 m. For the same reason the massless links
  between the coordinates of a multi-coordinate base (boom7's x, y, z, rx, ry) get a mass of
  :data:`MASS_FLOOR` kg and inertias of INERTIA_FLOOR kg m^2: 1e-9 kg against a 22 kg system.
- In MuJoCo 4.0 joint ``stiffness`` and ``damping`` are polynomial coefficient 3-vectors
  ``[a, b, c]`` with force -(a x + b x^2 + c x^3); only the linear coefficient ``a`` is set.
- ``option.gravity = 0``, ``option.timestep = dt``, ``option.integrator = RK4`` and
  ``mjDSBL_CONSTRAINT`` (pinocchio's ``aba`` knows neither joint limits nor contacts). Armature
  and friction loss are set to zero.
- ``mjDSBL_AUTORESET``: by default MuJoCo silently resets the state to ``qpos0`` when it meets a
  NaN; here a diverged run raises FloatingPointError instead of returning a finite trajectory
  (MuJoCo's warning text goes into the message instead of a MUJOCO_LOG.TXT in the working
  directory).

Coordinates are mapped by joint name between pinocchio's order (base joints first, then the arm
joints in pinocchio's URDF traversal order) and MuJoCo's ``jnt_qposadr`` / ``jnt_dofadr``.
Pinocchio is used for nothing but that list of joint names.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np
import pinocchio as pin

INERTIA_FLOOR = 1e-12
"""Lower bound (kg m^2) on the principal inertias of bodies with positive mass."""
MASS_FLOOR = 1e-9
"""Mass (kg) given to massless bodies that have a joint (MuJoCo rejects them)."""

_STRIPPED_LINK_ELEMENTS = ("visual", "collision")


@dataclass(frozen=True)
class MujocoPlant:
    """A compiled MuJoCo model of an FSMS and the map from pinocchio coordinates to MuJoCo's."""

    model: mujoco.MjModel
    joint_names: tuple[str, ...]  # pinocchio order: base joints, then arm joints
    qpos_index: np.ndarray  # (m+n,) MuJoCo qpos address of each pinocchio coordinate
    dof_index: np.ndarray  # (m+n,) MuJoCo dof address of each pinocchio velocity
    m: int  # base coordinates
    n: int  # arm joints

    @property
    def nv(self) -> int:
        return self.m + self.n


def pinocchio_joint_names(urdf_path: str | Path) -> tuple[str, ...]:
    """Names of the moving joints in pinocchio's coordinate order (one coordinate each)."""
    model = pin.buildModelFromUrdf(str(urdf_path))
    if model.nq != model.nv or any(j.nv != 1 for j in model.joints[1:]):
        raise ValueError(f"{urdf_path}: every moving joint must be prismatic or revolute (one coordinate)")
    return tuple(model.names[1:])


def _urdf_text_for_mujoco(urdf_path: Path) -> str:
    """The URDF with every link's visual and collision elements removed."""
    root = ET.fromstring(urdf_path.read_text())
    for link in root.iter("link"):
        for tag in _STRIPPED_LINK_ELEMENTS:
            for element in link.findall(tag):
                link.remove(element)
    return ET.tostring(root, encoding="unicode")


def _diagonal(matrix: np.ndarray, size: int, what: str) -> np.ndarray:
    """Diagonal of a (size, size) matrix or a (size,) vector; NotImplementedError if coupled."""
    arr = np.asarray(matrix, dtype=float)
    if arr.shape == (size,):
        diag = arr
    elif arr.shape == (size, size):
        diag = np.diag(arr).copy()
        if np.any(arr - np.diag(diag) != 0.0):
            raise NotImplementedError(
                f"{what} has off-diagonal entries: MuJoCo joint springs/dampers are per joint; "
                "coupled matrices are not supported by this oracle"
            )
    else:
        raise ValueError(f"{what} must have shape ({size}, {size}) or ({size},), got {arr.shape}")
    if not np.all(np.isfinite(diag)):
        raise ValueError(f"{what} must be finite")
    return diag


def _joint_or_tendons(matrix: np.ndarray, size: int, what: str) -> tuple[np.ndarray, list[tuple[float, np.ndarray]]]:
    """Per-joint diagonal of a diagonal matrix, or zeros and (lambda_j, a_j) tendons of a coupled one."""
    arr = np.asarray(matrix, dtype=float)
    if arr.shape != (size, size) or np.all(arr == np.diag(np.diag(arr))):
        return _diagonal(arr, size, what), []
    if not (np.all(np.isfinite(arr)) and np.array_equal(arr, arr.T)):
        raise ValueError(f"{what} must be finite and symmetric")
    values, vectors = np.linalg.eigh(arr)
    if values.min() < -1e-12 * values.max():
        raise ValueError(f"{what} must be positive semi-definite")
    return np.zeros(size), [(float(v), vectors[:, j]) for j, v in enumerate(values) if v > 0.0]


def _floor_inertia(spec: mujoco.MjSpec, floor: float) -> None:
    """Raise principal inertias below ``floor`` for every body with positive mass."""
    for body in spec.bodies:
        if body.mass <= 0.0 and body.first_joint() is not None:  # a massless link inside the base
            body.explicitinertial = True
            body.mass = MASS_FLOOR
            body.inertia = [floor, floor, floor]
            continue
        if body.mass <= 0.0:  # the world body and massless frames
            continue
        full = np.asarray(body.fullinertia, dtype=float)
        if np.isnan(full[0]):  # diagonal inertia in the principal frame (ipos, iquat)
            body.inertia = np.maximum(np.asarray(body.inertia, dtype=float), floor)
        else:  # full inertia (ixx, iyy, izz, ixy, ixz, iyz)
            tensor = np.array([[full[0], full[3], full[4]], [full[3], full[1], full[5]], [full[4], full[5], full[2]]])
            shortfall = floor - np.linalg.eigvalsh(tensor).min()
            if shortfall > 0.0:
                full[:3] += shortfall
                body.fullinertia = full


def build_model(
    urdf_path: str | Path,
    base_joints: Sequence[str],
    stiffness: np.ndarray,
    damping: np.ndarray,
    joint_damping: np.ndarray,
    dt: float,
    inertia_floor: float = INERTIA_FLOOR,
) -> MujocoPlant:
    """Compile the URDF in MuJoCo with the FSMS springs and dampers (see the module docstring).

    stiffness, damping: K_b, D_b, (m, m) diagonal (or (m,)), N/m or N m/rad, N s/m or N m s/rad.
    joint_damping: D_m, (n,) or (n, n) diagonal, N m s/rad. dt: time step, s.
    A coupled K_b or D_b becomes fixed tendons; raises NotImplementedError for a non-diagonal D_m.
    """
    path = Path(urdf_path)
    names = pinocchio_joint_names(path)
    base_joints = tuple(base_joints)
    m = len(base_joints)
    n = len(names) - m
    if m < 1 or names[:m] != base_joints:
        raise ValueError(f"{path}: base joints {list(base_joints)} must be the first joints, which are {names[:m]}")
    if n < 1:
        raise ValueError(f"{path}: no arm joints after the base joints")
    if not dt > 0.0:
        raise ValueError(f"dt must be positive, got {dt}")
    k_b, k_tendons = _joint_or_tendons(stiffness, m, "stiffness K_b")
    d_b, d_tendons = _joint_or_tendons(damping, m, "damping D_b")
    d_m = _diagonal(joint_damping, n, "joint damping D_m")

    spec = mujoco.MjSpec.from_string(_urdf_text_for_mujoco(path))
    spec.compiler.discardvisual = True
    spec.compiler.fusestatic = False
    spec.compiler.balanceinertia = False
    _floor_inertia(spec, inertia_floor)
    spec.option.gravity = [0.0, 0.0, 0.0]
    spec.option.timestep = dt
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_RK4
    # no joint limits or contacts (pinocchio's aba has neither); no silent reset to qpos0 on NaN
    spec.option.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT | mujoco.mjtDisableBit.mjDSBL_AUTORESET

    spec_joints = {j.name: j for j in spec.joints}
    if set(spec_joints) != set(names):
        raise ValueError(f"{path}: MuJoCo joints {sorted(spec_joints)} differ from pinocchio's {sorted(names)}")
    for i, name in enumerate(names):
        joint = spec_joints[name]
        stiff, damp = (k_b[i], d_b[i]) if i < m else (0.0, d_m[i - m])
        joint.stiffness = [stiff, 0.0, 0.0]  # polynomial coefficients in MuJoCo 4.0: linear only
        joint.damping = [damp, 0.0, 0.0]
        joint.springref = 0.0  # spring at rest at q = 0 (x_b = 0)
        joint.armature = 0.0
        joint.frictionloss = 0.0
        joint.limited = mujoco.mjtLimited.mjLIMITED_FALSE

    for kind, tendons in (("stiffness", k_tendons), ("damping", d_tendons)):
        for value, axis in tendons:
            tendon = spec.add_tendon()
            setattr(tendon, kind, [value, 0.0, 0.0])
            tendon.springlength = [0.0, 0.0]
            for name, coef in zip(base_joints, axis, strict=True):
                if coef != 0.0:
                    tendon.wrap_joint(name, float(coef))

    model = spec.compile()
    ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name) for name in names]
    one_dof = {int(mujoco.mjtJoint.mjJNT_SLIDE), int(mujoco.mjtJoint.mjJNT_HINGE)}
    for name, jid in zip(names, ids, strict=True):
        if int(model.jnt_type[jid]) not in one_dof:
            raise ValueError(f"{path}: joint {name!r} is not a slide or hinge joint in MuJoCo")
    return MujocoPlant(
        model=model,
        joint_names=names,
        qpos_index=np.array([model.jnt_qposadr[j] for j in ids]),
        dof_index=np.array([model.jnt_dofadr[j] for j in ids]),
        m=m,
        n=n,
    )


def simulate(
    plant: MujocoPlant,
    q0: np.ndarray,
    v0: np.ndarray,
    torques: np.ndarray,
    base_forces: np.ndarray | None,
) -> tuple[np.ndarray, np.ndarray]:
    """Step a built plant with held inputs; arguments and result as in :func:`replay`."""
    m, n, nv = plant.m, plant.n, plant.nv
    q0 = np.asarray(q0, dtype=float)
    v0 = np.asarray(v0, dtype=float)
    torques = np.asarray(torques, dtype=float)
    if q0.shape != (nv,) or v0.shape != (nv,):
        raise ValueError(f"q0 and v0 must have shape ({nv},), got {q0.shape} and {v0.shape}")
    if torques.ndim != 2 or torques.shape[1] != n:
        raise ValueError(f"torques must have shape (N, {n}), got {torques.shape}")
    steps = torques.shape[0]
    if base_forces is None:
        base_forces = np.zeros((steps, m))
    base_forces = np.asarray(base_forces, dtype=float)
    if base_forces.shape != (steps, m):
        raise ValueError(f"base_forces must have shape ({steps}, {m}), got {base_forces.shape}")
    for what, arr in (("q0", q0), ("v0", v0), ("torques", torques), ("base_forces", base_forces)):
        if not np.all(np.isfinite(arr)):
            raise ValueError(f"{what} must be finite")

    model = plant.model
    data = mujoco.MjData(model)
    qadr, dadr = plant.qpos_index, plant.dof_index
    data.qpos[qadr] = q0
    data.qvel[dadr] = v0
    applied = np.concatenate([base_forces, torques], axis=1)
    q = np.empty((steps + 1, nv))
    v = np.empty((steps + 1, nv))
    q[0], v[0] = q0, v0
    warnings: list[str] = []
    previous_handler = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(warnings.append)  # report in the exception, not in MUJOCO_LOG.TXT
    try:
        for k in range(steps):
            data.qfrc_applied[:] = 0.0
            data.qfrc_applied[dadr] = applied[k]
            mujoco.mj_step(model, data)  # RK4: qfrc_applied constant over the four stages
            q[k + 1] = data.qpos[qadr]
            v[k + 1] = data.qvel[dadr]
            if warnings or not (np.isfinite(q[k + 1]).all() and np.isfinite(v[k + 1]).all()):
                raise FloatingPointError(f"MuJoCo's RK4 diverged at step {k}: {'; '.join(warnings) or 'NaN state'}")
    finally:
        mujoco.set_mju_user_warning(previous_handler)
    return q, v


def replay(
    urdf_path: str | Path,
    base_joints: Sequence[str],
    stiffness: np.ndarray,
    damping: np.ndarray,
    joint_damping: np.ndarray,
    q0: np.ndarray,
    v0: np.ndarray,
    torques: np.ndarray,
    base_forces: np.ndarray | None,
    dt: float,
) -> tuple[np.ndarray, np.ndarray]:
    """q0, v0: (m+n,) pinocchio order (base joints first, then arm joints, URDF order).
    torques: (N, n) arm joint torques held over step k; base_forces: (N, m) external generalized
    force on the base coordinates held over step k (or None). Returns (q, v) arrays of shape (N+1, m+n):
    the state at t = 0, dt, ..., N dt, integrated by MuJoCo's RK4 integrator.

    stiffness K_b and damping D_b: (m, m), symmetric positive semi-definite, the
    spring at rest at x_b = 0 (coupled: fixed tendons); joint_damping D_m: (n,) or diagonal (n, n). Gravity is zero;
    joint limits and contacts are ignored. SI units; dt in s.
    """
    plant = build_model(urdf_path, base_joints, stiffness, damping, joint_damping, dt)
    return simulate(plant, q0, v0, torques, base_forces)


class HeldOverEachStep:
    """A force input held over each step at its value at the step's start: what mj_step applies
    (qfrc_applied is constant over its four RK4 stages), while rns_viz's step samples the force at
    the stage times t, t + dt/2, t + dt. The simulator asks for those three in that order."""

    def __init__(self, inner: Callable[[float], np.ndarray | None]) -> None:
        self.inner, self.calls, self.held = inner, 0, None

    def __call__(self, t: float) -> np.ndarray | None:
        if self.calls % 3 == 0:
            self.held = self.inner(t)
        self.calls += 1
        return self.held
