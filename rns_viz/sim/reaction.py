"""The force the arm exerts on its base at one simulation step: F = −(H_bm θ'' + c_b), Eq. (1).

θ'' is the plant's own forward dynamics (pinocchio's ABA through :class:`rns_viz.sim.Plant`) at the
step's start state with the step's torque and base force held, the first RK4 stage of that step;
H_bm and c_b are the model's (:meth:`FsmsModel.dynamics`). Units: N (or N m for a rotational base
coordinate), one entry per base coordinate.
"""

from __future__ import annotations

import numpy as np

from rns_viz.model import FsmsModel
from rns_viz.sim.plant import Plant


class ReactionProbe:
    """Evaluates the arm's reaction on the base of one model (own pinocchio data via its own Plant)."""

    def __init__(self, model: FsmsModel) -> None:
        self.model = model
        self.plant = Plant(model)

    def force(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, f_ext: np.ndarray | None) -> np.ndarray:
        """−(H_bm θ'' + c_b) at (q, v) with joint torques ``tau`` (N m) and base force ``f_ext`` (N)."""
        m = self.model.m
        a = self.plant.acceleration(q, v, tau, f_ext)  # (x_b'', θ''), the step's dynamics
        M, c, _ = self.model.dynamics(q, v)
        return -(M[:m, m:] @ a[m:] + c[:m])
