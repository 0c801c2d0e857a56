"""Reactionless paths: integral curves of the null-space vector n (Def. 3, Eq. 27, Fig. 8).

For a 1-D RNS each path solves d theta/ds = n / |n| (arc length s in joint space, rad), traced
with fixed-step RK4 (:func:`rns_viz.rns.rk4_along`) for many seeds at once, until it closes on itself,
reaches a joint limit, nears a singularity (|n| small, H_bm losing rank) or reaches ``max_length``.
For a 2-D RNS (the planar 3R) see :func:`rns_viz.paths.reactionless_reachable_set`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rns_viz.model import FsmsModel
from rns_viz.paths.field import TWO_PI, CouplingField, periodic_joints, right_inverse_times
from rns_viz.rns import null_vector, rk4_along

MAX_TURN = 0.15  # rad the tangent may turn in one step; steps shrink on tight loops


@dataclass(frozen=True)
class ReactionlessPath:
    """One integral curve of n."""

    theta: np.ndarray  # (k, n) joint angles, rad
    s: np.ndarray  # (k,) arc length in joint space from the first point, rad
    ee: np.ndarray  # (k, 3) end-effector positions in the base frame, m
    end: str  # why tracing stopped: "closed", "joint limit", "singularity" or "max length"


class _NullField(CouplingField):
    """Unit null-space direction n/|n| of a 1-D RNS (Eq. 27, generalised) at many configurations."""

    def __init__(self, model: FsmsModel) -> None:
        rns_dim = model.n - len(model.selected)
        if rns_dim != 1:
            raise ValueError(
                f"{model.name}: reactionless paths are curves only for a 1-D RNS; this model's RNS "
                f"has dimension {rns_dim} (use reactionless_reachable_set)"
            )
        super().__init__(model)

    def __call__(
        self, thetas: np.ndarray, want_potential: bool = False
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]:
        """Unit n (K, n), |n| (K,), rows S H_bm (K, r, n) and, if asked and defined, potentials (K, r)."""
        H, pot = self.rows_at(thetas, want_potential)
        out = null_vector(H)
        norm = np.sqrt(np.einsum("ij,ij->i", out, out))
        return out / np.maximum(norm, 1e-300)[:, None], norm, H, pot


def trace_paths(
    model: FsmsModel,
    seeds: np.ndarray,
    ds: float = 0.2,
    max_length: float = 60.0,
    singular_norm: float | None = None,
) -> list[ReactionlessPath]:
    """Integral curves of n through each seed (K, n), traced both ways unless they close.

    ``ds`` is the largest step in joint-space arc length (rad); a step is shortened so the
    tangent turns at most MAX_TURN over it. Joints whose limits span at least a
    full turn are periodic: a curve closes when it returns to its seed modulo 2 pi.
    A translating base has a potential of the coupling momentum, w x_cm (Eq. 26), constant on
    every reactionless path: there a Heun predictor is followed by a Newton and a chord step
    along H_bm back onto the seed's level (a projection method, Hairer et al., Geometric
    Numerical Integration IV.4), which keeps the invariant to rounding instead of letting it
    drift. Other bases take plain RK4 steps.
    ``singular_norm`` (units of ``|n|``) stops a curve near rank loss of H_bm; by default it is
    1e-2 of the largest ``|n|`` seen at the seeds.
    """
    if not (np.isfinite(ds) and ds > 0):
        raise ValueError(f"ds must be a positive step in rad, got {ds}")
    seeds = np.atleast_2d(np.asarray(seeds, dtype=float))
    field = _NullField(model)
    seed_norm = field(seeds)[1]
    if singular_norm is None:
        singular_norm = 1e-2 * max(float(seed_norm.max()), 1e-300)
    forward = _trace_one_way(model, field, seeds, ds, max_length, singular_norm, +1.0)
    open_idx = [k for k, f in enumerate(forward) if f[1] != "closed"]
    backward = _trace_one_way(model, field, seeds[open_idx], ds, max_length, singular_norm, -1.0) if open_idx else []
    back_of = dict(zip(open_idx, backward, strict=True))
    paths = []
    for k, (points, end) in enumerate(forward):
        if k in back_of:
            back_points, back_end = back_of[k]
            points = np.vstack([back_points[::-1], points[1:]])
            end = end if end == back_end else f"{back_end} / {end}"
        steps = np.sqrt(np.einsum("ij,ij->i", *(2 * [np.diff(points, axis=0)])))
        s = np.concatenate([[0.0], np.cumsum(steps)])
        paths.append(ReactionlessPath(points, s, model.ee_positions(points), end))
    return paths


def _trace_one_way(
    model: FsmsModel,
    field: _NullField,
    seeds: np.ndarray,
    ds: float,
    max_length: float,
    singular_norm: float,
    sign: float,
) -> list[tuple[np.ndarray, str]]:
    """Step all seeds in lock-step; returns each curve's points and why it stopped."""
    K = len(seeds)
    periodic = periodic_joints(model)
    lower, upper = model.lower, model.upper
    ends = np.full(K, "", dtype=object)
    active = np.arange(K)
    left_seed = np.zeros(K, dtype=bool)
    length = np.zeros(K)
    h = np.full(K, ds)  # per-curve step: ds, shortened where the path turns fast
    th = seeds.copy()
    k1, n1, _, levels = field(th, want_potential=True)
    recorded_idx, recorded_pts = [np.arange(K)], [seeds.copy()]
    stages: list[tuple[np.ndarray, np.ndarray]] = []  # unit n and |n| at RK4 stages 2-4 of a step

    def direction(_s: np.ndarray, x: np.ndarray) -> np.ndarray:
        unit, norm, _, _ = field(x)
        stages.append((unit, norm))
        return sign * unit

    while active.size:
        k1 *= sign
        hk = h[active][:, None]
        if levels is None:  # RK4 on d theta/ds = n/|n|
            stages.clear()
            new = rk4_along(direction, 0.0, th, hk, k1)
            (_, n2), (_, n3), (k4, n4) = stages
            k4 = sign * k4
            smallest = np.minimum(np.minimum(n1, n2), np.minimum(n3, n4))
            k1_next, n1_next, _, _ = field(new)
        else:  # Heun predictor, then Newton + chord corrector onto the seed's level c(theta) = c_seed
            k4, n4, _, _ = field(th + hk * k1)
            k4 *= sign
            new = th + 0.5 * hk * (k1 + k4)
            smallest = np.minimum(n1, n4)
            k1_next, n1_next, H, pot = field(new, want_potential=True)
            new -= right_inverse_times(H, pot - levels[active])
            for _chord in range(2):
                new -= right_inverse_times(H, field.potentials(new) - levels[active])
        smallest = np.minimum(smallest, n1_next)
        turn = np.sqrt(np.einsum("ij,ij->i", k4 - k1, k4 - k1))  # tangent turn over the step, rad
        delta = new - seeds[active]
        delta[:, periodic] = (delta[:, periodic] + np.pi) % TWO_PI - np.pi
        dist = np.sqrt(np.einsum("ij,ij->i", delta, delta))
        length[active] += hk[:, 0]
        singular = smallest < singular_norm
        outside = np.any(~periodic & ((new < lower) | (new > upper)), axis=1) & ~singular
        closed = left_seed[active] & (dist < 0.6 * hk[:, 0]) & ~singular & ~outside
        too_long = (length[active] >= max_length) & ~singular & ~outside & ~closed
        new[closed] -= delta[closed]  # close exactly on the seed (unwrapped)
        kept = ~(singular | outside)
        recorded_idx.append(active[kept])
        recorded_pts.append(new[kept])
        for mask, why in (
            (singular, "singularity"),
            (outside, "joint limit"),
            (closed, "closed"),
            (too_long, "max length"),
        ):
            ends[active[mask]] = why
        left_seed[active] |= dist > 2.0 * hk[:, 0]
        # Shorten the step where the tangent turns fast, and where |n| falls (a singularity ahead):
        # never step more than half the estimated distance to |n| = 0.
        falling = np.maximum(n1 - n1_next, 1e-300) / hk[:, 0]
        h_next = np.minimum(hk[:, 0] * MAX_TURN / np.maximum(turn, 1e-12), 0.5 * n1_next / falling)
        h[active] = np.clip(h_next, ds / 64.0, ds)
        go_on = ~(singular | outside | closed | too_long)
        active, th, k1, n1 = active[go_on], new[go_on], k1_next[go_on], n1_next[go_on]
    idx = np.concatenate(recorded_idx)
    pts = np.concatenate(recorded_pts)
    order = np.argsort(idx, kind="stable")
    split = np.searchsorted(idx[order], np.arange(1, K))
    return [(p, str(e)) for p, e in zip(np.split(pts[order], split), ends, strict=True)]


def potential(model: FsmsModel, theta: np.ndarray, row: int = 0) -> float:
    """w x_cm along selected base axis ``row`` (kg m): H_bm's row is its gradient (Eq. 26)."""
    axis = model.base_axes()[model.selected[row]]
    return float(axis @ model.arm_mass_moment(theta))


def default_seeds(model: FsmsModel, count: int, grid: int = 16) -> np.ndarray:
    """``count`` seeds on evenly spaced levels of the coupling potential w x_cm (Eq. 26).

    Reactionless paths of a translating base are the level sets of the potential, so seeds on
    levels spread between its minimum and maximum give a family that covers the workspace. The
    seeds lie on the joint-space segment from the potential's minimum to its maximum (found on a
    coarse grid; for periodic joints the segment passing nearest the default configuration) and
    are refined onto their level by Newton steps along H_bm.
    """
    if count < 1:
        raise ValueError(f"count must be a positive number of paths, got {count}")
    if not model.base_is_translational:
        raise ValueError(f"{model.name}: seeding by the potential needs a translating base")
    field = CouplingField(model)
    axes = [
        np.linspace(lo, lo + TWO_PI, grid, endpoint=False) if hi - lo >= TWO_PI else np.linspace(lo, hi, grid)
        for lo, hi in zip(np.maximum(model.lower, -np.pi), model.upper, strict=True)
    ]
    mesh = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, model.n)
    values = field.potentials(mesh)[:, 0]
    lo_th, hi_th = mesh[np.argmin(values)], mesh[np.argmax(values)]
    # Periodic joints: of the 2 pi shifts of the minimum, take the one whose segment to the maximum
    # passes nearest the default configuration, so the family covers the workspace around it.
    periodic = periodic_joints(model)
    shifts = np.stack(np.meshgrid(*[[-TWO_PI, 0.0, TWO_PI] if p else [0.0] for p in periodic], indexing="ij"), -1)
    candidates = lo_th + shifts.reshape(-1, model.n)
    lo_th = candidates[np.argmin(np.linalg.norm(0.5 * (candidates + hi_th) - model.spec.default_configuration, axis=1))]
    line = lo_th + np.linspace(0.0, 1.0, 101)[:, None] * (hi_th - lo_th)
    line_values = field.potentials(line)[:, 0]
    levels = line_values[0] + (np.arange(count) + 0.5) / count * (line_values[-1] - line_values[0])
    seeds = np.empty((count, model.n))
    for j, level in enumerate(levels):
        i = int(np.flatnonzero(np.diff(np.sign(line_values - level)) != 0)[0])
        t = (level - line_values[i]) / (line_values[i + 1] - line_values[i])
        seeds[j] = line[i] + t * (line[i + 1] - line[i])
    targets = field.potentials(seeds)  # other selected rows keep their values; row 0 gets its level
    targets[:, 0] = levels
    return field.project(seeds, targets, newton_steps=6)


def nearby_seeds(model: FsmsModel, theta: np.ndarray, count: int, spread: float = 0.3) -> np.ndarray:
    """``count`` seeds at ``spread`` rad from theta, across the paths (along the rows of S H_bm).

    For a base without a coupling potential (rotational base coordinates, e.g. boom7): the integral
    curves through them are the reactionless paths near theta. Directions are fixed (seeded), so
    the same call gives the same family; seeds are clipped to the joint limits.
    """
    theta = np.asarray(theta, dtype=float)
    rows = np.linalg.svd(model.coupling_at(theta))[2][: len(model.selected)]  # range of H^T
    directions = np.random.default_rng(0).normal(size=(count, len(rows)))
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    return np.clip(theta + spread * directions @ rows, model.lower, model.upper)


def path_family(model: FsmsModel, count: int = 40, ds: float = 0.2, max_length: float = 60.0) -> list[ReactionlessPath]:
    """The family of reactionless paths of Fig. 8: ``count`` curves on spread levels of the potential,
    or, for a base without one, through configurations near the default (:func:`nearby_seeds`)."""
    if model.base_is_translational:
        seeds = default_seeds(model, count)
    else:
        seeds = nearby_seeds(model, model.spec.default_configuration, count)
    return trace_paths(model, seeds, ds=ds, max_length=max_length)
