"""The drawn deflection factor chosen from the motion itself, so that µm and mm both show.

The base of these robots moves by micrometres (TREP on a reactionless path, Fig. 11: 2.8 µm) to
millimetres (the same end points in joint space: 1.3 mm). One fixed factor shows one of them and hides
the other. :class:`AutoExaggeration` draws the recent peak base displacement (live run and shadow run)
at about :data:`AIM` of the arm's reach, the factor a 1-2-5 step between :data:`LEAST` and :data:`MOST`,
and changes it only when the drawn peak leaves [:data:`LOW`, :data:`HIGH`] of the reach, so it does not
flicker. The factor is always written beside the drawing.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Iterable, Sequence

import numpy as np

AIM = 0.1  # the recent peak is drawn at this fraction of the arm's reach ...
LOW, HIGH = 0.03, 0.3  # ... and the factor is kept while the drawn peak stays within these fractions
WINDOW_S = 3.0  # s of simulated time: "recent" (a kick's swing, a Fig. 11 motion)
LEAST, MOST = 1.0, 10000.0  # never drawn smaller than simulated; 2.8 µm at most 28 mm


def step_below(x: float) -> float:
    """The largest 1-2-5 number (1, 2, 5, 10, 20, ...) not above ``x`` (x >= 1)."""
    decade = 10.0 ** math.floor(math.log10(x))
    for mantissa in (5.0, 2.0, 1.0):
        if mantissa * decade <= x * (1.0 + 1e-12):
            return mantissa * decade
    return decade  # pragma: no cover (mantissa 1 always fits)


class AutoExaggeration:
    """The factor for the base displacement of the last :data:`WINDOW_S` of simulated time.

    A base coordinate's displacement is its value (m) for a prismatic joint and its angle times the
    reach (the arc at the hand, m) for a revolute one, as the drawing multiplies both by the factor.
    """

    def __init__(self, reach: float, rotational: Sequence[bool], factor: float = 10.0) -> None:
        self.reach = float(reach)
        self.lever = np.where(np.asarray(rotational, dtype=bool), self.reach, 1.0)
        self.factor = float(np.clip(factor, LEAST, MOST))
        self._peaks: deque[tuple[float, float]] = deque()  # (t, displacement), displacements decreasing
        self._t = -math.inf

    def peak(self) -> float:
        """The largest base displacement of the window (m)."""
        return self._peaks[0][1] if self._peaks else 0.0

    def observe(self, t: float, bases: Iterable[np.ndarray | None]) -> float:
        """Take the base coordinates drawn at simulated time ``t`` (s; the live run's and the shadow's,
        None for a run not drawn) and return the factor to draw them with. Time going back (a reset, a
        replay seek) starts a new window; a repeated time (paused) changes nothing."""
        if t < self._t:
            self._peaks.clear()
        if t == self._t:
            return self.factor
        self._t = t
        finite = [np.abs(b) * self.lever for b in bases if b is not None and np.all(np.isfinite(b))]
        displacement = float(max((np.max(d) for d in finite), default=0.0))
        while self._peaks and self._peaks[-1][1] <= displacement:  # a monotonic queue: its head is the max
            self._peaks.pop()
        self._peaks.append((t, displacement))
        while self._peaks[0][0] < t - WINDOW_S:
            self._peaks.popleft()
        drawn = self.peak() * self.factor / self.reach
        if not LOW <= drawn <= HIGH:
            ideal = MOST if self.peak() == 0.0 else AIM * self.reach / self.peak()
            self.factor = step_below(float(np.clip(ideal, LEAST, MOST)))
        return self.factor
