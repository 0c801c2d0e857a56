"""FSMS model from URDF: the blocks of Eq. (1) and the end-effector kinematics, all by pinocchio.

Generalised coordinates are q = (x_b, theta): the first m joints of the URDF are the elastic
base coordinates named in the parameter file, the remaining n are the arm joints. Every
quantity comes from pinocchio (crba, nonLinearEffects, computeCoriolisMatrix, frame
Jacobians); nothing is hand-derived.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pinocchio as pin

from rns_viz.params import ModelFileError, ModelSpec, load_spec, param_path_for, spec_for_key
from rns_viz.rns import null_vector
from rns_viz.urdf import build_pinocchio_model

_AXIS_INDEX = {"x": 0, "y": 1, "z": 2}


@dataclass(frozen=True)
class Terms:
    """Dynamics and kinematics at one state (q, v); SI units, base-frame vectors."""

    H_b: np.ndarray  # (m, m) base inertia, kg or kg m^2
    H_bm: np.ndarray  # (m, n) inertia coupling matrix, Eq. (1)
    H_m: np.ndarray  # (n, n) arm inertia
    c_b: np.ndarray  # (m,) velocity terms, base rows of Eq. (1)
    c_m: np.ndarray  # (n,) velocity terms, arm rows
    hbm_dot_thetadot: np.ndarray  # (m,) H_bm' theta', Eq. (5)
    coupling_momentum: np.ndarray  # (m,) L = H_bm theta', Eq. (8)
    J: np.ndarray  # (p, n) end-effector Jacobian in the base frame, Eq. (21)
    Jdot_thetadot: np.ndarray  # (p,) J' theta' in the base frame
    ee: np.ndarray  # (3,) end-effector position in the base frame, m


class EndEffectorFrame(NamedTuple):
    """The end effector at one configuration, in the base frame (:meth:`FsmsModel.ee_frame_jacobian`)."""

    position: np.ndarray  # (3,) m
    rotation: np.ndarray  # (3, 3)
    linear: np.ndarray  # (3, n) m/rad: J, every axis (the task rows are FsmsModel.task_rows of it)
    angular: np.ndarray  # (3, n) rad/rad: the angular rows of the frame Jacobian


@dataclass(frozen=True)
class ArmBranch:
    """One arm of a tree: its joints' indices into theta (pinocchio's order) and its end-effector frame."""

    joints: tuple[str, ...]
    index: np.ndarray  # (k,) positions in theta, in the order of ``joints``
    frame: str


class FsmsModel:
    """Arms on an m-DOF elastic base (1 <= m <= 6), built from URDF + parameter file.

    One serial arm, or (with ``[arms]`` in the parameter file) a task arm and compensating arms
    branching from the base: then ``arm_groups`` holds each arm's indices into theta.
    """

    def __init__(self, spec: ModelSpec) -> None:
        self.spec = spec
        self.pin_model = build_pinocchio_model(spec)
        self.data = self.pin_model.createData()
        model = self.pin_model
        self.m = spec.base.dof
        self.n = model.nv - self.m
        names = list(model.names)[1:]
        if names[: self.m] != list(spec.base.joints):
            raise ModelFileError(
                f"{spec.param_path}: [base] joints {list(spec.base.joints)} must be the first "
                f"joints of {spec.urdf_path.name}, which are {names[: self.m]}"
            )
        if model.nq != model.nv or any(j.nv != 1 for j in model.joints[1:]):
            raise ModelFileError(
                f"{spec.urdf_path}: every joint must be prismatic or revolute with one coordinate "
                "(use 'revolute' with wide limits instead of 'continuous')"
            )
        if self.n < 1 or spec.default_configuration.size != self.n:
            raise ModelFileError(
                f"{spec.param_path}: [model] default_configuration_deg has "
                f"{spec.default_configuration.size} angles, the arm has {self.n} joints"
            )
        if not model.existFrame(spec.ee_frame):
            raise ModelFileError(f"{spec.urdf_path}: no link or frame named {spec.ee_frame!r} (ee_frame)")
        self.ee_frame_id = model.getFrameId(spec.ee_frame)
        self.base_joint_id = self.m  # pinocchio joint index of the last base joint
        self.arm_joint_names: tuple[str, ...] = tuple(names[self.m :])
        self.arm_groups = _arm_branches(spec, self.arm_joint_names, model)
        self.selected = np.flatnonzero(spec.base.selection)
        # S's rows as a slice where they run together: a view of pinocchio's fresh M (crba returns a
        # copy) instead of a fancy-indexed copy, in every reactionless-path step
        contiguous = len(self.selected) > 0 and bool(np.all(np.diff(self.selected) == 1))
        self._coupling_rows: slice | np.ndarray = (
            slice(int(self.selected[0]), int(self.selected[-1]) + 1) if contiguous else self.selected
        )
        self.task_rows = np.array([_AXIS_INDEX[a] for a in spec.task_axes])
        self.lower = model.lowerPositionLimit[self.m :].copy()
        self.upper = model.upperPositionLimit[self.m :].copy()
        self.K_b = spec.base.stiffness
        self.D_b = spec.base.damping
        self.D_m = np.diag(spec.joint_damping)
        self.has_joint_damping = bool(np.any(spec.joint_damping))  # D_m != 0: skip D_m theta' when not
        self.arm_mass = float(sum(model.inertias[i].mass for i in range(self.m + 1, model.njoints)))
        self.base_is_translational = all(
            model.joints[i].shortname().startswith("JointModelP") for i in range(1, self.m + 1)
        )
        # per base coordinate: a rotation (a revolute base joint: rad, N m) or not
        joints = model.joints
        self.base_rotational = tuple(joints[i].shortname().startswith("JointModelR") for i in range(1, self.m + 1))
        self.arm_reach = self._arm_reach()
        # S H_bm's rows in one unit: a moment row (kg m^2, a revolute base coordinate) divided by the arm's
        # reach, so sigma_min(W S H_bm) is a distance in kg m (rns.singularity_distance); None: all kg m
        turning = np.array([self.base_rotational[i] for i in self.selected], dtype=bool)
        weights = np.where(turning, 1.0 / self.arm_reach, 1.0)
        self.coupling_weights: np.ndarray | None = weights if turning.any() else None
        # c_b = H_bm' theta' exactly (M does not depend on x_b): see dynamics()
        self.gravity_free = not np.any(spec.gravity)
        self.cb_is_hbm_dot = self.base_is_translational and self.gravity_free
        # ee_kinematics: its buffers, the task rows as a slice where they are contiguous, and
        # whether the base frame is the world's axes at every x_b (translating, no rotated origin)
        self._v_rel, self._zero_v = np.zeros(model.nv), np.zeros(model.nv)
        rows = self.task_rows
        contiguous = len(rows) and np.array_equal(rows, np.arange(rows[0], rows[0] + len(rows)))
        self._task_index: slice | np.ndarray = slice(int(rows[0]), int(rows[0]) + len(rows)) if contiguous else rows
        self._base_axes_fixed = self.base_is_translational and bool(
            np.array_equal(self._base_rotation_at(np.zeros(model.nq)), np.eye(3))
        )

    def _arm_reach(self) -> float:
        """The arm's reach, m: its joint-to-joint distances plus the end-effector offset (pinocchio's joint
        placements; the arm stretched). boom7's 1.09 m, TREP's 0.2 m, the 3R's 3 m."""
        model = self.pin_model
        joints = range(self.m + 2, model.njoints)
        links = sum(float(np.linalg.norm(model.jointPlacements[j].translation)) for j in joints)
        return links + float(np.linalg.norm(model.frames[self.ee_frame_id].placement.translation))

    def _base_rotation_at(self, q: np.ndarray) -> np.ndarray:
        data = self.pin_model.createData()
        pin.forwardKinematics(self.pin_model, data, q)
        return data.oMi[self.base_joint_id].rotation.copy()

    @classmethod
    def from_name(cls, name: str) -> FsmsModel:
        """A bundled model: ``trep``, ``planar3r`` or ``boom7``."""
        return cls(load_spec(param_path_for(name)))

    @classmethod
    def from_key(cls, key: str) -> FsmsModel:
        """The model a key of :func:`rns_viz.params.model_key` names (bundled or a file, with its S)."""
        return cls(spec_for_key(key))

    def with_selection(self, selection: Sequence[int | bool]) -> FsmsModel:
        """The same system with another selection S: 0/1 flags over the base coordinates (Sec. III-B)."""
        return FsmsModel(self.spec.with_selection(selection))

    @classmethod
    def from_file(cls, param_path: str | Path) -> FsmsModel:
        return cls(load_spec(param_path))

    # -- coordinates ---------------------------------------------------------------------------
    @property
    def name(self) -> str:
        return self.spec.name

    @property
    def nv(self) -> int:
        return self.m + self.n

    def q(self, theta: np.ndarray, x_b: np.ndarray | None = None) -> np.ndarray:
        """Stack (x_b, theta) into pinocchio's configuration vector."""
        xb = np.zeros(self.m) if x_b is None else np.asarray(x_b, dtype=float)
        return np.concatenate([xb, np.asarray(theta, dtype=float)])

    # -- dynamics ------------------------------------------------------------------------------
    def mass_matrix(self, q: np.ndarray, data: pin.Data | None = None) -> np.ndarray:
        """Joint-space inertia matrix of Eq. (1), full and symmetric.

        ``data``: pinocchio data to work in (default: the model's own, which the laws also use).
        """
        return pin.crba(self.pin_model, self.data if data is None else data, q)

    def coupling_matrix(self, q: np.ndarray, data: pin.Data | None = None) -> np.ndarray:
        """S H_bm: the rows of the inertia coupling matrix selected by S (Sec. III-B)."""
        return self.mass_matrix(q, data)[self._coupling_rows, self.m :]

    def coupling_at(self, theta: np.ndarray, data: pin.Data | None = None) -> np.ndarray:
        """S H_bm at the arm configuration theta with the base at rest in its equilibrium (x_b = 0)."""
        return self.coupling_matrix(self.q(theta), data)

    def null_vector(self, theta: np.ndarray, data: pin.Data | None = None) -> np.ndarray:
        """n(theta) of a 1-D RNS (Eq. 27, generalised; :func:`rns_viz.rns.null_vector` of S H_bm), kg m: the
        unnormalised direction of the reactionless path through theta."""
        return null_vector(self.coupling_at(theta, data))

    def dynamics(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """M, the velocity terms c = (c_b, c_m) and H_bm' theta' at (q, v): what the laws need.

        Runs at every control step. M and c are new arrays; H_bm' theta' may be a view of c.

        For a translating base without gravity c_b is exactly H_bm' theta' (M does not depend
        on x_b), which saves the Coriolis matrix; otherwise H_bm' comes from M' = C + C^T, and
        without gravity c = C v from the same C (no second pass for nonLinearEffects).
        """
        model, data, m = self.pin_model, self.data, self.m
        M = pin.crba(model, data, q)  # pinocchio returns new arrays: nothing to copy
        if self.cb_is_hbm_dot:
            c = pin.nonLinearEffects(model, data, q, v)
            return M, c, c[:m]  # a view of c
        C = pin.computeCoriolisMatrix(model, data, q, v)
        c = C.dot(v) if self.gravity_free else pin.nonLinearEffects(model, data, q, v)
        return M, c, (C + C.T)[:m, m:] @ v[m:]

    def terms(self, q: np.ndarray, v: np.ndarray) -> Terms:
        """All blocks of Eq. (1) and the end-effector kinematics of Eq. (21) at (q, v)."""
        model, data, m = self.pin_model, self.data, self.m
        M = pin.crba(model, data, q).copy()
        c = pin.nonLinearEffects(model, data, q, v).copy()
        C = pin.computeCoriolisMatrix(model, data, q, v)
        M_dot = C + C.T  # M' = C + C^T for pinocchio's Coriolis matrix
        thetadot = v[m:]
        J, Jdot_thetadot, ee = self.ee_kinematics(q, thetadot)
        return Terms(
            H_b=M[:m, :m],
            H_bm=M[:m, m:],
            H_m=M[m:, m:],
            c_b=c[:m],
            c_m=c[m:],
            hbm_dot_thetadot=M_dot[:m, m:] @ thetadot,
            coupling_momentum=M[:m, m:] @ thetadot,
            J=J,
            Jdot_thetadot=Jdot_thetadot,
            ee=ee,
        )

    # -- kinematics ----------------------------------------------------------------------------
    def ee_kinematics(self, q: np.ndarray, thetadot: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """J, J' theta' and the end-effector position, all relative to and in the base frame."""
        model, data, m, frame = self.pin_model, self.data, self.m, self.ee_frame_id
        v_rel = self._v_rel  # (0, theta'): the base frame's own motion is not the arm's
        v_rel[m:] = thetadot
        pin.forwardKinematics(model, data, q, v_rel, self._zero_v)
        pin.updateFramePlacement(model, data, frame)
        base = data.oMi[self.base_joint_id]
        ee = data.oMf[frame].translation - base.translation
        acc = pin.getFrameClassicalAcceleration(model, data, frame, pin.LOCAL_WORLD_ALIGNED).linear
        pin.computeJointJacobians(model, data)  # on the placements just computed: no second pass
        J_world = pin.getFrameJacobian(model, data, frame, pin.LOCAL_WORLD_ALIGNED)[:3, m:]
        rows = self._task_index
        if self._base_axes_fixed:  # a translating base without rotated axes: R = E, nothing to rotate
            return J_world[rows], acc[rows].copy(), ee
        R = base.rotation
        return (R.T @ J_world)[rows], (R.T @ acc)[rows], R.T @ ee

    def _ee_placements(self, theta: np.ndarray, data: pin.Data | None) -> tuple[pin.SE3, pin.SE3]:
        """The base frame and the end-effector frame in the world at (x_b = 0, theta), forward kinematics done."""
        data = self.data if data is None else data
        pin.forwardKinematics(self.pin_model, data, self.q(theta))
        ee = pin.updateFramePlacement(self.pin_model, data, self.ee_frame_id)
        return data.oMi[self.base_joint_id], ee

    def ee_position(self, theta: np.ndarray, data: pin.Data | None = None) -> np.ndarray:
        """End-effector position in the base frame, m (forward kinematics by pinocchio).

        ``data``: pinocchio data to work in (default: the model's own, which the laws also use).
        """
        base, ee = self._ee_placements(theta, data)
        return base.rotation.T @ (ee.translation - base.translation)

    def ee_pose(self, theta: np.ndarray, data: pin.Data | None = None) -> tuple[np.ndarray, np.ndarray]:
        """End-effector position (3,), m, and orientation (3, 3) in the base frame."""
        base, ee = self._ee_placements(theta, data)
        R = base.rotation.T
        return R @ (ee.translation - base.translation), R @ ee.rotation

    def ee_frame_jacobian(self, theta: np.ndarray, data: pin.Data | None = None) -> EndEffectorFrame:
        """The end effector's position, orientation and full (6, n) Jacobian in the base frame at theta, x_b = 0."""
        model, m, frame = self.pin_model, self.m, self.ee_frame_id
        data = self.data if data is None else data
        J = pin.computeFrameJacobian(model, data, self.q(theta), frame, pin.LOCAL_WORLD_ALIGNED)[:, m:]
        base, ee = data.oMi[self.base_joint_id], data.oMf[frame]  # both placed by computeFrameJacobian
        R = base.rotation.T
        return EndEffectorFrame(R @ (ee.translation - base.translation), R @ ee.rotation, R @ J[:3], R @ J[3:])

    def arm_points(self, theta: np.ndarray, data: pin.Data | None = None) -> np.ndarray:
        """Base-frame positions (n + 1, 3) of the arm joints and the end effector, m: the arm's polyline."""
        return self._polyline(theta, range(self.m + 1, self.pin_model.njoints), self.ee_frame_id, data)

    def branch_points(self, theta: np.ndarray, arm: str, data: pin.Data | None = None) -> np.ndarray:
        """Base-frame positions (k + 1, 3) of one arm's joints and its end-effector frame, m (a tree's polyline)."""
        branch = self.arm_groups[arm]
        joints = [self.pin_model.getJointId(j) for j in branch.joints]
        return self._polyline(theta, joints, self.pin_model.getFrameId(branch.frame), data)

    def _polyline(self, theta: np.ndarray, joints: Sequence[int], frame: int, data: pin.Data | None) -> np.ndarray:
        """Base-frame positions of ``joints`` and then of ``frame`` at (x_b = 0, theta), m."""
        data = self.data if data is None else data
        pin.framesForwardKinematics(self.pin_model, data, self.q(theta))
        points = [data.oMi[i].translation for i in joints]
        points.append(data.oMf[frame].translation)
        base = data.oMi[self.base_joint_id]
        return (np.array(points) - base.translation) @ base.rotation

    def ee_positions(self, thetas: np.ndarray, data: pin.Data | None = None) -> np.ndarray:
        """End-effector positions (K, 3) in the base frame for K configurations (K, n), x_b = 0, m.

        ``data``: pinocchio data to work in (default: the model's own, which the laws also use).
        """
        model, fid, q = self.pin_model, self.ee_frame_id, np.zeros(self.nv)
        data = self.data if data is None else data
        out = np.empty((len(thetas), 3))
        for k, theta in enumerate(thetas):
            q[self.m :] = theta
            pin.forwardKinematics(model, data, q)
            out[k] = pin.updateFramePlacement(model, data, fid).translation
        base = data.oMi[self.base_joint_id]  # the base frame does not depend on theta
        return (out - base.translation) @ base.rotation

    def ee_jacobian(self, theta: np.ndarray) -> np.ndarray:
        """Task rows of the end-effector Jacobian in the base frame, (p, n)."""
        return self.ee_kinematics(self.q(theta), np.zeros(self.n))[0]

    def arm_mass_moment(self, theta: np.ndarray) -> np.ndarray:
        """w r_cm: arm mass times arm centre of mass, in the base frame (kg m).

        For a translating base its component along a base axis is a potential of that row of
        H_bm (Eq. 26), so reactionless paths are its level sets.
        """
        q = self.q(theta)
        model, data = self.pin_model, self.data
        pin.forwardKinematics(model, data, q)
        moment = sum(
            model.inertias[i].mass * data.oMi[i].act(model.inertias[i].lever) for i in range(self.m + 1, model.njoints)
        )
        base = data.oMi[self.base_joint_id]
        return base.rotation.T @ (moment - self.arm_mass * base.translation)

    def base_axes(self) -> np.ndarray:
        """Unit axes of the base joints, (m, 3), in the base frame (translational bases)."""
        axes = []
        for i in range(1, self.m + 1):
            S = self.pin_model.joints[i].shortname()
            axis = {"X": [1, 0, 0], "Y": [0, 1, 0], "Z": [0, 0, 1]}.get(S[-1])
            if axis is None:  # JointModelPrismaticUnaligned
                axis = list(self.pin_model.joints[i].extract().axis)
            axes.append(axis)
        return np.array(axes, dtype=float)


def _arm_branches(spec: ModelSpec, arm_joints: tuple[str, ...], model: pin.Model) -> dict[str, ArmBranch]:
    """``[arms]`` by name -> indices into theta: pinocchio orders a tree's branches its own way."""
    arms = spec.arms
    if arms is None:
        return {}
    groups = {"task": arms.task}
    for k, joints in enumerate(arms.compensating):
        groups["compensating" if k == 0 else f"compensating_{k + 1}"] = joints
    listed = [j for joints in groups.values() for j in joints]
    if sorted(listed) != sorted(arm_joints):
        raise ModelFileError(
            f"{spec.param_path}: [arms] must list every arm joint once, {sorted(arm_joints)}; got {sorted(listed)}"
        )
    branches = {}
    for name, joints in groups.items():
        frame = arms.ee_frames.get(name, spec.ee_frame if name == "task" else "")
        if not model.existFrame(frame):
            raise ModelFileError(f"{spec.urdf_path}: no frame {frame!r} for [arms] ee_frames.{name}")
        index = np.array([arm_joints.index(j) for j in joints])
        branches[name] = ArmBranch(tuple(joints), index, frame)
    return branches
