"""The divergence guard: physical bounds on the live state, checked every few steps by the loop.

A state outside them (base coordinate beyond its URDF joint limit, a joint faster than
:data:`MAX_JOINT_SPEED`, any non-finite number) means the simulation has left physics, e.g. an
unstable gain: the session pauses and tells everyone why. Kept out of the simulator's hot path.
"""

from __future__ import annotations

import numpy as np

from rns_viz.model import FsmsModel

GUARD_EVERY = 10  # steps between checks (10 ms)
MAX_JOINT_SPEED = 100.0  # rad/s: no arm joint of these robots moves anywhere near this
MAX_BASE_SPEED = 100.0  # m/s or rad/s of a base coordinate


class Bounds:
    """The bounds of one model, read once from its URDF (the base joints' position limits)."""

    def __init__(self, model: FsmsModel) -> None:
        m = model.m
        self.m = m
        self.lower = np.asarray(model.pin_model.lowerPositionLimit[:m], dtype=float).copy()
        self.upper = np.asarray(model.pin_model.upperPositionLimit[:m], dtype=float).copy()

    def violation(self, q: np.ndarray, v: np.ndarray) -> str | None:
        """Why (q, v) is outside physical bounds, or None if it is inside."""
        if not (np.all(np.isfinite(q)) and np.all(np.isfinite(v))):
            return "the state is no longer finite"
        m = self.m
        xb = q[:m]
        outside = (xb < self.lower) | (xb > self.upper)
        if np.any(outside):
            i = int(np.argmax(outside))
            return f"base coordinate {i + 1} = {xb[i]:.4g} left its joint limits [{self.lower[i]:g}, {self.upper[i]:g}]"
        base_speed = float(np.max(np.abs(v[:m])))
        if base_speed > MAX_BASE_SPEED:
            return f"the base moves at {base_speed:.3g} (limit {MAX_BASE_SPEED:g})"
        joint_speed = float(np.max(np.abs(v[m:]))) if len(v) > m else 0.0
        if joint_speed > MAX_JOINT_SPEED:
            return f"a joint turns at {joint_speed:.3g} rad/s (limit {MAX_JOINT_SPEED:g})"
        return None
