"""Acceleration-based composite law, Eqs. (12)/(15), realised by resolved acceleration (Fig. 1).

theta'' = H_bm^+ (H_b G_b x_b' - H_bm' theta') - G_m (E - P_RNS) theta' + P_RNS u

The paper's -G_m theta' is split: its part outside the RNS stays here (it is what the base sees:
S H_bm (-G_m theta') = -G_m L), its RNS part -G_m P theta' is the default null-space input
(:class:`DampNullMotion`), so other inputs (tracking, path motion) are not fought by damping.
"""

from __future__ import annotations

import operator

import numpy as np

from rns_viz.control.common import ControlOutput, Coupling, realize_acceleration
from rns_viz.control.composite import CompositeLaw
from rns_viz.control.null_input import NullOutput


def composite_acceleration(cp: Coupling, g_b: float, g_m: float, null: NullOutput) -> np.ndarray:
    """theta'' of Eq. (15) with G_b = g_b E, G_m = g_m E and the null-space input ``null``:

        theta'' = H_bm^+ (H_b G_b x_b' - H_bm' theta' - G_m L) + P_RNS u.

    -G_m L is the law's -G_m (E - P) theta', because (E - P) theta' = H_bm^+ H_bm theta' = H_bm^+ L
    (Eqs. 8, 9), also with the damped inverse.
    """
    if cp.row is not None:  # a 1-DOF base: its one row in Python floats
        return _one_coupling_row(cp, g_b, g_m, null)
    return _any_coupling_rows(cp, g_b, g_m, null)


def base_rows_demand(cp: Coupling, g_b: float, g_m: float, *, in_floats: bool = False) -> np.ndarray | float:
    """y of Eq. (15), theta'' = H_bm^+ y + P_RNS u: the S H_bm theta'' it demands, with S on the rows of H_b,

        y = g_b S H_b x_b' - S H_bm' theta' - g_m L,   L = S H_bm theta' (Eq. 8),

    so that d(S L)/dt = S H_bm' theta' + S H_bm theta'' = g_b S H_b x_b' - g_m S L, and with Eq. (1)'s base
    rows S [H_b (x_b'' + G_b x_b') + D_b x_b' + K_b x_b] = 0 (Eq. 13). S H_b x_b' (:attr:`Coupling.base_momentum`)
    takes every base velocity: S H_b S^T S x_b' would drop what the free coordinates' motion couples into the
    selected rows (documentation: models, boom7 in the app). An (r,) array; ``in_floats`` with a 1-DOF base's
    row in Python floats at hand (``cp.row``, per step): y as one float from them.
    """
    row = cp.row
    if in_floats and row is not None:
        return g_b * row.H_b * row.xdot_b - row.hbm_dot_thetadot - g_m * row.L
    return g_b * cp.base_momentum - cp.hbm_dot_thetadot - g_m * cp.coupling_momentum


def _any_coupling_rows(cp: Coupling, g_b: float, g_m: float, null: NullOutput) -> np.ndarray:
    """Eq. (15) for any number of coupling rows, as written above (:func:`base_rows_demand`)."""
    return cp.H_bm_pinv @ base_rows_demand(cp, g_b, g_m) + null.in_rns(cp)


def _one_coupling_row(cp: Coupling, g_b: float, g_m: float, null: NullOutput) -> np.ndarray:
    """Eq. (15) for the coupling row h of a 1-DOF base (S H_b x_b' = H_b x_b'), in the Python floats of
    ``cp.row`` (cheaper than numpy calls here).

    The damped h^+ is h^T s, s = 1 / (|h|^2 + lambda^2), and the input's P (u - g_u theta')
    = u - g_u theta' - h^+ (h u - g_u L) joins the factor of h^+:
        theta'' = h^T s (g_b H_b x_b' - h' theta' - (g_m - g_u) L - h u) + u - g_u theta'.
    """
    row = cp.row
    g_u = null.damping
    y = base_rows_demand(cp, g_b, g_m - g_u, in_floats=True)
    h, thetadot = row.h, row.thetadot
    if null.u is None:
        alpha = y * cp.inverse.row_scale
        thetaddot = np.array([alpha * h_i - g_u * w for h_i, w in zip(h, thetadot, strict=True)])
    else:
        u = null.u.tolist()
        alpha = (y - sum(map(operator.mul, h, u))) * cp.inverse.row_scale
        thetaddot = np.array([alpha * h_i - g_u * w + u_i for h_i, w, u_i in zip(h, thetadot, u, strict=True)])
    return thetaddot if null.Pu is None else thetaddot + null.Pu


class AccelerationLaw(CompositeLaw):
    """Eq. (15); ``suppress=False`` drops the G_b term (the reactionless part remains)."""

    kind = "acceleration"

    def acceleration(self, t: float, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, Coupling, NullOutput]:
        """theta'' of Eq. (15) (:func:`composite_acceleration`), with the coupling and null-space input it used."""
        cp = self.coupling(q, v)
        null = self.null_input(t, cp, q, v)
        return composite_acceleration(cp, self.suppression_gain(t), self.gains.g_m, null), cp, null

    def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> ControlOutput:
        thetaddot, cp, null = self.acceleration(t, q, v)
        return ControlOutput(
            tau=realize_acceleration(self.model, cp, q, v, thetaddot),
            coupling_momentum=cp.coupling_momentum,
            sigma_hbm=cp.sigma,
            sigma_jbar=null.sigma_jbar,
            theta_ref=null.theta_ref,
            ee_ref=null.ee_ref,
        )
