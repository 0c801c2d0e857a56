"""Reading a simulation's step log back: columns by prefix, one row as q, v, tau and the base force, and
the reaction of Eq. (1) recomputed from a row independently of the plant."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from rns_viz.live.loop.session import Session
from rns_viz.model import FsmsModel
from rns_viz.sim import Simulator


def columns(sim: Simulator, prefix: str, k: int) -> np.ndarray:
    """The logged columns ``prefix_1 .. prefix_k`` of a simulation, one row per logged step."""
    return np.column_stack([sim.log.column(f"{prefix}_{i + 1}") for i in range(k)])


def independent_reaction(model: FsmsModel, row: dict[str, np.ndarray]) -> float:
    """−(H_bm θ'' + c_b) of Eq. (1) with θ'' from M a = u − c solved directly (not the plant's ABA)."""
    m, pm = model.m, model.pin_model
    data = pm.createData()
    q, v = row["q"], row["v"]
    M = pin.crba(pm, data, q)
    M = np.triu(M) + np.triu(M, 1).T
    c = pin.rnea(pm, data, q, v, np.zeros(model.nv))  # velocity terms (zero gravity)
    u = np.concatenate([-model.K_b @ q[:m] - model.D_b @ v[:m] + row["f"], row["tau"] - model.D_m @ v[m:]])
    a = np.linalg.solve(M, u - c)
    return float(-(M[:m, m:] @ a[m:] + c[:m])[model.selected[0]])


def log_row(s: Session, t: float) -> dict[str, np.ndarray]:
    sim = s.state.runs.sim
    m, n = sim.model.m, sim.model.n
    log = sim.log
    k = int(np.flatnonzero(log.column("t") == t)[0])
    arr = log.array()[k]
    col = log.index
    get = lambda prefix, count: np.array([arr[col[f"{prefix}_{i + 1}"]] for i in range(count)])  # noqa: E731
    return {
        "q": np.concatenate([get("xb", m), get("theta", n)]),
        "v": np.concatenate([get("xbdot", m), get("thetadot", n)]),
        "tau": get("tau", n),
        "f": get("fext", m),
    }
