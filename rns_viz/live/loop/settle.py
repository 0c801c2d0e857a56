"""Where the arm came to rest: on another level of the coupling potential than its reference's?

After law (15) absorbed a kick, the arm rests on another reactionless path (1-D RNS) or in another
reachable set; the loop then re-anchors the operator's reference there and recomputes the geometry.
"""

from __future__ import annotations

import numpy as np

from rns_viz.control import LawKind
from rns_viz.live.operator.operator import Operator
from rns_viz.paths import CouplingField
from rns_viz.sim import Simulator

REST_SPEED = 1e-3  # rad/s (m/s): slower than this in every coordinate is at rest
REST_DEFLECTION = 1e-5  # of the arm's reach: a base this close to zero is at rest


def settled_elsewhere(
    sim: Simulator,
    op: Operator | None,
    law: LawKind,
    field: CouplingField,
    reach_m: float,
    tol: float,
    shown_level: np.ndarray | None,
) -> np.ndarray | None:
    """theta to re-anchor at when the run rests on another level than the reference's (or the shown
    geometry's, without an operator) by more than ``tol`` (kg m); None otherwise."""
    m = sim.model.m
    if float(np.max(np.abs(sim.v))) > REST_SPEED or float(np.max(np.abs(sim.q[:m]))) > REST_DEFLECTION * reach_m:
        return None
    if op is not None and (op.busy or law == "velocity"):
        return None  # (30) pulls the arm back to theta_ref in every direction: nothing to re-anchor
    theta = sim.q[m:].copy()
    level = field.potentials(theta[None])[0]
    reference_level = op.level if op is not None else shown_level
    if reference_level is None or float(np.max(np.abs(level - reference_level))) <= tol:
        return None
    return theta
