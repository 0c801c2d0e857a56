"""The reactionless-reachable set of a base that turns (boom7), and the Lie-bracket rank of its RNS.

A turning base has no coupling potential (angular momentum is not a gradient), so the set cannot be
explored on a level set as for a translating base (:func:`rns_viz.paths.reactionless_reachable_set`).
Instead every move integrates a smooth field of the distribution, X_v(theta) = P_RNS(theta) v with v in
N(S H_bm) where the move starts (Sec. III-A): the move is reactionless by construction, whether the
distribution is integrable or not. Breadth-first from the start, the end-effector space is cut into
voxels and one configuration is kept per voxel (the first reached, i.e. in the fewest moves), so the
cost grows with the end-effector volume, not with the joint space's. Moves follow the directions of
the RNS that move the end effector (the right singular vectors of J N), one voxel long, and both ways.
The sampled set is an inner approximation: a voxel reached only through a configuration kept in
another voxel's place is missed.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from rns_viz.model import FsmsModel
from rns_viz.rns import lie_bracket, rns_projector, singularity_distance


@dataclass(frozen=True)
class Explored:
    thetas: np.ndarray  # (N, n) rad: one configuration per voxel
    points: np.ndarray  # (N, 3) m: their end effectors, base frame
    complete: bool  # the frontier ran out (False: stopped at max_points)


def _rows(model: FsmsModel, data: pin.Data, thetas: np.ndarray) -> np.ndarray:
    """S H_bm (K, r, n) at x_b = 0."""
    q = np.zeros(model.nv)
    out = np.empty((len(thetas), len(model.selected), model.n))
    for k, th in enumerate(thetas):
        q[model.m :] = th
        out[k] = model.coupling_matrix(q, data)
    return out


def _field(model: FsmsModel, data: pin.Data, thetas: np.ndarray, v: np.ndarray) -> np.ndarray:
    """P_RNS(theta) v for K configurations and K vectors: v - H^T (H H^T)^-1 H v."""
    H = _rows(model, data, thetas)
    Hv = np.einsum("krn,kn->kr", H, v)
    lam = np.linalg.solve(H @ H.transpose(0, 2, 1), Hv[:, :, None])[:, :, 0]
    return v - np.einsum("krn,kr->kn", H, lam)


def _move(model: FsmsModel, data: pin.Data, thetas: np.ndarray, v: np.ndarray) -> np.ndarray:
    """theta moved along X_v over unit length (v carries the length): two midpoint steps."""
    half = 0.5 * v
    th = thetas
    for i in range(2):
        k1 = half if i == 0 else _field(model, data, th, half)  # X_v = v where the move starts
        th = th + _field(model, data, th + 0.5 * k1, half)
    return th


def _jacobians(model: FsmsModel, data: pin.Data, thetas: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """End-effector positions (K, 3) and task Jacobians (K, 3, n) in the base frame at x_b = 0."""
    pm, fid, m = model.pin_model, model.ee_frame_id, model.m
    q = np.zeros(model.nv)
    pos = np.empty((len(thetas), 3))
    jac = np.empty((len(thetas), 3, model.n))
    for k, th in enumerate(thetas):
        q[m:] = th
        J = pin.computeFrameJacobian(pm, data, q, fid, pin.LOCAL_WORLD_ALIGNED)[:3, m:]
        base = data.oMi[model.base_joint_id]
        pos[k] = base.rotation.T @ (data.oMf[fid].translation - base.translation)
        jac[k] = base.rotation.T @ J
    return pos, jac


def explore_rns(
    model: FsmsModel,
    theta0: np.ndarray,
    voxel: float,
    max_points: int = 1500,
    max_step: float = 0.5,
    singular_sigma: float = 1e-3,
    margin: float = 0.02,
) -> Explored:
    """Breadth-first sweep of the RNS distribution from ``theta0`` (see the module's notes).

    ``voxel`` (m): end-effector cell size and move length; ``max_step`` (rad): longest move;
    configurations nearer singularity than ``singular_sigma`` (kg m, rns.singularity_distance) or
    within ``margin`` (rad) of a joint limit are not kept.
    """
    data = model.pin_model.createData()
    rows = model.task_rows
    k = model.n - len(model.selected)
    lower, upper = model.lower + margin, model.upper - margin
    start = np.array(theta0, dtype=float)[None]
    ee, _ = _jacobians(model, data, start)
    visited = {tuple(np.floor(ee[0][rows] / voxel).astype(int))}
    thetas, points, frontier = [start[0]], [ee[0]], start
    while len(frontier) and len(thetas) < max_points:
        H = _rows(model, data, frontier)
        Vt = np.linalg.svd(H)[2]
        N = np.transpose(Vt[:, -k:, :], (0, 2, 1))  # (F, n, k) orthonormal bases of N(S H_bm)
        _, J = _jacobians(model, data, frontier)
        _, sj, Wt = np.linalg.svd(J[:, rows] @ N)  # directions of the RNS that move the hand
        d = min(k, len(rows))
        dirs = np.einsum("fnk,fjk->fjn", N, Wt[:, :d, :])  # (F, d, n) unit joint-space directions
        length = np.minimum(voxel / np.maximum(sj[:, :d], 1e-9), max_step)  # one voxel, at most max_step
        v = dirs * length[:, :, None]
        v = np.concatenate([v, -v], axis=1).reshape(-1, model.n)
        base = np.repeat(frontier, 2 * d, axis=0)
        cand = _move(model, data, base, v)
        ok = np.all((cand >= lower) & (cand <= upper), axis=1)
        cand = cand[ok]
        if not len(cand):  # every move leaves the joint limits: the sweep is complete
            frontier = cand
            break
        sig = singularity_distance(_rows(model, data, cand), model.coupling_weights)
        cand = cand[sig > singular_sigma]
        ee_c = model.ee_positions(cand, data) if len(cand) else np.empty((0, 3))
        new = []
        for th, p in zip(cand, ee_c, strict=True):
            key = tuple(np.floor(p[rows] / voxel).astype(int))
            if key not in visited:
                visited.add(key)
                new.append(th)
                thetas.append(th)
                points.append(p)
        frontier = np.array(new).reshape(-1, model.n)
    return Explored(np.array(thetas[:max_points]), np.array(points[:max_points]), len(frontier) == 0)


@dataclass(frozen=True)
class BracketRank:
    """The RNS distribution and its first Lie brackets at one configuration (Sec. III-A)."""

    rns_dim: int  # n - r
    with_brackets: int  # rank of [P_RNS, [P_i, P_j]]: > rns_dim where the distribution is not involutive
    residual: float  # largest |(E - P) [P_i, P_j]| / (|P_i| |P_j|)

    @property
    def involutive(self) -> bool:
        return self.with_brackets == self.rns_dim

    def words(self) -> str:
        if self.involutive:
            return (
                f"The distribution is involutive here (Lie brackets stay in it, residual {self.residual:.1e}): "
                f"reactionless motions stay on an integral manifold, the reachable set is {self.rns_dim}-dimensional "
                "in joint space."
            )
        return (
            f"The distribution is not involutive here (the Lie brackets add {self.with_brackets - self.rns_dim} "
            f"direction(s), rank {self.with_brackets} of n; residual {self.residual:.2g}): reactionless motions "
            f"reach a set larger than {self.rns_dim}-dimensional in joint space (at least {self.with_brackets})."
        )


def bracket_rank(coupling: Callable[[np.ndarray], np.ndarray], theta: np.ndarray, tol: float = 1e-6) -> BracketRank:
    """Rank of the columns of P_RNS with their pairwise Lie brackets at ``theta`` (central differences).

    ``coupling(theta)`` returns S H_bm. Brackets are measured relative to the columns' norms; a
    component out of the distribution below ``tol`` counts as zero.
    """
    theta = np.asarray(theta, dtype=float)
    P = rns_projector(coupling(theta))
    n = theta.size
    rns_dim = round(float(np.trace(P)))
    U = np.linalg.svd(P)[0][:, :rns_dim]  # orthonormal basis of the distribution
    out_of: list[np.ndarray] = []
    worst = 0.0

    def column(j: int) -> Callable[[np.ndarray], np.ndarray]:
        return lambda th: rns_projector(coupling(th))[:, j]

    for i in range(n):
        for j in range(i + 1, n):
            scale = float(np.linalg.norm(P[:, i]) * np.linalg.norm(P[:, j]))
            if scale < 1e-6:
                continue
            b = lie_bracket(column(i), column(j), theta)
            rest = (b - U @ (U.T @ b)) / scale
            worst = max(worst, float(np.linalg.norm(rest)))
            out_of.append(rest)
    extra = 0
    if out_of:
        s = np.linalg.svd(np.array(out_of).T, compute_uv=False)
        extra = int(np.sum(s > tol * max(1.0, np.sqrt(len(out_of)))))
    return BracketRank(rns_dim, min(n, rns_dim + extra), worst)
