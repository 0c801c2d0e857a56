"""Wall-clock pacing of the simulation loop, the real-time factor, the falling-behind flag and the time skipped."""

from __future__ import annotations

import time
from collections import deque

SPEEDS = (0.125, 0.25, 0.5, 1.0, 2.0)  # simulated seconds per wall-clock second
MAX_BACKLOG_S = 0.25  # wall s: a shorter stall (another process took the CPU) is caught up, a longer one
# dropped and flagged: catching up runs the simulation faster than real time for a moment
RTF_WINDOW_S = 1.0  # wall s over which the real-time factor is measured
SKIPPED_HOLD_S = 2.0  # wall s a dropped backlog stays reported (the status line says what was skipped)


class Pacer:
    """Maps wall time to the simulated time that is due, at a chosen speed factor."""

    def __init__(self, speed: float = 1.0) -> None:
        self.speed = speed
        self.anchor_wall = time.perf_counter()
        self.anchor_sim = 0.0
        self.dropped = 0  # how often a backlog was dropped
        self._last_drop = -1e9
        self._skipped = 0.0  # simulated s dropped within SKIPPED_HOLD_S of the last drop
        self._samples: deque[tuple[float, float]] = deque()

    def reanchor(self, sim_t: float) -> None:
        """Start pacing afresh from ``sim_t`` now (after pause, reset, speed change)."""
        self.anchor_wall = time.perf_counter()
        self.anchor_sim = sim_t
        self._samples.clear()

    def restart(self, sim_t: float) -> None:
        """:meth:`reanchor`, and no skip reported any more."""
        self.reanchor(sim_t)
        self._skipped, self._last_drop = 0.0, -1e9

    def set_speed(self, speed: float, sim_t: float) -> None:
        if speed not in SPEEDS:
            raise ValueError(f"speed must be one of {SPEEDS}, got {speed}")
        self.speed = speed
        self.reanchor(sim_t)

    def backlog(self, sim_t: float, now: float) -> float:
        """Wall seconds the simulation is behind schedule (negative: ahead)."""
        return (self.anchor_sim + (now - self.anchor_wall) * self.speed - sim_t) / self.speed

    def drop_backlog(self, sim_t: float) -> None:
        """Give up the simulated time that is due and not yet run (a stall longer than MAX_BACKLOG_S)."""
        now = time.perf_counter()
        skipped = self.backlog(sim_t, now) * self.speed
        self._skipped = skipped + (self._skipped if now - self._last_drop < SKIPPED_HOLD_S else 0.0)
        self.dropped += 1
        self._last_drop = now
        self.anchor_wall = now
        self.anchor_sim = sim_t

    def sample(self, sim_t: float, now: float) -> None:
        """Record (wall, sim) for the real-time factor; call a few times per second or more."""
        self._samples.append((now, sim_t))
        while len(self._samples) > 2 and now - self._samples[0][0] > RTF_WINDOW_S:
            self._samples.popleft()

    def rtf(self) -> float:
        """Simulated seconds per wall second over the last RTF_WINDOW_S (nan before enough data)."""
        if len(self._samples) < 2:
            return float("nan")
        (w0, s0), (w1, s1) = self._samples[0], self._samples[-1]
        return (s1 - s0) / (w1 - w0) if w1 - w0 > 0.2 else float("nan")

    def behind(self) -> bool:
        """True while the measured rate is under the chosen speed (by more than 5 %): the loop cannot keep up."""
        r = self.rtf()
        return r == r and r < 0.95 * self.speed

    def skipped(self) -> float:
        """Simulated seconds given up by the drops of the last SKIPPED_HOLD_S (0 if none): after a stall the
        rate may be at or above the speed again (catching up what is left), so this is said apart from it."""
        return self._skipped if time.perf_counter() - self._last_drop < SKIPPED_HOLD_S else 0.0

    def lateness(self, running: bool) -> tuple[bool, float]:
        """(:meth:`behind`, :meth:`skipped`) of a loop that runs in real time now; (False, 0) otherwise."""
        return (self.behind(), self.skipped()) if running else (False, 0.0)
