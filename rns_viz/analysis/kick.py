"""What a kick does to the linearised loop: the base deflection's peak, its time to 10 %, its decay, the arm's swing.

After a half-sine push of ``Kick.peak`` N lasting ``Kick.duration`` s the base deflection y (the kicked
coordinate) is a sum of the loop's modes. With lambda_i the poles, v_i, w_i right and left eigenvectors
(w_i^H v_j = delta_ij), C picking y and B the force input (per N, per step of the step map):

    y(T + tau) = Re sum_i a_i e^(lambda_i tau),   a_i = (C v_i)(w_i^H B d) F xi_i(T),

xi_i(T) being mode i's state at the push's end T (closed form of the sampled half-sine, below).
With each complex pair's part on its upper pole (Re(a e + conj) = Re(2 a e)), the envelope
E = |sum over real poles| + |sum over pairs| is smooth and bounds |y| from above. From it:

- peak P: max |y| (samples during and after the push, refined by Newton on y' = 0);
- settle time: after the push's end, the last time |y| reaches 10 % of P (at or before E's last crossing;
  where y swings there, on a swing within a turn before it, sampled and bisected);
- decay rate sigma_b: ln 10 over the settle time, the mean rate at which one sees the deflection fall to
  10 % of its peak after the kick (about a pole's -Re lambda where one mode carries the decay);
- arm swing: the joints' motion outside the reaction null space, (S H_bm)^+ integral of L dt (L = S H_bm
  theta', Eq. 8: at linear order every law's arm motion the base sees), at most ``swing`` rad.

A prediction is kept only where the linear loop speaks for the run (:data:`REASONS`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rns_viz.defaults import defaults_for
from rns_viz.model import FsmsModel

SETTLE_LEVEL = 0.1  # "time to 10 %"
UPPER_LEVEL = 0.05  # the envelope is followed until its bound falls under this fraction of the peak
LN10 = math.log(10.0)
MAX_SWING_RAD = 0.5  # rad: beyond this joint swing the configuration-dependent terms change too much
PULSE_SAMPLES = 6  # samples of y during the push (its middle among them)
# y and its envelope are sampled evenly within segments of the time after the push: to where the largest
# term first turns back (at most the first fraction below), then between these fractions of a time when E
# is surely under 5 % of the peak ...
SEGMENTS = (0.0, 1 / 64, 1 / 16, 1 / 4, 1.0)
SEGMENT_SAMPLES = 6  # ... this many samples each ...
FINE_SAMPLES = 8  # ... and over the sample step in which the envelope crosses 10 % of the peak;
SETTLE_SAMPLES = 16  # |y| over the turn before it, where it swings, ...
BISECTIONS = 7  # ... and bisections of the flank where it falls through 10 %
KEPT_PART = 1e-3  # the modes followed after the push: their part in y or L at least this of the largest

# Why a stable cell's prediction is not kept (index = KickResponse.reason; 0: kept).
REASONS = (
    "",
    "the arm would swing its joints by {swing:.2g} rad to absorb this kick (the linear loop holds to {max:.2g} rad)",
    "a joint would pass its limit to absorb this kick",
    "the deflection follows the push: it is under 10 % of its peak before the kick ends, no decay to watch",
)
KEPT, SWING, LIMIT, WITHIN_KICK = range(len(REASONS))


@dataclass(frozen=True)
class Kick:
    """A half-sine push on the base: ``peak`` N (N m on a rotation) times ``direction``'s weights."""

    peak: float  # N
    duration: float  # s
    direction: tuple[float, ...]  # weights over the m base coordinates

    def __post_init__(self) -> None:
        w = np.asarray(self.direction, dtype=float)
        if not (math.isfinite(self.peak) and self.peak > 0 and math.isfinite(self.duration) and self.duration > 0):
            raise ValueError(f"a kick needs a positive finite peak and duration, got {self.peak} N, {self.duration} s")
        if w.ndim != 1 or not np.all(np.isfinite(w)) or not np.any(w):
            raise ValueError(f"a kick's direction needs finite weights, not all zero: {self.direction}")

    @property
    def weights(self) -> np.ndarray:
        return np.asarray(self.direction, dtype=float)

    @property
    def output(self) -> np.ndarray:
        """(m,): y = output @ x_b, the deflection along the kick (the coordinate itself for one axis)."""
        w = self.weights
        return w / float(w @ w)

    def words(self, coordinates: tuple[str, ...]) -> str:
        """'a 5 N, 0.2 s kick along x' with the base coordinates' names."""
        w = self.weights
        along = [name for name, x in zip(coordinates, w, strict=True) if x != 0]
        where = f" along {along[0]}" if len(along) == 1 else ""
        return f"a {self.peak:g} N, {self.duration:g} s kick{where}"


def default_kick(model: FsmsModel) -> Kick:
    """The kick the app's Kick button gives this model by default (rns_viz.defaults)."""
    d = defaults_for(model.name)
    direction = np.zeros(model.m)
    direction[min(d.kick_axis, model.m - 1)] = 1.0
    return Kick(d.kick_peak_N, d.kick_duration_s, tuple(direction))


@dataclass(frozen=True)
class KickResponse:
    """The kick's predicted effect at K gain settings, arrays (K,) (nan where not computed)."""

    peak: np.ndarray  # max |y|, m (rad on a rotation)
    settle_time: np.ndarray  # s after the kick's end until |y| stays under 10 % of the peak
    decay_rate: np.ndarray  # 1/s: ln 10 / settle_time
    dominant: np.ndarray  # (K,) int: the pole whose term is largest at the 10 % crossing
    swing: np.ndarray  # rad: largest joint swing outside the RNS while the base recovers
    reason: np.ndarray  # int: index into REASONS (0: the prediction is kept)


def pulse_steps(kick: Kick, dt: float) -> np.ndarray:
    """(J,) control steps into the push where its response is sampled, evenly spaced, the last at its end."""
    steps = max(round(kick.duration / dt), 1)
    spacing = max(steps // PULSE_SAMPLES, 1)
    return np.append(np.arange(spacing, steps, spacing)[: PULSE_SAMPLES - 1], steps).astype(float)


def pulse_states(lam: np.ndarray, mu: np.ndarray | None, dt: float, duration: float, steps: np.ndarray) -> np.ndarray:
    """xi_i after ``steps`` (J,) control steps into a unit half-sine push, (..., s, J).

    Step map (``mu`` given): xi_{k+1} = mu xi_k + sin(w dt (k + 1/2)), w = pi / duration, the force
    at mid-step (the simulator samples it at RK4's stages, of which the midpoint carries 2/3):
        xi_K = [e^(i w dt/2) (mu^K - z^K) / (mu - z) - c.c.(z)] / 2i,   z = e^(i w dt).
    Continuous (``mu`` None): xi' = lambda xi + sin(w t), xi(t) = (w e^(lambda t) - w cos wt - lambda sin wt)
    / (lambda^2 + w^2).
    """
    w = math.pi / duration
    k = np.asarray(steps, dtype=float)
    with np.errstate(over="ignore", invalid="ignore"):  # a growing loop's modes may overflow: it is unstable anyway
        e = _powers(lam, k * dt)  # e^(lambda t) = mu^k
    if mu is None:
        t, lam = k * dt, lam[..., None]
        return (w * e - w * np.cos(w * t) - lam * np.sin(w * t)) / (lam * lam + w * w)
    m = mu[..., None]
    out = np.zeros(e.shape, dtype=complex)
    with np.errstate(over="ignore", invalid="ignore"):
        for sign in (1.0, -1.0):
            z = np.exp(sign * 1j * w * dt)
            diff = m - z
            diff = np.where(np.abs(diff) < 1e-12, 1e-12, diff)  # mu at the pulse's frequency: never in practice
            out += sign * np.exp(sign * 0.5j * w * dt) * (e - z**k) / diff
    return out / 2j


def _powers(lam: np.ndarray, times: np.ndarray) -> np.ndarray:
    """e^(lambda t) at ``times`` (J,), (..., s, J): by recurrence over an even spacing, the last time exactly."""
    out = np.empty((*lam.shape, len(times)), dtype=complex)
    even = len(times) > 2 and np.allclose(np.diff(times[:-1]), times[0])
    if not even:
        return np.exp(lam[..., None] * times)
    ratio = np.exp(lam * times[0])
    out[..., 0] = ratio
    for j in range(1, len(times) - 1):
        np.multiply(out[..., j - 1], ratio, out=out[..., j])
    out[..., -1] = np.exp(lam * times[-1])
    return out


def fold_pairs(lam: np.ndarray, a: np.ndarray) -> np.ndarray:
    """Amplitudes with each complex pair's part on its upper pole: Re(a e + conj) = Re(2 a e), 0 on the lower."""
    factor = np.where(lam.imag > 0, 2.0, np.where(lam.imag < 0, 0.0, 1.0))
    return a * (factor if a.ndim == lam.ndim else factor[:, None, :])


def _bound_time(sigma: np.ndarray, terms: np.ndarray, level: np.ndarray) -> np.ndarray:
    """A time (s) after which sum terms e^(-sigma tau), a bound on the envelope, is under ``level``:
    each of the p terms that are not 0 under level / p."""
    p = np.maximum((terms > 0).sum(axis=1, keepdims=True), 1)
    with np.errstate(divide="ignore", invalid="ignore"):
        each = np.where(terms * p > level[:, None], np.log(terms * p / level[:, None]) / sigma, 0.0)
    return np.maximum(each.max(axis=1), 1e-3)


def _sums(lam: np.ndarray, start: np.ndarray, step: np.ndarray, count: int, weights: np.ndarray) -> np.ndarray:
    """sum_i w_i e^(lambda_i t_k) at t_k = start + k step, k < count, for weights (K, W, s): (K, W, count).
    e^(lambda t_k) by recurrence (a product per sample, no exponential), the loops' axis last (fastest)."""
    e = np.exp(lam * start[:, None]).T.copy()  # (s, K)
    ratio = np.exp(lam * step[:, None]).T.copy()
    w = np.ascontiguousarray(weights.transpose(1, 2, 0))  # (W, s, K)
    out = np.empty((count, *w.shape[::2]), dtype=complex)  # (count, W, K)
    for k in range(count):
        if k:
            e *= ratio
        np.einsum("wsk,sk->wk", w, e, out=out[k])
    return out.transpose(2, 1, 0)


def _last_crossing(times: np.ndarray, values: np.ndarray, level: np.ndarray) -> np.ndarray:
    """Last time a sampled, positive ``values`` is at or above ``level``, log-interpolated to the next
    sample; the first time if never; inf if still above at the last sample."""
    above = values >= level[:, None]
    count = values.shape[1]
    last = count - 1 - np.argmax(above[:, ::-1], axis=1)
    last = np.where(above.any(axis=1), last, 0)
    nxt = np.minimum(last + 1, count - 1)
    t0, t1 = np.take_along_axis(times, last[:, None], 1)[:, 0], np.take_along_axis(times, nxt[:, None], 1)[:, 0]
    v0, v1 = np.take_along_axis(values, last[:, None], 1)[:, 0], np.take_along_axis(values, nxt[:, None], 1)[:, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        f = np.log(v0 / level) / np.log(v0 / v1)
    crossing = t0 + np.clip(np.nan_to_num(f, nan=0.0, posinf=1.0, neginf=0.0), 0.0, 1.0) * (t1 - t0)
    crossing = np.where(above.any(axis=1), crossing, times[:, 0])
    return np.where(above[:, -1], np.inf, crossing)


def _crossings(
    lam: np.ndarray, parts: np.ndarray, times: np.ndarray, envelope: np.ndarray, levels: np.ndarray
) -> np.ndarray:
    """Last times (s) the envelope sampled at ``times`` (K, N) is at ``levels`` (L, K): the last sample at or
    above each, then FINE_SAMPLES over the step after it, log-interpolated there. (L, K)."""
    K, count = envelope.shape
    L = len(levels)
    above = envelope[None] >= levels[..., None]  # (L, K, N)
    last = np.where(above.any(axis=2), count - 1 - np.argmax(above[..., ::-1], axis=2), 0)
    nxt = np.minimum(last + 1, count - 1)
    t0 = np.take_along_axis(np.broadcast_to(times, (L, K, count)), last[..., None], 2)[..., 0].ravel()
    t1 = np.take_along_axis(np.broadcast_to(times, (L, K, count)), nxt[..., None], 2)[..., 0].ravel()
    fine = (t1 - t0) / FINE_SAMPLES
    parts_l = np.tile(parts, (L, 1, 1))
    rest, osc = _sums(np.tile(lam, (L, 1)), t0, fine, FINE_SAMPLES + 1, parts_l).transpose(1, 0, 2)
    fine_times = t0[:, None] + fine[:, None] * np.arange(FINE_SAMPLES + 1)
    crossing = _last_crossing(fine_times, np.abs(rest.real) + np.abs(osc), levels.ravel()).reshape(L, K)
    crossing[~above.any(axis=2)] = 0.0  # under the level from the kick's end on
    crossing[above[..., -1]] = np.inf  # still above at the end of the samples: never, for the bound
    return crossing


def respond(
    lam: np.ndarray,
    a: np.ndarray,
    a_L: np.ndarray,
    y_pulse: np.ndarray,
    L_pulse: np.ndarray,
    swing_map: np.ndarray,
    pulse_times: np.ndarray,
    margins: tuple[np.ndarray, np.ndarray],
) -> KickResponse:
    """The kick's effect on K stable loops.

    lam (K, s): the poles (1/s) that carry y and L after the push; a (K, s), a_L (K, r, s): their parts in
    y and in L = S H_bm theta' at the push's end, y(T + tau) = Re sum a e^(lambda tau); y_pulse (K, J) and
    L_pulse (K, r, J): y and L during the push at ``pulse_times`` (J,) s, the last at its end; swing_map
    (n, r): (S H_bm)^+; margins: how far each joint may turn down and up to its limits (n,), rad.
    """
    K = len(lam)
    a, a_L = fold_pairs(lam, a), fold_pairs(lam, a_L)
    sigma = -lam.real
    oscillating = lam.imag != 0  # a pair (on its upper pole): enveloped in E; real poles are summed
    terms = np.abs(a)
    with np.errstate(divide="ignore", invalid="ignore"):
        a_int = np.where(lam[:, None, :] != 0, a_L / lam[:, None, :], 0.0)  # integral of L after the push, per mode

    # y and E after the push on a grid finer near its end (to where the largest term first turns back, then
    # in segments), until E's bound is under 5 % of the push's largest deflection; the peak refined there.
    at_pulse = np.abs(y_pulse)
    horizon = _bound_time(sigma, terms, UPPER_LEVEL * at_pulse.max(axis=1))
    big = np.take_along_axis(lam, np.argmax(terms, axis=1)[:, None], 1)[:, 0]
    with np.errstate(divide="ignore"):  # where the largest term first turns back: the peak is near
        turn = np.where(big.imag != 0, np.pi / np.abs(big.imag), 1.0 / -big.real)
    edges = np.vstack([np.zeros(K), np.minimum(turn, horizon * SEGMENTS[1]), *(horizon * f for f in SEGMENTS[1:])])
    parts = np.stack([np.where(oscillating, 0.0, a), np.where(oscillating, a, 0.0)], axis=1)
    times, sums = _grid(lam, edges, np.concatenate([parts, a_int], axis=1))
    rest, osc, integral_after = sums[:, 0], sums[:, 1], sums[:, 2:]  # real poles', pairs', integral of L
    y = np.abs(rest.real + osc.real)
    peak = _peak(lam, a, times, y, at_pulse)
    (envelope_10,) = _crossings(lam, parts, times, np.abs(rest.real) + np.abs(osc), SETTLE_LEVEL * peak[None])
    t10 = _last_on_y(lam, a, oscillating, envelope_10, SETTLE_LEVEL * peak)
    with np.errstate(divide="ignore", invalid="ignore"):
        decay = LN10 / t10  # the mean rate from the kick's end to 10 % of the peak
        at_10 = terms * np.exp(-sigma * t10[:, None])  # the pole whose term is largest at 10 %
    top = np.argmax(at_10, axis=1)

    # Arm swing: the integral of L over the push (trapezoid), after it (closed form) and in the end.
    dtau = np.diff(np.concatenate([[0.0], pulse_times]))
    before = np.concatenate([np.zeros_like(L_pulse[..., :1]), L_pulse[..., :-1]], 2)
    inside = np.cumsum(0.5 * (L_pulse + before) * dtau, 2)
    offset = inside[..., -1] - a_int.sum(axis=-1).real  # the integral at the push's end, minus the modes' start
    integral = np.concatenate([inside, integral_after.real + offset[..., None], offset[..., None]], 2)
    joints = np.einsum("nr,krj->knj", swing_map, integral)
    swing = np.abs(joints).max(axis=(1, 2))
    down, up = margins
    passes = np.any((joints.min(axis=2) < -down) | (joints.max(axis=2) > up), axis=1)

    reason = np.full(K, KEPT)
    reason[t10 <= 0] = WITHIN_KICK
    reason[swing > MAX_SWING_RAD] = SWING
    reason[passes] = LIMIT
    return KickResponse(peak, t10, decay, top, swing, reason)


def _grid(lam: np.ndarray, edges: np.ndarray, weights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """sum_i w_i e^(lambda_i tau) for weights (K, W, s), tau evenly within each segment between ``edges``
    (G + 1, K) s after the push: times (K, G SEGMENT_SAMPLES), sums (K, W, G SEGMENT_SAMPLES)."""
    K, G = len(lam), len(edges) - 1
    start = edges[:-1].ravel()  # (G K,) segment by segment
    step = np.diff(edges, axis=0).ravel() / SEGMENT_SAMPLES
    sums = _sums(np.tile(lam, (G, 1)), start, step, SEGMENT_SAMPLES, np.tile(weights, (G, 1, 1)))
    times = start[:, None] + step[:, None] * np.arange(SEGMENT_SAMPLES)
    times = np.concatenate([times[g * K : (g + 1) * K] for g in range(G)], axis=-1)
    return times, np.concatenate([sums[g * K : (g + 1) * K] for g in range(G)], axis=-1)


def _last_on_y(
    lam: np.ndarray, a: np.ndarray, oscillating: np.ndarray, t_env: np.ndarray, level: np.ndarray
) -> np.ndarray:
    """The last time |y| itself reaches ``level``: at or before ``t_env``, where the envelope does. Where an
    oscillation is part of the envelope there, |y| last reaches it on a swing within one turn of the
    largest one before: sampled over that turn, the crossing bisected on the flank after the last sample."""
    e = np.exp(lam * np.where(np.isfinite(t_env), t_env, 0.0)[:, None])
    swings = np.abs(np.where(oscillating, a, 0.0) * e)
    turning = np.isfinite(t_env) & (t_env > 0) & (swings.sum(axis=1) > 0.01 * level)
    if not turning.any():
        return t_env
    rows = np.flatnonzero(turning)
    lam, a = lam[rows], a[rows]
    omega = np.abs(np.take_along_axis(lam, np.argmax(swings[rows], axis=1)[:, None], 1)[:, 0].imag)
    end = t_env[rows]
    begin = np.maximum(end - 2 * np.pi / omega, 0.0)
    step = (end - begin) / SETTLE_SAMPLES
    y = np.abs(_sums(lam, begin, step, SETTLE_SAMPLES + 1, a[:, None])[:, 0].real)
    above = y >= level[rows, None]
    last = np.where(above.any(axis=1), SETTLE_SAMPLES - np.argmax(above[:, ::-1], axis=1), 0)
    lo, hi = begin + step * last, begin + step * np.minimum(last + 1, SETTLE_SAMPLES)
    for _ in range(BISECTIONS):  # |y| falls through the level between lo (above) and hi (under)
        mid = 0.5 * (lo + hi)
        high = np.abs((a * np.exp(lam * mid[:, None])).sum(axis=1).real) >= level[rows]
        lo, hi = np.where(high, mid, lo), np.where(high, hi, mid)
    out = t_env.copy()
    out[rows] = np.where(above.any(axis=1), lo, begin)
    return out


def _peak(lam: np.ndarray, a: np.ndarray, times: np.ndarray, y: np.ndarray, pushed: np.ndarray) -> np.ndarray:
    """The peak of |y|: the largest of the push's samples ``pushed`` (K, J) and of |y| sampled after it at
    ``times`` (K, N), the largest of these refined by Newton on y' = 0."""
    best = np.argmax(y, axis=1)
    tp = np.take_along_axis(times, best[:, None], 1)[:, 0]
    spacing = np.diff(times, axis=1)
    reach = np.take_along_axis(spacing, np.minimum(best, spacing.shape[1] - 1)[:, None], 1)[:, 0]
    for _ in range(2):
        e = np.exp(lam * tp[:, None])
        d1, d2 = (a * lam * e).sum(axis=1).real, (a * lam * lam * e).sum(axis=1).real
        with np.errstate(divide="ignore", invalid="ignore"):
            tp = np.maximum(tp + np.clip(np.nan_to_num(-d1 / d2), -reach, reach), 0.0)
    top = np.abs((a * np.exp(lam * tp[:, None])).sum(axis=1).real)
    return np.maximum.reduce([pushed.max(axis=1), y.max(axis=1), top])


def reason_text(code: int, swing: float) -> str:
    """The words for a reason code of :class:`KickResponse` ('' for a kept prediction)."""
    return REASONS[int(code)].format(swing=swing, max=MAX_SWING_RAD)
