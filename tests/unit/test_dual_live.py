"""trep2's compensation state on its own: each reason the compensating arm cannot cancel the reaction
(near its singularity, lagging, beyond its joints' speed) named as such."""

from __future__ import annotations

import numpy as np

from rns_viz.control import ControlOutput
from rns_viz.live.operator.dual_arm import compensation_state
from rns_viz.model import FsmsModel


def test_compensation_state_names_each_cause(trep2: FsmsModel) -> None:
    """Cancelling, near the singularity, lagging (residual L above 5 % of the task arm's), beyond the URDF's
    velocity limit of a compensator joint: each reported as such."""
    comp = trep2.m + trep2.arm_groups["compensating"].index
    limit = trep2.pin_model.velocityLimit[comp]

    def state(residual: float, sigma: float, comp_rate: float) -> str | None:
        out = ControlOutput(np.zeros(trep2.n), np.array([residual]), sigma, extra={"L_task": 0.01})
        v = np.zeros(trep2.nv)
        v[comp[0]] = comp_rate
        return compensation_state(trep2, out, v, warn_sigma=0.005)

    assert state(1e-6, 0.04, 1.0) is None
    assert "singularity" in (state(1e-6, 0.004, 1.0) or "")
    assert "lags" in (state(1e-3, 0.04, 1.0) or "")
    assert "beyond its speed" in (state(1e-6, 0.04, 1.01 * limit[0]) or "")
    assert state(1e-6, 0.04, 0.99 * limit[0]) is None
