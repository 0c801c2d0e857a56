"""The reactionless reachable set: every configuration reactionless motion reaches from theta_0.

A translating base has a coupling potential (Eq. 26): the set is its level set through theta_0, explored
on a joint-space lattice (:func:`reactionless_reachable_set`, the planar 3R's 2-D surface). A base that
turns has none: :func:`explore_rns` integrates the RNS distribution itself (:mod:`rns_viz.paths.turning`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rns_viz.model import FsmsModel
from rns_viz.paths.field import TWO_PI, CouplingField, periodic_joints
from rns_viz.rns import rns_basis, singularity_distance


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
    periodic = periodic_joints(model)
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
        r = H.shape[1]
        basis = rns_basis(H)  # (F, n, k) orthonormal null-space bases
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
