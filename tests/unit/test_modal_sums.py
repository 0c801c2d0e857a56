"""Tops and crossings of sums of damped modes (rns_viz.analysis.modal_sums), the kick response's peak and time
to 10 %, against an independent oracle: each sum sampled evenly over its whole decay (32 samples a turn of
its fastest mode), every top found where y' changes sign and bisected, every crossing bisected."""

from __future__ import annotations

import numpy as np
import pytest

from rns_viz.analysis import modal_sums

RNG = np.random.default_rng(25)


def y_at(lam: np.ndarray, a: np.ndarray, t: np.ndarray, order: int = 0) -> np.ndarray:
    """d^order y / dt^order at times t (N,) of one sum."""
    return (a[:, None] * lam[:, None] ** order * np.exp(lam[:, None] * t)).sum(axis=0).real


def bisect(f, lo: np.ndarray, hi: np.ndarray, steps: int = 60) -> np.ndarray:
    """Roots of f with f(lo) and f(hi) of opposite signs (arrays of brackets)."""
    f_lo = f(lo)
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        same = np.sign(f(mid)) == np.sign(f_lo)
        lo, hi, f_lo = np.where(same, mid, lo), np.where(same, hi, mid), np.where(same, f(mid), f_lo)
    return 0.5 * (lo + hi)


def oracle(lam: np.ndarray, a: np.ndarray, floor: float, until: float) -> tuple[float, float]:
    """Peak of max(floor, |y|) over [0, until] and the last time |y| reaches 10 % of it, by dense sampling."""
    step = 2 * np.pi / np.abs(lam).max() / 32
    t = np.arange(0.0, until + step, step)
    slope = y_at(lam, a, t, 1)
    turns = np.flatnonzero(np.sign(slope[:-1]) != np.sign(slope[1:]))
    tops = bisect(lambda s: y_at(lam, a, s, 1), t[turns], t[turns + 1])
    peak = max(floor, np.abs(y_at(lam, a, t)).max(), np.abs(y_at(lam, a, tops)).max(initial=0.0))
    level = 0.1 * peak
    points = np.concatenate([t, tops])
    above = points[np.abs(y_at(lam, a, points)) >= level]
    if not len(above):
        return peak, 0.0
    last = above.max()
    after = t[t > last]
    return peak, float(bisect(lambda s: np.abs(y_at(lam, a, s)) - level, np.array([last]), after[:1])[0])


def random_sum() -> tuple[np.ndarray, np.ndarray]:
    """1 to 4 modes: real poles and (upper poles of) pairs, rates 0.05-20 /s, swings up to 30 rad/s,
    amplitudes over two decades in random phases."""
    count = int(RNG.integers(1, 5))
    sigma = np.exp(RNG.uniform(np.log(0.05), np.log(20.0), count))
    omega = np.where(RNG.random(count) < 0.7, np.exp(RNG.uniform(np.log(0.1), np.log(30.0), count)), 0.0)
    size = np.exp(RNG.uniform(0.0, np.log(100.0), count))
    phase = np.where(omega > 0, RNG.uniform(0.0, 2 * np.pi, count), RNG.choice([0.0, np.pi], count))
    return -sigma + 1j * omega, size * np.exp(1j * phase)


def response(lam: np.ndarray, a: np.ndarray, floor: float) -> tuple[float, float]:
    """What the kick response reads: the peak (at least ``floor``, the push's), then the last time at 10 %."""
    peak = modal_sums.peak(lam[None], a[None], np.array([floor]))
    level = 0.1 * peak
    end = modal_sums.envelope_time(-lam.real[None], np.abs(a)[None], level)
    return float(peak[0]), float(modal_sums.last_above(lam[None], a[None], end, level)[0])


def test_random_sums_agree_with_the_dense_oracle() -> None:
    for _ in range(150):
        lam, a = random_sum()
        floor = float(RNG.uniform(0.0, 1.2) * np.abs(a.sum().real))  # at times the push's largest sample wins
        peak, settle = response(lam, a, floor)
        until = float(np.log(10 * np.abs(a).sum() / (0.1 * peak)) / (-lam.real).min()) + 1.0
        want_peak, want_settle = oracle(lam, a, floor, until)
        assert peak == pytest.approx(want_peak, rel=1e-6), (lam, a, floor)
        assert settle == pytest.approx(want_settle, rel=1e-6, abs=1e-9), (lam, a, floor)


@pytest.mark.parametrize("over", [1e-5, 1e-4, 1e-3, 1e-2])
def test_a_narrow_top_just_over_the_level_is_found(over: float) -> None:
    """A slow swing (period 22 s) from its peak at 0: the push's peak is set so that 10 % of it lies ``over``
    (relative) under one of the swing's tops; |y| is over the level there for a fraction of a second (0.03 s
    at 1e-5), which 16 samples a turn (1.4 s apart) may step over. The crossing is after that top."""
    lam, a = np.array([-0.116 + 0.288j]), np.array([0.01 + 0.0j])
    tops = (np.pi * np.arange(1, 8) - np.arctan(0.116 / 0.288)) / 0.288  # y' = 0 of e^(-st) cos(wt)
    top_values = np.abs(y_at(lam, a, tops))
    for k in np.flatnonzero(10 * top_values / (1 + over) >= 0.01):  # the push's peak must be the peak
        top, floor = tops[k], 10 * top_values[k] / (1 + over)
        peak, settle = response(lam, a, floor)
        assert peak == pytest.approx(floor)
        assert top < settle < top + 0.5
        assert settle == pytest.approx(oracle(lam, a, floor, 60.0)[1], rel=1e-6)


def test_a_peak_between_coarse_samples_is_found() -> None:
    """The 3R's kind of response: a fast real mode pulling against a slow swing; the peak comes late (near 2 s)."""
    lam = np.array([-1.19 + 0.0j, -0.05 + 1.77j])
    a = np.array([-0.0273 + 0.0j, 0.0634 * np.exp(-1.2j)])
    peak, settle = response(lam, a, 0.0)
    want_peak, want_settle = oracle(lam, a, 0.0, 80.0)
    assert peak == pytest.approx(want_peak, rel=1e-9)
    assert settle == pytest.approx(want_settle, rel=1e-6)


def test_a_sum_under_the_level_after_the_push_settles_at_once() -> None:
    lam, a = np.array([-3.0 + 0.0j]), np.array([1.0 + 0.0j])
    assert response(lam, a, 20.0) == (20.0, 0.0)  # the push's peak; after it |y| <= 1 < 2
