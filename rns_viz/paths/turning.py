"""The reactionless reachable set of a base that turns (boom7): the RNS distribution integrated.

A turning base has no coupling potential (angular momentum is not a gradient), so the set cannot be
explored on a level set as for a translating base (:func:`rns_viz.paths.reachable.reactionless_reachable_set`).
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

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from rns_viz.model import FsmsModel
from rns_viz.paths.field import CouplingField
from rns_viz.rns import project_onto_rns, rk4_along, rns_basis, singularity_distance


@dataclass(frozen=True)
class Explored:
    thetas: np.ndarray  # (N, n) rad: one configuration per voxel
    points: np.ndarray  # (N, 3) m: their end effectors, base frame
    complete: bool  # the frontier ran out (False: stopped at max_points)


def _move(coupling: CouplingField, thetas: np.ndarray, v: np.ndarray) -> np.ndarray:
    """theta moved along X_v = P_RNS(theta) v over unit length (v carries the length): one RK4 step, whose
    first slope is v itself (v lies in the RNS where the move starts)."""

    def field(_s: float, th: np.ndarray) -> np.ndarray:
        return project_onto_rns(v, coupling.rows_at(th)[0])

    return rk4_along(field, 0.0, thetas, 1.0, v)


def _jacobians(model: FsmsModel, data: pin.Data, thetas: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """End-effector positions (K, 3) and position Jacobians (K, 3, n) in the base frame at x_b = 0."""
    frames = [model.ee_frame_jacobian(th, data) for th in thetas]
    pos = np.array([f.position for f in frames]).reshape(len(thetas), 3)
    return pos, np.array([f.linear for f in frames]).reshape(len(thetas), 3, model.n)


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
    coupling = CouplingField(model, data=data)
    rows = model.task_rows
    k = model.n - len(model.selected)
    lower, upper = model.lower + margin, model.upper - margin
    start = np.array(theta0, dtype=float)[None]
    ee, _ = _jacobians(model, data, start)
    visited = {tuple(np.floor(ee[0][rows] / voxel).astype(int))}
    thetas, points, frontier = [start[0]], [ee[0]], start
    while len(frontier) and len(thetas) < max_points:
        N = rns_basis(coupling.rows_at(frontier)[0])  # (F, n, k) orthonormal bases of N(S H_bm)
        _, J = _jacobians(model, data, frontier)
        _, sj, Wt = np.linalg.svd(J[:, rows] @ N)  # directions of the RNS that move the hand
        d = min(k, len(rows))
        dirs = np.einsum("fnk,fjk->fjn", N, Wt[:, :d, :])  # (F, d, n) unit joint-space directions
        length = np.minimum(voxel / np.maximum(sj[:, :d], 1e-9), max_step)  # one voxel, at most max_step
        v = dirs * length[:, :, None]
        v = np.concatenate([v, -v], axis=1).reshape(-1, model.n)
        base = np.repeat(frontier, 2 * d, axis=0)
        cand = _move(coupling, base, v)
        ok = np.all((cand >= lower) & (cand <= upper), axis=1)
        cand = cand[ok]
        if not len(cand):  # every move leaves the joint limits: the sweep is complete
            frontier = cand
            break
        sig = singularity_distance(coupling.rows_at(cand)[0], model.coupling_weights)
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
