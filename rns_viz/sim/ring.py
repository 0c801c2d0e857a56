"""A ring of float rows of fixed width: bounded memory however long a run goes.

The step log (:class:`~rns_viz.sim.log.StepLog`), the live session's recorder (the last minute of steps)
and its plot buffers keep their newest rows in one. The rows are allocated once; appending to a full
ring overwrites the oldest row, and allocates nothing (the step log appends every 1 ms step).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike


class Ring:
    """The newest ``capacity`` rows of ``width`` floats, readable in time order.

    Not locked: one thread writes, and an owner that other threads read locks around both
    (rns_viz.live.published.plot_buffers).
    """

    def __init__(self, capacity: int, width: int) -> None:
        if capacity < 1:
            raise ValueError("a ring holds at least one row")
        self._data = np.full((capacity, width), np.nan)
        self._next = 0  # the slot of the next row
        self._count = 0  # rows held
        self.appended = 0  # rows appended since the last clear (past the capacity too)

    @property
    def capacity(self) -> int:
        return len(self._data)

    @property
    def width(self) -> int:
        return self._data.shape[1]

    @property
    def nbytes(self) -> int:
        """Memory held by the rows, bytes."""
        return self._data.nbytes

    def __len__(self) -> int:
        return self._count

    def next_row(self) -> np.ndarray:
        """The slot of a new row, to be filled in place by the caller (a view; a full ring drops its oldest)."""
        row = self._data[self._next]
        self._next += 1
        if self._next == len(self._data):
            self._next = 0
        if self._count < len(self._data):
            self._count += 1
        self.appended += 1
        return row

    def append(self, row: ArrayLike) -> None:
        self.next_row()[:] = row

    def extend(self, rows: ArrayLike) -> None:
        """Append the rows of a (k, width) block in order (of more than ``capacity``, the last ones stay)."""
        block = np.asarray(rows, dtype=float).reshape(-1, self.width)
        k, capacity = len(block), len(self._data)
        kept = block[-capacity:]
        first = min(len(kept), capacity - self._next)  # rows that fit before the end of the array
        self._data[self._next : self._next + first] = kept[:first]
        self._data[: len(kept) - first] = kept[first:]
        self._next = (self._next + len(kept)) % capacity
        self._count = min(self._count + k, capacity)
        self.appended += k

    def clear(self) -> None:
        """Forget every row (the memory is kept)."""
        self._next = self._count = self.appended = 0

    def latest(self) -> np.ndarray | None:
        """The newest row as a view (it changes when the slot is reused), or None when empty."""
        return self._data[self._next - 1] if self._count else None

    def newest(self, k: int | None = None, column: int | None = None) -> np.ndarray:
        """The newest ``k`` rows (all when None), oldest first, as a copy; ``column``: of that column only."""
        columns = slice(None) if column is None else column
        blocks = self.blocks(k)
        if len(blocks) == 1:
            return blocks[0][:, columns].copy()
        return np.concatenate([block[:, columns] for block in blocks])

    def blocks(self, k: int | None = None) -> list[np.ndarray]:
        """The newest ``k`` rows (all when None) as one or two views in time order (two where they wrap
        around the end of the array): what an owner fills in place."""
        k = self._count if k is None else max(0, min(k, self._count))
        start = self._next - k
        if start >= 0:
            return [self._data[start : self._next]]
        return [self._data[start:], self._data[: self._next]]
