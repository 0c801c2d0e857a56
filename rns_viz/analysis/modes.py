"""Closed-loop modes split into the base mode and the arm modes, batched over many gain settings.

Which modes are "the base": those the base deflection shows after a kick. For mode i with right and
left eigenvectors v_i, w_i (w_i^H v_j = delta_ij) the response of x_b to an impulse of base force is
sum_i (C v_i)(w_i^H B) e^(lambda_i t), C picking x_b and B = (0, M^-1 S^T) the velocity jump of a unit
impulse. The share of mode i, ||C v_i|| ||w_i^H B|| over the sum of all, is unit-free (scaling a state
coordinate scales v_i and w_i inversely). Modes with at least ``BASE_SHARE`` form the base group,
the rest the arm group. (The classical participation factors |v_ki w_ki| of x_b, x_b' misplace the
arm's slow return at high g_b and low g_m, which moves the base while the base states barely steer
it: the kick share counts it as base, which is what a student measures after a kick.)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rns_viz.analysis.linear import LinearLoop

BASE_SHARE = 0.05  # a mode with at least this share of x_b's kick response belongs to the base group
STABLE_MARGIN = 1e-6  # 1/s: stable if every kept mode decays faster than this
LN10 = float(np.log(10.0))


@dataclass(frozen=True)
class Modes:
    """Eigen-analysis at K gain settings (leading shape ``shape``); rates in 1/s."""

    poles: np.ndarray  # (*shape, d) complex lambda, 1/s (continuous-equivalent for the step map)
    base_share: np.ndarray  # (*shape, d) share of x_b's response to a base impulse, sums to 1
    is_base: np.ndarray  # (*shape, d) bool: the base group (base_share >= BASE_SHARE)
    base_decay_rate: np.ndarray  # (*shape,) sigma_b = -max Re lambda over the base group, 1/s
    arm_decay_rate: np.ndarray  # (*shape,) sigma_a over the arm group (nan if the group is empty), 1/s
    base_damping_ratio: np.ndarray  # (*shape,) -Re/|lambda| of the slowest base pole (1 if real)
    base_frequency: np.ndarray  # (*shape,) |Im lambda| of the slowest base pole, rad/s
    stable: np.ndarray  # (*shape,) bool: every kept mode decays (rate > STABLE_MARGIN)

    @property
    def base_time_to_10pct(self) -> np.ndarray:
        """ln 10 / sigma_b, s (inf where the base does not decay)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(self.base_decay_rate > 0, LN10 / self.base_decay_rate, np.inf)

    @property
    def arm_time_to_10pct(self) -> np.ndarray:
        """ln 10 / sigma_a, s (inf where the arm does not decay)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(self.arm_decay_rate > 0, LN10 / self.arm_decay_rate, np.inf)


def modes_of(loop: LinearLoop, g_b: float | np.ndarray, g_m: float | np.ndarray) -> Modes:
    """Poles and their base/arm grouping at gains (1/s) that broadcast together.

    In ``loop.basis`` A is block triangular: eigenvectors are needed only for the block x_b can
    show (the last ``loop.seen`` states); the other block's poles have no share in x_b.
    """
    T, d = loop.basis, len(loop.basis)
    k = d - loop.seen
    blocks = [T.T @ A @ T for A in (loop.A0, loop.A_b, loop.A_m)]
    gb = np.asarray(g_b, dtype=float)[..., None, None]
    gm = np.asarray(g_m, dtype=float)[..., None, None]
    shape = np.broadcast_shapes(gb.shape, gm.shape)[:-2]
    A = (blocks[0] + gb * blocks[1] + gm * blocks[2]).reshape(-1, d, d)
    mu, V = np.linalg.eig(A[:, k:, k:])
    try:
        W = np.linalg.inv(V)  # rows are the left eigenvectors, scaled so that W V = E
    except np.linalg.LinAlgError:  # a defective pole somewhere in the batch (V singular there)
        W = np.linalg.pinv(V)
    C = T[np.flatnonzero(loop.kept < loop.m)][:, k:]  # (m, seen): x_b on the observable block
    B = (T.T @ loop.impulse_input())[k:]  # (seen, m); C (sI - A)^-1 B involves this block only
    residue = np.linalg.norm(C @ V, axis=1) * np.linalg.norm(W @ B, axis=2)  # ||C v_i|| ||w_i^H B||
    share = residue / np.maximum(residue.sum(axis=1, keepdims=True), 1e-300)
    hidden = _hidden_poles(blocks, k, np.broadcast_to(gb, (*shape, 1, 1)), np.broadcast_to(gm, (*shape, 1, 1)))
    lam = loop.rates(np.concatenate((hidden, mu), axis=1))
    share = np.concatenate((np.zeros(hidden.shape), share), axis=1)
    is_base = share >= BASE_SHARE
    re = lam.real
    slowest = np.argmax(np.where(is_base, re, -np.inf), axis=1)
    s = np.take_along_axis(lam, slowest[:, None], axis=1)[:, 0]
    arm_rate = np.where(is_base.all(axis=1), np.nan, -np.where(is_base, -np.inf, re).max(axis=1))
    with np.errstate(divide="ignore", invalid="ignore"):
        zeta = np.where(np.abs(s) > 0, -s.real / np.abs(s), 1.0)
    return Modes(
        poles=lam.reshape(*shape, d),
        base_share=share.reshape(*shape, d),
        is_base=is_base.reshape(*shape, d),
        base_decay_rate=(-s.real).reshape(shape),
        arm_decay_rate=arm_rate.reshape(shape),
        base_damping_ratio=zeta.reshape(shape),
        base_frequency=np.abs(s.imag).reshape(shape),
        stable=(-re.max(axis=1) > STABLE_MARGIN).reshape(shape),
    )


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
    unique, index = np.unique(gains[:, used], axis=0, return_inverse=True)
    values = np.zeros((len(unique), 2))
    values[:, used] = unique
    H = H0 + values[:, 0, None, None] * Hb + values[:, 1, None, None] * Hm
    return np.linalg.eigvals(H)[index.ravel()]
