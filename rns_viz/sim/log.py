"""Step log: one row per control step in a fixed-size ring buffer (bounded memory in long runs)."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np


def log_columns(m: int, n: int, r: int, p: int) -> list[str]:
    """Column names, SI units and radians (see README, "CSV columns")."""

    def seq(prefix: str, k: int) -> list[str]:
        return [f"{prefix}_{i + 1}" for i in range(k)]

    return [
        "t",
        *seq("xb", m),
        *seq("xbdot", m),
        *seq("theta", n),
        *seq("thetadot", n),
        *seq("tau", n),
        *seq("fext", m),
        "ee_x",
        "ee_y",
        "ee_z",
        *seq("L", r),
        "sigma_hbm",
        "sigma_jbar",
        *seq("theta_ref", n),
        *[f"ee_ref_{a}" for a in "xyz"[:p]],
    ]


class StepLog:
    """A ring buffer of rows; ``capacity`` rows are kept, the oldest dropped first."""

    def __init__(self, columns: list[str], capacity: int) -> None:
        if capacity < 1:
            raise ValueError("log capacity must be at least one row")
        self.columns = columns
        self.index = {name: i for i, name in enumerate(columns)}
        self._data = np.full((capacity, len(columns)), np.nan)
        self._next = 0
        self._count = 0

    def append(self, row: np.ndarray) -> None:
        self._data[self._next] = row
        self._next = (self._next + 1) % len(self._data)
        self._count = min(self._count + 1, len(self._data))

    def clear(self) -> None:
        self._next = 0
        self._count = 0

    def __len__(self) -> int:
        return self._count

    def array(self, last: int | None = None) -> np.ndarray:
        """The rows in time order (a copy); ``last`` limits to the newest rows."""
        k = self._count if last is None else min(last, self._count)
        start = (self._next - k) % len(self._data)
        idx = (start + np.arange(k)) % len(self._data)
        return self._data[idx].copy()

    def column(self, name: str, last: int | None = None) -> np.ndarray:
        k = self._count if last is None else min(last, self._count)
        start = (self._next - k) % len(self._data)
        idx = (start + np.arange(k)) % len(self._data)
        return self._data[idx, self.index[name]]

    def write_csv(self, target: str | Path | object) -> None:
        """Write all kept rows with a header; ``target`` is a path or a text stream."""
        rows = self.array()
        if isinstance(target, str | Path):
            with Path(target).open("w", newline="") as handle:
                self._write(handle, rows)
        else:
            self._write(target, rows)

    def _write(self, handle: object, rows: np.ndarray) -> None:
        writer = csv.writer(handle)  # type: ignore[arg-type]
        writer.writerow(self.columns)
        writer.writerows([[f"{x:.10g}" for x in row] for row in rows])
