"""How each model is drawn: base drawing, camera, grid and marker sizes (metres, metres per newton).

One frozen dataclass per model; :func:`style_for` picks the bundled model's style or derives one
from the arm's reach for any other URDF.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Literal

import numpy as np

from rns_viz.live.reach.region import arm_reach
from rns_viz.model import FsmsModel
from rns_viz.params import model_source

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
    """The drawing style of a bundled model, or one scaled by the arm's reach."""
    if model.name in ("trep", "trep2"):
        trep = SceneStyle(
            base=DoubleBeamStyle(),
            camera_position=(0.29, 0.47, 0.48),
            camera_look_at=(0.0, 0.45, -0.03),
            grid_z=-0.075,
            grid_size=3.0,
            grid_cell=0.05,
            marker_radius=0.008,
            line_thickness=0.003,
            force_scale=0.25,
            force_arrow_max=0.15,
            force_origin=(0.065, -0.01, 0.035),  # above the drawn paths
            trail_capacity=150,
            trail_jump=0.1,
            overlay_z=0.024,
            base_label=(-0.065, -0.01, 0.0),
        )
        if model.name == "trep":
            return trep
        # trep2: TREP's beam and arm; its compensating arm hangs 0.09 m below the arm plane
        # seen from above the beam's tip, so neither arm hides behind it
        return replace(trep, grid_z=-0.17, camera_position=(0.3, 0.62, 0.45), camera_look_at=(0.0, 0.42, -0.07))
    if model.name == "planar3r":
        return SceneStyle(
            base=CartSpringStyle(),
            camera_position=(1.0, -3.3, 3.2),
            camera_look_at=(1.0, -0.3, -0.25),
            grid_z=-0.26,
            grid_size=24.0,
            grid_cell=0.5,
            marker_radius=0.07,
            line_thickness=0.025,
            force_scale=0.01,
            force_arrow_max=1.5,
            force_origin=(0.3, -0.25, -0.05),
            trail_jump=1.5,
            base_label=(-0.22, 0.1, 0.0),
        )
    if model_source(model.name) in ("boom7", "boom-panda"):  # the same boom, arm and view
        return SceneStyle(
            base=BoomStyle(),
            camera_position=(5.4, -1.7, 1.25),
            camera_look_at=(3.95, 0.0, 0.35),
            grid_z=-0.6,
            grid_size=12.0,
            grid_cell=0.25,
            marker_radius=0.025,
            line_thickness=0.006,
            force_scale=0.05,
            force_arrow_max=0.6,
            force_origin=(0.0, 0.0, -0.2),
            trail_jump=0.3,
            base_label=(0.0, -0.25, -0.1),
        )
    reach = arm_reach(model)
    return SceneStyle(
        base=BoomStyle(radius=0.03 * reach) if model.m == 6 and not model.base_is_translational else None,
        camera_position=(0.8 * reach, -1.6 * reach, 1.8 * reach),
        camera_look_at=(0.0, 0.0, 0.0),
        grid_z=-0.1 * reach,
        grid_size=4.0 * reach,
        grid_cell=reach / 8,
        marker_radius=0.04 * reach,
        line_thickness=0.012 * reach,
        force_scale=0.1 * reach,
        force_arrow_max=0.6 * reach,
        trail_jump=0.5 * reach,
    )
