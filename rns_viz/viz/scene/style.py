"""How each model is drawn: base drawing, camera, grid and marker sizes (metres, metres per newton).

One frozen dataclass per model; :func:`style_for` builds it from the model's parameter file (``[app.scene]``),
deriving what the file leaves out from the arm's reach.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from rns_viz.model import FsmsModel
from rns_viz.param_file import BaseDrawing, BoomDrawing, CartSpringDrawing, DoubleBeamDrawing, NoDrawing, SceneTable

Vec3 = tuple[float, float, float]


@dataclass(frozen=True)
class DoubleBeamStyle:
    """Two parallel plates clamped at the world origin, their guided tip at the base joint (TREP)."""

    spacing: float = 0.1  # m between the plates, along the deflection axis (Table II "interval")
    height: float = 0.08  # m, plate height (Table II)
    centre_offset: Vec3 = (0.0, 0.0, -0.03)  # m, plate mid-height relative to the beam axis
    stations: int = 21  # points along each plate
    clamp_size: Vec3 = (0.16, 0.04, 0.11)  # m, fixed block the plates are clamped in


@dataclass(frozen=True)
class CartSpringStyle:
    """A cart on the prismatic base joint, tied to a wall by a zig-zag spring (planar 3R)."""

    wall_x: float = -1.6  # m, world x of the wall face
    attach: Vec3 = (-0.3, 0.0, -0.15)  # m, spring end on the cart, in the cart frame
    coils: int = 9
    amplitude: float = 0.08  # m, zig-zag half-width (along y)
    wall_size: Vec3 = (0.1, 0.8, 0.5)


@dataclass(frozen=True)
class BoomStyle:
    """A tube clamped at the world origin, its tip at the base joint frame (a 6-DOF elastic boom tip)."""

    radius: float = 0.05  # m, boom7's 100 mm tube
    stations: int = 25  # rings along the boom
    sides: int = 12  # vertices per ring


@dataclass(frozen=True)
class SceneStyle:
    """Per-model drawing choices; every length in metres."""

    base: DoubleBeamStyle | CartSpringStyle | BoomStyle | None
    camera_position: Vec3
    camera_look_at: Vec3
    grid_z: float  # m, height of the ground grid
    grid_size: float  # m, width and height of the ground grid
    grid_cell: float  # m
    marker_radius: float  # m, target marker and reachable-set point size scale
    line_thickness: float  # m, path family and trail lines (world units)
    force_scale: float  # m of arrow per N of base reaction force
    force_arrow_max: float  # m, longest arrow drawn
    force_origin: Vec3 = (0.0, 0.0, 0.0)  # m, arrow tail in the base frame
    overlay_z: float = 0.0  # m, base-frame height of paths, target and trail (the drawn end effector's)
    base_label: Vec3 = (0.0, 0.0, 0.0)  # m, base-frame position of the base's label
    trail_capacity: int = 400
    trail_step: float = 0.0  # m between kept trail points; 0 means marker_radius / 4
    trail_jump: float = np.inf  # m; a longer jump of the end effector starts a new trail
    path_points: int = 240  # at most this many points per drawn path
    up: Literal["+z"] = "+z"

    @property
    def path_tolerance(self) -> float:
        """m a drawn path may stray from the computed one: a twelfth of the line's own width."""
        return self.line_thickness / 12.0


def style_for(model: FsmsModel) -> SceneStyle:
    """The drawing style of a model: its parameter file's ``[app.scene]``, any length left out scaled by the
    arm's reach (rns_viz.param_file.SceneTable)."""
    scene = model.spec.app.scene
    reach = model.arm_reach
    given = {
        name: value
        for name, value in ((_FIELD[key], getattr(scene, key)) for key in scene.__struct_fields__ if key in _FIELD)
        if value is not None
    }
    return SceneStyle(
        **{
            "base": _base_drawing(model, scene.base, reach),
            "camera_position": (0.8 * reach, -1.6 * reach, 1.8 * reach),
            "camera_look_at": (0.0, 0.0, 0.0),
            "grid_z": -0.1 * reach,
            "grid_size": 4.0 * reach,
            "grid_cell": reach / 8,
            "marker_radius": 0.04 * reach,
            "line_thickness": 0.012 * reach,
            "force_scale": 0.1 * reach,
            "force_arrow_max": 0.6 * reach,
            "trail_jump": 0.5 * reach,
            **given,
        }
    )


def _base_drawing(model: FsmsModel, drawing: BaseDrawing | None, reach: float) -> BaseStyle | None:
    """The base's drawing: the kind the file names with its dimensions (unit suffix dropped), or by default a
    tube for a base of six coordinates that turns."""
    if drawing is None:
        return BoomStyle(radius=0.03 * reach) if model.m == 6 and not model.base_is_translational else None
    kind = _BASE_KINDS[type(drawing)]
    if kind is None:
        return None
    dimensions = {_unitless(key): getattr(drawing, key) for key in drawing.__struct_fields__}
    return kind(**{key: value for key, value in dimensions.items() if value is not None})


def _unitless(key: str) -> str:
    """A parameter file's key without its unit: ``camera_position_m`` -> ``camera_position``."""
    for unit in ("_m_per_N", "_m"):
        if key.endswith(unit):
            return key.removesuffix(unit)
    return key


BaseStyle = DoubleBeamStyle | CartSpringStyle | BoomStyle
_BASE_KINDS: dict[type, type[BaseStyle] | None] = {
    DoubleBeamDrawing: DoubleBeamStyle,
    CartSpringDrawing: CartSpringStyle,
    BoomDrawing: BoomStyle,
    NoDrawing: None,
}
# [app.scene] keys -> SceneStyle fields (the exaggeration and the base are not lengths of the scene style)
_FIELD = {key: _unitless(key) for key in SceneTable.__struct_fields__ if key not in ("exaggeration", "base", "shown")}
