"""Callouts: labels beside the points they name, each tied to its point by a leader line.

A callout's nodes hang under the scene node its point moves with (the drawn base, the ghost's hand, the
handle's frame), so they follow it with nothing sent per frame; only a new place is sent.

Every LAYOUT_S the labels are placed (rns_viz.viz.scene.callout_layout) for the pages connected: candidate
places are taken on the primary page (the operator's, else the first), each scored on every page by the
cells of an arm (the robot's and the ghost's links) or another label it would cover; the first free place
wins, the one in use is kept while it stays free (labels do not hop). Between layouts a label keeps its
offset from its point in the world, so it follows a moving hand.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
import viser
import viser.transforms as vtf

from rns_viz.viz.scene.callout_layout import (
    CELL_PX,
    GAP_PX,
    Occupancy,
    PageCamera,
    Placement,
    box_at,
    candidates,
    cost,
    text_size,
)
from rns_viz.viz.scene.framing import band_for, main_panel_box

LAYOUT_S = 0.25  # s between layouts (while the view or the arm moves; none while both stand still)
STILL_PX = 0.5 * CELL_PX  # a layout is skipped while no page's projected point or solid moved more than this (px)
LEADER_COLOUR = (90, 90, 90)


def page_camera(client: viser.ClientHandle, notice: bool = False) -> PageCamera | None:
    """The camera a page last reported, or None before its first report; ``notice``: its floating panel
    shows the slowed-display line (and covers more of the scene)."""
    cam = client.camera
    if cam.update_timestamp == 0.0 or cam.image_width <= 0 or cam.image_height <= 0:
        return None
    rotation = vtf.SO3(np.asarray(cam.wxyz, dtype=float)).as_matrix()
    position, width, height = np.asarray(cam.position, dtype=float), cam.image_width, cam.image_height
    bottom, top = band_for(width, height)  # NDC y: a phone's panel sheet covers the page below the band
    shown = ((1.0 - top) / 2.0 * height, (1.0 - bottom) / 2.0 * height)
    return PageCamera(position, rotation, float(cam.fov), width, height, shown, main_panel_box(width, height, notice))


class FixedText(NamedTuple):
    """A label written at a fixed place in the scene (not a callout): callouts keep off its box."""

    point: np.ndarray  # world, m
    anchor: str  # viser's anchor of the label at ``point``
    text: str


@dataclass(eq=False)  # one callout is itself only (``in`` must not compare its arrays)
class Callout:
    """One label and its leader under a parent node; the owner calls :meth:`attach` and sets ``text`` and
    ``shown`` each frame."""

    label: viser.LabelHandle
    leader: viser.LineSegmentsHandle
    text: str
    point: np.ndarray | None = None  # world, m
    shown: bool = True
    keep_clear: float = 0.0  # m: a cube of this half-size about the point is also kept clear (a handle)
    placement: Placement | None = None
    offset: np.ndarray = field(default_factory=lambda: np.zeros(3))  # label - point, world, m
    local: np.ndarray = field(default_factory=lambda: np.zeros(3))  # the point in the parent's frame, m
    rotation: np.ndarray = field(default_factory=lambda: np.eye(3))  # the parent's, world from parent
    offset_local: np.ndarray = field(default_factory=lambda: np.zeros(3))  # ``offset`` in the parent's frame
    sent: tuple[tuple[float, ...], str, bool] | None = None

    def attach(self, rotation: np.ndarray, translation: np.ndarray, local: np.ndarray) -> None:
        """The parent's world pose now and the point in its frame (m)."""
        self.rotation, self.local = np.asarray(rotation, dtype=float), np.asarray(local, dtype=float)
        self.point = self.rotation @ self.local + np.asarray(translation, dtype=float)


class Callouts:
    """The scene's callouts; :meth:`frame` places and draws them."""

    def __init__(self, server: viser.ViserServer) -> None:
        self.server = server
        self.items: dict[str, Callout] = {}
        self.next_layout = 0.0
        self._laid_out: tuple[list[str], list[np.ndarray]] | None = None  # what the last layout saw

    def add(self, name: str, text: str, *, parent: str = "", keep_clear: float = 0.0) -> Callout:
        """A callout whose nodes hang under the scene node ``parent`` ('' for the world)."""
        scene = self.server.scene
        label = scene.add_label(f"{parent}/callout_{name}", text, anchor="bottom-left", visible=False)
        leader = scene.add_line_segments(
            f"{parent}/callout_{name}_leader",
            np.zeros((1, 2, 3)),
            LEADER_COLOUR,
            thickness=1.5,
            thickness_units="screen",
            visible=False,
        )
        item = Callout(label, leader, text, keep_clear=keep_clear)
        self.items[name] = item
        return item

    def frame(
        self,
        now: float,
        pages: Callable[[], Sequence[PageCamera]],
        solids: Callable[[], np.ndarray],
        labels_on: bool,
        texts: Callable[[], Sequence[FixedText]] = lambda: (),
    ) -> None:
        """Place the callouts if it is time (``pages()``: the pages' cameras, primary first; ``solids()``:
        (L, 8, 3) world corners of what no label may cover; ``texts()``: other labels written in the scene,
        which no callout may cover either) and send what changed."""
        live = [c for c in self.items.values() if labels_on and c.shown and _finite(c.point)]
        if live and now >= self.next_layout:
            self.next_layout = now + LAYOUT_S
            cameras = pages()
            if cameras:  # no page: the labels stay where they were
                corners, fixed = solids(), list(texts())
                seen = self._seen(live, cameras, corners, fixed)
                if not self._same(seen):
                    self._laid_out = seen
                    self._layout(live, cameras, corners, fixed)
        for item in self.items.values():
            self._draw(item, item in live)

    @staticmethod
    def _seen(
        live: list[Callout], pages: Sequence[PageCamera], solids: np.ndarray, fixed: Sequence[FixedText] = ()
    ) -> tuple[list[str], list[np.ndarray]]:
        """What a layout depends on: the callouts' words, and on each page its size, the box its floating panel
        covers, and the points' and solids' pixels."""
        points = np.array([item.point for item in live] + [text.point for text in fixed], dtype=float)
        world = np.concatenate([points, solids.reshape(-1, 3)])
        return [item.text for item in live] + [text.text for text in fixed], [
            np.r_[page.width, page.height, page.covered or (), page.project(world)[0].ravel()] for page in pages
        ]

    def _same(self, seen: tuple[list[str], list[np.ndarray]]) -> bool:
        last = self._laid_out
        if last is None or last[0] != seen[0] or len(last[1]) != len(seen[1]):
            return False
        return all(
            a.shape == b.shape and bool(np.all(np.abs(np.nan_to_num(a - b, nan=np.inf)) <= STILL_PX))
            for a, b in zip(last[1], seen[1], strict=True)
        )

    def _layout(
        self, live: list[Callout], pages: Sequence[PageCamera], solids: np.ndarray, fixed: Sequence[FixedText] = ()
    ) -> None:
        occupied = []
        for page in pages:
            grid = Occupancy(page.width, page.height, page.shown)
            if page.covered is not None:
                grid.add_box(np.array(page.covered))
            for text in fixed:
                at, depth = page.project(text.point)
                if np.all(np.isfinite(at)) and depth > 0:
                    grid.add_box(box_at(at, text.anchor, text_size(text.text)), GAP_PX)
            for corners in page.project(solids)[0] if len(solids) else ():
                grid.add_solid(corners)
            for item in live:
                if item.keep_clear > 0:
                    grid.add_solid(page.project(_cube(item.point, item.keep_clear))[0])  # type: ignore[arg-type]
            occupied.append(grid)
        primary = pages[0]
        for item in live:
            point = np.asarray(item.point, dtype=float)
            point_px, depth = primary.project(point)
            if not (np.all(np.isfinite(point_px)) and depth > 0):
                continue
            size = text_size(item.text)
            where = self._scored_elsewhere(point_px, float(depth), size, pages, occupied)
            away = point_px - np.nanmean(primary.project(solids.reshape(-1, 3))[0], axis=0) if len(solids) else None
            tried = [item.placement] if item.placement is not None else []
            best, best_cost = item.placement, np.inf
            for placement in tried + candidates(away):
                total = where(placement)
                if total < best_cost:
                    best, best_cost = placement, total
                if total == 0:
                    break
            assert best is not None
            item.placement = best
            label_world = primary.unproject(point_px + np.asarray(best.offset), float(depth))
            item.offset = label_world - point
            item.offset_local = item.rotation.T @ item.offset
            for page, grid in zip(pages, occupied, strict=True):  # the next callout keeps off this one
                at = page.project(label_world)[0]
                if np.all(np.isfinite(at)):
                    grid.add_box(box_at(at, best.anchor, size), GAP_PX)

    @staticmethod
    def _scored_elsewhere(
        point_px: np.ndarray,
        depth: float,
        size: tuple[float, float],
        pages: Sequence[PageCamera],
        occupied: list[Occupancy],
    ) -> Callable[[Placement], float]:
        """A placement's cost summed over the pages: on the primary as placed, on the others where its
        world point projects (the same anchor)."""
        primary = pages[0]

        def total(placement: Placement) -> float:
            score = cost(placement, point_px, size, occupied[0])
            if len(pages) > 1:
                label_world = primary.unproject(point_px + np.asarray(placement.offset), depth)
                for page, grid in zip(pages[1:], occupied[1:], strict=True):
                    at = page.project(label_world)[0]
                    if np.all(np.isfinite(at)):
                        score += cost(Placement((0.0, 0.0), placement.anchor), at, size, grid)
            return score

        return total

    def _draw(self, item: Callout, live: bool) -> None:
        if not live:
            if item.sent is None or item.sent[2]:
                item.label.visible = item.leader.visible = False
                item.sent = ((), "", False)
            return
        local, at = item.local, item.local + item.offset_local  # in the parent's frame: they move with it
        anchor = item.placement.anchor if item.placement is not None else "bottom-left"
        key = (tuple(np.round(np.r_[local, at], 5)), anchor, True)
        if key == item.sent and item.label.text == item.text:
            return
        if item.label.text != item.text:
            item.label.text = item.text
        item.label.position = tuple(at)
        if item.label.anchor != anchor:
            item.label.anchor = anchor  # type: ignore[assignment]
        item.leader.points = np.array([[local, at]])
        if not item.label.visible:
            item.label.visible = item.leader.visible = True
        item.sent = key


def _finite(point: np.ndarray | None) -> bool:
    return point is not None and bool(np.all(np.isfinite(point)))


def _cube(centre: np.ndarray | None, half: float) -> np.ndarray:
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
    return np.asarray(centre, dtype=float) + half * signs
