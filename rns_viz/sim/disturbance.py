"""External generalised forces on the elastic base coordinates (the paper's "arbitrary external force")."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

ForceInput = Callable[[float], "np.ndarray | None"]  # t (s) -> generalised base force (m,) or None
# The force at the RK4 stage times t, t + dt/2, t + dt of one step (None entries: no force then).
StageForces = tuple["np.ndarray | None", "np.ndarray | None", "np.ndarray | None"]


@dataclass(frozen=True)
class NoForce:
    """No external force."""

    def __call__(self, t: float) -> np.ndarray | None:
        return None


@dataclass(frozen=True)
class ForcePulse:
    """A half-sine force pulse on the base: f(t) = peak sin(pi (t - start)/duration) on [start, start + duration].

    ``peak`` is a vector over the m base coordinates, N (or N m for a revolute base coordinate).
    Its impulse is 2 peak duration / pi.
    """

    start: float  # s
    duration: float  # s
    peak: tuple[float, ...]  # N
    _peak: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if not (np.isfinite(self.start) and np.isfinite(self.duration) and self.duration > 0):
            raise ValueError(f"force pulse needs a finite start and a positive duration, got {self}")
        peak = np.asarray(self.peak, dtype=float)
        if not np.all(np.isfinite(peak)):
            raise ValueError(f"force pulse peak must be finite, got {self.peak}")
        object.__setattr__(self, "_peak", peak)

    def __call__(self, t: float) -> np.ndarray | None:
        phase = (t - self.start) / self.duration
        if phase < 0.0 or phase > 1.0:
            return None
        return self._peak * np.sin(np.pi * phase)

    @property
    def impulse(self) -> np.ndarray:
        """Integral of the pulse over time, N s."""
        return self._peak * 2.0 * self.duration / np.pi


@dataclass(frozen=True)
class Pulses:
    """Several pulses added together."""

    pulses: tuple[ForcePulse, ...]

    def __call__(self, t: float) -> np.ndarray | None:
        forces = [f for f in (p(t) for p in self.pulses) if f is not None]
        return np.sum(forces, axis=0) if forces else None


def stage_forces(force: ForceInput, t: float, dt: float) -> StageForces | None:
    """The force sampled where RK4 evaluates the plant in the step from t; None when it is zero
    throughout (no force input, or none of the three samples in a pulse)."""
    if isinstance(force, NoForce):
        return None
    samples = (force(t), force(t + 0.5 * dt), force(t + dt))
    return None if all(f is None for f in samples) else samples
