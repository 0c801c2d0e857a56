"""The operator of a 1-D reaction null space (TREP; boom7 with all six reactions selected, r = 6).

theta_ref lives on the current reactionless path (:class:`PathTable`); drags, the scrub slider, quintic
plays and cyclic motion all move sigma = integral of u-bar dt (Eq. 30); the point-to-point comparison leaves
the path on a joint-space quintic between the same end points (Fig. 11(b)).
"""

from __future__ import annotations

import numpy as np

from rns_viz.control import JointSample
from rns_viz.live.operator.moving_references import PathFollower, SigmaMotion
from rns_viz.live.operator.operator import UNCHANGED, InputRefused, Operator, OperatorChange, PathNotReady
from rns_viz.model import FsmsModel
from rns_viz.paths import PathTable
from rns_viz.profiles import QuinticSegment
from rns_viz.scenarios import FIG11_FAST_S

SNAP_TOLERANCE_M = 0.005  # m: a dragged target farther than this from the current path is said to be moved


class PathOperator(Operator):
    """theta_ref on the current reactionless path: the arm moves without reaction only along it."""

    kind = "reactionless path"
    follows = "path"
    shows = "path"

    def __init__(self, model: FsmsModel, theta0: np.ndarray, ubar_speed: float, target_speed: float) -> None:
        super().__init__(model, theta0, ubar_speed, target_speed)
        self.follower = PathFollower(model, self.joint.theta)
        self.motion = SigmaMotion(0.0, ubar_speed)
        self._moving = False
        self._joint_move_started = False

    @property
    def theta_ref(self) -> np.ndarray:
        return self.follower.theta

    @property
    def level(self) -> np.ndarray:
        return self.follower.level

    @property
    def busy(self) -> bool:
        return self.joint_move is not None or self.motion.moving

    @property
    def sigma(self) -> float | None:
        return None if self.table is None else self.table.centred(self.motion.sigma)

    def set_speeds(self, ubar_speed: float, target_speed: float) -> None:
        self.motion.set_speed(ubar_speed)

    def _hold_at(self, theta: np.ndarray) -> None:
        self.follower.reset(theta)
        self.motion.hold()
        self.table = None

    def accept_table(self, table: PathTable, tol: float) -> bool:
        if np.max(np.abs(table.level - self.follower.level)) > tol:
            return False
        self.table = table
        self.motion.rebase(table.sigma_nearest_theta(self.follower.theta))
        return True

    def law_task(self, kind: str) -> None:
        return None  # the laws follow theta_ref along the path

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

    def _go_to(self, point: np.ndarray, wxyz: tuple[float, ...] | None) -> bool:
        """The nearest point of the current reactionless path."""
        table = self._need_table()
        goal = table.nearest_copy(table.sigma_nearest_point(point), self.motion.sigma)
        self.motion.go_to(goal)
        self.target = self._point(table.ee_at(goal))
        self.mode = "moving along the path to the target"
        k = len(point)  # the coordinates the operator gave: (x, y) in the plane, (x, y, z) in space
        return bool(np.linalg.norm(self.target[:k] - point[:k]) > SNAP_TOLERANCE_M)

    def why_moved(self) -> str:
        where = "The arm moves without reaction only along its current reactionless path"
        return f"{where}; it goes to the nearest point ({self._target_words()}) m instead."

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
        if self.joint_move is not None:
            return self._advance_joint_move(t)
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

    def _advance_joint_move(self, t: float) -> OperatorChange:
        started, self._joint_move_started = self._joint_move_started, False
        seg = self.joint_move
        assert seg is not None
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
