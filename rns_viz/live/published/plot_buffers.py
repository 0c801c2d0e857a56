"""Ring buffers of the live plots: decimated samples over a sliding window of simulated time."""

from __future__ import annotations

import threading

import numpy as np

from rns_viz.sim.ring import Ring

# "suppress" is 1.0 while the operated run had suppression on (the shadow had it off), else 0.0.
# xb is the base deflection (mm): x_b itself on a 1-DOF base, |translation| on a larger one, whose
# coordinates are xb_1 ... xb_6 (mm or mrad, the operated run; 0 beyond the base's m).
BASE_COORDINATES = 6
PLOT_SERIES = (
    "t",
    "xb",
    "xb_shadow",
    "L",
    "L_shadow",
    "ee_error",
    "suppress",
    *(f"xb_{i + 1}" for i in range(BASE_COORDINATES)),
)


class PlotBuffers:
    """``capacity`` rows of PLOT_SERIES; the loop appends, any thread copies a time-ordered view."""

    def __init__(self, capacity: int = 1000) -> None:
        self._ring = Ring(capacity, len(PLOT_SERIES))
        self._lock = threading.Lock()
        self.version = 0

    def clear(self) -> None:
        with self._lock:
            self._ring.clear()
            self.version += 1

    def append(self, row: tuple[float, ...]) -> None:
        with self._lock:
            self._ring.append(row)
            self.version += 1

    def arrays(self) -> dict[str, np.ndarray]:
        """Each series, oldest first (copies)."""
        with self._lock:
            rows = self._ring.newest()
        return {name: rows[:, i].copy() for i, name in enumerate(PLOT_SERIES)}
