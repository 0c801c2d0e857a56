"""Authority along a path: the predicted base decay rate at many configurations; and the measured one.

The closed loop is linearised once per configuration (:func:`loops_along`, the slow part, a few ms
each); the rates at any gains then come from :func:`authority` without linearising again, so a view
can recolour a path as the gains change. :func:`fit_decay` measures the decay of a logged base
deflection after a kick, to set beside the prediction.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rns_viz.analysis.kick import LN10, SETTLE_LEVEL
from rns_viz.analysis.linear import LinearLoop, StateView, linearise
from rns_viz.analysis.modes import modes_of
from rns_viz.control import Gains, LawKind
from rns_viz.model import FsmsModel


def loops_along(
    model: FsmsModel,
    law: LawKind | str,
    thetas: np.ndarray,
    *,
    view: StateView = "discrete",
    dt: float = 1e-3,
    gains: Gains | None = None,
) -> list[LinearLoop]:
    """One linearised loop per configuration of ``thetas`` (K, n), rad, each held at rest."""
    thetas = np.atleast_2d(np.asarray(thetas, dtype=float))
    return [linearise(model, law, th, view=view, dt=dt, gains=gains) for th in thetas]


@dataclass(frozen=True)
class Authority:
    """Predicted rates at each configuration for one gain setting; arrays (K,)."""

    g_b: float  # 1/s
    g_m: float  # 1/s
    base_decay_rate: np.ndarray  # sigma_b, 1/s
    arm_decay_rate: np.ndarray  # sigma_a, 1/s
    base_damping_ratio: np.ndarray
    stable: np.ndarray  # bool
    coupling_norm: np.ndarray  # |S H_bm| at the configuration, kg m (small near its singularities)


def authority(loops: list[LinearLoop], g_b: float, g_m: float) -> Authority:
    """The base and arm decay rates (1/s) at gains (g_b, g_m) for every loop of :func:`loops_along`."""
    rows = [modes_of(loop, g_b, g_m) for loop in loops]
    norms = [float(np.linalg.norm(loop.M[loop.m :, : loop.m])) for loop in loops]
    return Authority(
        g_b=float(g_b),
        g_m=float(g_m),
        base_decay_rate=np.array([r.base_decay_rate for r in rows], dtype=float),
        arm_decay_rate=np.array([r.arm_decay_rate for r in rows], dtype=float),
        base_damping_ratio=np.array([r.base_damping_ratio for r in rows], dtype=float),
        stable=np.array([bool(r.stable) for r in rows]),
        coupling_norm=np.array(norms),
    )


def joined(parts: list[Authority]) -> Authority:
    """The authorities of consecutive runs of configurations (at the same gains) as one, in their order."""
    if not parts or any((p.g_b, p.g_m) != (parts[0].g_b, parts[0].g_m) for p in parts):
        raise ValueError("joined() needs one or more authorities at the same gains")
    arrays = {
        name: np.concatenate([getattr(p, name) for p in parts])
        for name in ("base_decay_rate", "arm_decay_rate", "base_damping_ratio", "stable", "coupling_norm")
    }
    return Authority(g_b=parts[0].g_b, g_m=parts[0].g_m, **arrays)


@dataclass(frozen=True)
class DecayFit:
    """An exponential envelope A e^(-rate t) fitted to ``|x|``; ``rate`` < 0 means growth."""

    rate: float  # 1/s
    amplitude: float  # units of x at t = 0 of the log
    times: np.ndarray  # (P,) s: the samples fitted (peaks of |x|, or the tail if it does not swing)
    values: np.ndarray  # (P,) |x| there
    method: str  # "peaks" or "tail"


def fit_decay(t: np.ndarray, x: np.ndarray, start: float | None = None, floor: float = 1e-3) -> DecayFit:
    """Decay rate (1/s) of the envelope of ``|x(t)|`` from ``start`` (s; default the first sample).

    The local maxima of ``|x|`` above ``floor`` times the largest are fitted by a straight line in
    ``log |x|`` (least squares); with fewer than three such peaks and no sign change after the largest
    ``|x|`` (an overdamped decay) the samples after it above the floor are fitted instead. ValueError if
    neither applies (fewer than three swings: the log is too short for the oscillation).
    """
    t, x = np.asarray(t, dtype=float), np.asarray(x, dtype=float)
    if t.shape != x.shape or t.ndim != 1:
        raise ValueError("t and x must be 1-D arrays of the same length")
    keep = np.isfinite(x) & (t >= (t[0] if start is None else start))
    t, s = t[keep], np.abs(x[keep])
    if len(s) < 3 or s.max() <= 0:
        raise ValueError("no deflection to fit")
    level = floor * s.max()
    peaks = np.flatnonzero((s[1:-1] > s[:-2]) & (s[1:-1] >= s[2:]) & (s[1:-1] > level)) + 1
    method = "peaks"
    if len(peaks) < 3:
        first = int(np.argmax(s))
        signs = np.sign(np.asarray(x)[keep][first:])
        if np.any(signs != signs[0]):
            raise ValueError("fewer than three swings to fit: log a longer stretch")
        peaks = first + np.flatnonzero(s[first:] > level)
        method = "tail"
        if len(peaks) < 3:
            raise ValueError("too few samples above the floor to fit a decay")
    slope, intercept = np.polyfit(t[peaks], np.log(s[peaks]), 1)
    return DecayFit(float(-slope), float(np.exp(intercept)), t[peaks], s[peaks], method)


@dataclass(frozen=True)
class KickMeasure:
    """What a logged kick shows, read as :mod:`rns_viz.analysis.kick` predicts it."""

    peak: float  # max |y| since the kick, units of y
    settle_time: float  # s after the kick's end until |y| stays under 10 % of the peak (inf: not yet)
    decay_rate: float  # 1/s: ln 10 / settle_time (nan: not settled yet)


def measure_kick(t: np.ndarray, y: np.ndarray, kick_end: float, quiet: float | None = None) -> KickMeasure:
    """Peak, time to 10 % and decay of a deflection y(t) logged from a kick's start; ``kick_end`` in s.

    The time to 10 % counts once ``|y|`` has stayed under 10 % of its peak for ``quiet`` s at the end of the
    log (default: as long as it took to get there, at least a second): a swing may still come back."""
    t, y = np.asarray(t, dtype=float), np.asarray(y, dtype=float)
    a = np.abs(y)
    top = int(np.argmax(a))
    above = np.flatnonzero((t >= kick_end) & (a >= SETTLE_LEVEL * a[top]))
    settle = max((float(t[above[-1]]) if len(above) else kick_end) - kick_end, 0.0)
    if float(t[-1]) - kick_end - settle < (max(settle, 1.0) if quiet is None else quiet):
        settle = math.inf
    rate = LN10 / settle if 0 < settle < math.inf else math.nan
    return KickMeasure(float(a[top]), settle, rate)
