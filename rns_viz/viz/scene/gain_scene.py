"""The gain map and the authority colours in the 3-D scene, so a click applies gains.

The map is an image standing beside the robot, facing the model's initial camera: g_b (1/s, log)
to the right, g_m (1/s, log) upwards, each grid cell coloured by a decay rate (1/s, log colour
scale), unstable cells hatched grey, cells whose prediction the linear loop cannot make for the
map's kick faded and hatched the other way (the panel says why). A click arrives as a ray (viser's
scene click); it is met with the map's plane and turned into the nearest grid point
(:func:`grid_point`). The authority along the current path (TREP) or over the reachable set (3R) is
drawn under ``/base`` in the same colours.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Literal

import numpy as np
import viser
import viser.transforms as vtf

from rns_viz.analysis import GainMap
from rns_viz.live.explorer.gain_explorer import GainView
from rns_viz.viz.scene.callouts import FixedText
from rns_viz.viz.scene.style import SceneStyle

Quantity = Literal["base", "time", "arm"]
LN10 = math.log(10.0)
CELL_PIXELS = 4  # image pixels per grid cell (the hatching of unstable cells needs a few)
UNSTABLE_RGB = (90, 90, 90)  # hatched with UNSTABLE_HATCH
UNSTABLE_HATCH = (200, 200, 200)
UNPREDICTABLE_FADE = 0.6  # a not-predictable cell's colour is mixed this much with white ...
UNPREDICTABLE_HATCH = (110, 110, 110)  # ... and hatched the other way in this
MISSING_RGB = (235, 235, 235)  # no such mode (an empty arm group)
NOW_COLOUR = (255, 255, 255)
# viser's client turns an image's plane by pi about x, so its back faces the camera, and the outline it
# draws on a hovered clickable node (back faces, yellow at 0.8 opacity) then covered the whole map: every
# colour washed to yellow while the mouse was on it. Turned back, the plane's front faces the camera and
# the outline shows only as a frame around the map.
IMAGE_TURN = tuple(vtf.SO3.from_x_radians(math.pi).wxyz)
PAPER_COLOUR = (20, 20, 20)
LABEL_ROOM = 0.15  # x the map's side: the title above it, the legend below, the tick labels left of it
MAP_SIZE = 0.5  # the map's side, x the distance of the model's camera to the robot
MAP_UP = 0.9  # the map's centre above the robot's, x that distance (the robot spans about +-0.4 of it)
# viridis at 0, 1/4, 1/2, 3/4, 1 (slow decay dark, fast decay yellow)
_ANCHORS = np.array([[68, 1, 84], [59, 82, 139], [33, 145, 140], [94, 201, 98], [253, 231, 37]], dtype=float)


def colours(rates: np.ndarray, scale: tuple[float, float]) -> np.ndarray:
    """RGB uint8 (..., 3) of decay rates (1/s) on a log colour scale from scale[0] to scale[1] (1/s).

    Rates at or below zero, or NaN, take the lowest colour (a caller marks them separately)."""
    lo, hi = np.log(scale[0]), np.log(scale[1])
    r = np.asarray(rates, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        x = (np.log(np.where(r > 0, r, scale[0])) - lo) / max(hi - lo, 1e-12)
    x = np.clip(np.nan_to_num(x, nan=0.0), 0.0, 1.0) * (len(_ANCHORS) - 1)
    k = np.minimum(x.astype(int), len(_ANCHORS) - 2)
    f = (x - k)[..., None]
    return np.round(_ANCHORS[k] * (1 - f) + _ANCHORS[k + 1] * f).astype(np.uint8)


def colour_scale(rates: np.ndarray, stable: np.ndarray) -> tuple[float, float]:
    """Colour range (1/s): the 2nd to 98th percentile of the positive rates at stable points, at most
    a factor 1000 wide (the slowest corners would otherwise squeeze every other colour)."""
    good = np.asarray(rates)[np.asarray(stable) & (np.asarray(rates) > 0) & np.isfinite(rates)]
    if len(good) == 0:
        return 0.01, 1.0
    lo, hi = np.percentile(good, [2.0, 98.0])
    return float(max(lo, 1e-3 * hi)), float(max(hi, 1.01 * lo))


def map_rates(gain_map: GainMap, quantity: Quantity) -> np.ndarray:
    """The (B, G) rates (1/s) a map view colours: the base mode's, ln 10 over its time to 10 % (so that
    fast is yellow in every view), or the arm's."""
    if quantity == "time":
        with np.errstate(divide="ignore"):
            return LN10 / gain_map.base_time_to_10pct
    return gain_map.arm_decay_rate if quantity == "arm" else gain_map.base_decay_rate


def map_image(gain_map: GainMap, quantity: Quantity) -> tuple[np.ndarray, tuple[float, float]]:
    """RGB image (G*CELL_PIXELS, B*CELL_PIXELS, 3) of the map and its colour scale: column = g_b (left to
    right), row = g_m (row 0 the highest), as :class:`GainScene` shows it (g_b right, g_m up)."""
    rates = map_rates(gain_map, quantity)
    scale = colour_scale(rates, gain_map.predictable)  # over the cells drawn in the legend's colours
    rgb = colours(rates, scale)  # (B, G, 3)
    rgb[~np.isfinite(rates)] = MISSING_RGB
    hatch = np.zeros((CELL_PIXELS, CELL_PIXELS), dtype=bool)
    hatch[np.add.outer(np.arange(CELL_PIXELS), np.arange(CELL_PIXELS)) % CELL_PIXELS == 0] = True
    # Row 0 is the highest g_m: the image node is turned by pi about x (IMAGE_TURN) back against viser's own
    # turn of its plane, so row 0 is drawn at the map frame's +y, g_m up.
    cells = np.repeat(np.repeat(rgb.transpose(1, 0, 2)[::-1], CELL_PIXELS, 0), CELL_PIXELS, 1)
    bad = np.repeat(np.repeat((~gain_map.stable).T[::-1], CELL_PIXELS, 0), CELL_PIXELS, 1)
    stripes = np.tile(hatch, (gain_map.g_m.size, gain_map.g_b.size))
    cells[bad] = UNSTABLE_RGB
    cells[bad & stripes] = UNSTABLE_HATCH
    mark_unpredictable(cells, np.repeat(np.repeat(not_predictable(gain_map).T[::-1], CELL_PIXELS, 0), CELL_PIXELS, 1))
    return cells, scale


def not_predictable(gain_map: GainMap) -> np.ndarray:
    """(B, G) bool: stable cells whose prediction the linear loop cannot make for the map's kick."""
    return gain_map.stable & ~gain_map.predictable


def mark_unpredictable(pixels: np.ndarray, where: np.ndarray) -> None:
    """Fade the colour of the pixels ``where`` (an image-shaped mask) and hatch them along the other diagonal."""
    faded = pixels[where] * (1 - UNPREDICTABLE_FADE) + 255 * UNPREDICTABLE_FADE
    pixels[where] = np.round(faded).astype(np.uint8)
    rows, cols = np.indices(where.shape)
    pixels[where & ((rows - cols) % CELL_PIXELS == 0)] = UNPREDICTABLE_HATCH


def axis_fraction(axis: np.ndarray, value: float) -> float:
    """Where ``value`` (1/s) lies along a log axis, 0 at the first grid point's cell edge, 1 at the last's."""
    lo, hi = np.log(axis[0]), np.log(axis[-1])
    half = 0.5 * (hi - lo) / max(len(axis) - 1, 1)  # cells are centred on the grid points
    return float((np.log(max(value, 1e-300)) - lo + half) / (hi - lo + 2 * half))


def grid_point(gain_map: GainMap, u: float, v: float) -> tuple[float, float] | None:
    """The grid point (g_b, g_m), 1/s, of the cell at map fractions (u right, v up) in [0, 1], else None."""
    if not (math.isfinite(u) and math.isfinite(v) and 0.0 <= u <= 1.0 and 0.0 <= v <= 1.0):
        return None
    i = min(int(u * gain_map.g_b.size), gain_map.g_b.size - 1)
    j = min(int(v * gain_map.g_m.size), gain_map.g_m.size - 1)
    return float(gain_map.g_b[i]), float(gain_map.g_m[j])


class GainScene:
    """The map image, its marks and labels, and the authority overlay, for one model's scene."""

    FRAME = "/gain_map"
    IMAGE = "/gain_map/image"
    NOW = "/gain_map/now"
    AUTHORITY = "/base/authority"

    def __init__(
        self, server: viser.ViserServer, style: SceneStyle, on_point: Callable[[viser.ClientHandle, float, float], None]
    ) -> None:
        self.server, self.style = server, style
        scene = server.scene
        cam, look = np.asarray(style.camera_position, float), np.asarray(style.camera_look_at, float)
        ahead = (look - cam) / np.linalg.norm(look - cam)
        right = np.cross(ahead, [0.0, 0.0, 1.0])
        right /= np.linalg.norm(right)
        up = np.cross(right, ahead)
        self.rotation = np.column_stack([right, up, -ahead])  # map x: g_b, y: g_m, z: towards the camera
        distance = float(np.linalg.norm(look - cam))
        self.size = MAP_SIZE * distance  # m, side of the map
        # above the robot as the model's camera frames it, a little towards the camera: clear of the arm and its
        # base, and stacked so that the scene between the docked panels (taller than wide on a laptop) holds both
        self.centre = look + distance * (MAP_UP * up - 0.2 * ahead)
        self.frame = scene.add_frame(
            self.FRAME,
            wxyz=vtf.SO3.from_matrix(self.rotation).wxyz,
            position=self.centre,
            show_axes=False,
            visible=False,
        )
        blank = np.full((8, 8, 3), MISSING_RGB, dtype=np.uint8)
        self.image = scene.add_image(
            self.IMAGE, blank, self.size, self.size, format="png", receive_shadow=False, wxyz=IMAGE_TURN
        )
        self.image.on_click(lambda event: self._clicked(event, on_point))
        mark = 0.018 * self.size
        self.now = scene.add_icosphere(self.NOW, radius=mark, color=NOW_COLOUR, visible=False)
        self.now_label = scene.add_label(f"{self.NOW}/label", "now", position=(mark, mark, 0.0), anchor="bottom-left")
        self.title = scene.add_label(
            f"{self.FRAME}/title",
            "",
            position=(-0.5 * self.size, 0.5 * self.size + 2 * mark, 0.0),
            anchor="bottom-left",
        )
        self.legend = scene.add_label(
            f"{self.FRAME}/legend", "", position=(-0.5 * self.size, -0.5 * self.size - 5 * mark, 0.0), anchor="top-left"
        )
        self.shown = False  # the Gain map toggle: the map and the authority overlay are drawn only while on
        self._ticks: list[object] = []
        self._paper: list[object] = []
        self._paper_key: tuple[tuple[str, float, float], ...] | None = None
        self.gain_map: GainMap | None = None
        self.scale = (0.01, 1.0)  # 1/s, the colour scale of the map shown
        self.base_scale = (0.01, 1.0)  # 1/s, that of the base mode's map (the authority's colours)
        self.authority = scene.add_point_cloud(
            self.AUTHORITY,
            np.zeros((1, 3)),
            (0, 0, 0),
            point_size=0.6 * style.marker_radius,
            point_shape="circle",
            precision="float32",
            visible=False,
        )
        self.authority_lines = scene.add_line_segments(
            f"{self.AUTHORITY}_path",
            np.zeros((1, 2, 3)),
            (0, 0, 0),
            thickness=2.5 * style.line_thickness,
            visible=False,
        )

    # -- the map ---------------------------------------------------------------------------------
    def show_map(self, view: GainView, quantity: Quantity) -> None:
        """Draw the map of ``view`` (nothing if it is still being computed) with its marks and labels."""
        gm = view.map
        if gm is None:
            self.frame.visible = False
            self.gain_map = None
            return
        image, self.scale = map_image(gm, quantity)
        self.base_scale = colour_scale(gm.base_decay_rate, gm.predictable)  # the authority's, whatever is shown
        new_axes = self.gain_map is None or not (
            np.array_equal(gm.g_b, self.gain_map.g_b) and np.array_equal(gm.g_m, self.gain_map.g_m)
        )
        self.gain_map = gm
        with self.server.atomic():
            self.image.image = image
            if new_axes:
                self._draw_ticks(gm)
            if new_axes or view.paper != self._paper_key:
                self._paper_key = view.paper
                self._draw_paper(gm, view.paper)
            self.show_now(view)
            self.title.text = _title(view, quantity)
            self.legend.text = _legend(quantity, self.scale)
            self.frame.visible = self.shown

    def set_shown(self, on: bool) -> bool:
        """Draw the map (once computed) or hide it and the authority overlay; True if that changed (the
        overlay is then drawn again by :meth:`show_authority`)."""
        if on == self.shown:
            return False
        self.shown = on
        with self.server.atomic():
            self.frame.visible = on and self.gain_map is not None
            if not on:
                self.authority.visible = self.authority_lines.visible = False
        return True

    def texts(self) -> list[FixedText]:
        """The title and the legend while the map is shown: callouts keep off them (their lines run past the
        map's sides)."""
        if not (self.shown and self.gain_map is not None):
            return []
        return [
            FixedText(self.centre + self.rotation @ np.asarray(label.position, dtype=float), label.anchor, label.text)
            for label in (self.title, self.legend)
        ]

    def framed_corners(self) -> np.ndarray:
        """World corners (4, 3), m, of the map with room for its title, legend and axis ticks around it."""
        half = 0.5 * self.size + LABEL_ROOM * self.size
        local = np.array([[x, y, 0.0] for x in (-half, half) for y in (-half, half)])
        return self.centre + local @ self.rotation.T

    def show_now(self, view: GainView) -> None:
        """The white marker at the gains in force (hidden outside the map's range)."""
        gm = self.gain_map
        if gm is None:
            return
        u, v = axis_fraction(gm.g_b, view.gains.g_b), axis_fraction(gm.g_m, view.gains.g_m)
        inside = 0.0 <= u <= 1.0 and 0.0 <= v <= 1.0
        self.now.visible = inside
        if inside:
            self.now.position = self._local(u, v, 0.02)

    def _local(self, u: float, v: float, lift: float = 0.0) -> tuple[float, float, float]:
        """Map fractions (u right, v up) -> the map frame (m), ``lift`` x size towards the camera."""
        return ((u - 0.5) * self.size, (v - 0.5) * self.size, lift * self.size)

    def _draw_ticks(self, gm: GainMap) -> None:
        for handle in self._ticks:
            handle.remove()  # type: ignore[attr-defined]
        self._ticks = []
        add = self.server.scene.add_label
        for k, value in enumerate(_decades(gm.g_b)):
            x, y, _ = self._local(axis_fraction(gm.g_b, value), 0.0)
            self._ticks.append(add(f"{self.FRAME}/tick_b{k}", f"{value:g}", position=(x, y, 0.0), anchor="top-center"))
        for k, value in enumerate(_decades(gm.g_m)):
            x, y, _ = self._local(0.0, axis_fraction(gm.g_m, value))
            self._ticks.append(
                add(f"{self.FRAME}/tick_m{k}", f"{value:g} ", position=(x, y, 0.0), anchor="center-right")
            )
        x, y, _ = self._local(1.0, 0.0)
        self._ticks.append(add(f"{self.FRAME}/axis_b", "g_b (1/s) →", position=(x, y, 0.0), anchor="bottom-right"))
        x, y, _ = self._local(0.0, 1.0)
        self._ticks.append(add(f"{self.FRAME}/axis_m", "↑ g_m (1/s)", position=(x, y, 0.0), anchor="top-left"))

    def _draw_paper(self, gm: GainMap, paper: tuple[tuple[str, float, float], ...]) -> None:
        for handle in self._paper:
            handle.remove()  # type: ignore[attr-defined]  # (its label goes with it)
        self._paper = []
        scene = self.server.scene
        for k, (label, g_b, g_m) in enumerate(paper):
            u, v = axis_fraction(gm.g_b, g_b), axis_fraction(gm.g_m, g_m)
            if not (0.0 <= u <= 1.0 and 0.0 <= v <= 1.0):
                continue
            name = f"{self.FRAME}/paper{k}"
            self._paper.append(
                scene.add_icosphere(
                    name, radius=0.012 * self.size, color=PAPER_COLOUR, position=self._local(u, v, 0.01)
                )
            )
            scene.add_label(f"{name}/label", label, position=(-0.015 * self.size, 0.0, 0.0), anchor="center-right")

    # -- clicks ----------------------------------------------------------------------------------
    def map_fractions(self, origin: np.ndarray, direction: np.ndarray) -> tuple[float, float] | None:
        """Where a world ray (m) meets the map's plane, as fractions (u right, v up); None if it does not."""
        o, d = np.asarray(origin, dtype=float), np.asarray(direction, dtype=float)
        if o.shape != (3,) or d.shape != (3,) or not (np.all(np.isfinite(o)) and np.all(np.isfinite(d))):
            return None
        with np.errstate(over="ignore", invalid="ignore"):
            far, length = float(np.linalg.norm(o - self.centre)), float(np.linalg.norm(d))
        if not (far < 1e4 * self.size and 1e-12 < length < np.inf):
            return None  # no camera is that far away (and the arithmetic would be meaningless)
        d = d / length
        normal = self.rotation[:, 2]
        denom = float(normal @ d)
        if abs(denom) < 1e-12:
            return None
        t = float(normal @ (self.centre - o)) / denom
        if not math.isfinite(t) or t < 0:
            return None
        local = self.rotation.T @ (o + t * d - self.centre)
        return float(local[0] / self.size + 0.5), float(local[1] / self.size + 0.5)

    def clicked_gains(self, origin: object, direction: object) -> tuple[float, float] | None:
        """The grid point (g_b, g_m), 1/s, a click ray lands on, or None (off the map, bad numbers)."""
        if self.gain_map is None:
            return None
        try:
            where = self.map_fractions(np.asarray(origin, dtype=float), np.asarray(direction, dtype=float))
        except (TypeError, ValueError):
            return None
        return None if where is None else grid_point(self.gain_map, *where)

    def _clicked(self, event: viser.SceneNodePointerEvent, on_point: Callable) -> None:
        on_point(event.client, event.ray_origin, event.ray_direction)

    # -- authority along the path ----------------------------------------------------------------
    def show_authority(self, view: GainView, on_path: bool) -> np.ndarray | None:
        """Colour the current path (TREP) or the reachable-set points (3R) by the predicted base decay
        rate (1/s) on the base mode map's colour scale; returns the colours drawn (K, 3) or None."""
        pts, auth = view.path_points, view.authority
        if not self.shown or pts is None or auth is None or len(pts) != len(auth.base_decay_rate) or len(pts) < 2:
            self.authority.visible = self.authority_lines.visible = False
            return None
        rates = np.asarray(auth.base_decay_rate, dtype=float)
        rgb = colours(rates, self.base_scale)
        rgb[~np.asarray(auth.stable)] = UNSTABLE_RGB
        st = self.style
        lifted = np.asarray(pts, dtype=float) + np.array([0.0, 0.0, st.overlay_z + 2 * st.line_thickness])
        with self.server.atomic():
            if on_path:
                self.authority_lines.points = np.stack([lifted[:-1], lifted[1:]], axis=1)
                self.authority_lines.colors = np.stack([rgb[:-1], rgb[1:]], axis=1)
                self.authority_lines.visible, self.authority.visible = True, False
            else:
                self.authority.points = lifted.astype(np.float32)
                self.authority.colors = rgb
                self.authority.visible, self.authority_lines.visible = True, False
        return rgb


def _decades(axis: np.ndarray) -> list[float]:
    lo, hi = math.ceil(math.log10(axis[0]) - 1e-9), math.floor(math.log10(axis[-1]) + 1e-9)
    return [10.0**k for k in range(lo, hi + 1)]


def _title(view: GainView, quantity: Quantity) -> str:
    what = {
        "base": "base decay rate σ_b (1/s)",
        "time": "base time to 10 % of its peak (s)",
        "arm": "arm mode decay rate σ_a (1/s)",
    }[quantity]
    regime = "" if view.map is None else "\n" + view.map.loop.regime.replace(", arm at rest", ",\narm at rest")
    return f"Gain map, law {_law_eq(view)}: {what}{regime}\nclick a cell to apply its gains"


def _legend(quantity: Quantity, scale: tuple[float, float]) -> str:
    lo, hi = scale
    if quantity == "time":
        span = f"dark {LN10 / lo:.3g} s (slow) … yellow {LN10 / hi:.3g} s (fast)"
    else:
        sym = "σ_a" if quantity == "arm" else "σ_b"
        span = f"{sym}: dark {lo:.3g} … yellow {hi:.3g} 1/s (log)"
    marks = "grey, hatched: unstable\nfaded, hatched \\: not predictable (the panel says why)"
    return f"{span}\n{marks}\nwhite: the gains now; black: the paper's"


def _law_eq(view: GainView) -> str:
    return {"acceleration": "(15)", "torque": "(16)", "velocity": "(30)"}.get(view.law, view.law)
