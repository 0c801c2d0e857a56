"""Velocity-command law for TREP, Eq. (30), behind a joint velocity servo.

theta'_cmd = H_bm^+ H_b g_b x_b + g_m (theta_ref - theta)       [+ theta_ref' if feedforward]

Read with the base deflection x_b, not its rate: (30) is (29) integrated once in time with
H_bm^+ held constant, and the integral of (29)'s term H_bm^+ m_b g_b x_b' is H_bm^+ m_b g_b x_b.
Printed with x_b', the term would have units of rad/s^2 in a velocity command; with x_b it has
rad/s, and damps. m_b is H_b, the base inertia of Eq. (1). theta_ref is the path
integral of n u-bar (PathReference), a fixed configuration, or any joint reference.

The servo: the motor drivers of TREP take velocity commands; we model them as a velocity loop
of bandwidth w_s, theta'' = w_s (theta'_cmd - theta'), realised by resolved acceleration.
"""

from __future__ import annotations

import numpy as np

from rns_viz.control.common import ControlOutput, Coupling, CouplingEvaluator, Gains, realize_acceleration
from rns_viz.control.reference import JointReference, JointSample, ReferenceSample
from rns_viz.model import FsmsModel


class VelocityLaw:
    """Eq. (30); ``suppress=False`` sets the g_b term to zero: the joints just hold/track theta_ref."""

    kind = "velocity"

    def __init__(
        self,
        model: FsmsModel,
        gains: Gains,
        reference: JointReference,
        suppress: bool = True,
        feedforward: bool = False,
        suppress_after: float = float("-inf"),
    ) -> None:
        self.model = model
        self.gains = gains
        self.reference = reference
        self.suppress = suppress
        self.suppress_after = suppress_after  # s: suppression starts here (Fig. 3)
        self.feedforward = feedforward
        self.coupling = CouplingEvaluator(model)

    def suppression_gain(self, t: float) -> float:
        """g_b in force at time t, 1/s (0 before ``suppress_after`` or without suppression)."""
        return self.gains.g_b if self.suppress and t >= self.suppress_after else 0.0

    def sampled(self, t: float) -> bool:
        """A digital controller while g_b is in force; without it the servo holds or tracks theta_ref
        (see ControlLaw.sampled)."""
        return self.suppression_gain(t) != 0.0

    def retune(self, gains: Gains) -> None:
        self.gains = gains

    def set_suppression(self, on: bool) -> None:
        self.suppress = on

    def follow(self, sample: ReferenceSample) -> None:
        if not isinstance(sample, JointSample):
            raise TypeError(f"the velocity law (30) follows a joint reference, not a {type(sample).__name__}")
        self.reference = sample

    def command(self, t: float, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray, Coupling]:
        """theta'_cmd of Eq. (30), theta_ref and the coupling it used."""
        cp = self.coupling(q, v)
        theta_r, thetadot_r, _ = self.reference(t)
        g_b = self.suppression_gain(t)
        # S H_b g_b x_b with every base coordinate (S on rows only, as in (15))
        cmd = cp.H_bm_pinv @ (g_b * (cp.H_b_rows @ q[: self.model.m])) + self.gains.g_m * (theta_r - cp.theta)
        if self.feedforward:
            cmd = cmd + thetadot_r
        return cmd, theta_r, cp

    def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> ControlOutput:
        cmd, theta_r, cp = self.command(t, q, v)
        thetaddot = self.gains.servo_bandwidth * (cmd - cp.thetadot)
        tau = realize_acceleration(self.model, cp, q, v, thetaddot)
        return ControlOutput(
            tau=tau,
            coupling_momentum=cp.coupling_momentum,
            sigma_hbm=cp.sigma,
            theta_ref=theta_r,
            extra={f"thetadot_cmd_{i + 1}": float(c) for i, c in enumerate(cmd)},
        )
