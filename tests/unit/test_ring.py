"""The ring of rows behind the step log, the recorder and the plot buffers (rns_viz.sim.ring): rows come
back in time order across the seam where it wraps, the oldest leave first, and clear forgets them."""

from __future__ import annotations

import numpy as np
import pytest

from rns_viz.sim.ring import Ring


def rows(start: int, stop: int, width: int = 3) -> np.ndarray:
    """Rows whose entries name them: row k is (k, 10 k, 100 k, ...)."""
    return np.arange(start, stop)[:, None] * 10.0 ** np.arange(width)


def test_appends_wrap_around_and_the_newest_rows_come_back_in_time_order() -> None:
    ring = Ring(5, 3)
    for row in rows(0, 8):  # three past the capacity: rows 0, 1, 2 overwritten
        ring.append(row)
    assert len(ring) == 5 and ring.appended == 8
    np.testing.assert_array_equal(ring.newest(), rows(3, 8))
    np.testing.assert_array_equal(ring.newest(4), rows(4, 8))  # across the seam (slots 4, 0, 1, 2)
    np.testing.assert_array_equal(ring.newest(2), rows(6, 8))  # before it
    np.testing.assert_array_equal(ring.newest(99), rows(3, 8))  # at most what is held
    np.testing.assert_array_equal(ring.newest(4, column=1), rows(4, 8)[:, 1])
    np.testing.assert_array_equal(ring.latest(), rows(7, 8)[0])
    assert [len(b) for b in ring.blocks()] == [2, 3]  # slots 3-4, then 0-2: two views in time order


def test_newest_is_a_copy_and_next_row_a_slot_filled_in_place() -> None:
    ring = Ring(3, 2)
    ring.next_row()[:] = (1.0, 2.0)
    out = ring.newest()
    out[0, 0] = -1.0
    assert ring.newest()[0, 0] == 1.0
    for block in ring.blocks(1):
        block[:, 1] = 5.0  # an owner completing a column in place (the step log's end-effector columns)
    np.testing.assert_array_equal(ring.newest(), [[1.0, 5.0]])


@pytest.mark.parametrize("chunks", [(2, 2, 2, 2), (4, 3), (7,), (12,), (1, 9, 1)])
def test_extend_equals_appending_row_by_row(chunks: tuple[int, ...]) -> None:
    by_row, by_block = Ring(5, 3), Ring(5, 3)
    start = 0
    for k in chunks:
        block = rows(start, start + k)
        for row in block:
            by_row.append(row)
        by_block.extend(block)
        start += k
        np.testing.assert_array_equal(by_block.newest(), by_row.newest())
        assert len(by_block) == len(by_row) and by_block.appended == by_row.appended


def test_clear_forgets_the_rows_and_keeps_the_memory() -> None:
    ring = Ring(4, 2)
    ring.extend(rows(0, 6, 2))
    memory = ring.nbytes
    ring.clear()
    assert len(ring) == 0 and ring.appended == 0 and ring.latest() is None
    assert ring.newest().shape == (0, 2)
    ring.append((7.0, 8.0))
    np.testing.assert_array_equal(ring.newest(), [[7.0, 8.0]])
    assert ring.nbytes == memory == 4 * 2 * 8


def test_a_ring_holds_at_least_one_row() -> None:
    with pytest.raises(ValueError, match="at least one row"):
        Ring(0, 3)
