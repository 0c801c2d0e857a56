"""Tops and level crossings of sums of damped modes, y(tau) = Re sum_i a_i e^(lambda_i tau), K sums at once.

The kick response (:mod:`rns_viz.analysis.kick`) reads the peak of |y| and the last time |y| reaches 10 %
of it from these; complex pairs come folded onto their upper poles (y real). Sampling alone cuts the tops
of a swing (by up to 2 % at 16 samples a turn), so every sampled top that could matter is refined to the
top itself, and a crossing is solved between a sample or top above the level and the next sample under it.
"""

from __future__ import annotations

import numpy as np

SIGNIFICANT = 1e-5  # a term under this fraction of the level cannot carry |y| (or its slope) through it
WINDOW_SAMPLES = 16  # samples in a window scanned for the peak or the crossing (:func:`_window`)
NEAR_LEVEL = 0.8  # sampled tops of |y| above this fraction of the level are refined for the crossing ...
NEAR_PEAK = 0.97  # ... and above this fraction of the largest sample for the peak
TOP_STEPS = 6  # Newton (or bisection) steps on y' = 0 to a top ...
CROSSING_STEPS = 12  # ... and on |y| = level where it falls through the level
ENVELOPE_STEPS = 8  # Newton steps on the bound's log
SETTLED = 1e-13  # relative step under which a Newton iteration has converged
MAX_WINDOWS = 200  # windows scanned per sum (a few in practice) ...
LONGER_AFTER = 8  # ... their samples doubled every this many windows ...
MAX_WINDOW_SAMPLES = 1024  # ... up to this many


def grid_sums(lam: np.ndarray, start: np.ndarray, step: np.ndarray, count: int, weights: np.ndarray) -> np.ndarray:
    """sum_i w_i e^(lambda_i t) at t = start + k step, k < count, for K sums' poles lam (K, s), start and step
    (K,) or (K, G) segments, weights (K, W, s): complex (K, W, count) or (K, W, G count), segment by segment.
    By recurrence: a product per sample, an exponential per segment."""
    lam_ = lam.reshape(*lam.shape, *(1,) * (start.ndim - 1))  # (K, s, [G])
    e = np.empty((*lam_.shape[:2], *start.shape[1:], count), dtype=complex)
    e[..., 0] = np.exp(lam_ * start[:, None])
    e[..., 1:] = np.exp(lam_ * step[:, None])[..., None]
    np.cumprod(e, axis=-1, out=e)
    return weights @ e.reshape(*e.shape[:2], -1)


def values(lam: np.ndarray, a: np.ndarray, t: np.ndarray) -> np.ndarray:
    """y at one time per sum, t (K,)."""
    return (a * np.exp(lam * t[:, None])).sum(axis=1).real


def _falling_root(
    coef: np.ndarray, lam: np.ndarray, shift: np.ndarray, lo: np.ndarray, hi: np.ndarray, t: np.ndarray, steps: int
) -> np.ndarray:
    """A root of g(t) = Re sum coef e^(lam t) - shift in [lo, hi] (K,), g > 0 before it and < 0 after it, reached
    from t: Newton steps (g' = Re sum coef lam e^(lam t)), bisecting the bracket where a step would leave it or g
    does not fall. A row leaves the batch once its step is under rounding (SETTLED): the few slow rows do not
    hold the many back."""
    out, rows = t.copy(), np.arange(len(t))
    coef_slope = coef * lam
    for _ in range(steps):
        e = np.exp(lam * t[:, None])
        g = (coef * e).sum(axis=1).real - shift
        dg = (coef_slope * e).sum(axis=1).real
        before = g > 0
        lo, hi = np.where(before, t, lo), np.where(before, hi, t)
        with np.errstate(divide="ignore", invalid="ignore"):
            newton = t - g / dg
        moved = np.where((dg < 0) & (newton >= lo) & (newton <= hi), newton, 0.5 * (lo + hi))
        out[rows] = moved
        going = np.abs(moved - t) > SETTLED * (1.0 + np.abs(t))
        if not going.any():
            break
        if going.all():
            t = moved
            continue
        rows, t, lo, hi, shift = rows[going], moved[going], lo[going], hi[going], shift[going]
        coef, coef_slope, lam = coef[going], coef_slope[going], lam[going]
    return out


def _refine_tops(
    lam: np.ndarray, a: np.ndarray, t: np.ndarray, step: np.ndarray, sign: np.ndarray, offset: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Sampled tops of |y| (one per row: a sum's poles and parts, the sample's time, the samples' spacing, the
    sign of y there and the vertex of the parabola through the three samples, in steps) refined to the top
    (y' = 0) between the samples either side, from the vertex: their times and |y| there."""
    lo, hi = np.maximum(t - step, 0.0), t + step
    start = np.clip(t + offset * step, lo, hi)
    t = _falling_root(sign[:, None] * a * lam, lam, np.zeros(len(t)), lo, hi, start, TOP_STEPS)
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
        times, y = _samples(lam[rows], a[rows], start, step, count)
        v = np.abs(y)
        largest = np.maximum(best[rows], v.max(axis=1))
        cell, k, offset = _sampled_tops(v, v >= NEAR_PEAK * largest[:, None])
        sign = np.where(y[cell, k] < 0, -1.0, 1.0)
        _, tops = _refine_tops(lam[rows[cell]], a[rows[cell]], times[cell, k], step[cell], sign, offset)
        np.maximum.at(largest, cell, tops)
        best[rows] = largest
        start = start + span
    return best


def envelope_time(sigma: np.ndarray, terms: np.ndarray, level: np.ndarray) -> np.ndarray:
    """A time (K,) after which E = sum terms e^(-sigma tau), which bounds |y|, is under ``level`` (0 if it
    starts under it): where E falls to it, by Newton on log E (convex in tau, so from tau = 0 no step passes
    the root), or where it has not converged, where each of the p terms is under level / p."""
    t = np.zeros(len(terms))
    for _ in range(ENVELOPE_STEPS):
        e = terms * np.exp(-sigma * t[:, None])
        total = e.sum(axis=1)
        with np.errstate(divide="ignore", invalid="ignore"):
            t += np.maximum(np.log(total / level) * total / (e * sigma).sum(axis=1), 0.0)
    under = (terms * np.exp(-sigma * t[:, None])).sum(axis=1) <= level * (1 + 1e-9)
    if under.all():
        return t
    p = np.maximum((terms > 0).sum(axis=1), 1)[:, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        each = np.where(terms * p > level[:, None], np.log(terms * p / level[:, None]) / sigma, 0.0)
    return np.where(under, t, each.max(axis=1))


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


def _window_samples() -> list[int]:
    """Samples per window, window after window: WINDOW_SAMPLES, doubled every LONGER_AFTER windows (the few
    sums still scanned then, nearly undamped swings, go on for many turns) up to MAX_WINDOW_SAMPLES."""
    return [min(WINDOW_SAMPLES * 2 ** (k // LONGER_AFTER), MAX_WINDOW_SAMPLES) for k in range(MAX_WINDOWS)]


def _window(lam: np.ndarray, a: np.ndarray, at: np.ndarray, level: np.ndarray) -> np.ndarray:
    """The length (s, (K,)) of the window to scan next from time ``at``, sampled WINDOW_SAMPLES times: one turn
    of the largest swing above SIGNIFICANT of the level there (else the slowest such real mode's time
    constant), at most one turn (2 pi / |lambda|) of the fastest such mode."""
    weight = np.abs(a) * np.exp(lam.real * at[:, None])
    significant = (weight >= SIGNIFICANT * level[:, None]) | (weight == weight.max(axis=1, keepdims=True))
    swinging = significant & (lam.imag != 0)
    omega = np.abs(lam[np.arange(len(lam)), np.argmax(np.where(swinging, weight, -1.0), axis=1)].imag)
    slowest = np.where(significant & ~swinging, -lam.real, np.inf).min(axis=1)
    fastest = np.where(significant, np.abs(lam), 0.0).max(axis=1)
    with np.errstate(divide="ignore"):
        return np.minimum(np.where(swinging.any(axis=1), 2 * np.pi / omega, 1.0 / slowest), 2 * np.pi / fastest)


def _samples(lam: np.ndarray, a: np.ndarray, begin: np.ndarray, step: np.ndarray, count: int):
    """Times begin + k step, k <= count, and y there: (K, count + 1) each."""
    times = begin[:, None] + step[:, None] * np.arange(count + 1)
    return times, grid_sums(lam, begin, step, count + 1, a[:, None])[:, 0].real


def _sampled_tops(v: np.ndarray, wanted: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The sampled tops of v = |y| (K, N) where ``wanted``: their rows, sample indices and the vertex of the
    parabola through the sample and its neighbours (offset in samples, within +-1; 0 at either end)."""
    v_before, v_after = np.full_like(v, -np.inf), np.full_like(v, -np.inf)
    v_before[:, 1:], v_after[:, :-1] = v[:, :-1], v[:, 1:]
    cell, k = np.nonzero((v >= v_before) & (v >= v_after) & wanted)
    before, here, after = v_before[cell, k], v[cell, k], v_after[cell, k]
    curvature = before - 2.0 * here + after
    with np.errstate(divide="ignore", invalid="ignore"):
        offset = np.where(np.isfinite(curvature) & (curvature < 0), 0.5 * (before - after) / curvature, 0.0)
    return cell, k, np.clip(offset, -1.0, 1.0)


def _scan(lam: np.ndarray, a: np.ndarray, begin: np.ndarray, end: np.ndarray, level: np.ndarray, count: int):
    """The last time in [begin, end] (K,) |y| reaches ``level`` (nan where it does not): ``count`` + 1
    samples, the sampled tops after the last sample above refined, the crossing after the last of these
    above solved (from the line through |y| at either end of its bracket)."""
    step = (end - begin) / count
    times, y = _samples(lam, a, begin, step, count)
    v = np.abs(y)
    K, rows = len(lam), np.arange(len(lam))
    above = v >= level[:, None]
    last = np.where(above.any(axis=1), count - np.argmax(above[:, ::-1], axis=1), -1)
    found = np.where(last >= 0, times[rows, np.maximum(last, 0)], -np.inf)
    following = np.minimum(last + 1, count)
    wanted = (v >= NEAR_LEVEL * level[:, None]) & (np.arange(count + 1) > last[:, None])
    cell, k, offset = _sampled_tops(v, wanted)  # a top between samples may reach the level
    sign = np.where(y[cell, k] < 0, -1.0, 1.0)
    t_top, v_top = _refine_tops(lam[cell], a[cell], times[cell, k], step[cell], sign, offset)
    latest = np.full(K, -np.inf)
    reach = v_top >= level[cell]
    np.maximum.at(latest, cell[reach], t_top[reach])
    later = latest > found
    found[later] = latest[later]
    following[later] = np.clip(np.ceil((latest[later] - begin[later]) / step[later]), 0, count).astype(int)
    done = np.isfinite(found)
    lo = found[done]
    hi = np.maximum(times[done, following[done]], lo)
    lam, a, level = lam[done], a[done], level[done]
    y_lo = values(lam, a, lo)
    sign = np.where(y_lo < 0, -1.0, 1.0)  # |y| = sign y from lo until it falls through the level
    over, under = np.abs(y_lo) - level, v[done, following[done]] - level
    with np.errstate(divide="ignore", invalid="ignore"):
        start = np.where(over > under, lo + (hi - lo) * over / (over - under), 0.5 * (lo + hi))
    crossing = _falling_root(sign[:, None] * a, lam, level, lo, hi, np.clip(start, lo, hi), CROSSING_STEPS)
    out = np.full(K, np.nan)
    out[done] = crossing
    return out
