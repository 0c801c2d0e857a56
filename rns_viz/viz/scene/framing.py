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
# px: a scene this narrow is a phone's page, which viser (below 576 px of page) covers with its panels' sheet
# from below. The server learns the scene's width only, and on a desktop page the docked panels take
# 744 px of it: this bound counts a 1280 px desktop page (536 px of scene) as wide, a phone held upright
# (at most ~430 px) as narrow.
NARROW_PX = 500
NARROW_BAND = (0.2, 0.95)  # NDC y band (bottom, top) the robot is fitted into on a narrow page (sheet below)
# px: viser's main panel floats in the scene's top right corner on a wide page, (x, y, width) as
# ``main_panel.float`` takes them (negative x: from the right edge), and about this tall (Frame robot and
# who operates); callouts keep off it
MAIN_PANEL_PX = (-12, 12, 300)
MAIN_PANEL_HEIGHT_PX = 190
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


def band_for(width_px: int) -> tuple[float, float]:
    """The vertical band of the view the robot is fitted into on a page ``width_px`` wide."""
    return NARROW_BAND if 0 < width_px < NARROW_PX else (-1.0, 1.0)


def main_panel_box(width: int) -> tuple[float, float, float, float] | None:
    """The floating main panel's box (x0, y0, x1, y1) on a page ``width`` px wide, in the canvas's px;
    None on a narrow page (a sheet there, below the band of :func:`band_for`)."""
    if width < NARROW_PX:
        return None
    x, y, panel_width = MAIN_PANEL_PX
    right = width + x if x < 0 else x + panel_width
    return (right - panel_width, float(y), float(right), float(y + MAIN_PANEL_HEIGHT_PX))
