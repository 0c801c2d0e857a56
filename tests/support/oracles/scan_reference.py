"""The scans of sums of damped modes before rows left the Newton batch as they settle (rns_viz.analysis.modal_sums
as first written), kept only as the oracle of tests/unit/test_scan_refinement.py: every top refined from its sample,
the whole batch iterating until all rows settle, the crossing from the middle of its bracket. The parts not shown
(grid_sums, envelope_time, the windows, the constants) are the product's own."""

from __future__ import annotations

import numpy as np

from rns_viz.analysis.modal_sums import (
    CROSSING_STEPS,
    NEAR_LEVEL,
    NEAR_PEAK,
    SETTLED,
    TOP_STEPS,
    WINDOW_SAMPLES,
    _window,
    _window_samples,
    envelope_time,
    grid_sums,
    values,
)

__all__ = ["envelope_time", "grid_sums", "last_above", "peak"]


def _falling_root(slope_of, lo: np.ndarray, hi: np.ndarray, t: np.ndarray, steps: int) -> np.ndarray:
    """A root of g in [lo, hi] (K,), g > 0 before it and < 0 after it, reached from t: Newton steps, bisecting
    the bracket where a step would leave it or g does not fall. ``slope_of(t)`` gives g and g' at t."""
    for _ in range(steps):
        g, dg = slope_of(t)
        before = g > 0
        lo, hi = np.where(before, t, lo), np.where(before, hi, t)
        with np.errstate(divide="ignore", invalid="ignore"):
            newton = t - g / dg
        moved = np.where((dg < 0) & (newton >= lo) & (newton <= hi), newton, 0.5 * (lo + hi))
        if np.all(np.abs(moved - t) <= SETTLED * (1.0 + np.abs(t))):  # every root to rounding (or no rows)
            return moved
        t = moved
    return t


def top(lam: np.ndarray, a: np.ndarray, lo: np.ndarray, hi: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The top of |y| within [lo, hi] (K,) reached from t (y' = 0 there). Its time and |y| there."""
    sign = np.where(values(lam, a, t) < 0, -1.0, 1.0)  # |y| = sign y near t

    def slope(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        e = a * lam * np.exp(lam * t[:, None])
        return sign * e.sum(axis=1).real, sign * (e * lam).sum(axis=1).real

    t = _falling_root(slope, lo, hi, t, TOP_STEPS)
    return t, np.abs(values(lam, a, t))


def peak(lam: np.ndarray, a: np.ndarray, floor: np.ndarray) -> np.ndarray:
    """max (floor, max over tau >= 0 of |y|) (K,): scanned forward window by window (:func:`_window`) while
    the bound E = sum |a_i| e^(-sigma_i tau) is above the largest |y| found, the sampled tops near it refined."""
    best = floor.astype(float).copy()
    sigma, terms = -lam.real, np.abs(a)
    rows, start = np.arange(len(lam)), np.zeros(len(lam))
    for count in _window_samples():
        bound = (terms[rows] * np.exp(-sigma[rows] * start[:, None])).sum(axis=1)
        more = bound > best[rows]
        rows, start = rows[more], start[more]
        if not len(rows):
            break
        span = _window(lam[rows], a[rows], start, best[rows]) * (count / WINDOW_SAMPLES)
        step = span / count
        times, v = _samples(lam[rows], a[rows], start, step, count)
        largest = np.maximum(best[rows], v.max(axis=1))
        cell, _, tops = _tops(lam[rows], a[rows], times, v, step, v >= NEAR_PEAK * largest[:, None])
        np.maximum.at(largest, cell, tops)
        best[rows] = largest
        start = start + span
    return best


def last_above(lam: np.ndarray, a: np.ndarray, end: np.ndarray, level: np.ndarray) -> np.ndarray:
    """The last time in [0, end] (K,) at which |y| reaches ``level`` (K,), 0 if it never does (|y| is under
    it after ``end``). Scanned back from ``end`` window by window (:func:`_window`) until found."""
    out = np.zeros(len(lam))
    rows = np.flatnonzero(end > 0)
    end = end[rows]
    for count in _window_samples():
        if not len(rows):
            break
        span = _window(lam[rows], a[rows], end, level[rows]) * (count / WINDOW_SAMPLES)
        begin = np.maximum(end - span, 0.0)
        found = _scan(lam[rows], a[rows], begin, end, level[rows], count)
        done = ~np.isnan(found)
        out[rows[done]] = found[done]
        more = ~done & (begin > 0)
        rows, end = rows[more], begin[more]
    out[rows] = end  # still not found (never seen): the time is at most this
    return out


def _samples(lam: np.ndarray, a: np.ndarray, begin: np.ndarray, step: np.ndarray, count: int):
    """Times begin + k step, k <= count, and |y| there: (K, count + 1) each."""
    times = begin[:, None] + step[:, None] * np.arange(count + 1)
    return times, np.abs(grid_sums(lam, begin, step, count + 1, a[:, None])[:, 0].real)


def _tops(lam: np.ndarray, a: np.ndarray, times: np.ndarray, v: np.ndarray, step: np.ndarray, wanted: np.ndarray):
    """The sampled tops of |y| (v at ``times``, (K, N) evenly ``step`` apart) where ``wanted``, each refined
    between the samples either side: their sums' indices, times and |y| (flat)."""
    edge = np.full((len(v), 1), -np.inf)
    sampled_top = (v >= np.c_[edge, v[:, :-1]]) & (v >= np.c_[v[:, 1:], edge])
    cell, k = np.nonzero(sampled_top & wanted)
    t = times[cell, k]
    t_top, v_top = top(lam[cell], a[cell], np.maximum(t - step[cell], 0.0), t + step[cell], t)
    return cell, t_top, v_top


def _scan(lam: np.ndarray, a: np.ndarray, begin: np.ndarray, end: np.ndarray, level: np.ndarray, count: int):
    """The last time in [begin, end] (K,) |y| reaches ``level`` (nan where it does not): ``count`` + 1
    samples, the sampled tops after the last sample above refined, the crossing after the last of these
    above solved."""
    step = (end - begin) / count
    times, v = _samples(lam, a, begin, step, count)
    K, rows = len(lam), np.arange(len(lam))
    above = v >= level[:, None]
    last = np.where(above.any(axis=1), count - np.argmax(above[:, ::-1], axis=1), -1)
    found = np.where(last >= 0, times[rows, np.maximum(last, 0)], -np.inf)
    after = times[rows, np.minimum(last + 1, count)]
    wanted = (v >= NEAR_LEVEL * level[:, None]) & (np.arange(count + 1) > last[:, None])
    cell, t_top, v_top = _tops(lam, a, times, v, step, wanted)  # a top between samples may reach the level
    latest = np.full(K, -np.inf)
    reach = v_top >= level[cell]
    np.maximum.at(latest, cell[reach], t_top[reach])
    later = latest > found
    following = np.ceil((latest[later] - begin[later]) / step[later])
    found[later], after[later] = latest[later], times[later, np.clip(following, 0, count).astype(int)]
    done = np.isfinite(found)
    lo, hi = found[done], np.maximum(after[done], found[done])
    lam, a, level = lam[done], a[done], level[done]
    sign = np.where(values(lam, a, lo) < 0, -1.0, 1.0)  # |y| = sign y from lo until it falls through the level

    def excess(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        e = a * np.exp(lam * t[:, None])
        return sign * e.sum(axis=1).real - level, sign * (e * lam).sum(axis=1).real

    crossing = _falling_root(excess, lo, hi, 0.5 * (lo + hi), CROSSING_STEPS)
    out = np.full(K, np.nan)
    out[done] = crossing
    return out
