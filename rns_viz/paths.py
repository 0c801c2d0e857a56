"""Reactionless paths: integral curves of the null-space vector n (Def. 3, Eq. 27, Fig. 8).

For a 1-D RNS each path solves d theta/ds = n / |n| (arc length s in joint space, rad), traced
with fixed-step RK4 for many seeds at once, until it closes on itself, reaches a joint limit,
nears a singularity (|n| small, H_bm losing rank) or reaches ``max_length``. For a 2-D RNS (the
planar 3R) see :func:`reactionless_reachable_set`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from rns_viz import _native
from rns_viz.model import FsmsModel
from rns_viz.rns import null_vector, singularity_distance

TWO_PI = 2.0 * np.pi
MAX_TURN = 0.15  # rad the tangent may turn in one step; steps shrink on tight loops


@dataclass(frozen=True)
class ReactionlessPath:
    """One integral curve of n."""

    theta: np.ndarray  # (k, n) joint angles, rad
    s: np.ndarray  # (k,) arc length in joint space from the first point, rad
    ee: np.ndarray  # (k, 3) end-effector positions in the base frame, m
    end: str  # why tracing stopped: "closed", "joint limit", "singularity" or "max length"


_NO_COM = np.empty(0)  # "no centre of mass wanted" for the native kernel


class CouplingField:
    """The coupling rows S H_bm, and their potential where one exists, at many configurations.

    For a translating base, row i of H_bm is M_total a_i . J_com (the base momentum along axis
    a_i) and M_total a_i . r_com its potential (Eq. 26, up to a constant): one
    jacobianCenterOfMass call gives both. Other bases read H_bm from crba and have no potential.
    With the optional native module installed, the K configurations of a call go to pinocchio in
    one C++ call (``native=False``: one Python call each, the same numbers).
    """

    def __init__(self, model: FsmsModel, native: bool = True) -> None:
        self.model = model
        self.native = _native.robot_model(model) if native else None
        self.q = np.zeros(model.nv)
        self.rows = model.selected
        self.m = model.m
        self.translational = model.base_is_translational
        pin.forwardKinematics(model.pin_model, model.data, self.q)
        total_mass = float(sum(inertia.mass for inertia in model.pin_model.inertias))
        world_axes = (model.data.oMi[model.base_joint_id].rotation @ model.base_axes().T).T[self.rows]
        self.scaled_axes = total_mass * world_axes  # (r, 3)

    def rows_at(self, thetas: np.ndarray, want_potential: bool = False) -> tuple[np.ndarray, np.ndarray | None]:
        """S H_bm (K, r, n) and, if asked and defined, the potentials (K, r) in kg m."""
        pm, data, q, m, rows = self.model.pin_model, self.model.data, self.q, self.m, self.rows
        K, n = thetas.shape
        if not self.translational:
            H = np.empty((K, len(rows), n))
            for k in range(K):
                q[m:] = thetas[k]
                H[k] = self.model.coupling_matrix(q)
            return H, None
        J = np.empty((K, 3, n))
        com = np.empty((K, 3))
        if self.native is not None:
            flat = np.ascontiguousarray(thetas, dtype=float).reshape(-1)
            self.native.com_jacobians(m, flat, J.reshape(-1), com.reshape(-1) if want_potential else _NO_COM)
            H = np.einsum("ra,kan->krn", self.scaled_axes, J)
            return H, (com @ self.scaled_axes.T if want_potential else None)
        jacobian_com = pin.jacobianCenterOfMass
        for k in range(K):
            q[m:] = thetas[k]
            J[k] = jacobian_com(pm, data, q, False)[:, m:]
            if want_potential:
                com[k] = data.com[0]
        H = np.einsum("ra,kan->krn", self.scaled_axes, J)
        return H, (com @ self.scaled_axes.T if want_potential else None)

    def potentials(self, thetas: np.ndarray) -> np.ndarray:
        """Potentials (K, r) alone, kg m: one centerOfMass call each (translating base only)."""
        pm, data, q, m = self.model.pin_model, self.model.data, self.q, self.m
        com = np.empty((len(thetas), 3))
        if self.native is not None:
            self.native.centers_of_mass(m, np.ascontiguousarray(thetas, dtype=float).reshape(-1), com.reshape(-1))
            return com @ self.scaled_axes.T
        for k in range(len(thetas)):
            q[m:] = thetas[k]
            com[k] = pin.centerOfMass(pm, data, q, False)
        return com @ self.scaled_axes.T

    def project(self, thetas: np.ndarray, levels: np.ndarray, newton_steps: int = 3) -> np.ndarray:
        """Move each configuration onto its level set c(theta) = level along H_bm (min-norm Newton).

        A base that turns has no potential of its angular rows (angular momentum is not a gradient):
        the configurations are returned unchanged, the integration alone keeps them on the path.
        """
        thetas = thetas.copy()
        if not self.translational:
            return thetas
        for _ in range(newton_steps):
            H, pot = self.rows_at(thetas, want_potential=True)
            thetas -= _right_inverse_times(H, pot - levels)
        return thetas


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
    ``singular_norm`` (units of |n|) stops a curve near rank loss of H_bm; by default it is
    1e-2 of the largest |n| seen at the seeds.
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
    periodic = (model.upper - model.lower) >= TWO_PI * (1 - 1e-6)
    lower, upper = model.lower, model.upper
    ends = np.full(K, "", dtype=object)
    active = np.arange(K)
    left_seed = np.zeros(K, dtype=bool)
    length = np.zeros(K)
    h = np.full(K, ds)  # per-curve step: ds, shortened where the path turns fast
    th = seeds.copy()
    k1, n1, _, levels = field(th, want_potential=True)
    recorded_idx, recorded_pts = [np.arange(K)], [seeds.copy()]
    while active.size:
        k1 *= sign
        hk = h[active][:, None]
        if levels is None:  # RK4 on d theta/ds = n/|n|
            k2, n2, _, _ = field(th + 0.5 * hk * k1)
            k3, n3, _, _ = field(th + 0.5 * hk * sign * k2)
            k4, n4, _, _ = field(th + hk * sign * k3)
            k2, k3, k4 = sign * k2, sign * k3, sign * k4
            new = th + hk / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
            smallest = np.minimum(np.minimum(n1, n2), np.minimum(n3, n4))
            k1_next, n1_next, _, _ = field(new)
        else:  # Heun predictor, then Newton + chord corrector onto the seed's level c(theta) = c_seed
            k4, n4, _, _ = field(th + hk * k1)
            k4 *= sign
            new = th + 0.5 * hk * (k1 + k4)
            smallest = np.minimum(n1, n4)
            k1_next, n1_next, H, pot = field(new, want_potential=True)
            new -= _right_inverse_times(H, pot - levels[active])
            for _chord in range(2):
                new -= _right_inverse_times(H, field.potentials(new) - levels[active])
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


def _right_inverse_times(H: np.ndarray, r: np.ndarray) -> np.ndarray:
    """H_k^+ r_k for a stack of full-row-rank H_k (K, rows, n): the minimum-norm Newton step."""
    if H.shape[1] == 1:
        h = H[:, 0, :]
        hh = np.einsum("ij,ij->i", h, h)  # 0 where H loses rank: no step there (never 0/0)
        return h * (r[:, 0] / np.where(hh > 1e-300, hh, np.inf))[:, None]
    return np.einsum("kir,kr->ki", np.linalg.pinv(H), r)


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
    periodic = (model.upper - model.lower) >= TWO_PI * (1 - 1e-6)
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
    rows = np.linalg.svd(model.coupling_matrix(model.q(theta)))[2][: len(model.selected)]  # range of H^T
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


@dataclass(frozen=True)
class ReachableSet:
    """Configurations reachable from theta_0 by reactionless motion, and their end-effector points."""

    theta: np.ndarray  # (N, n) rad, on the level set of the coupling potential through theta_0
    ee: np.ndarray  # (N, 3) m, base frame
    spacing: float  # rad between neighbouring samples in joint space
    complete: bool  # False if max_points stopped the exploration


def reactionless_reachable_set(
    model: FsmsModel, theta0: np.ndarray, spacing: float = 0.15, max_points: int = 20000, singular_sigma: float = 1e-3
) -> ReachableSet:
    """Explore the reaction null-space manifold through ``theta0`` (a 2-D surface for the 3R).

    Breadth-first over a joint-space lattice of cell ``spacing`` (rad): from every sample, step
    +-spacing along an orthonormal basis of N(S H_bm), project back onto the level set of the
    potential (Newton along H_bm, as the path tracer does), keep samples inside the joint limits
    whose distance to singularity (rns.singularity_distance) exceeds ``singular_sigma`` (kg m), and drop
    those in a visited cell.
    Needs a translating base, where the RNS distribution is integrable (Eq. 26).
    """
    if not model.base_is_translational:
        raise ValueError(f"{model.name}: the reachable set needs a translating base")
    field = CouplingField(model)
    periodic = (model.upper - model.lower) >= TWO_PI * (1 - 1e-6)
    start = np.atleast_2d(np.asarray(theta0, dtype=float))
    level = field.potentials(start)[0]

    def cell(th: np.ndarray) -> tuple[int, ...]:
        wrapped = np.where(periodic, (th + np.pi) % TWO_PI - np.pi, th)
        return tuple(np.floor(wrapped / (0.7 * spacing)).astype(int))

    visited = {cell(start[0])}
    accepted = [start[0]]
    frontier = start
    while len(frontier) and len(accepted) < max_points:
        H, _ = field.rows_at(frontier)
        _, _, Vt = np.linalg.svd(H)
        r = H.shape[1]
        basis = np.transpose(Vt[:, r:, :], (0, 2, 1))  # (F, n, k) orthonormal null-space bases
        steps = np.concatenate([basis, -basis], axis=2) * spacing
        candidates = (frontier[:, :, None] + steps).transpose(0, 2, 1).reshape(-1, model.n)
        candidates = field.project(candidates, np.broadcast_to(level, (len(candidates), r)).copy())
        H_c, pot = field.rows_at(candidates, want_potential=True)
        ok = np.abs(pot - level).max(axis=1) < 1e-9 * max(1.0, float(np.abs(level).max()))
        ok &= singularity_distance(H_c, model.coupling_weights) > singular_sigma
        ok &= np.all(periodic | ((candidates >= model.lower) & (candidates <= model.upper)), axis=1)
        new = []
        for th in candidates[ok]:
            key = cell(th)
            if key not in visited:
                visited.add(key)
                new.append(th)
        accepted.extend(new)
        frontier = np.array(new).reshape(-1, model.n)
    theta = np.array(accepted[:max_points])
    return ReachableSet(theta, model.ee_positions(theta), spacing, len(frontier) == 0)
