"""Comparison laws: joints held (no vibration suppression) and a switch between two laws at a time."""

from __future__ import annotations

import numpy as np

from rns_viz.control.common import ControlLaw, ControlOutput, CouplingEvaluator, Gains, LawKind, realize_acceleration
from rns_viz.control.reference import JointReference, JointSample, ReferenceSample
from rns_viz.model import FsmsModel


class JointServo:
    """Stiff joint-space servo: theta'' = theta_r'' + k_d (theta_r' - theta') + k_p (theta_r - theta).

    With a fixed reference this is "joints held": the arm does nothing about the base. It is never
    sampled (:meth:`sampled`): evaluated at every RK4 stage, the computed torque keeps theta'' at the
    servo's value whatever the base does, so a held arm is rigid and the base rings as the structure.
    """

    kind = "servo"
    suppress = False  # nothing to switch: the servo ignores the base

    def __init__(self, model: FsmsModel, gains: Gains, reference: JointReference) -> None:
        self.model = model
        self.gains = gains
        self.reference = reference
        self.coupling = CouplingEvaluator(model)

    def retune(self, gains: Gains) -> None:
        self.gains = gains

    def set_suppression(self, on: bool) -> None:
        """No g_b term to switch: the servo stays a comparison without suppression."""

    def sampled(self, t: float) -> bool:
        """Never: a joint servo acts on the measured state at every stage (see the protocol)."""
        return False

    def follow(self, sample: ReferenceSample) -> None:
        if not isinstance(sample, JointSample):
            raise TypeError(f"the joint servo follows a joint reference, not a {type(sample).__name__}")
        self.reference = sample

    def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> ControlOutput:
        cp = self.coupling(q, v)
        theta_r, thetadot_r, thetaddot_r = self.reference(t)
        g = self.gains
        thetaddot = thetaddot_r + g.k_d * (thetadot_r - cp.thetadot) + g.k_p * (theta_r - cp.theta)
        return ControlOutput(
            tau=realize_acceleration(self.model, cp, q, v, thetaddot),
            coupling_momentum=cp.coupling_momentum,
            sigma_hbm=cp.sigma,
            theta_ref=theta_r,
        )


class Switched:
    """``before`` until ``at`` seconds, ``after`` from then on (Fig. 3: suppression on at t = 3 s)."""

    def __init__(self, before: ControlLaw, after: ControlLaw, at: float) -> None:
        self.before, self.after, self.at = before, after, at

    # A switch counts as the law it switches to.
    @property
    def kind(self) -> LawKind:
        return self.after.kind

    @property
    def gains(self) -> Gains:
        return self.after.gains

    @property
    def suppress(self) -> bool:
        return self.after.suppress

    def retune(self, gains: Gains) -> None:
        self.before.retune(gains)
        self.after.retune(gains)

    def set_suppression(self, on: bool) -> None:
        self.after.set_suppression(on)

    def sampled(self, t: float) -> bool:
        return (self.after if t >= self.at else self.before).sampled(t)

    def follow(self, sample: ReferenceSample) -> None:
        self.before.follow(sample)
        self.after.follow(sample)

    def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> ControlOutput:
        return (self.after if t >= self.at else self.before)(t, q, v)
