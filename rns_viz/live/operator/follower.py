"""Smooth goal following for operator inputs (drags, sliders): bounded speed and acceleration."""

from __future__ import annotations

import math

import numpy as np


class ScalarFollower:
    """A number that moves toward a goal: v -> k (goal - x), |v| <= v_max, |v'| <= a_max = 1.5 k v_max.

    With a_max >= k v_max the approach is a first-order lag near the goal (no overshoot); far from it
    the value cruises at v_max. Plain floats: this runs at every control step.
    """

    def __init__(self, x: float, v_max: float, k: float = 5.0) -> None:
        self.x = float(x)
        self.v = 0.0
        self.k = k
        self.v_max = v_max

    def reset(self, x: float) -> None:
        self.x, self.v = float(x), 0.0

    def step(self, goal: float, dt: float, tol: float = 0.0) -> bool:
        """Advance by dt toward ``goal``; snaps to it once within ``tol`` and slow. True when at rest there."""
        v_des = min(max(self.k * (goal - self.x), -self.v_max), self.v_max)
        limit = 1.5 * self.k * self.v_max * dt
        v_new = self.v + min(max(v_des - self.v, -limit), limit)
        self.x += 0.5 * (self.v + v_new) * dt
        self.v = v_new
        if abs(goal - self.x) <= tol and abs(self.v) <= self.k * tol:
            self.x, self.v = goal, 0.0
            return True
        return False


class Follower:
    """The vector version of :class:`ScalarFollower`: speed and acceleration (k v_max) bounded in norm."""

    def __init__(self, x: np.ndarray, v_max: float, k: float = 4.0) -> None:
        self.x = np.array(x, dtype=float)
        self.v = np.zeros_like(self.x)
        self.k = k
        self.v_max = v_max

    def reset(self, x: np.ndarray) -> None:
        self.x = np.array(x, dtype=float)
        self.v = np.zeros_like(self.x)

    def step(self, goal: np.ndarray, dt: float, tol: float = 0.0) -> bool:
        """Advance by dt toward ``goal``; snaps to it once within ``tol`` and slow. True when at rest there."""
        e = goal - self.x
        v_des = self.k * e
        speed = math.sqrt(float(v_des @ v_des))
        if speed > self.v_max:
            v_des *= self.v_max / speed
        dv = v_des - self.v
        change = math.sqrt(float(dv @ dv))
        limit = self.k * self.v_max * dt
        if change > limit:
            dv *= limit / change
        v_new = self.v + dv
        self.x = self.x + 0.5 * (self.v + v_new) * dt
        self.v = v_new
        if float(np.max(np.abs(goal - self.x))) <= tol and float(np.max(np.abs(self.v))) <= self.k * tol:
            self.x = np.array(goal, dtype=float)
            self.v = np.zeros_like(self.x)
            return True
        return False
