"""Camera framing from the robot's geometry: the arm and its base fill a stated part of the view.

The points framed are the model's joint and frame origins at its default configuration (every arm's
end effector included), the base joint, and the base's clamp (the world origin) when it is near enough
to belong in the picture (not a 4 m boom whose arm would then be a few pixels). The camera looks at
the points' bounding-box centre from the model's view direction, at the distance that fits every
corner of the box into ``fill`` of the screen's half-width and half-height (a pinhole camera with
vertical field of view ``fov``). On a narrow screen (a phone) viser's panel is a sheet over the lower
part of the page, so the robot is fitted into the band above it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from rns_viz.live.reach.region import arm_reach
from rns_viz.model import FsmsModel

FILL = 0.72  # the framed box spans at most this fraction of the view's width or height
# A scene narrower than this, width over height, is a phone's page held upright, which viser covers with its
# panels' sheet from below. The server learns the scene's size only in the page's drawing pixels (CSS pixels
# times the screen's density, which viser also lowers while a page draws slowly), so the rule is a shape:
# a phone's scene is 0.45-0.6 (390x844 CSS px: 0.46), a desktop's between the docked panels 0.67 (1280x800)
# and wider.
NARROW_ASPECT = 0.62
NARROW_BAND = (0.2, 0.95)  # NDC y band (bottom, top) the robot is fitted into on a narrow page (sheet below)
# px: viser's main panel floats in the scene's top right corner on a wide page, (x, y, width) as
# ``main_panel.float`` takes them (negative x: from the right edge), and about this tall (Frame robot and
# who operates); callouts keep off it
MAIN_PANEL_PX = (-12, 12, 300)
MAIN_PANEL_HEIGHT_PX = 190
NOTICE_HEIGHT_PX = 120  # px the floating panel grows by while a paced page's slowed-display line shows (~108)
PAD_REACH = 0.2  # the box grows by this fraction of the arm's reach on every side: links have thickness
CLAMP_REACHES = 1.5  # the clamp at the origin is framed if it is within this many arm reaches of the base
DEFAULT_FOV = 1.309  # rad, viser's vertical field of view
DEFAULT_ASPECT = 16 / 9


@dataclass(frozen=True)
class CameraPose:
    position: np.ndarray  # m, world
    look_at: np.ndarray  # m, world


def framed_points(model: FsmsModel) -> np.ndarray:
    """Two opposite corners (2, 3) of the world box the view must hold, m: joint and frame origins of the
    arm(s) at the default configuration with the base at rest, the base joint, and the clamp if it is near
    the base, padded by PAD_REACH of the arm's reach."""
    pm = model.pin_model
    data = pm.createData()
    pin.framesForwardKinematics(pm, data, model.q(model.spec.default_configuration))
    points = [data.oMi[j].translation for j in range(model.m, pm.njoints)]
    points += [data.oMf[f].translation for f in range(pm.nframes) if pm.frames[f].parentJoint >= model.m]
    base = data.oMi[model.m].translation
    reach = arm_reach(model)
    if np.linalg.norm(base) <= CLAMP_REACHES * reach:
        points.append(np.zeros(3))
    pts = np.array(points, dtype=float)
    pad = PAD_REACH * reach
    return np.vstack([pts.min(axis=0) - pad, pts.max(axis=0) + pad])  # the padded box's two corners


def frame_points(
    points: np.ndarray,
    direction: np.ndarray,
    fov: float = DEFAULT_FOV,
    aspect: float = DEFAULT_ASPECT,
    fill: float = FILL,
    band: tuple[float, float] = (-1.0, 1.0),
) -> CameraPose:
    """The camera on the ray from the points' box centre along ``direction`` (towards the camera) at the
    distance where every box corner lies within ``fill`` of the view (vertically within the NDC ``band``)."""
    d = np.asarray(direction, dtype=float)
    d /= np.linalg.norm(d)
    right = np.cross(-d, [0.0, 0.0, 1.0])
    if np.linalg.norm(right) < 1e-6:  # looking straight down
        right = np.array([1.0, 0.0, 0.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, -d)
    lo, hi = points.min(axis=0), points.max(axis=0)
    centre = 0.5 * (lo + hi)
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    rel = corners - centre
    tan_y = np.tan(0.5 * fov)
    tan_x = tan_y * max(aspect, 1e-3)
    half_band = 0.5 * (band[1] - band[0])
    x, y, toward = rel @ right, rel @ up, rel @ d  # toward: how much nearer the camera a corner is
    need_x = np.abs(x) / (fill * tan_x) + toward
    need_y = np.abs(y) / (fill * half_band * tan_y) + toward
    distance = float(max(need_x.max(), need_y.max(), 1e-3))
    shift = -0.5 * (band[0] + band[1]) * tan_y * distance * up  # the box's centre at the band's middle
    look_at = centre + shift
    return CameraPose(position=look_at + distance * d, look_at=look_at)


def is_narrow(width: float, height: float) -> bool:
    """Whether a scene of this size (the page's drawing px) is a phone's, with viser's sheet over its lower part."""
    return width > 0 and height > 0 and width / height < NARROW_ASPECT


RESIZE_PX = 8  # a canvas that changed by at most this (px) each way keeps its framing


def framing_holds(framed: tuple[float, float], size: tuple[float, float]) -> bool:
    """Whether a page framed at canvas size ``framed`` (w, h) keeps that framing at ``size``: the same size to
    rounding, or the same shape (its drawing density changed, which viser lowers on a slow page: the framing
    follows the shape, so it holds)."""
    (w0, h0), (w, h) = framed, size
    if abs(w - w0) <= RESIZE_PX and abs(h - h0) <= RESIZE_PX:
        return True
    return abs(w * h0 - h * w0) <= RESIZE_PX * max(w, h)


def band_for(width: float, height: float) -> tuple[float, float]:
    """The vertical band of the view the robot is fitted into on a scene of this size."""
    return NARROW_BAND if is_narrow(width, height) else (-1.0, 1.0)


def main_panel_box(width: float, height: float, notice: bool = False) -> tuple[float, float, float, float] | None:
    """The floating main panel's box (x0, y0, x1, y1) on a scene of this size, in its px (taken as CSS px:
    a dense screen's is smaller); None on a phone's (a sheet there, below the band of :func:`band_for`).
    ``notice``: the page is paced and its panel carries the slowed-display line (NOTICE_HEIGHT_PX more)."""
    if is_narrow(width, height):
        return None
    x, y, panel_width = MAIN_PANEL_PX
    right = width + x if x < 0 else x + panel_width
    bottom = y + MAIN_PANEL_HEIGHT_PX + (NOTICE_HEIGHT_PX if notice else 0.0)
    return (right - panel_width, float(y), float(right), float(bottom))
