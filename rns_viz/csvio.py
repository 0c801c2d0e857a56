"""CSV tables of numbers: the one format of every table rns_viz writes.

A header line with one cell per column carrying its unit, ``xb_1 (m)``, then one line per row with every
value to 17 significant digits, which a reader turns back into the very floats written (``nan``, ``inf``,
``-0`` and subnormals too). The step log, the app's downloads, ``rns-viz run``, ``paths`` and ``gains``
all write through :func:`write_csv`; :func:`read_csv` reads any of them back.
"""

from __future__ import annotations

import io
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import IO

import numpy as np
from numpy.typing import ArrayLike

VALUE_FORMAT = "%.17g"  # 17 significant digits: enough for any float64 to read back exactly


@dataclass(frozen=True)
class CsvTable:
    """A CSV table read back: column names, their units (as the header gave them) and the rows."""

    columns: tuple[str, ...]
    units: tuple[str, ...]
    rows: np.ndarray  # (rows, columns), float64

    def column(self, name: str) -> np.ndarray:
        return self.rows[:, self.columns.index(name)]


def header_cell(name: str, unit: str) -> str:
    """``("xb_1", "m")`` -> ``"xb_1 (m)"``."""
    return f"{name} ({unit})"


def csv_text(columns: Sequence[str], units: Sequence[str], rows: ArrayLike) -> str:
    """The table as CSV text: a header of :func:`header_cell` per column, then one line per row."""
    table = np.asarray(rows, dtype=float)
    if table.ndim != 2 or table.shape[1] != len(columns) or len(units) != len(columns):
        raise ValueError(f"{len(columns)} columns, {len(units)} units and rows of shape {table.shape} do not agree")
    for cell in (*columns, *units):
        if not cell or any(c in cell for c in ',()\n\r"'):
            raise ValueError(f"a column name or unit must be non-empty, without , ( ) or quotes: {cell!r}")
    line = ",".join([VALUE_FORMAT] * len(columns))
    out = [",".join(map(header_cell, columns, units))]
    out.extend(line % tuple(row) for row in table.tolist())
    return "\n".join(out) + "\n"


def write_csv(target: str | Path | IO[str], columns: Sequence[str], units: Sequence[str], rows: ArrayLike) -> int:
    """Write the table to a path or an open text stream; returns the number of rows written."""
    text = csv_text(columns, units, rows)
    if isinstance(target, str | Path):
        Path(target).write_text(text)
    else:
        target.write(text)
    return text.count("\n") - 1


def read_csv(source: str | Path | bytes | IO[str]) -> CsvTable:
    """Read a table written by :func:`write_csv` (a path, the bytes of a download or a text stream)."""
    if isinstance(source, bytes):
        text = source.decode()
    elif isinstance(source, str | Path):
        text = Path(source).read_text()
    else:
        text = source.read()
    header, _, body = text.partition("\n")
    names, units = [], []
    for cell in header.strip().split(","):
        name, _, unit = cell.partition(" (")
        names.append(name.strip())
        units.append(unit.removesuffix(")"))
    rows = np.loadtxt(io.StringIO(body), delimiter=",", dtype=float, ndmin=2) if body.strip() else np.empty((0, 0))
    return CsvTable(tuple(names), tuple(units), rows.reshape(-1, len(names)))
