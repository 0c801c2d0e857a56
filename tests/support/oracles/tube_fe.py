"""Finite-element oracle: a clamped-free tube of 3-D Euler-Bernoulli frame elements with a rigid tip.

Independent of ``rns_viz`` (numpy and scipy only). The tube runs along +x from the clamp at x = 0;
each node has the six coordinates (u_x, u_y, u_z, theta_x, theta_y, theta_z): axial and torsion by
linear elements, bending in x-y (v, theta_z = v') and x-z (w, theta_y = -w') by Hermite cubics, all
with consistent mass matrices (the section's rotary inertia in bending is left out, as in an
Euler-Bernoulli beam). A rigid body at the tip enters as a 6 x 6 inertia on the tip node, in the
order (linear, angular) about the tip point.

- :func:`assemble` -> stiffness and mass with the clamp removed (tip node last);
- :func:`condensed` -> Guyan's static condensation onto the tip: the tip stiffness K_tt - K_ti K_ii^-1
  K_it and the mass T^T M T of the static shapes T;
- :func:`modes` -> :class:`Modes`: the lowest natural frequencies and, per mode, the share of its kinetic
  energy carried by the tip node and by each kind of coordinate.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla


@dataclass(frozen=True)
class Tube:
    """A thin-walled circular tube, SI units."""

    E: float  # Pa
    G: float  # Pa
    rho: float  # kg/m^3
    length: float  # m
    outer_diameter: float  # m
    wall: float  # m

    @property
    def area(self) -> float:
        d = self.outer_diameter - 2 * self.wall
        return np.pi / 4 * (self.outer_diameter**2 - d**2)

    @property
    def second_moment(self) -> float:
        """I of the section about a diameter, m^4 (the polar J is 2 I)."""
        d = self.outer_diameter - 2 * self.wall
        return np.pi / 64 * (self.outer_diameter**4 - d**4)

    @property
    def mass(self) -> float:
        return self.rho * self.area * self.length


def _element(tube: Tube, h: float) -> tuple[np.ndarray, np.ndarray]:
    """12 x 12 stiffness and consistent mass of one element of length h (node 1 then node 2)."""
    E, G, rho, A, I = tube.E, tube.G, tube.rho, tube.area, tube.second_moment
    J = 2 * I
    k, m = np.zeros((12, 12)), np.zeros((12, 12))
    bar_k, bar_m = np.array([[1.0, -1.0], [-1.0, 1.0]]), np.array([[2.0, 1.0], [1.0, 2.0]]) / 6
    for dofs, stiffness, inertia in (([0, 6], E * A / h, rho * A * h), ([3, 9], G * J / h, rho * J * h)):
        k[np.ix_(dofs, dofs)] += stiffness * bar_k
        m[np.ix_(dofs, dofs)] += inertia * bar_m
    hh = h * h
    beam_k = E * I / h**3 * np.array([[12, 6 * h, -12, 6 * h], [6 * h, 4 * hh, -6 * h, 2 * hh],
                                     [-12, -6 * h, 12, -6 * h], [6 * h, 2 * hh, -6 * h, 4 * hh]])  # fmt: skip
    beam_m = rho * A * h / 420 * np.array([[156, 22 * h, 54, -13 * h], [22 * h, 4 * hh, 13 * h, -3 * hh],
                                           [54, 13 * h, 156, -22 * h], [-13 * h, -3 * hh, -22 * h, 4 * hh]])  # fmt:skip
    for dofs, sign in (([1, 5, 7, 11], 1.0), ([2, 4, 8, 10], -1.0)):  # (v, theta_z), (w, theta_y = -w')
        S = np.diag([1.0, sign, 1.0, sign])
        k[np.ix_(dofs, dofs)] += S @ beam_k @ S
        m[np.ix_(dofs, dofs)] += S @ beam_m @ S
    return k, m


def assemble(tube: Tube, elements: int, tip_inertia: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """K and M of the clamped tube (6 * elements coordinates, the tip node's six last), plus a rigid tip."""
    n = 6 * (elements + 1)
    K, M = np.zeros((n, n)), np.zeros((n, n))
    k, m = _element(tube, tube.length / elements)
    for e in range(elements):
        idx = np.arange(6 * e, 6 * e + 12)
        K[np.ix_(idx, idx)] += k
        M[np.ix_(idx, idx)] += m
    if tip_inertia is not None:
        M[-6:, -6:] += tip_inertia
    return K[6:, 6:], M[6:, 6:]


def condensed(tube: Tube, elements: int) -> tuple[np.ndarray, np.ndarray]:
    """Guyan's reduction of the bare tube onto its tip: the 6 x 6 tip stiffness and mass."""
    K, M = assemble(tube, elements)
    inner = slice(0, K.shape[0] - 6)
    T = np.vstack([-np.linalg.solve(K[inner, inner], K[inner, -6:]), np.eye(6)])  # static shapes
    return T.T @ K @ T, T.T @ M @ T


@dataclass(frozen=True)
class Modes:
    """The lowest natural modes of the tube with its tip body."""

    frequency_hz: np.ndarray  # (count,)
    tip_share: np.ndarray  # (count,) share of each mode's kinetic energy on the tip node (its rigid body included)
    coordinate_share: np.ndarray  # (count, 6) share on u_x, u_y, u_z, theta_x, theta_y, theta_z over all nodes


def modes(tube: Tube, elements: int, tip_inertia: np.ndarray, count: int) -> Modes:
    """The ``count`` lowest modes (generalised symmetric eigenproblem K v = omega^2 M v)."""
    K, M = assemble(tube, elements, tip_inertia)
    w2, V = sla.eigh(K, M, subset_by_index=[0, count - 1])
    energy = V * (M @ V)  # per coordinate; each column sums to v^T M v
    total = energy.sum(axis=0)
    tip = np.einsum("im,ij,jm->m", V[-6:], M[-6:, -6:], V[-6:]) / total
    by_coordinate = np.stack([energy[k::6].sum(axis=0) for k in range(6)], axis=1) / total[:, None]
    return Modes(np.sqrt(w2) / (2 * np.pi), tip, by_coordinate)
