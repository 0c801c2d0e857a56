"""References the operator moves while the simulation runs; the session advances them once per step.

The operator (rns_viz.live.operator.operator) advances them once *before* the step at time t and hands
immutable samples of them to both runs' laws, so the shadow sees the same operator inputs.

- :class:`SigmaMotion`: sigma = integral of u-bar dt (Eq. 30) held, driven to a goal (scrub, drag),
  by a quintic (Fig. 11) or cyclically (Fig. 12).
- :class:`PathFollower`: theta_ref on the reactionless path, d theta / d sigma = n(theta) by RK4
  (:func:`~rns_viz.control.reference.along_path`) from knot to knot, a cubic Hermite curve between knots.
- :class:`ResolvedRate`: the reactionless resolved-rate reference of a multi-dimensional RNS,
  theta_ref' = J-bar(theta_ref)^+ (x_f' + k (x_f - x(theta_ref))) with a damped inverse, x_f the
  smoothed target (Eq. 24's J-bar = J P_RNS); in space, optionally an orientation target as a
  secondary task in the RNS directions that leave the position still (task priority).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from rns_viz.control.reference import along_path
from rns_viz.live.operator.follower import ScalarFollower
from rns_viz.live.operator.smoothed_target import SmoothedTarget
from rns_viz.model import FsmsModel
from rns_viz.paths import CouplingField
from rns_viz.profiles import quintic
from rns_viz.rns import DampedInverse, rns_projector, svd_inverse, truncated_inverse


class SigmaMotion:
    """sigma(t) and u-bar = sigma'(t): held, driven to a goal, a quintic, or cyclic with smooth ramps."""

    RAMP = 1.0  # s, the smooth start and stop of cyclic motion (Sec. VII-D-3)
    TOL = 1e-3  # 1/(kg m): a goal this close is reached (about 5e-5 rad for TREP)

    def __init__(self, sigma: float = 0.0, speed: float = 30.0) -> None:
        self.follower = ScalarFollower(sigma, speed)
        self.mode = "hold"  # hold | goal | quintic | cyclic | stopping
        self.goal = sigma
        self._quintic: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0)  # t0, sigma0, total, T
        self._cyclic: tuple[float, float, float] = (0.0, 0.0, 0.0)  # t0, level, u-bar at t0

    @property
    def sigma(self) -> float:
        return self.follower.x

    @property
    def ubar(self) -> float:
        return self.follower.v

    @property
    def moving(self) -> bool:
        return self.mode != "hold"

    def set_speed(self, speed: float) -> None:
        self.follower.v_max = speed

    def rebase(self, sigma: float) -> None:
        """Re-express the current position as ``sigma`` (a new table), keeping the motion's shape."""
        shift = sigma - self.sigma
        self.follower.x = sigma
        self.goal += shift
        t0, s0, total, T = self._quintic
        self._quintic = (t0, s0 + shift, total, T)

    def hold(self) -> None:
        self.mode, self.goal = "hold", self.sigma
        self.follower.v = 0.0

    def go_to(self, goal: float) -> None:
        self.mode, self.goal = "goal", goal

    def play(self, t: float, total: float, duration: float) -> None:
        self.mode = "quintic"
        self._quintic = (t, self.sigma, total, duration)

    def start_cyclic(self, t: float, level: float) -> None:
        self.mode = "cyclic"
        self._cyclic = (t, level, self.ubar)

    def stop(self, t: float) -> None:
        """Smoothly bring any motion to rest (cyclic and quintic motion ramp down over RAMP)."""
        if self.mode in ("cyclic", "quintic"):
            self.mode = "stopping"
            self._cyclic = (t, 0.0, self.ubar)
        elif self.mode == "goal":
            self.go_to(self.sigma + self.ubar / self.follower.k)

    def step(self, t: float, dt: float) -> None:
        """Advance from t to t + dt."""
        f = self.follower
        if self.mode == "goal":
            if f.step(self.goal, dt, tol=self.TOL):
                self.mode = "hold"
        elif self.mode == "quintic":
            t0, s0, total, T = self._quintic
            s, ds, _ = quintic((t + dt - t0) / T)
            f.x, f.v = s0 + total * s, total * ds / T
            if t + dt >= t0 + T:
                self.hold()
        elif self.mode in ("cyclic", "stopping"):
            t0, level, u0 = self._cyclic
            s, _, _ = quintic((t + dt - t0) / self.RAMP)
            u_next = u0 + (level - u0) * s
            f.x += 0.5 * (f.v + u_next) * dt
            f.v = u_next
            if self.mode == "stopping" and t + dt >= t0 + self.RAMP:
                self.hold()


class PathFollower:
    """theta_ref on the reactionless path: d theta / d sigma = n(theta) (Eq. 27).

    The path is integrated by RK4 from knot to knot (steps of at most STEP rad in joint space, n known at each
    knot); between two knots theta(sigma) is the cubic Hermite curve through their theta and n, so a step of
    the simulation costs no n(theta) unless it passes a knot (a 1 ms step moves sigma a small fraction of a
    knot: n(theta), a crba and m + 1 determinants, had been taken four times every step). The curve meets the
    RK4 points and their n exactly; between them it is off by O(STEP^4). Every ``project_every`` knots the
    configuration is pulled back onto the level of the coupling potential it started on (Newton along H_bm),
    so rounding never walks it off the path.
    """

    STEP = 0.01  # rad: the largest joint-space move between two knots (one RK4 step)
    MAX_KNOT_SIGMA = 1.0  # 1/(kg m): the largest sigma between two knots, where n(theta) nearly vanishes (there the
    # joints barely move: |n| is 0.054 kg m on TREP, 0.020 on boom7 at their default configurations)
    END_STEP = 0.2  # 1/(kg m): the largest sigma of one RK4 step of :meth:`end_point`

    def __init__(self, model: FsmsModel, theta: np.ndarray, project_every: int = 4) -> None:
        self.model = model
        self.data = model.pin_model.createData()
        self.field = CouplingField(model)
        self.project_every = project_every
        self.reset(theta)

    def reset(self, theta: np.ndarray) -> None:
        self.theta = np.array(theta, dtype=float)
        self.level = self.field.potentials(self.theta[None])
        self._knots_made = 0
        self._last_rate = np.zeros_like(self.theta)
        self._sigma = 0.0  # 1/(kg m): sigma moved since the reset
        knot = (0.0, self.theta.copy(), self.n(self.theta))
        self._before, self._after = knot, knot  # the knots either side of sigma (sigma, theta, n)
        self._rate = knot[2]  # d theta / d sigma at theta

    def n(self, theta: np.ndarray) -> np.ndarray:
        """Null-space vector n(theta), kg m (unnormalised)."""
        return self.model.null_vector(theta, self.data)

    def _knot_from(
        self, knot: tuple[float, np.ndarray, np.ndarray], forward: bool
    ) -> tuple[float, np.ndarray, np.ndarray]:
        """The next knot from ``knot`` along the path (or back along it): one RK4 step of at most STEP rad."""
        sigma, theta, n = knot
        size = min(self.STEP / max(float(np.sqrt(n @ n)), 1e-300), self.MAX_KNOT_SIGMA)
        h = size if forward else -size
        th = along_path(self.model, theta, h, 1, self.data, n)
        self._knots_made += 1
        if self._knots_made % self.project_every == 0:
            th = self.field.project(th[None], self.level.copy(), newton_steps=2)[0]
        return sigma + h, th, self.n(th)

    def advance(self, dsigma: float) -> None:
        """Move theta by dsigma along the path: new knots where sigma leaves the two around it, then the Hermite
        curve between them."""
        if dsigma == 0.0:
            return
        self._sigma += dsigma
        while self._sigma > self._after[0]:
            self._before, self._after = self._after, self._knot_from(self._after, forward=True)
        while self._sigma < self._before[0]:
            self._before, self._after = self._knot_from(self._before, forward=False), self._before
        self.theta, self._rate = self._between(self._sigma)

    def _between(self, sigma: float) -> tuple[np.ndarray, np.ndarray]:
        """theta and d theta / d sigma at ``sigma`` on the cubic Hermite curve between the two knots."""
        (s0, th0, n0), (s1, th1, n1) = self._before, self._after
        h = s1 - s0
        if h == 0.0:
            return th0.copy(), n0
        s = (sigma - s0) / h
        s2, s3 = s * s, s * s * s
        theta = (2 * s3 - 3 * s2 + 1) * th0 + (s3 - 2 * s2 + s) * h * n0 + (3 * s2 - 2 * s3) * th1 + (s3 - s2) * h * n1
        rate = (6 * s2 - 6 * s) / h * (th0 - th1) + (3 * s2 - 4 * s + 1) * n0 + (3 * s2 - 2 * s) * n1
        return theta, rate

    def reference(self, ubar: float, dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """theta_ref, theta_ref' = (d theta / d sigma) u-bar (n(theta) at a knot, the curve's slope between: equal
        to 1e-9) and theta_ref'' (backward difference over dt)."""
        rate = self._rate * ubar if ubar else np.zeros_like(self.theta)
        acc = (rate - self._last_rate) / dt
        self._last_rate = rate
        return self.theta.copy(), rate, acc

    def end_point(self, dsigma: float) -> np.ndarray:
        """theta after moving dsigma along the path (RK4 steps of at most END_STEP, then back onto the level),
        without moving this reference."""
        steps = max(1, int(np.ceil(abs(dsigma) / self.END_STEP)))
        th = along_path(self.model, self.theta, dsigma, steps, self.data)
        return self.field.project(th[None], self.level.copy(), newton_steps=3)[0]


class ResolvedRate(SmoothedTarget):
    """Reactionless resolved-rate reference for a multi-dimensional RNS (the planar 3R).

    The operator's target is smoothed by a :class:`Follower` (speed ``v_max`` m/s), then
    theta_ref' = J-bar^+ (x_f' + k (x_f - x(theta_ref))), J-bar = J P_RNS at theta_ref, damped
    below ``threshold`` (m/rad). The smoothed target never runs more than ``leash`` ahead of the
    reference, so at a singular curve of J-bar (a fold of the reachable set) the reference stops
    there, slowly, instead of winding up and shaking the base; and it makes no move that takes
    sigma_min(J-bar) below ``stop_sigma``: it stops before the singular curve (``blocked``).
    |theta_ref'| is limited to ``joint_speed``: fast joint motion shows the discretisation of a
    1 kHz controller as base vibration.
    """

    # rad/s: the orientation is done once its joint rate falls below this. By least squares (fewer than three
    # rotations free) it creeps toward the best reachable orientation at ~3/s, not k: stopping here leaves
    # ~ 1e-3 / 3 rad (0.02 deg) and ends the motion about 1 s after the position arrived
    TURN_TOL = 1e-3

    def __init__(
        self,
        model: FsmsModel,
        theta: np.ndarray,
        v_max: float = 1.0,
        k: float = 10.0,
        threshold: float = 0.05,
        leash: float = 0.01,
        stop_sigma: float = 0.08,
        joint_speed: float = 1.0,
    ) -> None:
        self.rows = model.task_rows
        super().__init__(model, len(self.rows), v_max)
        self.data = model.pin_model.createData()
        self.k = k
        self.threshold = threshold
        self.leash = leash  # m: the smoothed target waits when it gets this far ahead of the reference
        self.stop_sigma = stop_sigma  # m/rad: no motion that lowers sigma_min(J-bar) below this
        self.joint_speed = joint_speed  # rad/s: |theta_ref'| at most
        # rotational DOF the RNS leaves beyond the position rows (spatial models): 0 to 3
        self.orient_dof = max(0, min(3, model.n - len(model.selected) - len(self.rows))) if len(self.rows) == 3 else 0
        # Track the goal orientation (secondary task) by default only where all of it can be held (r <= 1):
        # with fewer rotational DOF it is opt-in, so forces-only tracking stays the paper's Eq. (24).
        self.orienting = self.orient_dof == 3
        self.omega_max = 1.0  # rad/s: the orientation error's commanded rate at most
        self.goal_R = np.eye(3)  # goal orientation of the end effector, base frame
        self._still = np.zeros(model.n)  # rad/s, never written to
        self.theta_dot_o = self._still  # rad/s: the secondary (orientation) part of theta_ref'
        self.reset(theta)

    def reset(self, theta: np.ndarray, keep_goal: bool = False) -> None:
        super().reset(theta, keep_goal)
        if not keep_goal:
            self.goal_R = self.ee_rotation(self.theta)
        self._steps = 0
        self._next: np.ndarray | None = None

    def ee_rotation(self, theta: np.ndarray) -> np.ndarray:
        """The end effector's orientation in the base frame at ``theta``."""
        return self.model.ee_pose(theta, self.data)[1]

    def set_orientation(self, on: bool) -> None:
        """Track the goal orientation or not; switched on, the goal is the present orientation (no jump)."""
        if on and self.orient_dof == 0:
            raise ValueError("no RNS directions are left beyond the position: orientation cannot be tracked")
        self.orienting = bool(on)
        self.goal_R = self.ee_rotation(self.theta)

    def set_goal_rotation(self, R: np.ndarray) -> None:
        """The goal orientation (a rotation matrix, base frame); followed while :attr:`orienting`."""
        self.goal_R = np.array(R, dtype=float)
        if self.orienting:
            self.idle = False

    def _projector(self, theta: np.ndarray) -> np.ndarray:
        """P_RNS at theta, from S H_bm."""
        return rns_projector(self.model.coupling_at(theta, self.data))

    def _sigma_at(self, theta: np.ndarray) -> float:
        """The distance to singularity of J-bar at theta (m/rad)."""
        J = self.model.ee_frame_jacobian(theta, self.data).linear[self.rows]
        return self._inverse(J @ self._projector(theta)).sigma_min

    def _toward_fold(self, thetadot: np.ndarray) -> bool:
        """Close to a singular curve of J-bar (sigma_min below ``stop_sigma``) and ``thetadot`` goes closer."""
        return self.sigma_jbar < self.stop_sigma and self._sigma_at(self.theta + 0.05 * thetadot) < self.sigma_jbar

    def _inverse(self, J_bar: np.ndarray) -> DampedInverse:
        """J-bar^+, damped below ``threshold``. With fewer RNS directions than task rows (boom7, r = 5: a 2-D
        RNS, a 3-D target) J-bar has rank n - r at most: it is inverted on its range (the hand moves toward
        the target's projection on the reachable surface) and sigma_min is its (n - r)-th singular value."""
        return truncated_inverse(J_bar, self.model.n - len(self.model.selected), self.threshold)

    def orientation_rate(
        self, V: np.ndarray, P: np.ndarray, J_o: np.ndarray, R: np.ndarray, thetadot_p: np.ndarray
    ) -> np.ndarray:
        """The secondary task: N (J_o N)^+ (w - J_o theta_p'), N = P - V^T V = P - J-bar^+ J-bar (the RNS
        directions that leave the hand's position still; V: J-bar's right singular vectors of its nonzero
        singular values), w = k log3(R_d R^T) limited to ``omega_max``; least squares when N has fewer
        than 3 directions (``orient_dof``)."""
        N = P - V.T @ V
        w = self.k * pin.log3(self.goal_R @ R.T)
        w_norm = float(np.sqrt(w @ w))
        if w_norm > self.omega_max:
            w *= self.omega_max / w_norm
        return N @ (truncated_inverse(J_o @ N, self.orient_dof, self.threshold).inverse @ (w - J_o @ thetadot_p))

    def ee(self, theta: np.ndarray) -> np.ndarray:
        return self.model.ee_position(theta, self.data)[self.rows]

    def step(self, dt: float) -> None:
        """Commit the last integration step, then set (theta', x, x', x'') at the new theta_ref.

        Called once before each simulation step at time t: afterwards ``theta`` is theta_ref(t).
        """
        if self._next is not None:
            self.theta, self._next = self._next, None
            self._steps += 1
            if self._steps % 100 == 0:
                self.theta = self.field.project(self.theta[None], self.level.copy(), newton_steps=2)[0]
        if self.idle:
            return
        f = self.follower
        at_goal = f.step(self.goal, dt, tol=1e-6)
        frame = self.model.ee_frame_jacobian(self.theta, self.data)
        J, x = frame.linear[self.rows], frame.position[self.rows]
        gap = f.x - x
        gap_norm = float(np.sqrt(gap @ gap))
        if gap_norm > self.leash:  # the reference is held up (a singular curve of J-bar): wait for it
            f.x = x + gap * (self.leash / gap_norm)
            f.v = np.zeros_like(f.v)
            at_goal = False
        P = self._projector(self.theta)
        J_bar = J @ P
        rank = min(len(self.rows), self.model.n - len(self.model.selected))
        svd = np.linalg.svd(J_bar, full_matrices=False) if self.orienting else None  # one SVD for both tasks
        inverse = self._inverse(J_bar) if svd is None else svd_inverse(*svd, rank, self.threshold)
        self.sigma_jbar = inverse.sigma_min
        thetadot = P @ (inverse.inverse @ (f.v + self.k * (f.x - x)))
        speed = float(np.sqrt(thetadot @ thetadot))
        if speed > self.joint_speed:
            thetadot *= self.joint_speed / speed
        self.theta_dot_o = self._still
        if self.orienting:  # orthogonal to the primary part: it gets the joint speed the position leaves
            th_o = self.orientation_rate(svd[2][:rank], P, frame.angular, frame.rotation, thetadot)  # type: ignore[index]
            room = float(np.sqrt(max(0.0, self.joint_speed**2 - float(thetadot @ thetadot))))
            speed_o = float(np.sqrt(th_o @ th_o))
            self.theta_dot_o = th_o * (room / speed_o) if speed_o > room else th_o
            thetadot = thetadot + self.theta_dot_o
        if self.orienting and self._toward_fold(thetadot):  # the turn would lead into a fold: not from here
            thetadot, self.theta_dot_o = thetadot - self.theta_dot_o, self._still
        self.blocked = self._toward_fold(thetadot)
        if self.blocked:  # the way to the target crosses a singular curve of J-bar: stop before it
            thetadot = np.zeros_like(thetadot)
            self.theta_dot_o = self._still
            f.x, f.v = x.copy(), np.zeros_like(f.v)
            at_goal = False
        xdot = J @ thetadot
        self.xddot = (xdot - self.xdot) / dt
        self.x, self.xdot, self.thetadot = x, xdot, thetadot
        self._next = self.theta + thetadot * dt
        turning = self.orienting and float(np.sqrt(self.theta_dot_o @ self.theta_dot_o)) > self.TURN_TOL
        if at_goal and float(np.abs(f.x - x).max()) < 1e-6 and not turning:
            self.idle, self._next = True, None
            self.thetadot = np.zeros_like(thetadot)
            self.xdot = np.zeros_like(xdot)
            self.xddot = np.zeros_like(xdot)
