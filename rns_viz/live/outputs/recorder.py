"""Always-on recording of the last minute of a live session.

:class:`Recorder` is fed by the simulation loop after every 1 ms step (through
:class:`~rns_viz.live.outputs.step_outputs.Outputs`) and keeps the newest :data:`MAX_RECORD_S` seconds in one
preallocated ring buffer, one row per step (the columns of a
:class:`~rns_viz.live.published.recording.Recording`). Always on because it costs
one row copy per step, and 60 s of TREP fill 15 MB (3R: 18 MB);
it restarts with the run (reset, model switch, preset load), so a recording never spans two systems.
:meth:`Recorder.take` copies the newest N seconds into an immutable recording.
"""

from __future__ import annotations

import numpy as np

from rns_viz.live.published.recording import SUPPRESS, Recording, reaction_columns, reaction_units
from rns_viz.live.runs.run_pair import RunPair
from rns_viz.model import FsmsModel
from rns_viz.sim.ring import Ring

MAX_RECORD_S = 60.0  # s of simulated time kept
_SHADOW = ("xb", "xbdot", "theta", "thetadot", "L", "tau")  # the shadow run's columns kept (prefixes)


class Recorder:
    """The ring buffer of the newest MAX_RECORD_S seconds of steps; only the loop thread writes it."""

    def __init__(self, seconds: float = MAX_RECORD_S) -> None:
        self.seconds = seconds
        self._ring: Ring | None = None
        self.columns: tuple[str, ...] = ()
        self.units: tuple[str, ...] = ()
        self.restart()

    def restart(self) -> None:
        """Forget the steps (a new run); the buffer is kept for a run of the same shape."""
        if self._ring is not None:
            self._ring.clear()
        self._configured = False

    def _configure(self, runs: RunPair) -> None:
        log = runs.sim.log
        # The shadow's columns kept: two contiguous runs of its log row (state and torque; L), cheap to copy.
        i = log.index
        n, r = runs.model.n, len(runs.model.selected)
        self._shadow_blocks = (slice(1, i["tau_1"] + n), slice(i["L_1"], i["L_1"] + r))
        shadow_names = [c for block in self._shadow_blocks for c in log.columns[block]]
        assert all(c.rsplit("_", 1)[0] in _SHADOW for c in shadow_names)
        extra = (*reaction_columns(runs.model.m), SUPPRESS)
        self._extra = len(extra)
        columns = (*log.columns, *(f"shadow_{c}" for c in shadow_names), *extra)
        shadow_units = [u for block in self._shadow_blocks for u in log.units[block]]
        self.units = (*log.units, *shadow_units, *reaction_units(runs.model), "1 = on")
        self._log_width = w = len(log.columns)
        self._shadow_into = (slice(w, w + i["tau_1"] + n - 1), slice(w + i["tau_1"] + n - 1, len(columns) - len(extra)))
        capacity = round(self.seconds / runs.sim.dt)
        if self._ring is None or columns != self.columns or self._ring.capacity != capacity:
            self._ring = Ring(capacity, len(columns))
        self.columns, self.dt, self._configured = columns, runs.sim.dt, True

    def nbytes(self) -> int:
        """Memory held by the buffer, bytes."""
        return 0 if self._ring is None else self._ring.nbytes

    def __len__(self) -> int:
        return 0 if self._ring is None else len(self._ring)

    def append(self, runs: RunPair, shadow_on: bool, wrench: tuple[float, ...], suppress: bool) -> None:
        """Book the step just taken: the newest log rows of both runs (state at the step's start t) and
        the reaction's base rows as last evaluated (``wrench``, m floats; () before the first: NaN)."""
        row_log = runs.sim.log.latest()
        if row_log is None:
            return
        if not self._configured:
            self._configure(runs)
        assert self._ring is not None
        row = self._ring.next_row()
        row[: self._log_width] = row_log
        (state, coupling), (state_to, coupling_to) = self._shadow_blocks, self._shadow_into
        shadow = runs.shadow.log.latest() if shadow_on else None
        if shadow is not None and shadow[0] == row_log[0]:
            row[state_to] = shadow[state]
            row[coupling_to] = shadow[coupling]
        else:
            row[state_to.start : coupling_to.stop] = np.nan
        row[-self._extra : -1] = wrench if len(wrench) == self._extra - 1 else np.nan
        row[-1] = 1.0 if suppress else 0.0

    def take(self, seconds: float, model: FsmsModel) -> Recording | None:
        """The newest ``seconds`` of steps as an immutable :class:`Recording` (None if under two steps)."""
        if self._ring is None or len(self._ring) < 2:
            return None
        rows = self._ring.newest(max(2, round(seconds / self.dt)))  # a copy
        return Recording(self.columns, self.units, rows, model, self.dt)
