"""Gain maps and root loci of the linearised closed loop (rns_viz.analysis.linear), and their CSV.

A map is the base and arm decay rates over a log grid of (g_b, g_m), both 1/s, about one rest
configuration, with the base's response to the loop's kick (its time to 10 %, whether the linear loop
speaks for it); a locus is the closed-loop poles as one gain sweeps with the other fixed.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import IO, Literal

import numpy as np

from rns_viz.analysis.kick import Kick
from rns_viz.analysis.linear import LinearLoop, StateView, law_kind, linearise
from rns_viz.analysis.modes import Modes, modes_of
from rns_viz.control import Gains, LawKind
from rns_viz.csvio import write_csv
from rns_viz.model import FsmsModel

GRID_SIZE = 60
# 1/s, both axes, every law: the loop is stable at the low end for every bundled model and loses
# stability near the top (g_b or g_m of a few hundred to a few thousand 1/s, where the gain times
# the 1 ms hold approaches one, or the servo of (30) cannot follow).
GAIN_RANGE: dict[LawKind, tuple[float, float]] = {
    "acceleration": (0.1, 3000.0),
    "torque": (0.1, 3000.0),
    "velocity": (0.1, 3000.0),
}


# What g_m does in each law, for a view to say where the gain is set.
G_M_MEANING: dict[LawKind, str] = {
    "acceleration": "g_m (1/s): damping of the joint motion outside the RNS, -G_m theta' in (15)",
    "torque": "g_m (1/s): damping of the joint motion outside the RNS, -G_m theta' in (16)",
    "velocity": "g_m (1/s): position gain pulling the joints to their reference, g_m (theta_ref - theta) in (30)",
}


@dataclass(frozen=True)
class PaperGains:
    label: str  # where the paper uses them
    g_b: float  # 1/s
    g_m: float  # 1/s


# The paper's gains, to mark on a map: Sec. VII-D (TREP, law (30)) and Sec. VI (the 3R, law (15)).
PAPER_GAINS: dict[tuple[str, LawKind], tuple[PaperGains, ...]] = {
    ("trep", "velocity"): (PaperGains("Fig. 10", 24.0, 20.0), PaperGains("Fig. 11", 24.0, 50.0)),
    ("planar3r", "acceleration"): (PaperGains("Fig. 3", 10.0, 1.0),),
}

# The map's CSV: column name -> unit. After g_b and g_m, each column is the Modes attribute of its name.
CSV_COLUMNS: dict[str, str] = {
    "g_b": "1/s",
    "g_m": "1/s",
    "base_decay_rate": "1/s",  # sigma_b = ln 10 / base_time_to_10pct (growing loop: its fastest growth, negative)
    "arm_decay_rate": "1/s",  # sigma_a, the slowest decay of the modes under 5 % of the kick's peak (nan if none)
    "base_damping_ratio": "1",  # of the pole that carries the deflection as it passes 10 % (1 if real)
    "stable": "1 = stable",  # every mode decays
    "base_time_to_10pct": "s",  # after the kick's end until |x_b| stays under 10 % of its peak (inf if it grows)
    "arm_time_to_10pct": "s",  # ln 10 / sigma_a
    "base_frequency": "rad/s",  # |Im lambda| of that pole
    "predictable": "1 = predictable",  # the kick's response stays in the linear range (else the map hatches it)
    "swing": "rad",  # the joints' largest swing outside the RNS while absorbing the kick
    "reason": "code",  # why not predictable: 0 it is, 1 swing too large, 2 a joint limit, 3 decays within the kick
}


def default_axes(law: LawKind | str, n: int = GRID_SIZE) -> tuple[np.ndarray, np.ndarray]:
    """Log-spaced g_b and g_m axes (1/s) of the default map for a law."""
    lo, hi = GAIN_RANGE[law_kind(law)]
    axis = np.geomspace(lo, hi, n)
    return axis, axis.copy()


@dataclass(frozen=True)
class GainMap:
    """Modes over the grid g_b (rows) x g_m (columns) about ``loop.theta``; arrays (len(g_b), len(g_m))."""

    loop: LinearLoop
    g_b: np.ndarray  # (B,) 1/s
    g_m: np.ndarray  # (G,) 1/s
    modes: Modes  # fields of shape (B, G) or (B, G, d)

    @property
    def base_decay_rate(self) -> np.ndarray:
        """sigma_b, 1/s: slowest decay among the modes the base deflection shows."""
        return self.modes.base_decay_rate

    @property
    def arm_decay_rate(self) -> np.ndarray:
        """sigma_a, 1/s: slowest decay among the other modes (the arm's)."""
        return self.modes.arm_decay_rate

    @property
    def stable(self) -> np.ndarray:
        return self.modes.stable

    @property
    def predictable(self) -> np.ndarray:
        """Stable, and the linear loop speaks for the run after the map's kick (``modes.why_not`` says why not)."""
        return self.modes.predictable

    @property
    def base_time_to_10pct(self) -> np.ndarray:
        """s after the kick's end until the base deflection stays under 10 % of its peak."""
        return self.modes.base_time_to_10pct

    def best(self, predictable: bool = True) -> tuple[float, float, float]:
        """(g_b, g_m, sigma_b) of the grid point whose base decays fastest among the predictable ones
        (``predictable=False``: among all stable ones)."""
        rate = np.where(self.predictable if predictable else self.stable, self.base_decay_rate, -np.inf)
        i, j = np.unravel_index(int(np.argmax(rate)), rate.shape)
        return float(self.g_b[i]), float(self.g_m[j]), float(rate[i, j])

    def write_csv(self, target: str | Path | IO[str]) -> int:
        """One row per grid point (g_b varies slowest), columns :data:`CSV_COLUMNS` with their units
        (rns_viz.csvio); returns the rows."""
        g_b, g_m = np.meshgrid(self.g_b, self.g_m, indexing="ij")
        values = [g_b, g_m, *(getattr(self.modes, name) for name in list(CSV_COLUMNS)[2:])]
        rows = np.column_stack([np.asarray(v, dtype=float).ravel() for v in values])
        return write_csv(target, list(CSV_COLUMNS), list(CSV_COLUMNS.values()), rows)


def map_of(loop: LinearLoop, g_b: np.ndarray | None = None, g_m: np.ndarray | None = None) -> GainMap:
    """The map of a linearised loop over the given axes (1/s; default :func:`default_axes`)."""
    axes = default_axes(loop.law)
    gb = np.asarray(axes[0] if g_b is None else g_b, dtype=float)
    gm = np.asarray(axes[1] if g_m is None else g_m, dtype=float)
    if gb.ndim != 1 or gm.ndim != 1 or not (np.all(gb >= 0) and np.all(gm >= 0)):
        raise ValueError("g_b and g_m must be 1-D arrays of gains >= 0 (1/s)")
    return GainMap(loop, gb, gm, modes_of(loop, gb[:, None], gm[None, :]))


def gain_map(
    model: FsmsModel,
    law: LawKind | str,
    theta: np.ndarray | None = None,
    *,
    g_b: np.ndarray | None = None,
    g_m: np.ndarray | None = None,
    view: StateView = "discrete",
    dt: float = 1e-3,
    gains: Gains | None = None,
    kick: Kick | None = None,
) -> GainMap:
    """Linearise about theta at rest (default configuration by default) and map the grid."""
    return map_of(linearise(model, law, theta, view=view, dt=dt, gains=gains, kick=kick), g_b, g_m)


@dataclass(frozen=True)
class Locus:
    """Closed-loop poles as ``sweep`` runs over ``values`` with the other gain at ``fixed`` (1/s)."""

    sweep: Literal["g_b", "g_m"]
    values: np.ndarray  # (K,) 1/s
    fixed: float  # 1/s
    poles: np.ndarray  # (K, d) complex, 1/s
    is_base: np.ndarray  # (K, d) bool: the pole belongs to the base group
    base_share: np.ndarray  # (K, d) share of x_b's kick response, 0..1


def root_locus(loop: LinearLoop, sweep: Literal["g_b", "g_m"], fixed: float, values: np.ndarray | None = None) -> Locus:
    """Poles (1/s) as g_b (or g_m) sweeps over ``values`` (default: the map's axis, 200 points)."""
    if sweep not in ("g_b", "g_m"):
        raise ValueError(f"sweep must be 'g_b' or 'g_m', got {sweep!r}")
    lo, hi = GAIN_RANGE[loop.law]
    vals = np.geomspace(lo, hi, 200) if values is None else np.asarray(values, dtype=float)
    modes = modes_of(loop, vals, fixed) if sweep == "g_b" else modes_of(loop, fixed, vals)
    return Locus(sweep, vals, float(fixed), modes.poles, modes.is_base, modes.base_share)
