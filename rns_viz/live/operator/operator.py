"""What the operator drives in live mode: the joint reference (and, for a multi-dimensional RNS, the
end-effector reference) that the operated and the shadow law both follow.

The operator owns its references and hands out immutable samples (:attr:`Operator.joint`,
:attr:`Operator.task`), which the loop passes to both laws at every step; :meth:`Operator.advance`
returns what changed for the loop to act on.

1-D RNS (TREP): theta_ref lives on the current reactionless path (:class:`PathTable`); drags, the
scrub slider, quintic plays and cyclic motion all move sigma = integral of u-bar dt (Eq. 30); the
point-to-point comparison leaves the path on a joint-space quintic between the same end points.

Multi-dimensional RNS (planar 3R, boom7 with r <= 5): the target is clamped to the reactionless
reachable set and followed by the :class:`ResolvedRate` reference; in space with n - r >= 4 its
orientation too, as a secondary task (the laws (15)/(16) then follow theta_ref, see :meth:`Operator.law_task`).

Dual arms (trep2): the target is clamped to the task arm's workspace and followed by the task arm
(:class:`~rns_viz.live.operator.dual_arm.TaskTarget`); the compensating arm cancels the reaction.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from rns_viz.control import JointSample, TaskSample
from rns_viz.live.operator.dual_arm import TaskTarget, is_dual
from rns_viz.live.operator.moving_references import PathFollower, ResolvedRate, SigmaMotion
from rns_viz.live.published.snapshot import OrientationView
from rns_viz.live.reach.region import ReachRegion
from rns_viz.model import FsmsModel
from rns_viz.paths import PathTable
from rns_viz.profiles import QuinticSegment
from rns_viz.scenarios import FIG11_FAST_S


@dataclass(frozen=True)
class OperatorChange:
    """What one :meth:`Operator.advance` changed that the loop must act on."""

    joint_move_changed: bool = False  # a point-to-point move started or ended: other laws apply
    target_jumped: bool = False  # the target moved other than by a drag: the handle follows it


UNCHANGED = OperatorChange()


SNAP_TOLERANCE_M = 0.005  # m: a dragged target farther than this from the current path is said to be moved


BLOCKED = "stopped before a singularity of J-bar (a fold of the reachable set): drag the target elsewhere"


def orientation_note(model: FsmsModel) -> str:
    """How many rotational DOF the RNS leaves beyond the hand's position (shown on the panel)."""
    free = model.n - len(model.selected) - len(model.task_rows)
    if len(model.task_rows) < 3:
        return "orientation: not offered (a planar task)"
    dim = model.n - len(model.selected)
    if free <= 0:
        return f"orientation: not offered (n − r = {dim} ≤ 3: the hand's position takes every RNS direction)"
    least = "" if free >= 3 else ", tracked by least squares"
    return f"orientation: {min(free, 3)} of 3 rotational DOF free (n − r = {dim}){least}"


class InputRefused(ValueError):
    """An operator input that cannot be applied now; the message says why (shown to that client)."""


class PathNotReady(InputRefused):
    """The current reactionless path is still being computed: the input can wait for it."""


class Operator:
    """The live references of one model; owned and advanced by the simulation loop."""

    def __init__(self, model: FsmsModel, theta0: np.ndarray, ubar_speed: float, target_speed: float) -> None:
        self.model = model
        self.rns_dim = model.n - len(model.selected)
        self.on_path = self.rns_dim == 1
        theta0 = np.array(theta0, dtype=float)
        self.joint = JointSample.held(theta0)  # theta_ref with its rates, for the laws
        self.ee_z = float(model.ee_position(theta0)[2])
        self.target: np.ndarray | None = None  # where the arm is going, base frame (m)
        self.target_raw: np.ndarray | None = None  # where the operator put the target
        self.table: PathTable | None = None
        self.reach: ReachRegion | None = None
        self.joint_move: QuinticSegment | None = None
        self.task: TaskSample | None = None  # x_d with its rates (multi-dimensional RNS), for the laws
        self.mode = "holding"
        if self.on_path:
            self.follower = PathFollower(model, theta0)
            self.motion = SigmaMotion(0.0, ubar_speed)
        elif is_dual(model):  # no reactionless restriction: anywhere in the task arm's workspace
            self.rr = TaskTarget(model, theta0, v_max=target_speed)  # type: ignore[assignment]
            self.reach = self.rr.workspace  # type: ignore[assignment]
        else:
            self.rr = ResolvedRate(model, theta0, v_max=target_speed)
        if not self.on_path:
            self.task = TaskSample.held(self.rr.x)
            self.target = self._point(self.rr.x)
        self._moving = False
        self._joint_move_started = False
        self.dragging = False

    # -- state ---------------------------------------------------------------------------------
    @property
    def theta_ref(self) -> np.ndarray:
        return self.follower.theta if self.on_path else self.rr.theta

    @property
    def level(self) -> np.ndarray:
        return self.follower.level if self.on_path else self.rr.level

    @property
    def busy(self) -> bool:
        """The reference is moving (a re-anchor now would fight the operator)."""
        if self.on_path:
            return self.joint_move is not None or self.motion.moving
        return not self.rr.idle

    @property
    def sigma(self) -> float | None:
        """Path position shown on the scrub slider (centred for closed paths), or None."""
        if not self.on_path or self.table is None:
            return None
        return self.table.centred(self.motion.sigma)

    def _point(self, xy: np.ndarray) -> np.ndarray:
        """A base-frame point (m): (x, y) of a planar task at the end effector's height, or (x, y, z)."""
        return np.array([xy[0], xy[1], xy[2] if len(xy) > 2 else self.ee_z], dtype=float)

    def set_speeds(self, ubar_speed: float, target_speed: float) -> None:
        if self.on_path:
            self.motion.set_speed(ubar_speed)
        else:
            self.rr.follower.v_max = target_speed

    # -- new configuration or overlays ---------------------------------------------------------
    def re_anchor(self, theta: np.ndarray) -> None:
        """Hold at ``theta`` (the arm's configuration) from now on; forgets the path table."""
        theta = np.array(theta, dtype=float)
        self.joint = JointSample.held(theta)
        self.joint_move = None
        if self.on_path:
            self.follower.reset(theta)
            self.motion.hold()
            self.table = None
        else:
            self.rr.reset(theta)
            self.task = TaskSample.held(self.rr.x)
            self.target = self._point(self.rr.x)  # the old reachable set serves until the new one is in
        self.mode = "holding"

    def accept_table(self, table: PathTable, tol: float) -> bool:
        """Use ``table`` if it is the path theta_ref is on; sigma is re-expressed on it."""
        if not self.on_path or np.max(np.abs(table.level - self.follower.level)) > tol:
            return False
        self.table = table
        self.motion.rebase(table.sigma_nearest_theta(self.follower.theta))
        return True

    # -- operator inputs -----------------------------------------------------------------------
    def _need_table(self) -> PathTable:
        if self.table is None:
            raise PathNotReady("The reactionless path through the current configuration is still being computed.")
        if self.joint_move is not None:
            raise InputRefused("Wait until the point-to-point comparison motion has finished.")
        if len(self.table.sigma) < 2:
            raise InputRefused(
                "The arm is at a singularity of the coupling H_bm (no reactionless path passes here); "
                "kick the base or press Reset to leave it."
            )
        return self.table

    @property
    def orienting(self) -> bool:
        """The reference also tracks the target's orientation (spatial models with n - r >= 4)."""
        return isinstance(getattr(self, "rr", None), ResolvedRate) and self.rr.orienting

    def law_task(self, kind: str) -> TaskSample | None:
        """The task sample the laws follow: none on a path; none for (15)/(16) while the orientation is tracked
        (they then track the pose-carrying theta_ref inside the RNS, as the velocity law (30) does)."""
        return None if self.on_path or (self.orienting and kind != "velocity") else self.task

    def orientation_view(self) -> OrientationView | None:
        """The orientation target as the panel and the handle show it (spatial tracking only)."""
        rr = None if self.on_path else self.rr
        if not isinstance(rr, ResolvedRate) or len(rr.rows) != 3:
            return None
        q = pin.Quaternion(rr.goal_R)
        wxyz = (float(q.w), float(q.x), float(q.y), float(q.z))
        return OrientationView(rr.orient_dof > 0, rr.orienting, orientation_note(self.model), wxyz)

    def set_orientation(self, on: bool) -> str:
        """Track the target's orientation or not; what to tell the operator."""
        rr = self.rr if not self.on_path else None
        if not isinstance(rr, ResolvedRate) or rr.orient_dof == 0:
            raise InputRefused(orientation_note(self.model))
        rr.set_orientation(on)
        return orientation_note(self.model) if on else "orientation not tracked: the hand turns as Eq. (24) lets it"

    def drag(self, point: np.ndarray, final: bool = True, wxyz: tuple[float, ...] | None = None) -> bool:
        """Send the arm toward a target (x, y) in the base frame; True if the target had to be moved
        (onto the current reactionless path, or into the reactionless reachable set). ``wxyz``: the goal
        orientation (base frame), followed when the orientation is tracked.

        ``final`` is False while the operator still holds the handle (it is then never moved under them).
        """
        point = np.asarray(point, dtype=float)
        if wxyz is not None and self.orienting:
            self.rr.set_goal_rotation(pin.Quaternion(*(float(v) for v in wxyz)).toRotationMatrix())
        self.dragging = not final
        self.target_raw = self._point(point)
        if self.on_path:  # 1-D RNS: the nearest point of the current reactionless path
            table = self._need_table()
            goal = table.nearest_copy(table.sigma_nearest_point(point), self.motion.sigma)
            self.motion.go_to(goal)
            self.target = self._point(table.ee_at(goal))
            self.mode = "moving along the path to the target"
            k = len(point)  # the coordinates the operator gave: (x, y) in the plane, (x, y, z) in space
            return bool(np.linalg.norm(self.target[:k] - point[:k]) > SNAP_TOLERANCE_M)
        clamped, moved = (point[: len(self.rr.rows)].copy(), False) if self.reach is None else self.reach.clamp(point)
        self.rr.set_goal(clamped)
        self.target = self._point(clamped)
        self.mode = "tracking the target"
        if moved and not isinstance(self.rr, TaskTarget):
            self.mode = f"target outside the reactionless-reachable set: held at {self._held_mm():.0f} mm from it"
        return moved

    def _held_mm(self) -> float:
        """How far (mm) the target in force is from where the operator put it."""
        k = len(self.model.task_rows)
        return 1e3 * float(np.linalg.norm(self.target[:k] - self.target_raw[:k]))  # type: ignore[index]

    def why_moved(self) -> str:
        """What to tell the operator when :meth:`drag` moved their target."""
        point = ", ".join(f"{v:.2f}" for v in self.target[: len(self.model.task_rows)])  # type: ignore[index]
        if self.on_path:
            where = "The arm moves without reaction only along its current reactionless path"
        elif isinstance(self.rr, TaskTarget):
            where = "That target is outside the task arm's workspace"
        else:
            return (
                "Target outside the reactionless-reachable set from this configuration: held at "
                f"{self._held_mm():.0f} mm from it, at its nearest reachable point ({point}) m."
            )
        return f"{where}; it goes to the nearest point ({point}) m instead."

    def scrub(self, sigma: float) -> None:
        """Move along the path to the slider's sigma (centred for closed paths), rate-limited by u-bar."""
        table = self._need_table()
        goal = table.nearest_copy(sigma, self.motion.sigma)
        self.motion.go_to(goal)
        self.target = self._point(table.ee_at(goal))
        self.mode = "moving along the path (scrub)"

    def half_way(self) -> float:
        """sigma to the 'other end': half a closed path, or the farther end of an open one."""
        table = self._need_table()
        if table.closed:
            return 0.5 * table.period
        s = table.wrap(self.motion.sigma)
        return table.hi - s if table.hi - s >= s - table.lo else table.lo - s

    def play(self, t: float, duration: float) -> None:
        """Quintic u-bar over ``duration`` s to the other end of the path (Fig. 11, slow or fast)."""
        total = self.half_way()
        self.motion.play(t, total, duration)
        self.target = self._point(self.table.ee_at(self.motion.sigma + total))  # type: ignore[union-attr]
        self.mode = f"quintic along the path, {duration:g} s"

    def cyclic(self, t: float, on: bool, level: float) -> None:
        """Start (u-bar ramps to ``level``) or stop (ramps to 0) cyclic motion along a closed path (Fig. 12)."""
        table = self._need_table()
        if on:
            if not table.closed:
                raise InputRefused("The current reactionless path is not closed: cyclic motion needs a closed path.")
            self.motion.start_cyclic(t, level)
            self.mode = f"cyclic along the path, u-bar = {level:g}"
        else:
            self.motion.stop(t)
            self.mode = "stopping"

    def point_to_point(self, t: float, duration: float = FIG11_FAST_S) -> None:
        """Joint-space quintic to the same end point as :meth:`play` (Fig. 11(b), "link 2 only")."""
        total = self.half_way()
        if self.motion.moving:
            raise InputRefused("Stop the motion along the path first.")
        start = self.follower.theta.copy()
        end = self.follower.end_point(total)
        self.joint_move = QuinticSegment(start, end, duration, t0=t)
        self._joint_move_started = True
        self._after_move = self.motion.sigma + total
        self.target = self._point(self.table.ee_at(self._after_move))  # type: ignore[union-attr]
        self.mode = "point-to-point (same end points)"

    # -- per step --------------------------------------------------------------------------------
    def advance(self, t: float, dt: float) -> OperatorChange:
        """Set the references for time t (call once, before the simulation step at t)."""
        if not self.on_path:
            rr = self.rr
            was_idle = rr.idle
            rr.step(dt)
            if not rr.idle or not was_idle:
                self.joint = JointSample(rr.theta, rr.thetadot, np.zeros_like(rr.thetadot))
                self.task = TaskSample(rr.x, rr.xdot, rr.xddot)
                if rr.idle:
                    self.mode = "holding at the target"
                elif getattr(rr, "blocked", False):
                    self.mode = BLOCKED
            return UNCHANGED
        if self.joint_move is not None:
            started, self._joint_move_started = self._joint_move_started, False
            seg = self.joint_move
            self.joint = JointSample(*seg(t))
            if t < seg.t0 + seg.duration:
                return OperatorChange(joint_move_changed=True) if started else UNCHANGED
            self.follower.reset(seg.end)
            self.joint = JointSample.held(seg.end)
            if self.table is not None:
                self.motion.rebase(self._after_move)
            self.joint_move = None
            self.mode = "holding"
            return OperatorChange(joint_move_changed=not started)
        motion = self.motion
        if motion.moving:
            before = motion.sigma
            motion.step(t - dt, dt)
            self.follower.advance(motion.sigma - before)
            self.joint = JointSample(*self.follower.reference(motion.ubar, dt))
            self._moving = True
            if not motion.moving:
                self.mode = "holding"
                if self.table is not None and not self.dragging:
                    self.target = self._point(self.table.ee_at(motion.sigma))
                    return OperatorChange(target_jumped=True)
        elif self._moving:
            self._moving = False
            self.follower.reference(0.0, dt)
            self.joint = JointSample.held(self.follower.theta)
        return UNCHANGED
