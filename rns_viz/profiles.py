"""Time profiles: quintic splines (rest to rest) and the cyclic u-bar of Sec. VII-D."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


def quintic(tau: float) -> tuple[float, float, float]:
    """s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5 on [0, 1] and its first two derivatives (per tau)."""
    if tau <= 0.0:
        return 0.0, 0.0, 0.0
    if tau >= 1.0:
        return 1.0, 0.0, 0.0
    t2 = tau * tau
    return (
        t2 * tau * (10.0 - 15.0 * tau + 6.0 * t2),
        30.0 * t2 * (1.0 - tau) ** 2,
        60.0 * tau * (1.0 - tau) * (1.0 - 2.0 * tau),
    )


@dataclass(frozen=True)
class QuinticUbar:
    """u-bar(t) such that sigma = integral of u-bar dt goes from 0 to ``total`` over [start, start + duration].

    sigma is the path integral of Eq. (30): theta_ref' = n(theta_ref) u-bar. Units of u-bar:
    1/(kg m s) for a translating base, so that n u-bar is in rad/s.
    """

    total: float
    duration: float  # s
    start: float = 0.0  # s

    def __post_init__(self) -> None:
        if not (math.isfinite(self.total) and math.isfinite(self.duration) and self.duration > 0):
            raise ValueError(f"quintic profile needs a finite total and a positive duration, got {self}")

    def __call__(self, t: float) -> tuple[float, float]:
        """(u-bar, u-bar') at time t."""
        _, ds, dds = quintic((t - self.start) / self.duration)
        return self.total * ds / self.duration, self.total * dds / self.duration**2

    def peak(self) -> float:
        return 1.875 * abs(self.total) / self.duration


@dataclass(frozen=True)
class CyclicUbar:
    """u-bar rising smoothly (quintic step) from 0 to ``level`` over ``ramp`` s, then constant (Fig. 12)."""

    level: float
    ramp: float = 1.0  # s
    start: float = 0.0  # s

    def __post_init__(self) -> None:
        if not (math.isfinite(self.level) and math.isfinite(self.ramp) and self.ramp > 0):
            raise ValueError(f"cyclic profile needs a finite level and a positive ramp, got {self}")

    def __call__(self, t: float) -> tuple[float, float]:
        s, ds, _ = quintic((t - self.start) / self.ramp)
        return self.level * s, self.level * ds / self.ramp


@dataclass(frozen=True)
class QuinticSegment:
    """A straight line from ``start`` to ``end`` (joint or task space), quintic in time, rest to rest.

    Returns the point, its velocity and acceleration at time t (units of ``start`` per s, s^2).
    """

    start: np.ndarray
    end: np.ndarray
    duration: float  # s
    t0: float = 0.0  # s

    def __call__(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        s, ds, dds = quintic((t - self.t0) / self.duration)
        d = self.end - self.start
        return self.start + s * d, ds / self.duration * d, dds / self.duration**2 * d
