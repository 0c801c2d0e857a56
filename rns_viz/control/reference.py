"""Joint-space references: fixed, quintic point to point, and reactionless paths (Eq. 30's integral)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Protocol

import numpy as np
import pinocchio as pin

from rns_viz.model import FsmsModel
from rns_viz.profiles import QuinticSegment
from rns_viz.rns import rk4_along


class JointReference(Protocol):
    """theta_ref(t), theta_ref'(t), theta_ref''(t), rad and its rates."""

    def __call__(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]: ...


@dataclass(frozen=True)
class FixedReference:
    """A configuration to hold (Sec. VII-D-1: the integral replaced by fixed joint angles)."""

    theta: np.ndarray

    def __call__(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        zero = np.zeros_like(self.theta)
        return self.theta, zero, zero


JointQuintic = QuinticSegment  # point-to-point joint motion (Fig. 11(b))


@dataclass(frozen=True)
class JointSample:
    """theta_ref, theta_ref', theta_ref'' at one instant (rad, rad/s, rad/s^2): what a live loop hands a
    law with :meth:`follow` at each step. Immutable, so no one changes it behind the law's back.

    ``t0``: when it was taken (s; :meth:`taken_at`). A law evaluated at other times within the step
    (a joint servo at the RK4 stages, ControlLaw.sampled) then sees the sample's Taylor polynomial,
    theta + tau theta' + tau^2/2 theta'' with tau = t - t0; None: the same values at every time."""

    theta: np.ndarray
    thetadot: np.ndarray
    thetaddot: np.ndarray
    t0: float | None = None

    @classmethod
    def held(cls, theta: np.ndarray) -> JointSample:
        theta = np.array(theta, dtype=float)
        return cls(theta, np.zeros_like(theta), np.zeros_like(theta))

    def taken_at(self, t: float) -> JointSample:
        return replace(self, t0=t)

    def __call__(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return _near(self.theta, self.thetadot, self.thetaddot, self.t0, t)


@dataclass(frozen=True)
class TaskSample:
    """x_d, x_d', x_d'' at one instant, base frame, task rows (m, m/s, m/s^2); see :class:`JointSample`."""

    x: np.ndarray
    xdot: np.ndarray
    xddot: np.ndarray
    t0: float | None = None

    @classmethod
    def held(cls, x: np.ndarray) -> TaskSample:
        x = np.array(x, dtype=float)
        return cls(x, np.zeros_like(x), np.zeros_like(x))

    def taken_at(self, t: float) -> TaskSample:
        return replace(self, t0=t)

    def __call__(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return _near(self.x, self.xdot, self.xddot, self.t0, t)


ReferenceSample = JointSample | TaskSample


def _near(
    value: np.ndarray, rate: np.ndarray, acceleration: np.ndarray, t0: float | None, t: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A sample taken at t0, at time t: itself at t0 (or without t0), its Taylor polynomial elsewhere."""
    if t0 is None or t == t0:
        return value, rate, acceleration
    tau = t - t0
    return value + tau * rate + 0.5 * tau * tau * acceleration, rate + tau * acceleration, acceleration


class PathReference:
    """theta_ref' = n(theta_ref) u-bar(t): the reactionless reference path of Eq. (30).

    n is the null-space vector of S H_bm (Eq. 27), unnormalised, from pinocchio. The path is
    integrated with RK4 in steps of at most ``max_step`` as time advances; asking for an earlier
    time restarts from ``theta0``. Queries must come in non-decreasing time between restarts.
    """

    def __init__(
        self,
        model: FsmsModel,
        theta0: np.ndarray,
        ubar: Callable[[float], tuple[float, float]],
        max_step: float = 1e-3,
        t0: float = 0.0,
    ) -> None:
        if model.n - len(model.selected) != 1:
            raise ValueError(f"{model.name}: a reactionless reference path needs a 1-D RNS")
        self.model = model
        self.data = model.pin_model.createData()
        self.theta0 = np.asarray(theta0, dtype=float).copy()
        self.ubar = ubar
        self.max_step = max_step
        self.t0 = t0
        self.restart()

    def restart(self, theta0: np.ndarray | None = None, t0: float | None = None) -> None:
        if theta0 is not None:
            self.theta0 = np.asarray(theta0, dtype=float).copy()
        if t0 is not None:
            self.t0 = t0
        self._t = self.t0
        self._theta = self.theta0.copy()
        self._n_here: np.ndarray | None = None  # n(theta_ref) at the current point, once evaluated

    def n(self, theta: np.ndarray) -> np.ndarray:
        """Null-space vector n(theta) (Eq. 27 generalised), kg m."""
        return self.model.null_vector(theta, self.data)

    def _rate(self, t: float, theta: np.ndarray) -> np.ndarray:
        """theta_ref' = n(theta_ref) u-bar(t), Eq. (30)'s integrand."""
        return self.n(theta) * self.ubar(t)[0]

    def _n_at_current(self) -> np.ndarray:
        if self._n_here is None:
            self._n_here = self.n(self._theta)
        return self._n_here

    def _advance(self, t: float) -> None:
        if t < self._t - 1e-12:
            self.restart()
        while self._t < t - 1e-12:
            h = min(self.max_step, t - self._t)
            k1 = self._n_at_current() * self.ubar(self._t)[0]  # the last query's n(theta), at this point
            self._theta = rk4_along(self._rate, self._t, self._theta, h, k1)
            self._t, self._n_here = self._t + h, None

    def __call__(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        self._advance(t)
        theta = self._theta.copy()
        u, du = self.ubar(t)
        n = self._n_at_current()
        eps = 1e-6
        dn_along_n = (self.n(theta + eps * n) - self.n(theta - eps * n)) / (2 * eps)  # (Dn) n
        return theta, n * u, dn_along_n * u * u + n * du


def along_path(
    model: FsmsModel,
    theta: np.ndarray,
    dsigma: float,
    steps: int,
    data: pin.Data | None = None,
    n_here: np.ndarray | None = None,
) -> np.ndarray:
    """theta moved by ``dsigma`` along its reactionless path, d theta/d sigma = n(theta) (Eq. 27; sigma is the
    integral of u-bar dt, Eq. 30, 1/(kg m)), in ``steps`` equal RK4 steps. ``n_here``: n(theta), if at hand."""
    h = dsigma / steps

    def n(_sigma: float, th: np.ndarray) -> np.ndarray:
        return model.null_vector(th, data)

    for i in range(steps):
        theta = rk4_along(n, 0.0, theta, h, n_here if i == 0 else None)
    return theta


def path_integral_to(
    model: FsmsModel,
    theta0: np.ndarray,
    crossing: Callable[[np.ndarray], float],
    step: float = 1e-2,
    limit: float = 1e4,
    tol: float = 1e-12,
) -> tuple[float, np.ndarray]:
    """sigma and theta where the path theta' = n(theta) from theta0 first makes ``crossing`` change sign.

    Integrates in sigma (the integral of u-bar dt) with steps ``step``, then bisects the last
    step. Gives the total of u-bar that carries a reference to a chosen point of its path.
    """
    ref = PathReference(model, theta0, lambda _t: (1.0, 0.0), max_step=step)
    sigma, prev = 0.0, np.asarray(theta0, dtype=float)
    while sigma < limit:
        theta = ref(sigma + step)[0]
        if crossing(prev) * crossing(theta) <= 0 and sigma > 0:
            break
        sigma, prev = sigma + step, theta
    else:
        raise ValueError("the reactionless path did not reach the requested point")
    lo, hi = 0.0, step
    fine = PathReference(model, prev, lambda _t: (1.0, 0.0), max_step=step / 100)
    sign = np.sign(crossing(prev))
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        fine.restart()
        if np.sign(crossing(fine(mid)[0])) == sign:
            lo = mid
        else:
            hi = mid
    fine.restart()
    return sigma + hi, fine(hi)[0]
