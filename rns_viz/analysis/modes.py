"""Closed-loop modes, the base's response to the loop's kick, and the base/arm grouping, batched over gains.

What the map predicts is what a student sees after pressing Kick (:mod:`rns_viz.analysis.kick`): the
base deflection's peak, its time to 10 % of the peak and the mean decay rate that makes, and whether the
linear loop can speak for that run at all. The base group is the modes whose part in that response
reaches ``BASE_SHARE`` of its peak, the arm group the rest (in a growing loop every mode the base shows
at all is the base's: the fastest growth takes over).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rns_viz.analysis.kick import (
    KEPT,
    KEPT_PART,
    KickResponse,
    fold_pairs,
    pulse_modes,
    pulse_states,
    pulse_steps,
    reason_text,
    respond,
)
from rns_viz.analysis.linear import LinearLoop

BASE_SHARE = 0.05  # a mode whose part in the kick response reaches this fraction of its peak is the base's
UNSTABLE_SHARE = 1e-6  # in a growing loop, every mode with more than this share (numerically not 0) is the base's
STABLE_MARGIN = 1e-6  # 1/s: stable if every kept mode decays faster than this
LN10 = float(np.log(10.0))


@dataclass(frozen=True)
class Modes:
    """Eigen-analysis and kick response at K gain settings (leading shape ``shape``); rates in 1/s."""

    poles: np.ndarray  # (*shape, d) complex lambda, 1/s (continuous-equivalent for the step map)
    base_share: np.ndarray  # (*shape, d) each mode's envelope in the kick response over its peak (0 if unseen)
    is_base: np.ndarray  # (*shape, d) bool: the base group (base_share >= BASE_SHARE)
    base_decay_rate: np.ndarray  # (*shape,) sigma_b: the deflection's decay as it passes 10 % (growing: -max Re)
    arm_decay_rate: np.ndarray  # (*shape,) sigma_a over the arm group (nan if the group is empty), 1/s
    base_damping_ratio: np.ndarray  # (*shape,) -Re/|lambda| of the pole that dominates at 10 % (1 if real)
    base_frequency: np.ndarray  # (*shape,) |Im lambda| of that pole, rad/s
    stable: np.ndarray  # (*shape,) bool: every kept mode decays (rate > STABLE_MARGIN)
    base_time_to_10pct: np.ndarray  # (*shape,) s after the kick's end until |x_b| stays under 10 % of its peak
    peak: np.ndarray  # (*shape,) the kick's peak deflection, m (rad on a rotation)
    swing: np.ndarray  # (*shape,) rad: the joints' largest swing outside the RNS while absorbing the kick
    reason: np.ndarray  # (*shape,) int: why the prediction is not kept (kick.REASONS; 0: kept)

    @property
    def predictable(self) -> np.ndarray:
        """Stable and the linear loop speaks for the kick's run (``reason`` 0)."""
        return self.stable & (self.reason == KEPT)

    @property
    def arm_time_to_10pct(self) -> np.ndarray:
        """ln 10 / sigma_a, s (inf where the arm does not decay)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(self.arm_decay_rate > 0, LN10 / self.arm_decay_rate, np.inf)

    def why_not(self, index: tuple[int, ...] = ()) -> str:
        """Why the prediction at ``index`` is not kept, in words ('' if it is; 'unstable' if it grows)."""
        if not bool(self.stable[index]):
            return "the loop is unstable"
        return reason_text(int(self.reason[index]), float(self.swing[index]))


def modes_of(loop: LinearLoop, g_b: float | np.ndarray, g_m: float | np.ndarray) -> Modes:
    """Poles, the kick response and the base/arm grouping at gains (1/s) that broadcast together.

    In ``loop.basis`` A is block triangular: eigenvectors are needed only for the block x_b can
    show (the last ``loop.seen`` states); the other block's poles have no share in x_b.
    """
    T, d = loop.basis, len(loop.basis)
    k = d - loop.seen
    blocks = [T.T @ A @ T for A in (loop.A0, loop.A_b, loop.A_m)]
    gb = np.asarray(g_b, dtype=float)[..., None, None]
    gm = np.asarray(g_m, dtype=float)[..., None, None]
    shape = np.broadcast_shapes(gb.shape, gm.shape)[:-2]
    seen_blocks = [B[k:, k:] for B in blocks]  # the block x_b can show, at every gain setting
    mu, V = np.linalg.eig((seen_blocks[0] + gb * seen_blocks[1] + gm * seen_blocks[2]).reshape(-1, d - k, d - k))
    kick = loop.kick
    observed = T[:, k:]
    C_y = kick.output @ observed[np.flatnonzero(loop.kept < loop.m)]  # (seen,): y on the observable block
    C_L = loop.coupling @ loop.joint_rates @ observed  # (r, seen): L = S H_bm theta'
    b = observed.T @ loop.force_input @ kick.weights
    try:  # (K, seen): w_i^H B d, the left eigenvectors scaled so that W V = E
        forcing = np.linalg.solve(V, np.broadcast_to(b, (len(V), len(b)))[..., None])[..., 0]
    except np.linalg.LinAlgError:  # a defective pole somewhere in the batch (V singular there)
        forcing = np.linalg.pinv(V) @ b
    y_gain = (C_y @ V) * forcing  # (K, seen)
    seen = loop.rates(mu)
    hidden = _hidden_poles(blocks, k, np.broadcast_to(gb, (*shape, 1, 1)), np.broadcast_to(gm, (*shape, 1, 1)))
    lam = np.concatenate((loop.rates(hidden), seen), axis=1)
    re = lam.real
    stable = -re.max(axis=1) > STABLE_MARGIN
    count = len(stable)

    # Every mode's state through the push, its envelope after it, then the response where the loop is stable.
    steps = pulse_steps(kick, loop.dt)
    discrete = mu if loop.view == "discrete" else None
    c, b = pulse_modes(seen, discrete, loop.dt, kick.duration)  # the push as modes, for y between the samples
    xi = pulse_states(seen, discrete, loop.dt, kick.duration, steps, (c, b))  # (K, seen, J)
    after = kick.peak * y_gain * xi[..., -1]
    pair = np.abs(fold_pairs(seen, after))
    pair = np.where(seen.imag < 0, np.abs(2 * after), pair)  # the lower pole shows its pair's amplitude too
    amplitude = np.concatenate((np.zeros(hidden.shape), pair), axis=1)
    peak, settle, swing = (np.full(count, np.nan) for _ in range(3))
    reason = np.full(count, KEPT)
    base_rate = np.full(count, np.nan)
    dominant = np.zeros(count, dtype=int)
    if stable.any():
        rows = np.flatnonzero(stable)
        push = kick.peak * y_gain[rows] * c[rows], kick.peak * (y_gain[rows, :, None] * b[rows]).sum(axis=1)
        resp = _respond(loop, seen[rows], xi[rows], V[rows], forcing[rows], y_gain[rows], C_L, steps, push)
        peak[rows], settle[rows], swing[rows], reason[rows] = resp.peak, resp.settle_time, resp.swing, resp.reason
        base_rate[rows] = resp.decay_rate
        dominant[rows] = k + resp.dominant
    scale = np.where(stable, peak, amplitude.max(axis=1))
    share = amplitude / np.maximum(scale, 1e-300)[:, None]
    # a growing mode the base shows at all takes over in the end
    is_base = np.where(stable[:, None], share >= BASE_SHARE, share > UNSTABLE_SHARE)
    is_base[np.arange(count), dominant] |= stable
    slowest = np.argmax(np.where(is_base, re, -np.inf), axis=1)
    dominant = np.where(stable, dominant, slowest)
    base_rate = np.where(stable, base_rate, -re[np.arange(count), slowest])
    s = lam[np.arange(count), dominant]
    arm_rate = np.where(is_base.all(axis=1), np.nan, -np.where(is_base, -np.inf, re).max(axis=1))
    with np.errstate(divide="ignore", invalid="ignore"):
        zeta = np.where(np.abs(s) > 0, -s.real / np.abs(s), 1.0)
    return Modes(
        poles=lam.reshape(*shape, d),
        base_share=share.reshape(*shape, d),
        is_base=is_base.reshape(*shape, d),
        base_decay_rate=base_rate.reshape(shape),
        arm_decay_rate=arm_rate.reshape(shape),
        base_damping_ratio=zeta.reshape(shape),
        base_frequency=np.abs(s.imag).reshape(shape),
        stable=stable.reshape(shape),
        base_time_to_10pct=np.where(stable, settle, np.inf).reshape(shape),
        peak=peak.reshape(shape),
        swing=swing.reshape(shape),
        reason=reason.reshape(shape),
    )


def _respond(
    loop: LinearLoop,
    lam: np.ndarray,
    xi: np.ndarray,
    V: np.ndarray,
    forcing: np.ndarray,
    y_gain: np.ndarray,
    C_L: np.ndarray,
    steps: np.ndarray,
    push: tuple[np.ndarray, np.ndarray],
) -> KickResponse:
    """The kick's response at K stable loops from their observable modes (lam, forcing, y_gain: (K, s); V
    (K, s, s); xi (K, s, J) the modes' states through the push at ``steps``; ``push``: y through the push as
    modes, its parts on lam (K, s) and on e^(+-i w t) (K, 2)); its ``dominant`` indexes these modes.

    Through the push every mode counts (fast ones too: they cancel slower ones while it lasts); after it,
    :func:`~rns_viz.analysis.kick.respond` follows the modes with a part in y or in the integral of L (a
    pair's on its upper pole, the lower goes) of at least KEPT_PART of the largest: modes that cancel each
    other stay together. The loops go in two batches by how many modes they need (each batch is padded to
    its largest, with parts 0).
    """
    kick = loop.kick
    w = np.pi / kick.duration
    push_lam = np.concatenate([lam, np.broadcast_to([1j * w, -1j * w], (len(lam), 2))], axis=1)
    push_a = np.concatenate(push, axis=1)
    push_steps = int(steps[-1])
    L_gain = (C_L @ V) * forcing[:, None, :]  # (K, r, s)
    y_pulse = kick.peak * (y_gain[:, None, :] @ xi)[:, 0].real
    L_pulse = kick.peak * (L_gain @ xi).real
    a, a_L = kick.peak * y_gain * xi[..., -1], kick.peak * L_gain * xi[:, None, :, -1]
    part = np.abs(fold_pairs(lam, a))
    part_L = np.linalg.norm(fold_pairs(lam, a_L), axis=1) / np.abs(lam)
    with np.errstate(invalid="ignore"):
        part = np.nan_to_num(part / part.max(axis=1, keepdims=True) + part_L / part_L.max(axis=1, keepdims=True))
    needed = np.maximum((part >= KEPT_PART).sum(axis=1), 1)
    order = np.argsort(-part, axis=1)
    split = int(np.percentile(needed, 80))
    swing_map = loop.swing_map
    out = [np.empty(len(lam)) for _ in range(4)]
    reason, dominant = np.empty(len(lam), dtype=int), np.empty(len(lam), dtype=int)
    for rows in (np.flatnonzero(needed <= split), np.flatnonzero(needed > split)):
        if len(rows) == 0:
            continue
        take = order[rows, : int(needed[rows].max())]
        real = np.take_along_axis(part[rows], take, 1) >= KEPT_PART  # the batch's padding counts 0
        lam_p, a_p, a_L_p = (_modes(x[rows], take) for x in (lam, a, a_L))
        through = (push_lam[rows], push_a[rows], loop.dt, push_steps)
        got = respond(lam_p, a_p * real, a_L_p * real[:, None, :], y_pulse[rows], L_pulse[rows], swing_map,
                      steps * loop.dt, loop.joint_margins, through)  # fmt: skip
        for store, value in zip(out, (got.peak, got.settle_time, got.decay_rate, got.swing), strict=True):
            store[rows] = value
        reason[rows] = got.reason
        dominant[rows] = take[np.arange(len(rows)), got.dominant]
    return KickResponse(*out[:3], dominant, out[3], reason)


def _modes(x: np.ndarray, take: np.ndarray) -> np.ndarray:
    """The modes ``take`` (K, p) of x (K, s) or (K, r, s)."""
    return np.take_along_axis(x, take if x.ndim == 2 else take[:, None, :], axis=-1)


def _hidden_poles(blocks: list[np.ndarray], k: int, gb: np.ndarray, gm: np.ndarray) -> np.ndarray:
    """Eigenvalues of the block x_b never shows, (K, k), solved once per distinct value of the gains
    it depends on (the arm's motion in the RNS sees g_m only: x_b, which g_b multiplies, is zero there).
    """
    H0, Hb, Hm = (A[:k, :k] for A in blocks)
    gains = np.stack([gb.ravel(), gm.ravel()], axis=1)  # (K, 2)
    if k == 0:
        return np.empty((len(gains), 0), dtype=complex)
    scale = max(np.abs(H0).max(), 1.0)
    used = np.array([np.abs(H).max() > 1e-9 * scale for H in (Hb, Hm)])
    if used.sum() == 1:  # a 1-D unique is many times faster than one over rows
        unique, index = np.unique(gains[:, used][:, 0], return_inverse=True)
        unique = unique[:, None]
    else:
        unique, index = np.unique(gains[:, used], axis=0, return_inverse=True)
    values = np.zeros((len(unique), 2))
    values[:, used] = unique
    H = H0 + values[:, 0, None, None] * Hb + values[:, 1, None, None] * Hm
    return np.linalg.eigvals(H)[index.ravel()]
