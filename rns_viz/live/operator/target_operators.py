"""The operators that drag a target: a multi-dimensional reaction null space (the planar 3R, boom7 with
r <= 5) and a task arm whose reaction compensating arms cancel (trep2).

Reachable set: the target is clamped to the reactionless-reachable set and followed by the
:class:`ResolvedRate` reference (Eq. 24); in space with n - r >= 4 its orientation too, as a secondary
task (the laws (15)/(16) then follow theta_ref, see :meth:`ReachOperator.law_task`).

Task arm: the target is clamped to the task arm's workspace and followed by the task arm
(:class:`~rns_viz.live.operator.dual_arm.TaskTarget`); the compensating arm cancels the reaction.
"""

from __future__ import annotations

from abc import abstractmethod

import numpy as np
import pinocchio as pin

from rns_viz.control import JointSample, LawKind, TaskSample
from rns_viz.live.operator.dual_arm import TaskTarget
from rns_viz.live.operator.moving_references import ResolvedRate
from rns_viz.live.operator.operator import UNCHANGED, InputRefused, Operator, OperatorChange, orientation_note
from rns_viz.live.operator.smoothed_target import SmoothedTarget
from rns_viz.live.published.snapshot import OrientationView
from rns_viz.live.reach.region import ReachRegion
from rns_viz.model import FsmsModel

BLOCKED = "stopped before a singularity of J-bar (a fold of the reachable set): drag the target elsewhere"


class TargetOperator(Operator):
    """A dragged target, smoothed and followed by ``tracker`` (the joint and task references both come from it)."""

    follows = "target"
    tracker: SmoothedTarget

    def __init__(self, model: FsmsModel, theta0: np.ndarray, ubar_speed: float, target_speed: float) -> None:
        super().__init__(model, theta0, ubar_speed, target_speed)
        self.tracker = self._tracker(model, self.joint.theta, target_speed)
        self.task = TaskSample.held(self.tracker.x)
        self.target = self._point(self.tracker.x)

    @abstractmethod
    def _tracker(self, model: FsmsModel, theta0: np.ndarray, target_speed: float) -> SmoothedTarget:
        """The smoothed target this kind follows, at rest at ``theta0``."""

    @abstractmethod
    def _clamp(self, point: np.ndarray) -> tuple[np.ndarray, bool]:
        """Where a target may go: the nearest allowed point to ``point``, and whether it had to be moved."""

    @property
    def theta_ref(self) -> np.ndarray:
        return self.tracker.theta

    @property
    def level(self) -> np.ndarray:
        return self.tracker.level

    @property
    def busy(self) -> bool:
        return not self.tracker.idle

    def set_speeds(self, ubar_speed: float, target_speed: float) -> None:
        self.tracker.follower.v_max = target_speed

    def _hold_at(self, theta: np.ndarray) -> None:
        self.tracker.reset(theta)
        self.task = TaskSample.held(self.tracker.x)
        self.target = self._point(self.tracker.x)  # the old reachable set serves until the new one is in

    def _go_to(self, point: np.ndarray, wxyz: tuple[float, ...] | None) -> bool:
        clamped, moved = self._clamp(point)
        self.tracker.set_goal(clamped)
        self.target = self._point(clamped)
        self.mode = "tracking the target"
        return moved

    def advance(self, t: float, dt: float) -> OperatorChange:
        tracker = self.tracker
        was_idle = tracker.idle
        tracker.step(dt)
        if not tracker.idle or not was_idle:
            self.joint = JointSample(tracker.theta, tracker.thetadot, np.zeros_like(tracker.thetadot))
            self.task = TaskSample(tracker.x, tracker.xdot, tracker.xddot)
            if tracker.idle:
                self.mode = "holding at the target"
            elif tracker.blocked:
                self.mode = BLOCKED
        return UNCHANGED


class ReachOperator(TargetOperator):
    """A multi-dimensional RNS: targets clamped to the reactionless-reachable set, tracked by Eq. (24)."""

    kind = "reachable set"
    shows = "reachable set"
    tracker: ResolvedRate
    reach: ReachRegion | None = None  # the reachable set around the arm, once computed (until then: anywhere)

    def _tracker(self, model: FsmsModel, theta0: np.ndarray, target_speed: float) -> ResolvedRate:
        return ResolvedRate(model, theta0, v_max=target_speed)

    def take_reach(self, region: ReachRegion) -> None:
        self.reach = region

    def _clamp(self, point: np.ndarray) -> tuple[np.ndarray, bool]:
        if self.reach is None:
            return point[: len(self.tracker.rows)].copy(), False
        return self.reach.clamp(point)

    @property
    def orienting(self) -> bool:
        return self.tracker.orienting

    def law_task(self, kind: str) -> TaskSample | None:
        """None for (15)/(16) while the orientation is tracked: they then track the pose-carrying theta_ref inside
        the RNS, as the velocity law (30) does."""
        return None if self.orienting and kind != "velocity" else self.task

    def orientation_view(self) -> OrientationView | None:
        tracker = self.tracker
        if len(tracker.rows) != 3:
            return None
        q = pin.Quaternion(tracker.goal_R)
        wxyz = (float(q.w), float(q.x), float(q.y), float(q.z))
        return OrientationView(tracker.orient_dof > 0, tracker.orienting, orientation_note(self.model), wxyz)

    def set_orientation(self, on: bool) -> str:
        if self.tracker.orient_dof == 0:
            raise InputRefused(orientation_note(self.model))
        self.tracker.set_orientation(on)
        return orientation_note(self.model) if on else "orientation not tracked: the hand turns as Eq. (24) lets it"

    def _go_to(self, point: np.ndarray, wxyz: tuple[float, ...] | None) -> bool:
        if wxyz is not None and self.orienting:
            self.tracker.set_goal_rotation(pin.Quaternion(*(float(v) for v in wxyz)).toRotationMatrix())
        moved = super()._go_to(point, wxyz)
        if moved:
            self.mode = f"target outside the reactionless-reachable set: held at {self._held_mm():.0f} mm from it"
        return moved

    def why_moved(self) -> str:
        return (
            "Target outside the reactionless-reachable set from this configuration: held at "
            f"{self._held_mm():.0f} mm from it, at its nearest reachable point ({self._target_words()}) m."
        )


class TaskArmOperator(TargetOperator):
    """A task arm and compensating arms: targets anywhere in the task arm's workspace (no reactionless
    restriction); the compensating law cancels the reaction (Sec. III-B)."""

    kind = "task arm"
    shows = "workspace"
    compensates = True
    laws: tuple[LawKind, ...] = ("acceleration",)  # the compensating law resolves accelerations like (15)
    law_words = "the compensating law (resolved acceleration, like (15))"
    tracker: TaskTarget

    def _tracker(self, model: FsmsModel, theta0: np.ndarray, target_speed: float) -> TaskTarget:
        return TaskTarget(model, theta0, v_max=target_speed)

    def _clamp(self, point: np.ndarray) -> tuple[np.ndarray, bool]:
        return self.tracker.workspace.clamp(point)  # the annulus the task arm reaches

    def why_moved(self) -> str:
        where = "That target is outside the task arm's workspace"
        return f"{where}; it goes to the nearest point ({self._target_words()}) m instead."
