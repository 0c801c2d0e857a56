"""What a kick does to the linearised loop: the base deflection's peak, its time to 10 %, its decay, the arm's swing.

After a half-sine push of ``Kick.peak`` N lasting ``Kick.duration`` s the base deflection y (the kicked
coordinate) is a sum of the loop's modes. With lambda_i the poles, v_i, w_i right and left eigenvectors
(w_i^H v_j = delta_ij), C picking y and B the force input (per N, per step of the step map):

    y(T + tau) = Re sum_i a_i e^(lambda_i tau),   a_i = (C v_i)(w_i^H B d) F xi_i(T),

xi_i(T) being mode i's state at the push's end T (closed form of the sampled half-sine, below), each
complex pair's part on its upper pole (Re(a e + conj) = Re(2 a e)). E = sum |a_i| e^(-sigma_i tau) bounds
|y|. From y (:mod:`rns_viz.analysis.modal_sums`):

- peak P: max |y| (through the push at every control step, as the simulator logs it, where its modes'
  bound allows more than the rest; after it, scanned forward while E can exceed the largest top found, the
  sampled tops near it refined);
- settle time: after the push's end, the last time |y| reaches 10 % of P: scanned back from where E falls
  to that level, a turn of the slowest swing at a time, the tops between samples refined, then solved for;
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

from rns_viz.analysis import modal_sums
from rns_viz.defaults import defaults_for
from rns_viz.model import FsmsModel

SETTLE_LEVEL = 0.1  # "time to 10 %"
UPPER_LEVEL = 0.05  # the swing is sampled until E falls under this fraction of the push's largest deflection
LN10 = math.log(10.0)
MAX_SWING_RAD = 0.5  # rad: beyond this joint swing the configuration-dependent terms change too much
PULSE_SAMPLES = 6  # samples of y during the push (its middle among them)
# the integral of L is sampled evenly within segments of the time after the push: to where y's largest
# term first turns back (at most the first fraction below), then between these fractions of a time when E
# is surely under 5 % of the peak ...
SEGMENTS = (0.0, 1 / 64, 1 / 16, 1 / 4, 1.0)
SEGMENT_SAMPLES = 6  # ... this many samples each
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


def pulse_modes(lam: np.ndarray, mu: np.ndarray | None, dt: float, duration: float) -> tuple[np.ndarray, np.ndarray]:
    """xi_i through a unit half-sine push as modes: xi_i(t) = c_i e^(lambda_i t) + b_i+ e^(i w t) + b_i- e^(-i w t),
    w = pi / duration (for the step map at its steps t = k dt). c (..., s), b (..., s, 2).

    Step map (``mu`` given): xi_{k+1} = mu xi_k + sin(w dt (k + 1/2)), the force at mid-step (the simulator
    samples it at RK4's stages, of which the midpoint carries 2/3):
        xi_K = [e^(i w dt/2) (mu^K - z^K) / (mu - z) - c.c.(z)] / 2i,   z = e^(i w dt).
    Continuous (``mu`` None): xi' = lambda xi + sin(w t), xi(t) = (w e^(lambda t) - w cos wt - lambda sin wt)
    / (lambda^2 + w^2).
    """
    w = math.pi / duration
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):  # a growing loop may overflow: unstable
        if mu is None:
            denominator = lam * lam + w * w
            b = np.stack([-0.5 * w - lam / 2j, -0.5 * w + lam / 2j], axis=-1) / denominator[..., None]
            return w / denominator, b
        diff = mu[..., None] - np.exp(np.array([1j, -1j]) * w * dt)
        diff = np.where(np.abs(diff) < 1e-12, 1e-12, diff)  # mu at the pulse's frequency: never in practice
        g = np.array([1.0, -1.0]) * np.exp(np.array([0.5j, -0.5j]) * w * dt) / (2j * diff)  # (..., s, 2)
        return g.sum(axis=-1), -g


def pulse_states(
    lam: np.ndarray,
    mu: np.ndarray | None,
    dt: float,
    duration: float,
    steps: np.ndarray,
    modes: tuple[np.ndarray, np.ndarray] | None = None,
) -> np.ndarray:
    """xi_i after ``steps`` (J,) control steps into a unit half-sine push, (..., s, J), from :func:`pulse_modes`
    (``modes``: its (c, b) if already at hand)."""
    t = np.asarray(steps, dtype=float) * dt
    c, b = pulse_modes(lam, mu, dt, duration) if modes is None else modes
    swing = np.exp(1j * (math.pi / duration) * t)  # e^(+i w t); e^(-i w t) is its conjugate
    with np.errstate(over="ignore", invalid="ignore"):  # a growing loop's modes may overflow: it is unstable anyway
        return _powers(lam, t) * c[..., None] + b[..., :1] * swing + b[..., 1:] * swing.conj()


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


def respond(
    lam: np.ndarray,
    a: np.ndarray,
    a_L: np.ndarray,
    y_pulse: np.ndarray,
    L_pulse: np.ndarray,
    swing_map: np.ndarray,
    pulse_times: np.ndarray,
    margins: tuple[np.ndarray, np.ndarray],
    push: tuple[np.ndarray, np.ndarray, float, int],
) -> KickResponse:
    """The kick's effect on K stable loops.

    lam (K, s): the poles (1/s) that carry y and L after the push; a (K, s), a_L (K, r, s): their parts in
    y and in L = S H_bm theta' at the push's end, y(T + tau) = Re sum a e^(lambda tau); y_pulse (K, J) and
    L_pulse (K, r, J): y and L during the push at ``pulse_times`` (J,) s, the last at its end; swing_map
    (n, r): (S H_bm)^+; margins: how far each joint may turn down and up to its limits (n,), rad; push: y
    through the push as a sum of modes (poles (K, p), parts (K, p)), and the control step (s) and steps in it.
    """
    K = len(lam)
    a, a_L = fold_pairs(lam, a), fold_pairs(lam, a_L)
    sigma = -lam.real
    terms = np.abs(a)
    with np.errstate(divide="ignore", invalid="ignore"):
        a_int = np.where(lam[:, None, :] != 0, a_L / lam[:, None, :], 0.0)  # integral of L after the push, per mode

    # The integral of L after the push on a grid finer near its end (to where y's largest term first turns
    # back, then in segments), until the bound on |y| is under 5 % of the push's largest deflection.
    at_pulse = np.abs(y_pulse)
    horizon = _bound_time(sigma, terms, UPPER_LEVEL * at_pulse.max(axis=1))
    big = lam[np.arange(K), np.argmax(terms, axis=1)]
    with np.errstate(divide="ignore"):  # where the largest term first turns back: the swing is largest near
        turn = np.where(big.imag != 0, np.pi / np.abs(big.imag), 1.0 / -big.real)
    edges = np.stack([np.zeros(K), np.minimum(turn, horizon * SEGMENTS[1]), *(horizon * f for f in SEGMENTS[1:])], 1)
    sums = _grid(lam, edges, a_int)
    peak = modal_sums.peak(lam, a, at_pulse.max(axis=1))
    peak = np.maximum(peak, _push_peak(*push, peak))
    level = SETTLE_LEVEL * peak
    t10 = modal_sums.last_above(lam, a, modal_sums.envelope_time(sigma, terms, level), level)
    with np.errstate(divide="ignore", invalid="ignore"):
        decay = LN10 / t10  # the mean rate from the kick's end to 10 % of the peak
        at_10 = terms * np.exp(-sigma * t10[:, None])  # the pole whose term is largest at 10 %
    top = np.argmax(at_10, axis=1)

    # Arm swing: the integral of L over the push (trapezoid), after it (closed form) and in the end.
    dtau = np.diff(np.concatenate([[0.0], pulse_times]))
    before = np.concatenate([np.zeros_like(L_pulse[..., :1]), L_pulse[..., :-1]], 2)
    inside = np.cumsum(0.5 * (L_pulse + before) * dtau, 2)
    offset = inside[..., -1] - a_int.sum(axis=-1).real  # the integral at the push's end, minus the modes' start
    integral = np.concatenate([inside, sums.real + offset[..., None], offset[..., None]], 2)
    joints = swing_map @ integral  # (K, n, samples)
    lowest, highest = joints.min(axis=2), joints.max(axis=2)
    swing = np.maximum(-lowest.min(axis=1), highest.max(axis=1))
    down, up = margins
    passes = np.any((lowest < -down) | (highest > up), axis=1)

    reason = np.full(K, KEPT)
    reason[t10 <= 0] = WITHIN_KICK
    reason[swing > MAX_SWING_RAD] = SWING
    reason[passes] = LIMIT
    return KickResponse(peak, t10, decay, top, swing, reason)


def _push_peak(lam: np.ndarray, a: np.ndarray, dt: float, steps: int, floor: np.ndarray) -> np.ndarray:
    """max |y| over the control steps through the push (as the simulator logs them) where the sum of its modes'
    parts (bounding it, none grows) exceeds ``floor`` (K,); 0 elsewhere."""
    out = np.zeros(len(lam))
    rows = np.flatnonzero(np.abs(a).sum(axis=1) > floor)
    if len(rows):
        at = np.full(len(rows), dt)
        out[rows] = np.abs(modal_sums.grid_sums(lam[rows], at, at, steps, a[rows, None])[:, 0].real).max(axis=1)
    return out


def _grid(lam: np.ndarray, edges: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """sum_i w_i e^(lambda_i tau) for weights (K, W, s), tau evenly within each segment between ``edges``
    (K, G + 1) s after the push: (K, W, G SEGMENT_SAMPLES)."""
    step = np.diff(edges, axis=1) / SEGMENT_SAMPLES
    return modal_sums.grid_sums(lam, edges[:, :-1], step, SEGMENT_SAMPLES, weights)


def reason_text(code: int, swing: float) -> str:
    """The words for a reason code of :class:`KickResponse` ('' for a kept prediction)."""
    return REASONS[int(code)].format(swing=swing, max=MAX_SWING_RAD)
