"""Dynamic redundancy in the live app (Sec. III-B): a task arm and a compensating arm on one base.

For a model with ``[arms]`` (trep2) the live session runs :class:`~rns_viz.control.compensation.CompensatingLaw`:

- the task arm follows the dragged target anywhere in its workspace (:class:`TaskTarget`, the smoothed
  target; :class:`TaskWorkspace` keeps it inside the arm's reach): ordinary resolved-acceleration tracking,
  no reactionless restriction;
- the compensating arm keeps the total coupling momentum S (H_bm,1 theta_1' + H_bm,2 theta_2') at zero,
  Eqs. (9)-(10), with (15)'s g_b acting through it alone;
- the shadow run does the same task with the compensator held still (``compensate=False``), so the
  plots show what compensation saves.

:func:`compensation_state` says when the compensator cannot cancel: near its own singularity
(sigma_min(W S H_bm,2) small) or when the task asks more of it than its joints' velocity limits.
"""

from __future__ import annotations

import numpy as np

from rns_viz.control import ControlOutput, Gains, TaskSample
from rns_viz.control.compensation import CompensatingLaw
from rns_viz.live.operator.smoothed_target import SmoothedTarget
from rns_viz.model import FsmsModel
from rns_viz.rns import singularity_distance

WORKSPACE_MARGIN = 0.03  # fraction of the task arm's reach kept clear of its outer and inner boundary
CANCEL_FLOOR = 1e-4  # kg m/s: below this task-arm momentum there is nothing to cancel
CANCEL_RATIO = 0.05  # a residual L above this fraction of the task arm's momentum: not cancelled


def is_dual(model: FsmsModel) -> bool:
    """The model has a task arm and a compensating arm (``[arms]`` of its parameter file)."""
    return "task" in model.arm_groups and "compensating" in model.arm_groups


def dual_law(model: FsmsModel, gains: Gains, suppress: bool, task: TaskSample | None, shadow: bool) -> CompensatingLaw:
    """The live law of a dual-arm model: the shadow's compensator is held where it is (not at theta_0)."""
    target = task if task is not None else TaskSample.held(model.ee_position(model.spec.default_configuration)[:2])
    law = CompensatingLaw(model, gains, target, compensate=True, suppress=suppress)
    if shadow:
        law.set_compensation(False)  # holds the compensator at its angles at the first step
    return law


def flip_compensation(operated: object, shadow: object) -> None:
    """A preset's shadow compensates when the operated run does not, and holds still when it does."""
    if isinstance(operated, CompensatingLaw) and isinstance(shadow, CompensatingLaw):
        shadow.set_compensation(not operated.compensate)


def rehold(law: object) -> None:
    """After the shadow was restarted from the operated state, its held compensator stays where it is now."""
    if isinstance(law, CompensatingLaw) and not law.compensate:
        law.set_compensation(True)
        law.set_compensation(False)


def operated_is_better(law: object, suppress: bool) -> bool:
    """Which plot series is the 'on' one: compensating (dual arms) or suppressing (one arm)."""
    return law.compensate if isinstance(law, CompensatingLaw) else suppress


class TaskWorkspace:
    """The task arm's reachable annulus about its first joint, base frame (planar x, y), m."""

    def __init__(self, model: FsmsModel) -> None:
        data = model.pin_model.createData()  # not the model's own: the loop's laws use that
        xy = model.branch_points(model.spec.default_configuration, "task", data)[:, :2]
        lengths = np.linalg.norm(np.diff(xy, axis=0), axis=1)
        self.center = xy[0]
        reach = float(lengths.sum())
        margin = WORKSPACE_MARGIN * reach
        self.outer = reach - margin
        self.inner = max(0.0, 2.0 * float(lengths.max()) - reach) + margin

    def clamp(self, point: np.ndarray) -> tuple[np.ndarray, bool]:
        """The nearest point of the annulus, and whether ``point`` had to be moved."""
        xy = np.asarray(point, dtype=float)[:2]
        d = xy - self.center
        r = float(np.hypot(*d))
        if self.inner <= r <= self.outer:
            return xy.copy(), False
        direction = d / r if r > 1e-12 else np.array([1.0, 0.0])
        return self.center + float(np.clip(r, self.inner, self.outer)) * direction, True


class TaskTarget(SmoothedTarget):
    """The task arm's reference for the operator: the dragged target smoothed by a :class:`Follower`
    (speed ``v_max`` m/s), with its rates x_d', x_d'' for resolved-acceleration tracking.

    It stands where the operator's multi-dimensional reference (``ResolvedRate``) stands, so the
    operator drives it the same way; the joint reference it hands out is the held configuration
    (the compensating law follows the task sample only).
    """

    def __init__(self, model: FsmsModel, theta: np.ndarray, v_max: float = 0.1) -> None:
        super().__init__(model, 2, v_max)
        self.workspace = TaskWorkspace(model)
        self.reset(theta)

    def ee(self, theta: np.ndarray) -> np.ndarray:
        return self.model.ee_position(theta)[:2]

    def step(self, dt: float) -> None:
        """x_d(t), x_d'(t), x_d''(t) for the step at t (called once before it)."""
        if self.idle:
            return
        f = self.follower
        v_before = f.v.copy()
        at_goal = f.step(self.goal, dt, tol=1e-7)
        self.x, self.xdot, self.xddot = f.x.copy(), f.v.copy(), (f.v - v_before) / dt
        if at_goal:
            self.idle = True
            self.xdot, self.xddot = np.zeros(2), np.zeros(2)


def compensator_sigmas(model: FsmsModel, theta: np.ndarray) -> tuple[np.ndarray, float, float, int]:
    """S H_bm, the compensator's distance to singularity sigma_min(W S H_bm,2) (kg m, rns.singularity_distance),
    sigma_min(J_1) of the task arm, the RNS dimension."""
    H = model.coupling_at(theta)
    comp, task = model.arm_groups["compensating"].index, model.arm_groups["task"].index
    J1 = model.ee_jacobian(theta)[:, task]
    sigma_2 = float(singularity_distance(H[:, comp], model.coupling_weights))
    return H, sigma_2, float(np.linalg.svd(J1, compute_uv=False)[-1]), model.n - H.shape[0]


def compensation_state(model: FsmsModel, out: ControlOutput | None, v: np.ndarray, warn_sigma: float) -> str | None:
    """Why the compensator cannot cancel the task arm's reaction now, or None when it does.

    Near its singularity: sigma_min(W S H_bm,2) below ``warn_sigma`` (kg m), where the damped inverse of
    (9)-(10) gives up cancelling. Lagging: the residual coupling momentum exceeds CANCEL_RATIO of the
    task arm's. Beyond its speed: a compensator joint faster than its URDF velocity limit (rad/s).
    """
    if out is None:
        return None
    if out.sigma_hbm < warn_sigma:
        return f"compensator near its singularity (σ_min(W S H_bm,2) = {out.sigma_hbm:.2g} kg·m): it cannot cancel"
    L_task = float(out.extra.get("L_task", 0.0)) if out.extra else 0.0
    residual = float(np.linalg.norm(out.coupling_momentum))
    if L_task > CANCEL_FLOOR and residual > CANCEL_RATIO * L_task:
        return f"compensator lags the task arm: {100 * residual / L_task:.0f} % of its reaction remains"
    joints = model.m + model.arm_groups["compensating"].index
    over = np.abs(v[joints]) - model.pin_model.velocityLimit[joints]  # rad/s beyond the URDF's limits
    if float(np.max(over)) > 0.0:
        k = int(np.argmax(over))
        rate, limit = abs(float(v[joints[k]])), float(model.pin_model.velocityLimit[joints[k]])
        return f"compensator beyond its speed: {rate:.1f} rad/s > its {limit:g} rad/s limit"
    return None
