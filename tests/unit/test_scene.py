"""The scene's pure drawing geometry, no viser server: thinned and simplified paths, the bounded trail,
the beam's shape and the spring's coils."""

from __future__ import annotations

import numpy as np
import pytest

from rns_viz.viz.scene.shapes import Trail, guided_cantilever, path_family_segments, simplify, zigzag
from tests.support.drawing import distance_to_segments


def test_long_paths_are_thinned() -> None:
    curve = np.column_stack([np.linspace(0, 1, 1000), np.zeros(1000), np.zeros(1000)])  # straight
    segs, colours, owners = path_family_segments([curve, curve[:10]], None, 100, (0.5, 0.5, 0.5), (1, 0, 0))
    assert len(segs) == 99 + 9 and np.all(owners[:99] == 0)  # tolerance 0: every thinned point is kept
    assert np.allclose(segs[0, 0], curve[0]) and np.allclose(segs[98, 1], curve[-1])
    assert np.allclose(colours, 0.5)


@pytest.mark.parametrize("tolerance", [1e-4, 1e-3, 1e-2])
def test_simplified_paths_stay_within_the_tolerance_with_fewer_points(tolerance: float) -> None:
    s = np.linspace(0.0, 1.0, 2000)
    curve = np.column_stack([s, 0.2 * np.sin(7 * s), 0.05 * np.cos(3 * s)])
    kept = simplify(curve, tolerance)
    rows = [int(np.flatnonzero((curve == point).all(axis=1))[0]) for point in kept]  # whole points of the curve
    assert rows[0] == 0 and rows[-1] == len(curve) - 1 and np.all(np.diff(rows) > 0)  # in order, ends kept
    assert len(kept) < len(curve) / 4
    assert distance_to_segments(curve, np.stack([kept[:-1], kept[1:]], axis=1)).max() <= tolerance
    line = np.column_stack([s, 2 * s, -s])
    assert len(simplify(line, tolerance)) == 2  # a straight line is its two ends
    there_and_back = np.array([[0.0, 0, 0], [1.0, 0, 0], [0.0, 0, 0]])
    assert len(simplify(there_and_back, tolerance)) == 3  # a reversal is kept, however short its chord
    assert len(simplify(line, 0.0)) == len(line)  # no tolerance: nothing dropped, even on a straight line


def test_trail_is_bounded_and_restarts_after_a_jump() -> None:
    trail = Trail(capacity=5, min_step=0.01, max_jump=1.0)
    for k in range(8):
        assert trail.push(np.array([0.1 * k, 0.0, 0.0]))
    assert not trail.push(np.array([0.705, 0.0, 0.0]))  # closer than min_step
    pts = trail.points()
    assert len(pts) == 5 and np.allclose(pts[:, 0], [0.3, 0.4, 0.5, 0.6, 0.7])
    trail.push(np.array([5.0, 0.0, 0.0]))
    assert len(trail) == 1


def test_beam_shape_and_spring_geometry() -> None:
    xi = np.linspace(0, 1, 101)
    u = guided_cantilever(xi)
    assert u[0] == 0 and u[-1] == 1 and np.isclose(u[50], 0.5)
    h = 1e-6
    slope = (guided_cantilever(np.array([h, 1.0])) - guided_cantilever(np.array([0.0, 1.0 - h]))) / h
    assert np.all(np.abs(slope) < 1e-5)  # clamped root, guided tip: no slope at either end
    pts = zigzag(np.zeros(3), np.array([1.0, 0, 0]), np.array([0, 1.0, 0]), coils=4, amplitude=0.1)
    assert np.allclose(pts[0], 0) and np.allclose(pts[-1], [1, 0, 0]) and np.isclose(np.abs(pts[:, 1]).max(), 0.1)
