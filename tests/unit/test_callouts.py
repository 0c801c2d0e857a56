"""Callouts' geometry: the page's pinhole projection, cells taken by a projected solid, and labels placed on
free cells inside the page, off each other, on every page at once (rns_viz.viz.scene.callout_layout)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rns_viz.viz.scene.callout_layout import (
    CELL_PX,
    Occupancy,
    PageCamera,
    Placement,
    box_at,
    convex_hull,
    text_size,
)
from rns_viz.viz.scene.callouts import Callout, Callouts, FixedText


def look_at(eye: np.ndarray, target: np.ndarray, width: int = 800, height: int = 600) -> PageCamera:
    """A camera at ``eye`` looking at ``target`` with world z up (OpenCV axes: x right, y down, z ahead)."""
    forward = (target - eye) / np.linalg.norm(target - eye)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    down = np.cross(forward, right)
    return PageCamera(eye, np.column_stack([right, down, forward]), math.radians(60.0), width, height)


def test_projection_is_the_pinhole_and_unprojection_inverts_it() -> None:
    rng = np.random.default_rng(3)
    cam = look_at(np.array([2.0, -3.0, 1.5]), np.zeros(3))
    centre, depth = cam.project(np.zeros(3))
    assert np.allclose(centre, [400.0, 300.0]) and depth == pytest.approx(np.linalg.norm([2.0, -3.0, 1.5]))
    # a point 0.1 m right of the target, seen from distance d: focal * 0.1 / d px right of the centre
    right = cam.rotation[:, 0]
    px, _ = cam.project(0.1 * right)
    focal = 300.0 / math.tan(math.radians(30.0))
    assert px[0] - 400.0 == pytest.approx(focal * 0.1 / depth) and px[1] == pytest.approx(300.0)
    for _ in range(20):
        pixel, d = rng.uniform([0, 0], [800, 600]), rng.uniform(0.5, 9.0)
        world = cam.unproject(pixel, d)
        back, d_back = cam.project(world)
        assert np.allclose(back, pixel, atol=1e-9) and d_back == pytest.approx(d)
    behind, _ = cam.project(cam.position - cam.rotation[:, 2])
    assert np.all(np.isnan(behind))


def test_a_solid_takes_the_cells_under_its_hull_and_no_others() -> None:
    page = Occupancy(400, 300)
    triangle = np.array([[100.0, 100.0], [200.0, 100.0], [100.0, 200.0]])
    page.add_solid(triangle)
    assert page.taken(np.array([110.0, 110.0, 130.0, 130.0])) > 0  # inside
    assert page.taken(np.array([170.0, 170.0, 200.0, 200.0])) == 0  # beyond the hypotenuse
    assert page.taken(np.array([250.0, 50.0, 390.0, 290.0])) == 0
    # a link seen end-on projects to a segment one pixel wide: its cells are still taken
    thin = Occupancy(400, 300)
    thin.add_solid(np.array([[50.0, 250.0], [350.0, 250.5]]))
    assert thin.taken(np.array([195.0, 245.0, 205.0, 255.0])) > 0
    assert thin.taken(np.array([195.0, 200.0, 205.0, 240.0])) == 0


def test_hull_is_the_convex_hull() -> None:
    rng = np.random.default_rng(0)
    pts = rng.normal(size=(40, 2))
    hull = convex_hull(pts)
    # every point is on the inner side of every hull edge (counter-clockwise in y-up terms)
    for a, b in zip(hull, np.roll(hull, -1, axis=0), strict=True):
        e = b - a
        assert np.all(e[0] * (pts[:, 1] - a[1]) - e[1] * (pts[:, 0] - a[0]) >= -1e-12)


def test_box_at_puts_the_box_on_the_anchors_side() -> None:
    point, size = np.array([100.0, 100.0]), (40.0, 20.0)
    assert np.allclose(box_at(point, "bottom-left", size), [100.0, 80.0, 140.0, 100.0])  # above right
    assert np.allclose(box_at(point, "top-right", size), [60.0, 100.0, 100.0, 120.0])  # below left
    assert np.allclose(box_at(point, "center-center", size), [80.0, 90.0, 120.0, 110.0])


def _corners(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    return np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])


def _label_box(cam: PageCamera, item: Callout) -> np.ndarray:
    at, _ = cam.project(np.asarray(item.point) + item.offset)
    assert item.placement is not None
    return box_at(at, item.placement.anchor, text_size(item.text))


def test_two_callouts_land_off_the_arm_off_each_other_and_inside_two_pages() -> None:
    # an "arm": three link boxes around the named points, seen by two pages from different sides
    links = np.stack(
        [
            _corners(np.array([-0.05, -0.05, 0.0]), np.array([0.05, 0.05, 0.6])),
            _corners(np.array([-0.05, -0.05, 0.55]), np.array([0.45, 0.05, 0.65])),
            _corners(np.array([0.4, -0.05, 0.3]), np.array([0.5, 0.05, 0.65])),
        ]
    )
    pages = [
        look_at(np.array([1.2, -1.8, 1.2]), np.array([0.2, 0.0, 0.35])),
        look_at(np.array([-1.0, -1.6, 0.9]), np.array([0.2, 0.0, 0.35]), 390, 500),
    ]
    hand, elbow = np.array([0.45, 0.0, 0.45]), np.array([0.05, 0.0, 0.6])
    drag = Callout(None, None, "drag me", point=hand, keep_clear=0.05)  # type: ignore[arg-type]
    ghost = Callout(None, None, "ghost: suppression off", point=elbow)  # type: ignore[arg-type]
    callouts = Callouts(None)  # type: ignore[arg-type]
    callouts._layout([drag, ghost], pages, links)
    for cam in pages:
        arm = Occupancy(cam.width, cam.height)
        for corners in cam.project(links)[0]:
            arm.add_solid(corners)
        boxes = [_label_box(cam, item) for item in (drag, ghost)]
        for box in boxes:
            assert arm.inside(box) and arm.taken(box) == 0, (cam.width, box)
        a, b = boxes
        assert min(a[2], b[2]) <= max(a[0], b[0]) or min(a[3], b[3]) <= max(a[1], b[1])  # disjoint
    # the place in use is kept while it stays free (no hopping between equally good places)
    kept = drag.placement
    callouts._layout([drag, ghost], pages, links)
    assert drag.placement == kept


def test_a_place_that_is_no_longer_free_is_given_up() -> None:
    cam = look_at(np.array([0.0, -2.0, 0.0]), np.zeros(3))
    item = Callout(None, None, "drag me", point=np.zeros(3))  # type: ignore[arg-type]
    item.placement = Placement((22.0, 0.0), "center-left")  # right of the point ...
    wall = _corners(np.array([0.005, -0.1, -0.1]), np.array([0.5, 0.1, 0.1]))  # ... where a link now is
    Callouts(None)._layout([item], [cam], wall[None])  # type: ignore[arg-type]
    assert item.placement is not None and item.placement.offset[0] < 0  # moved to the free side
    page = Occupancy(cam.width, cam.height)
    page.add_solid(cam.project(wall)[0])
    assert page.taken(_label_box(cam, item)) == 0


def test_taken_cells_counted_as_the_cells_under_the_box_after_every_addition() -> None:
    """The summed-area count of taken cells equals a direct count over the box's cells, also right after
    a solid or a box is added (a stale table would count the cells before the addition)."""
    rng = np.random.default_rng(7)
    page = Occupancy(333, 217)
    for _ in range(20):
        if rng.random() < 0.5:
            page.add_solid(rng.uniform([0, 0], [333, 217], size=(8, 2)))
        else:
            x, y = rng.uniform(-20, 330), rng.uniform(-20, 210)
            page.add_box(np.array([x, y, x + rng.uniform(0, 60), y + rng.uniform(0, 40)]))
        for _ in range(25):
            x0, y0 = rng.uniform(-30, 340), rng.uniform(-30, 220)
            box = np.array([x0, y0, x0 + rng.uniform(-5, 120), y0 + rng.uniform(-5, 80)])
            i0, j0, i1, j1 = (
                int(np.clip(f(v / CELL_PX), 0, n))
                for v, f, n in zip(
                    box,
                    (math.floor, math.floor, math.ceil, math.ceil),
                    (page.cells.shape[1], page.cells.shape[0]) * 2,
                    strict=True,
                )
            )
            want = int(np.count_nonzero(page.cells[j0:j1, i0:i1])) if i1 > i0 and j1 > j0 else 0
            assert page.taken(box) == want, box


def test_a_written_text_is_kept_clear_of_like_a_solid() -> None:
    """The gain map's title and legend (several lines) are written in the scene: a callout whose place is on
    one of them gives it up, and its box is then off the text's whole box (every line of it)."""
    cam = look_at(np.array([0.0, -2.0, 0.0]), np.zeros(3))
    item = Callout(None, None, "drag me", point=np.zeros(3))  # type: ignore[arg-type]
    item.placement = Placement((22.0, 0.0), "center-left")  # right of the point ...
    legend = FixedText(np.array([0.02, 0.0, 0.05]), "top-left", "line one\nline two, longer\nline three")  # ... there
    no_solids = np.zeros((0, 8, 3))
    Callouts(None)._layout([item], [cam], no_solids, [legend])  # type: ignore[arg-type]
    at, _ = cam.project(legend.point)
    width, height = text_size(legend.text)
    assert height > text_size("line one")[1] + 30  # three lines are taller than one
    page = Occupancy(cam.width, cam.height)
    page.add_box(box_at(at, legend.anchor, (width, height)))
    assert page.taken(_label_box(cam, item)) == 0
    assert item.placement is not None and item.placement.offset != (22.0, 0.0)


def test_the_longest_callout_fits_a_phones_page() -> None:
    """A label wider than the page has no place inside it: the layout then puts it anywhere (the 3R's region
    edge had landed under a phone's panel sheet). Its words are in two lines."""
    from rns_viz.viz.scene.callout_layout import EDGE_PX
    from rns_viz.viz.scene.teach_scene import EDGE_TEXT

    assert text_size(EDGE_TEXT)[0] <= 390 - 2 * EDGE_PX < text_size(EDGE_TEXT.replace("\n", " "))[0]
