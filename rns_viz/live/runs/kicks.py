"""Operator kicks: half-sine force pulses on the base, added while the simulation runs."""

from __future__ import annotations

import numpy as np

from rns_viz.sim.disturbance import ForceInput, ForcePulse

MAX_KICK_N = 1e4  # N: larger peaks are refused as input errors, not physics


class KickSchedule:
    """A simulator's force input: an optional preset force plus the pulses the operator added.

    Pulses that have ended are dropped as time passes; ``clear()`` forgets all (after a reset).
    """

    def __init__(self, preset: ForceInput | None = None) -> None:
        self.preset = preset
        self.pulses: list[ForcePulse] = []

    def add(self, pulse: ForcePulse) -> None:
        self.pulses.append(pulse)

    def clear(self) -> None:
        self.pulses = []

    def copy(self) -> KickSchedule:
        other = KickSchedule(self.preset)
        other.pulses = list(self.pulses)
        return other

    def __call__(self, t: float) -> np.ndarray | None:
        f = self.preset(t) if self.preset is not None else None
        if not self.pulses:
            return f
        if any(t > p.start + p.duration for p in self.pulses):
            self.pulses = [p for p in self.pulses if t <= p.start + p.duration]
        for pulse in self.pulses:
            g = pulse(t)
            if g is not None:
                f = g if f is None else f + g
        return f


def kick_pulse(
    t: float, peak: float, duration: float, m: int, direction: tuple[float, ...] | None = None
) -> ForcePulse:
    """A pulse starting at ``t``, N (N m on rotational coordinates): ``peak`` times ``direction``'s weights
    over the m base coordinates (None: along the first alone); raises ValueError for bad input."""
    if not np.isfinite(peak) or abs(peak) > MAX_KICK_N:
        raise ValueError(f"kick peak must be a finite force of at most {MAX_KICK_N:g} N, got {peak}")
    weights = (1.0,) + (0.0,) * (m - 1) if direction is None else tuple(direction)
    if len(weights) != m:
        raise ValueError(f"this model's base has {m} coordinates; the kick direction gives {len(weights)}")
    return ForcePulse(start=t, duration=duration, peak=tuple(float(peak) * w for w in weights))
