"""Acceleration-based composite law, Eqs. (12)/(15), realised by resolved acceleration (Fig. 1).

theta'' = H_bm^+ (H_b G_b x_b' - H_bm' theta') - G_m (E - P_RNS) theta' + P_RNS u

The paper's -G_m theta' is split: its part outside the RNS stays here (it is what the base sees:
S H_bm (-G_m theta') = -G_m L), its RNS part -G_m P theta' is the default null-space input
(:class:`DampNullMotion`), so other inputs (tracking, path motion) are not fought by damping.
"""

from __future__ import annotations

import numpy as np

from rns_viz.control.common import (
    ControlOutput,
    Coupling,
    CouplingEvaluator,
    Gains,
    range_acceleration,
    realize_acceleration,
)
from rns_viz.control.null_input import DampNullMotion, NullInput, NullOutput
from rns_viz.model import FsmsModel


class AccelerationLaw:
    """Eq. (15); ``suppress=False`` drops the G_b term (the reactionless part remains)."""

    def __init__(
        self,
        model: FsmsModel,
        gains: Gains,
        null_input: NullInput | None = None,
        suppress: bool = True,
        suppress_after: float = float("-inf"),
    ) -> None:
        self.model = model
        self.gains = gains
        self.null_input = null_input or DampNullMotion(gains.g_m)
        self.suppress = suppress
        self.suppress_after = suppress_after  # s: suppression starts here (Fig. 3)
        self.coupling = CouplingEvaluator(model)

    def acceleration(self, t: float, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, Coupling, NullOutput]:
        """theta'' of Eq. (15), with the coupling and null-space input it used."""
        cp = self.coupling(q, v)
        g_b = self.gains.g_b if self.suppress and t >= self.suppress_after else 0.0
        null = self._null_input(t, cp, q, v)
        return range_acceleration(cp, g_b, self.gains.g_m) + null.Pu, cp, null

    def _null_input(self, t: float, cp: Coupling, q: np.ndarray, v: np.ndarray) -> NullOutput:
        if type(self.null_input) is DampNullMotion:  # the default: P u = -G_m P theta', without forming P
            return NullOutput(cp.project(cp.thetadot) * -self.null_input.g_m)
        return self.null_input(t, cp, q, v)

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
