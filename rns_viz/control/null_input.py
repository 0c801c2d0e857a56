"""Null-space inputs P_RNS u for the composite laws (12)/(15)/(16): what the arm does in the RNS.

Each gives the joint acceleration P u (rad/s^2), which by Eq. (14) never reaches the base: u for
the law to project, or P u itself (Eq. 24). Which of them the native step also computes is listed,
by exact type, in rns_viz.sim.native.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from rns_viz.control.common import Coupling, Gains
from rns_viz.control.reference import JointReference, JointSample, ReferenceSample, TaskSample
from rns_viz.model import FsmsModel
from rns_viz.profiles import QuinticSegment
from rns_viz.rns import damped_pinv


@dataclass
class NullOutput:
    """A null-space input, P_RNS (u - damping theta') + Pu: ``u`` and ``damping`` for the law to project,
    ``Pu`` already in the RNS (Eq. 24). The law projects, so a one-row coupling needs no P_RNS formed."""

    Pu: np.ndarray | None = None  # (n,) rad/s^2, already in the RNS
    sigma_jbar: float = float("nan")
    theta_ref: np.ndarray | None = None
    ee_ref: np.ndarray | None = None
    u: np.ndarray | None = None  # (n,) rad/s^2, to be projected
    damping: float = 0.0  # 1/s: -damping theta' joins u

    def in_rns(self, cp: Coupling) -> np.ndarray:
        """The whole input as a joint acceleration in the RNS, rad/s^2."""
        u = -self.damping * cp.thetadot if self.u is None else self.u - self.damping * cp.thetadot
        Pu = cp.project(u)
        return Pu if self.Pu is None else Pu + self.Pu


class NullInput(Protocol):
    def __call__(self, t: float, cp: Coupling, q: np.ndarray, v: np.ndarray) -> NullOutput: ...

    def retune(self, gains: Gains) -> None:
        """Take this input's gains from ``gains``."""
        ...

    def follow(self, sample: ReferenceSample) -> None:
        """Track ``sample`` from the next evaluation on (TypeError if this input tracks no such thing)."""
        ...


def _refuse(owner: object, sample: object) -> TypeError:
    return TypeError(f"{type(owner).__name__} cannot follow a {type(sample).__name__}")


@dataclass
class DampNullMotion:
    """u = -G_m theta': with the law's own -G_m (E - P) theta' this is the paper's -G_m theta' (Fig. 3)."""

    g_m: float  # 1/s

    def __post_init__(self) -> None:
        self._output = NullOutput(damping=self.g_m)  # the same every step: built once per g_m

    def __call__(self, t: float, cp: Coupling, q: np.ndarray, v: np.ndarray) -> NullOutput:
        if self._output.damping != self.g_m:
            self._output = NullOutput(damping=self.g_m)
        return self._output

    def retune(self, gains: Gains) -> None:
        self.g_m = gains.g_m

    def follow(self, sample: ReferenceSample) -> None:
        raise _refuse(self, sample)


@dataclass
class TrackJointReference:
    """u = theta_r'' + k_d (theta_r' - theta') + k_p (theta_r - theta), projected into the RNS."""

    reference: JointReference
    k_p: float  # 1/s^2
    k_d: float  # 1/s

    def __call__(self, t: float, cp: Coupling, q: np.ndarray, v: np.ndarray) -> NullOutput:
        theta_r, thetadot_r, thetaddot_r = self.reference(t)
        u = thetaddot_r + self.k_d * (thetadot_r - cp.thetadot) + self.k_p * (theta_r - cp.theta)
        return NullOutput(u=u, theta_ref=theta_r)

    def retune(self, gains: Gains) -> None:
        self.k_p, self.k_d = gains.k_p, gains.k_d

    def follow(self, sample: ReferenceSample) -> None:
        if not isinstance(sample, JointSample):
            raise _refuse(self, sample)
        self.reference = sample


class TaskReference(Protocol):
    """x_e^d(t), its velocity and acceleration in the base frame (task rows only), SI units."""

    def __call__(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]: ...


@dataclass
class TrackEndEffector:
    """Reactionless end-effector tracking, Eq. (24):

    P u = J-bar^+ [x_d'' + G_d e' + G_p e - J' theta' + J H_bm^+ H_bm' theta'],  e = x_d - x_e.
    J-bar = J P_RNS is inverted with the damped inverse; its smallest singular value is reported.
    """

    model: FsmsModel
    target: TaskReference
    G_p: float  # 1/s^2
    G_d: float  # 1/s
    threshold: float = 1e-2  # sigma_min of J-bar (m/rad) below which damping starts

    def __call__(self, t: float, cp: Coupling, q: np.ndarray, v: np.ndarray) -> NullOutput:
        J, Jdot_thetadot, ee = self.model.ee_kinematics(q, cp.thetadot)
        x_d, xdot_d, xddot_d = self.target(t)
        p = len(x_d)
        e = x_d - ee[self.model.task_rows][:p]
        edot = xdot_d - J @ cp.thetadot
        J_bar = J @ cp.P
        inv = damped_pinv(J_bar, self.threshold, self.threshold)
        rhs = xddot_d + self.G_d * edot + self.G_p * e - Jdot_thetadot + J @ (cp.H_bm_pinv @ cp.hbm_dot_thetadot)
        return NullOutput(inv.inverse @ rhs, sigma_jbar=inv.sigma_min, ee_ref=x_d)

    def retune(self, gains: Gains) -> None:
        self.G_p, self.G_d = gains.G_p, gains.G_d

    def follow(self, sample: ReferenceSample) -> None:
        if not isinstance(sample, TaskSample):
            raise _refuse(self, sample)
        self.target = sample


TaskQuintic = QuinticSegment  # straight end-effector path, quintic in time (Fig. 4)
