"""Step log: one row per control step in a fixed-size ring buffer (bounded memory in long runs)."""

from __future__ import annotations

import csv
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from rns_viz.control.common import ControlOutput
    from rns_viz.model import FsmsModel

RowCompleter = Callable[[np.ndarray], None]  # fills derived columns of a block of new rows in place


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


class RowLayout:
    """Where each quantity of a step goes in a row of :func:`log_columns` (index arrays and slices)."""

    def __init__(self, model: FsmsModel) -> None:
        m, n = model.m, model.n
        r, p = len(model.selected), len(model.task_rows)
        self.columns = log_columns(m, n, r, p)
        col = {name: i for i, name in enumerate(self.columns)}
        # The stacked state (x_b, theta, x_b', theta') goes to columns xb, theta, xbdot, thetadot.
        names = [f"xb_{i + 1}" for i in range(m)] + [f"theta_{i + 1}" for i in range(n)]
        names += [f"xbdot_{i + 1}" for i in range(m)] + [f"thetadot_{i + 1}" for i in range(n)]
        self.state = np.array([col[name] for name in names])
        self.theta = slice(col["theta_1"], col["theta_1"] + n)
        self.tau = slice(col["tau_1"], col["tau_1"] + n)
        self.fext = slice(col["fext_1"], col["fext_1"] + m)
        self.ee = slice(col["ee_x"], col["ee_x"] + 3)
        self.coupling = slice(col["L_1"], col["L_1"] + r)
        self.sigma_hbm = col["sigma_hbm"]
        self.sigma_jbar = col["sigma_jbar"]
        self.theta_ref = slice(col["theta_ref_1"], col["theta_ref_1"] + n)
        self.ee_ref = slice(self.theta_ref.stop, self.theta_ref.stop + p)
        self.references = slice(self.theta_ref.start, self.ee_ref.stop)

    def write(self, row: np.ndarray, t: float, x: np.ndarray, out: ControlOutput, f: np.ndarray | None) -> None:
        """Fill ``row`` for the step from state x = (q, v) at time t; the end-effector columns are left."""
        row[0] = t
        row[self.state] = x
        row[self.tau] = out.tau
        row[self.fext] = 0.0 if f is None else f
        row[self.coupling] = out.coupling_momentum
        row[self.sigma_hbm] = out.sigma_hbm
        row[self.sigma_jbar] = out.sigma_jbar
        row[self.references] = np.nan  # theta_ref and ee_ref: the last columns
        if out.theta_ref is not None:
            row[self.theta_ref] = out.theta_ref
        if out.ee_ref is not None:
            row[self.ee_ref.start : self.ee_ref.start + len(out.ee_ref)] = out.ee_ref


class StepLog:
    """A ring buffer of rows; ``capacity`` rows are kept, the oldest dropped first.

    ``complete``, if given, fills derived columns (the end-effector position) of newly added rows
    in place, in blocks, when the log is next read: a step only pays for what it measured.
    """

    def __init__(self, columns: list[str], capacity: int, complete: RowCompleter | None = None) -> None:
        if capacity < 1:
            raise ValueError("log capacity must be at least one row")
        self.columns = columns
        self.index = {name: i for i, name in enumerate(columns)}
        self._data = np.full((capacity, len(columns)), np.nan)
        self._next = 0
        self._count = 0
        self._complete = complete
        self._incomplete = 0  # newest rows not yet passed to ``complete``

    def append(self, row: np.ndarray) -> None:
        self.next_row()[:] = row

    def next_row(self) -> np.ndarray:
        """A new row, to be filled in place by the caller (a view into the buffer, oldest row dropped)."""
        row = self._data[self._next]
        self._next += 1
        if self._next == len(self._data):
            self._next = 0
        if self._count < len(self._data):
            self._count += 1
        self._incomplete += 1
        return row

    def newest(self) -> np.ndarray | None:
        """The newest row as a view (derived columns not yet filled), or None if the log is empty."""
        return self._data[self._next - 1] if self._count else None

    def clear(self) -> None:
        self._next = 0
        self._count = 0
        self._incomplete = 0

    def __len__(self) -> int:
        return self._count

    def array(self, last: int | None = None) -> np.ndarray:
        """The rows in time order (a copy); ``last`` limits to the newest rows."""
        return self._data[self._indices(last)].copy()

    def column(self, name: str, last: int | None = None) -> np.ndarray:
        return self._data[self._indices(last), self.index[name]]

    def _indices(self, last: int | None) -> np.ndarray:
        self._complete_rows()
        k = self._count if last is None else min(last, self._count)
        start = (self._next - k) % len(self._data)
        return (start + np.arange(k)) % len(self._data)

    def _complete_rows(self) -> None:
        k = min(self._incomplete, self._count)
        self._incomplete = 0
        if self._complete is not None and k:
            for block in self._newest_blocks(k):
                self._complete(block)

    def _newest_blocks(self, k: int) -> Iterator[np.ndarray]:
        """The newest k rows as at most two contiguous views (the ring may wrap around)."""
        start = self._next - k
        if start < 0:
            yield self._data[start:]
            start = 0
        if self._next > start:
            yield self._data[start : self._next]

    def write_csv(self, target: str | Path | object) -> None:
        """Write all kept rows with a header; ``target`` is a path or a text stream."""
        rows = self.array()
        if isinstance(target, str | Path):
            with Path(target).open("w", newline="") as handle:
                self._write(handle, rows)
        else:
            self._write(target, rows)

    def _write(self, handle: object, rows: np.ndarray) -> None:
        write_csv_rows(handle, self.columns, rows)


def write_csv_rows(handle: object, header: list[str], rows: np.ndarray, digits: int = 10) -> None:
    """A header line and one line per row, ``digits`` significant digits (17 reads back bit-exact)."""
    writer = csv.writer(handle)  # type: ignore[arg-type]
    writer.writerow(header)
    writer.writerows([[f"{x:.{digits}g}" for x in row] for row in rows])
