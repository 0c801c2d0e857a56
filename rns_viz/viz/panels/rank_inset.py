"""The joint-space inset of rank loss: a small picture of a plane of two joints under the scene toggle.

Why an image and not a uPlot chart: the picture is a field (sigma_min(W S H_bm) over the plane, log
colour) with markers, which a uPlot line chart cannot draw. The field, the axes and the rank-loss
markers are drawn once per plane with matplotlib (Agg) into an RGB array, in a thread of its own
(0.1-0.3 s: never in the render thread); each refresh (with the text, 5 Hz) only stamps the arm's
configuration as a dot into a copy of it, with numpy, and sends the image when the dot moved (a
~300 px JPEG). Data: :func:`rns_viz.live.teaching.rank_view.rank_inset`, whose
configurations are the overlay's (each checked: sigma_min <= 1e-9 of the most coupled ||S H_bm||).
"""

from __future__ import annotations

import math
import threading
import traceback
from dataclasses import dataclass

import numpy as np
import viser

from rns_viz.live.published.snapshot import Snapshot
from rns_viz.live.teaching.rank_view import RANK_HINT, RankInset, has_rank_inset, inset_slice, rank_inset
from rns_viz.model import FsmsModel
from rns_viz.viz.scene.view_toggles import ViewToggles

SIZE_PX = 300  # width and height of the picture
DPI = 100
DOT_RADIUS_PX = 5
DOT_COLOUR = (31, 111, 209)  # the arm now: the charts' blue
MARK_COLOUR = "#c87800"  # amber, as the overlay's poses
INSET_TEXT = (
    "Amber: where S H_bm loses rank. "
    "Blue dot: the arm now. Colour: σ_min(W S H_bm) relative to its largest, dark where the joints barely push "
    "the base. "
)


@dataclass(frozen=True)
class InsetPicture:
    """The drawn plane and the pixel of each joint value: column = a0 + k0 * x, row = a1 + k1 * y."""

    image: np.ndarray  # (SIZE_PX, SIZE_PX, 3) uint8
    pixel: tuple[float, float, float, float]  # a0, k0, a1, k1
    data: RankInset


def draw_inset(data: RankInset, labels: tuple[str, str], title: str) -> InsetPicture:
    """The field and the markers of ``data`` as an RGB image, and its joint-to-pixel map."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(SIZE_PX / DPI, SIZE_PX / DPI), dpi=DPI)
    canvas = FigureCanvasAgg(fig)
    ax = fig.add_axes((0.17, 0.15, 0.78, 0.75))
    half = 0.5 * float(np.rad2deg(data.axis[1] - data.axis[0]))  # the grid nodes are the pixels' centres
    extent = (-180.0 - half, 180.0 + half, -180.0 - half, 180.0 + half)
    field = np.log10(np.maximum(data.sigma.T, 1e-4))
    ax.imshow(field, cmap="gray", vmin=-3.0, vmax=0.0, origin="lower", extent=extent, interpolation="nearest")
    marks = np.rad2deg(np.angle(np.exp(1j * data.theta[:, list(data.columns)])))
    filled, rings = marks[data.in_plane], marks[~data.in_plane]
    ax.scatter(filled[:, 0], filled[:, 1], s=60, color=MARK_COLOUR, edgecolors="black", zorder=3)
    ax.scatter(rings[:, 0], rings[:, 1], s=90, facecolors="none", edgecolors=MARK_COLOUR, linewidths=2, zorder=3)
    ax.set(xlim=(-180, 180), ylim=(-180, 180), xticks=(-180, -90, 0, 90, 180), yticks=(-180, -90, 0, 90, 180))
    ax.set_xlabel(labels[0], fontsize=8, labelpad=1)
    ax.set_ylabel(labels[1], fontsize=8, labelpad=0)
    ax.set_title(title, fontsize=8)
    ax.tick_params(labelsize=7)
    canvas.draw()
    image = np.asarray(canvas.buffer_rgba())[..., :3].copy()
    (x0, y0), (x1, y1) = ax.transData.transform([(-180.0, -180.0), (180.0, 180.0)])
    height = image.shape[0]  # display y grows upwards, image rows downwards
    k0, k1 = (x1 - x0) / 360.0, -(y1 - y0) / 360.0
    return InsetPicture(image, (x0 + 180.0 * k0, k0, (height - y0) + 180.0 * k1, k1), data)


def dot_pixel(picture: InsetPicture, theta: np.ndarray) -> tuple[float, float]:
    """(column, row) of the configuration ``theta`` in the picture."""
    x, y = np.rad2deg(np.angle(np.exp(1j * np.asarray(theta, dtype=float)[list(picture.data.columns)])))
    a0, k0, a1, k1 = picture.pixel
    return a0 + k0 * x, a1 + k1 * y


def with_dot(picture: InsetPicture, theta: np.ndarray) -> np.ndarray:
    """A copy of the picture with the configuration stamped as a dot."""
    image = picture.image.copy()
    cx, cy = dot_pixel(picture, theta)
    rows, cols = np.ogrid[: image.shape[0], : image.shape[1]]
    r2 = (cols - cx) ** 2 + (rows - cy) ** 2
    image[r2 <= (DOT_RADIUS_PX + 1.5) ** 2] = 255  # a white rim on dark field
    image[r2 <= DOT_RADIUS_PX**2] = DOT_COLOUR
    return image


class RankInsetPanel:
    """A folder under *Show in the scene*: the picture and why, shown while the rank-loss box is ticked for a
    model that has one (TREP, the 3R). ``refresh`` is called with the text (5 Hz)."""

    def __init__(self, server: viser.ViserServer, view: ViewToggles) -> None:
        self.view = view
        with server.gui.add_folder("Rank loss in joint space", visible=False) as self.folder:
            self.image = server.gui.add_image(np.full((SIZE_PX, SIZE_PX, 3), 255, np.uint8), jpeg_quality=90)
            self.text = server.gui.add_markdown("")
        self.picture: InsetPicture | None = None  # what is drawn (tests read it)
        self.theta: np.ndarray | None = None  # the configuration the dot shows
        self.updates = 0  # images sent
        self._plane: tuple[str, float | None] | None = None  # the plane of ``picture``
        self._drawing: tuple[str, float | None] | None = None  # the plane being drawn in the background
        self._lock = threading.Lock()
        self._model: tuple[str, FsmsModel] | None = None

    def refresh(self, snap: Snapshot) -> None:
        key = snap.settings.model
        on = self.view.on("rank") and "rank" in self.view.boxes
        if on and (self._model is None or self._model[0] != key):
            self._model = (key, FsmsModel.from_key(key))  # loaded once per model, not every refresh
        model = self._model[1] if on and self._model is not None else None
        theta = None if model is None else np.asarray(snap.q[model.m :], dtype=float)
        drawable = model is not None and has_rank_inset(model) and theta is not None and np.all(np.isfinite(theta))
        if not drawable:
            if self.folder.visible:
                self.folder.visible = False
            return
        assert model is not None and theta is not None
        plane = (key, inset_slice(key, theta))
        with self._lock:
            picture = self.picture if plane == self._plane else None
            if picture is None and self._drawing is None:  # draw the new plane in the background
                self._drawing = plane
                threading.Thread(target=self._draw, args=(model.n, plane), daemon=True).start()
        if picture is None:
            return  # the old picture stays until the new one is ready
        if self.theta is None or not np.allclose(theta, self.theta, atol=np.deg2rad(0.5)):
            self.theta = theta.copy()
            self.image.image = with_dot(picture, theta)
            self.updates += 1
        if not self.folder.visible:
            self.folder.visible = True

    def _draw(self, n: int, plane: tuple[str, float | None]) -> None:
        try:
            data = rank_inset(*plane)
            assert data is not None
            picture = draw_inset(data, *_words(n, plane[1]))
            text = INSET_TEXT + _slice_words(n, plane[1]) + RANK_HINT
        except Exception:  # drawing must never kill the app; the next refresh tries again
            traceback.print_exc()
            picture = None
        with self._lock:
            self._drawing = None
            if picture is not None:
                self.picture, self._plane, self.theta = picture, plane, None
                self.text.content = text


def _words(n: int, fixed: float | None) -> tuple[tuple[str, str], str]:
    if n == 2:
        return ("θ₁ (deg)", "θ₂ (deg)"), "rank loss of S H_bm, (θ₁, θ₂)"
    return ("θ₂ (deg)", "θ₃ (deg)"), f"the plane θ₁ = {math.degrees(fixed or 0.0):.0f}°"


def _slice_words(n: int, fixed: float | None) -> str:
    if n == 2:
        return "The four poses are isolated points, not curves: one base row must vanish as a whole. "
    return (
        f"The 3R's plane is (θ₂, θ₃) through its θ₁ (now {math.degrees(fixed or 0.0):.0f}°, in 5° steps): its eight "
        "poses have θ₁ = 0° or 180°: filled, those in this plane; rings, the same (θ₂, θ₃) at another θ₁. "
    )
