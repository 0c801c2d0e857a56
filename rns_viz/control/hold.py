"""Comparison laws: joints held (no vibration suppression) and a switch between two laws at a time."""

from __future__ import annotations

import numpy as np

from rns_viz.control.common import ControlLaw, ControlOutput, CouplingEvaluator, Gains, realize_acceleration
from rns_viz.control.reference import JointReference
from rns_viz.model import FsmsModel


class JointServo:
    """Stiff joint-space servo: theta'' = theta_r'' + k_d (theta_r' - theta') + k_p (theta_r - theta).

    With a fixed reference this is "joints held": the arm does nothing about the base.
    """

    def __init__(self, model: FsmsModel, gains: Gains, reference: JointReference) -> None:
        self.model = model
        self.gains = gains
        self.reference = reference
        self.coupling = CouplingEvaluator(model)

    def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> ControlOutput:
        cp = self.coupling(q, v)
        theta_r, thetadot_r, thetaddot_r = self.reference(t)
        g = self.gains
        thetaddot = thetaddot_r + g.k_d * (thetadot_r - cp.thetadot) + g.k_p * (theta_r - cp.theta)
        return ControlOutput(
            tau=realize_acceleration(self.model, cp, q, v, thetaddot),
            coupling_momentum=cp.H_bm @ cp.thetadot,
            sigma_hbm=cp.sigma,
            theta_ref=theta_r,
        )


class Switched:
    """``before`` until ``at`` seconds, ``after`` from then on (Fig. 3: suppression on at t = 3 s)."""

    def __init__(self, before: ControlLaw, after: ControlLaw, at: float) -> None:
        self.before, self.after, self.at = before, after, at

    def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> ControlOutput:
        return (self.after if t >= self.at else self.before)(t, q, v)
