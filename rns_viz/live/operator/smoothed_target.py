"""The operator's target smoothed by a :class:`~rns_viz.live.operator.follower.Follower`: the state shared by the
planar 3R's reactionless resolved-rate reference (:class:`~rns_viz.live.operator.moving_references.ResolvedRate`) and
trep2's task-arm target (:class:`~rns_viz.live.operator.dual_arm.TaskTarget`), reset in one place.
"""

from __future__ import annotations

import math

import numpy as np

from rns_viz.live.operator.follower import Follower
from rns_viz.model import FsmsModel
from rns_viz.paths import CouplingField


class SmoothedTarget:
    """theta (the joint reference), the goal and its smoothed x_d, x_d', x_d'' (``dims`` task coordinates, m).

    Subclasses give the task coordinates of a configuration (:meth:`ee`) and the step.
    """

    def __init__(self, model: FsmsModel, dims: int, v_max: float) -> None:
        self.model = model
        self.field = CouplingField(model)
        self.follower = Follower(np.zeros(dims), v_max)
        self.blocked = False

    def ee(self, theta: np.ndarray) -> np.ndarray:
        """The task coordinates of the end effector at ``theta`` (m)."""
        raise NotImplementedError

    def step(self, dt: float) -> None:
        """Move the smoothed target (and theta) on by ``dt`` s; sets ``idle`` once at the goal."""
        raise NotImplementedError

    def reset(self, theta: np.ndarray, keep_goal: bool = False) -> None:
        """Stand still at ``theta``: the smoothed target on the end effector, at rest; the goal kept if asked
        (then the target moves on towards it)."""
        self.theta = np.array(theta, dtype=float)
        self.level = self.field.potentials(self.theta[None])
        x = self.ee(self.theta)
        self.follower.reset(x)
        if not keep_goal:
            self.goal = x.copy()
        self.thetadot = np.zeros_like(self.theta)
        self.x, self.xdot, self.xddot = x, np.zeros_like(x), np.zeros_like(x)
        self.sigma_jbar = math.nan
        self.idle = not keep_goal

    def set_goal(self, goal: np.ndarray) -> None:
        self.goal = np.array(goal, dtype=float)[: self.follower.x.size]
        self.idle = False
