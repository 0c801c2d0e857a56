"""Acceleration-based composite law, Eqs. (12)/(15), realised by resolved acceleration (Fig. 1).

theta'' = H_bm^+ (H_b G_b x_b' - H_bm' theta') - G_m (E - P_RNS) theta' + P_RNS u

The paper's -G_m theta' is split: its part outside the RNS stays here (it is what the base sees:
S H_bm (-G_m theta') = -G_m L), its RNS part -G_m P theta' is the default null-space input
(:class:`DampNullMotion`), so other inputs (tracking, path motion) are not fought by damping.
"""

from __future__ import annotations

import math
import operator

import numpy as np

from rns_viz.control.common import ControlOutput, Coupling, range_acceleration, realize_acceleration
from rns_viz.control.composite import CompositeLaw
from rns_viz.control.null_input import DampNullMotion, NullOutput
from rns_viz.rns import damping_squared


class AccelerationLaw(CompositeLaw):
    """Eq. (15); ``suppress=False`` drops the G_b term (the reactionless part remains)."""

    kind = "acceleration"

    def acceleration(self, t: float, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, Coupling, NullOutput]:
        """theta'' of Eq. (15), with the coupling and null-space input it used.

        -G_m (E - P) theta' = -G_m H_bm^+ L is part of :func:`range_acceleration`.
        """
        cp = self.coupling(q, v)
        null = self.null_input(t, cp, q, v)
        return range_acceleration(cp, self.suppression_gain(t), self.gains.g_m) + null.Pu, cp, null

    def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> ControlOutput:
        if self.model.m == 1 and type(self.null_input) is DampNullMotion:
            return self._one_dof_base(t, q, v)
        thetaddot, cp, null = self.acceleration(t, q, v)
        return ControlOutput(
            tau=realize_acceleration(self.model, cp, q, v, thetaddot),
            coupling_momentum=cp.coupling_momentum,
            sigma_hbm=cp.sigma,
            sigma_jbar=null.sigma_jbar,
            theta_ref=null.theta_ref,
            ee_ref=null.ee_ref,
        )

    def _one_dof_base(self, t: float, q: np.ndarray, v: np.ndarray) -> ControlOutput:
        """:meth:`__call__` for a 1-DOF base (TREP, the 3R) and the default null input, in plain numbers.

        With u = -G_u theta' (Fig. 3), P u = -G_u theta' + G_u h^+ L, so Eq. (15) reads
            theta'' = h^+ (H_b g_b x_b' - h' theta' - (g_m - G_u) L) - G_u theta',  h^+ = h / (|h|^2 + lambda^2)
        for the coupling row h = H_bm and L = h theta' (Eq. 8), and resolved acceleration (Fig. 1) gives
            x_b'' = (-k x_b - d x_b' - c_b - h theta'') / H_b,  tau = h^T x_b'' + H_m theta'' + c_m + D_m theta'.
        Python floats instead of numpy arrays: for a few joints each numpy call costs more than its
        arithmetic. M, c and H_bm' theta' still come from pinocchio (model.dynamics).
        """
        model, coupling = self.model, self.coupling
        M, c, hbm_dot = model.dynamics(q, v)
        (H_b, *h), *arm_rows = M.tolist()
        c_b, *c_m = c.tolist()
        xdot_b, *thetadot = v.tolist()
        sigma2 = _dot(h, h)
        sigma = math.sqrt(sigma2)
        lam2 = damping_squared(sigma, coupling.threshold, coupling.max_damping)
        L = _dot(h, thetadot)
        g_u = self.null_input.g_m
        y = self.suppression_gain(t) * H_b * xdot_b - hbm_dot.item(0) - (self.gains.g_m - g_u) * L
        alpha = y / (sigma2 + lam2)
        thetaddot = [alpha * h_i - g_u * w_i for h_i, w_i in zip(h, thetadot, strict=True)]
        spring = -model.K_b.item(0) * q.item(0) - model.D_b.item(0) * xdot_b
        xddot_b = (spring - c_b - _dot(h, thetaddot)) / H_b
        tau = np.array(
            [h_i * xddot_b + _dot(row[1:], thetaddot) + c_i for h_i, row, c_i in zip(h, arm_rows, c_m, strict=True)]
        )
        if model.has_joint_damping:
            tau += model.D_m @ v[1:]
        return ControlOutput(tau=tau, coupling_momentum=np.array([L]), sigma_hbm=sigma)


def _dot(a: list[float], b: list[float]) -> float:
    return sum(map(operator.mul, a, b))
