"""The current reactionless path of a 1-D RNS as a table over the path integral sigma (Eq. 30).

sigma is the integral of u-bar dt: along the path d theta / d sigma = n(theta) (Eq. 27, unnormalised,
kg m), so sigma has units 1/(kg m). The table is traced by :func:`rns_viz.paths.tracing.trace_paths`
(arc length s in joint space) and re-parametrised with d sigma = ds / |n|; sigma = 0 at the seed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rns_viz.model import FsmsModel
from rns_viz.paths.field import TWO_PI, CouplingField
from rns_viz.paths.tracing import trace_paths
from rns_viz.rns import null_vector


@dataclass(frozen=True)
class PathTable:
    """One reactionless path: configurations, end-effector points and sigma, in path order."""

    theta: np.ndarray  # (k, n) rad, continuous (not wrapped)
    sigma: np.ndarray  # (k,) 1/(kg m), increasing, 0 at the seed
    ee: np.ndarray  # (k, 3) m, base frame
    closed: bool
    level: np.ndarray  # (r,) coupling potential w x_cm on the path, kg m
    seed: np.ndarray  # (n,) rad

    @property
    def period(self) -> float:
        """sigma once around a closed path (nan for an open one)."""
        return float(self.sigma[-1] - self.sigma[0]) if self.closed else float("nan")

    @property
    def lo(self) -> float:
        return float(self.sigma[0])

    @property
    def hi(self) -> float:
        return float(self.sigma[-1])

    def wrap(self, sigma: float) -> float:
        """sigma into the table's range: modulo the period (closed) or clipped (open)."""
        if self.closed:
            return self.lo + (sigma - self.lo) % self.period
        return float(np.clip(sigma, self.lo, self.hi))

    def centred(self, sigma: float) -> float:
        """sigma of a closed path shown in [-period/2, period/2) (the scrub slider's range)."""
        if not self.closed:
            return float(np.clip(sigma, self.lo, self.hi))
        p = self.period
        return (sigma + 0.5 * p) % p - 0.5 * p

    def nearest_copy(self, sigma: float, near: float) -> float:
        """The copy sigma + k period closest to ``near`` (closed paths); sigma itself otherwise."""
        if not self.closed:
            return float(np.clip(sigma, self.lo, self.hi))
        p = self.period
        return sigma + p * round((near - sigma) / p)

    def ee_at(self, sigma: float) -> np.ndarray:
        s = self.wrap(sigma)
        return np.array([np.interp(s, self.sigma, self.ee[:, i]) for i in range(3)])

    def sigma_nearest_point(self, point: np.ndarray) -> float:
        """sigma of the path point whose end effector is nearest ``point``: (x, y) in the task plane, or (x, y, z)."""
        p = np.asarray(point, dtype=float)[:3]
        k = len(p)
        a, b = self.ee[:-1, :k], self.ee[1:, :k]
        d = b - a
        length2 = np.einsum("ij,ij->i", d, d)
        u = np.clip(np.einsum("ij,ij->i", p - a, d) / np.maximum(length2, 1e-300), 0.0, 1.0)
        dist2 = np.sum((a + u[:, None] * d - p) ** 2, axis=1)
        k = int(np.argmin(dist2))
        return float(self.sigma[k] + u[k] * (self.sigma[k + 1] - self.sigma[k]))

    def sigma_nearest_theta(self, theta: np.ndarray) -> float:
        """sigma of the tabulated configuration nearest ``theta`` (angles compared modulo 2 pi)."""
        delta = (self.theta - np.asarray(theta) + np.pi) % TWO_PI - np.pi
        k = int(np.argmin(np.einsum("ij,ij->i", delta, delta)))
        return float(self.sigma[k])


def build_path_table(model: FsmsModel, seed: np.ndarray, ds: float = 0.02) -> PathTable:
    """Trace the reactionless path through ``seed`` and tabulate it over sigma (a 1-D RNS only)."""
    seed = np.asarray(seed, dtype=float)
    path = trace_paths(model, seed[None], ds=ds)[0]
    field = CouplingField(model)
    H, _ = field.rows_at(path.theta)
    norms = np.array([np.linalg.norm(n) for n in null_vector(H)])  # |n| (kg m) along the path
    steps = np.diff(path.s) * 0.5 * (1.0 / norms[1:] + 1.0 / norms[:-1])
    sigma = np.concatenate([[0.0], np.cumsum(steps)])
    delta = (path.theta - seed + np.pi) % TWO_PI - np.pi
    start = int(np.argmin(np.einsum("ij,ij->i", delta, delta)))
    level = field.potentials(seed[None])[0]
    return PathTable(path.theta, sigma - sigma[start], path.ee, path.end == "closed", level, seed)
