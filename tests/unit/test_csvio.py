"""The one CSV format (rns_viz.csvio): every float written reads back bit-identical (subnormals, signed
zeros, the largest and smallest exponents, inf and nan), and every header cell carries its unit."""

from __future__ import annotations

import io
import sys
from pathlib import Path

import numpy as np
import pytest

from rns_viz.csvio import csv_text, read_csv, write_csv

SPECIAL = [
    0.0,
    -0.0,
    5e-324,  # the smallest subnormal
    -5e-324,
    2.2250738585072009e-308,  # the largest subnormal
    sys.float_info.min,
    sys.float_info.max,
    -sys.float_info.max,
    sys.float_info.epsilon,
    1.0 + sys.float_info.epsilon,
    0.1,
    1.0 / 3.0,
    np.inf,
    -np.inf,
    np.nan,
]


def random_floats(count: int, seed: int = 1) -> np.ndarray:
    """Floats with random bits: every exponent and mantissa alike (subnormals included), NaNs left out."""
    bits = np.random.default_rng(seed).integers(0, 2**64, count, dtype=np.uint64, endpoint=False)
    values = bits.view(np.float64)
    return values[np.isfinite(values)]


def same_floats(a: np.ndarray, b: np.ndarray) -> bool:
    """Equal bit patterns, any NaN equal to any NaN (the format writes one nan)."""
    nan_a, nan_b = np.isnan(a), np.isnan(b)
    return bool(np.array_equal(nan_a, nan_b) and np.array_equal(a[~nan_a].view(np.uint64), b[~nan_b].view(np.uint64)))


def test_random_and_special_floats_read_back_bit_identical(tmp_path: Path) -> None:
    values = np.concatenate((SPECIAL, random_floats(30_000)))
    values = values[: len(values) // 5 * 5].reshape(-1, 5)
    columns, units = ["t", "xb_1", "theta_1", "tau_1", "L_1"], ["s", "m", "rad", "N m", "kg m^2/s"]
    assert write_csv(tmp_path / "floats.csv", columns, units, values) == len(values)
    table = read_csv(tmp_path / "floats.csv")
    assert table.columns == tuple(columns) and table.units == tuple(units)
    assert table.rows.shape == values.shape and same_floats(table.rows, values)
    assert same_floats(read_csv(csv_text(columns, units, values).encode()).rows, values)  # bytes alike
    assert np.signbit(table.rows.ravel()[1]) and table.rows.ravel()[2] == 5e-324  # -0 stays negative


def test_the_header_carries_each_unit_and_values_have_17_digits() -> None:
    text = csv_text(["t", "xb_1"], ["s", "m"], [[0.1, 1.0 / 3.0]])
    header, line = text.splitlines()
    assert header == "t (s),xb_1 (m)"
    assert line == "0.10000000000000001,0.33333333333333331"
    stream = io.StringIO()
    write_csv(stream, ["t"], ["s"], np.empty((0, 1)))
    assert stream.getvalue() == "t (s)\n" and read_csv(stream.getvalue().encode()).rows.shape == (0, 1)


@pytest.mark.parametrize(
    ("columns", "units", "rows", "fragment"),
    [
        (["t", "x"], ["s"], [[1.0, 2.0]], "do not agree"),
        (["t"], ["s"], [[1.0, 2.0]], "do not agree"),
        (["t"], [""], [[1.0]], "non-empty"),
        (["t,x"], ["s"], [[1.0]], "without"),
        (["t"], ["kg (dry)"], [[1.0]], "without"),
    ],
)
def test_a_table_that_would_not_read_back_is_refused(
    columns: list[str], units: list[str], rows: list[list[float]], fragment: str
) -> None:
    with pytest.raises(ValueError, match=fragment):
        csv_text(columns, units, rows)
