"""The parameter file's schema: every table and key a model's TOML may hold, typed, with units in the keys.

:func:`read_param_file` reads a file (and the file it ``extends``), converts it into these frozen
structures with msgspec and checks what one file can check: an unknown key anywhere is refused with
its table and the nearest known key (``[base] dampng: unknown key (did you mean damping?)``), a wrong
type or shape with the element at fault (``[base] stiffness: expected a 6 x 6 matrix, got 6 x 5``).
What needs the URDF (joint names, the arm's size) is checked when the model is built (rns_viz.model).

Tables: ``[model]`` (URDF, end effector, task axes, theta_0, gravity, a packaged arm), ``[base]``
(the elastic coordinates x_b: K_b, D_b, selection S), ``[arm]`` (D_m), ``[arms]`` (a task arm and
compensating arms on one base) and ``[app]`` (how the live app offers the model: label, law and
gains, kick, target speed, drawing, presets, lessons). A file without ``[app]`` gets the defaults
written here; ``extends = "other.toml"`` takes the other file's tables as defaults, key by key.
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path
from typing import Annotated, Any, Literal

import msgspec

from rns_viz.param_errors import element, every_number, explain, kind_of, unknown

Vec3 = tuple[float, float, float]
Positive = Annotated[float, msgspec.Meta(gt=0.0)]
NonNegative = Annotated[float, msgspec.Meta(ge=0.0)]
LawName = Literal["acceleration", "torque", "velocity"]  # the laws the app runs (rns_viz.control)
# what the scene can show (the app's *Show in the scene* toggles, rns_viz.viz.scene.view_toggles)
Overlay = Literal[
    "labels",
    "paths",
    "gain_map",
    "ghost",
    "reaction",
    "coupling",
    "null_vector",
    "path_arrows",
    "trail",
    "reach",
    "rank",
]


class ModelFileError(ValueError):
    """A URDF or parameter file that cannot be used; the message names the file and element."""


class Table(msgspec.Struct, forbid_unknown_fields=True, frozen=True, kw_only=True):
    """A TOML table: its keys are exactly the fields; any other key is refused."""


class ModelTable(Table):
    urdf: str  # relative to the parameter file
    ee_frame: str
    default_configuration_deg: tuple[float, ...]  # theta_0, deg, pinocchio's joint order
    name: str | None = None  # default: the file's stem
    task_axes: tuple[Literal["x", "y", "z"], ...] = ("x", "y")  # end-effector task rows, base frame
    gravity_m_per_s2: Vec3 = (0.0, 0.0, 0.0)  # world frame
    arm: str | None = None  # a packaged arm replacing the URDF's (rns_viz.robots.PACKAGED_ARMS)


class BaseTable(Table):
    joints: tuple[str, ...]  # the elastic base coordinates x_b, the URDF's first joints
    stiffness: tuple[tuple[float, ...], ...]  # K_b, N/m, N m/rad or N (coupling)
    damping: tuple[tuple[float, ...], ...] | None = None  # D_b, N s/m, N m s/rad or N s; default zero
    selection: tuple[Literal[0, 1], ...] | None = None  # diag of S; default all ones


class ArmTable(Table):
    joint_damping: tuple[NonNegative, ...] | None = None  # D_m diagonal, N m s/rad; default zero


class ArmsTable(Table):
    task: tuple[str, ...]  # the task arm's joints
    compensating: tuple[str | tuple[str, ...], ...]  # one compensating arm's joints, or a list of such lists
    ee_frames: dict[str, str] = msgspec.field(default_factory=dict)  # "task", "compensating", ... -> frame


class LawGains(Table):
    """One law's gains (rns_viz.control.Gains); a key left out keeps Gains' default."""

    g_b_per_s: NonNegative | None = None
    g_m_per_s: NonNegative | None = None
    G_p_per_s2: NonNegative | None = None
    G_d_per_s: NonNegative | None = None
    k_p_per_s2: NonNegative | None = None
    k_d_per_s: NonNegative | None = None


class GainsTable(Table):
    """[app.gains.<law>]: the gains the app starts each law with (a law left out: rns_viz.defaults)."""

    acceleration: LawGains | None = None
    torque: LawGains | None = None
    velocity: LawGains | None = None


# The base's drawing, by kind; a dimension left out keeps the drawing's default (rns_viz.viz.scene.style).
class DoubleBeamDrawing(Table, tag_field="kind", tag="double-beam"):
    """Two parallel plates clamped at the world origin, their guided tip at the base joint (TREP)."""

    spacing_m: Positive | None = None
    height_m: Positive | None = None
    centre_offset_m: Vec3 | None = None
    stations: Annotated[int, msgspec.Meta(ge=2)] | None = None
    clamp_size_m: Vec3 | None = None


class CartSpringDrawing(Table, tag_field="kind", tag="cart-spring"):
    """A cart on a prismatic base joint tied to a wall by a zig-zag spring (the planar 3R)."""

    wall_x_m: float | None = None
    attach_m: Vec3 | None = None
    coils: Annotated[int, msgspec.Meta(ge=1)] | None = None
    amplitude_m: Positive | None = None
    wall_size_m: Vec3 | None = None


class BoomDrawing(Table, tag_field="kind", tag="boom"):
    """A tube clamped at the world origin, its tip at the base joint (a 6-DOF boom tip)."""

    radius_m: Positive | None = None
    stations: Annotated[int, msgspec.Meta(ge=2)] | None = None
    sides: Annotated[int, msgspec.Meta(ge=3)] | None = None


class NoDrawing(Table, tag_field="kind", tag="none"):
    """No structure drawn: only the base frame."""


BaseDrawing = DoubleBeamDrawing | CartSpringDrawing | BoomDrawing | NoDrawing


class SceneTable(Table):
    """[app.scene]: how the model is drawn; a key left out is scaled from the arm's reach."""

    # drawn deflection factor: "auto" (chosen from the recent motion, rns_viz.viz.scene.auto_scale) or fixed
    exaggeration: Annotated[float, msgspec.Meta(ge=1.0, le=100.0)] | Literal["auto"] = "auto"
    shown: frozenset[Overlay] = frozenset({"ghost", "reaction", "trail", "labels"})  # overlays drawn at first
    base: BaseDrawing | None = None  # default: a boom for a 6-coordinate base that turns, else none
    camera_position_m: Vec3 | None = None
    camera_look_at_m: Vec3 | None = None
    grid_z_m: float | None = None
    grid_size_m: Positive | None = None
    grid_cell_m: Positive | None = None
    marker_radius_m: Positive | None = None
    line_thickness_m: Positive | None = None
    force_scale_m_per_N: Positive | None = None  # arrow length per newton of base reaction
    force_arrow_max_m: Positive | None = None
    force_origin_m: Vec3 | None = None  # arrow tail, base frame
    overlay_z_m: float | None = None  # base-frame height of paths, target and trail
    base_label_m: Vec3 | None = None  # the base label's position, base frame
    trail_capacity: Annotated[int, msgspec.Meta(ge=2)] | None = None  # points kept
    trail_jump_m: Positive | None = None  # a longer end-effector jump starts a new trail


class AppTable(Table):
    """[app]: how the live app offers the model. Every key is optional; these defaults serve any file."""

    label: str | None = None  # the model dropdown's text; default "file: NAME.toml"
    short_label: str | None = None  # in lists of lessons; default the file's stem
    menu_order: int = 100  # a bundled model's place in the dropdown (smaller first)
    law: LawName = "acceleration"  # the law the app starts with
    gains: GainsTable = GainsTable()
    kick_peak_N: float = 1.0  # the kick's default peak force
    kick_duration_s: Positive = 0.1  # the half-sine pulse's duration
    kick_range_N: Positive = 5.0  # the kick slider's half range
    kick_axis: str | None = None  # the base joint a kick pushes along first; default the first
    target_speed_m_per_s: Positive = 0.5  # speed limit of the smoothed end-effector target
    presets_heading: str | None = None  # the presets row's heading; models sharing one share the row
    presets: tuple[str, ...] = ()  # rns_viz.scenarios names
    lessons: tuple[str, ...] = ()  # rns_viz.live.teaching names, in teaching order
    scene: SceneTable = SceneTable()


class ParamFile(Table):
    model: ModelTable
    base: BaseTable
    arm: ArmTable = ArmTable()
    arms: ArmsTable | None = None
    app: AppTable = AppTable()


LAW_NAMES: tuple[str, ...] = GainsTable.__struct_fields__  # the laws a file may give gains for


def read_param_file(path: Path) -> ParamFile:
    """Read, merge (``extends``), convert and check a parameter file; ModelFileError names file and element."""
    data = _read_toml(path)
    where = str(path)
    parent = data.pop("extends", None)
    if parent is not None:  # the other file's tables are defaults, key by key at every depth
        if not isinstance(parent, str):
            raise ModelFileError(f"{path}: extends: expected a parameter file's name, got {kind_of(parent)}")
        parent_path = path.parent / parent
        defaults = _read_toml(parent_path)
        if "extends" in defaults:  # a chain of files would hide where a number comes from
            raise ModelFileError(
                f"{path}: extends {parent}, which extends {defaults['extends']!r} itself; extend a file "
                "that extends nothing"
            )
        data = merged(defaults, data)
        where = f"{path} (with {parent_path.name}'s tables)"
    try:
        spec = msgspec.convert(data, ParamFile)
    except msgspec.ValidationError as exc:
        raise ModelFileError(f"{where}: {explain(str(exc), data, ParamFile)}") from None
    for tokens, value in every_number(data):
        if not math.isfinite(value):
            raise ModelFileError(f"{where}: {element(ParamFile, tokens)}: expected a finite number, got {value}")
    problem = _check(spec)
    if problem is not None:
        raise ModelFileError(f"{where}: {problem}")
    return spec


def own_tables(path: Path) -> dict[str, Any]:
    """The tables written in the file itself (not those it extends): a bundled model is one with its own [app]."""
    return _read_toml(path)


def merged(defaults: dict[str, Any], own: dict[str, Any]) -> dict[str, Any]:
    """``own`` over ``defaults``: tables merged key by key at every depth, any other value replaced.
    The label is a file's own: a file that extends another is not listed under the other's name."""
    out = dict(defaults)
    for key, value in own.items():
        out[key] = merged(out[key], value) if isinstance(value, dict) and isinstance(out.get(key), dict) else value
    if isinstance(out.get("app"), dict) and "label" not in own.get("app", {}):
        out["app"] = {k: v for k, v in out["app"].items() if k != "label"}
    return out


def _read_toml(path: Path) -> dict[str, Any]:
    try:
        return tomllib.loads(path.read_text())
    except OSError as exc:
        raise ModelFileError(f"{path}: cannot read ({exc.strerror})") from None
    except tomllib.TOMLDecodeError as exc:
        raise ModelFileError(f"{path}: not valid TOML ({exc})") from None


def _check(spec: ParamFile) -> str | None:
    """What the types cannot say: sizes that depend on other keys, flags, names of base joints."""
    base, m = spec.base, len(spec.base.joints)
    if not 1 <= m <= 6:
        return f"[base] joints: expected 1 to 6 elastic base coordinates, got {m}"
    for key in ("stiffness", "damping"):
        value = getattr(base, key)
        if value is not None and (len(value) != m or any(len(row) != m for row in value)):
            got = f"{len(value)} x {len(value[0])}" if len({len(r) for r in value}) == 1 else "rows of unequal length"
            shape = "its shape: a row and a column per base joint"
            return f"[base] {key}: expected a {m} x {m} matrix, got {got} ({shape})"
    if base.selection is not None and (len(base.selection) != m or not any(base.selection)):
        return f"[base] selection: expected {m} flags of 0 or 1 with at least one 1, got {list(base.selection)}"
    n = len(spec.model.default_configuration_deg)
    if spec.arm.joint_damping is not None and len(spec.arm.joint_damping) != n:
        return f"[arm] joint_damping: expected {n} numbers (one per arm joint), got {len(spec.arm.joint_damping)}"
    axes = spec.model.task_axes
    if not axes or len(set(axes)) != len(axes):
        return f"[model] task_axes: expected distinct names from x, y, z, got {list(axes)}"
    arms = spec.arms
    if arms is not None:
        groups = arms.compensating
        lists = all(isinstance(g, tuple) and len(g) > 0 for g in groups)
        if not arms.task or not groups or not (all(isinstance(g, str) for g in groups) or lists):
            return "[arms] task and compensating: expected a non-empty list of joint names (or of such lists)"
    app = spec.app
    if app.kick_axis is not None and app.kick_axis not in base.joints:
        return f"[app] kick_axis: {unknown(app.kick_axis, base.joints, 'base joint')}"
    if abs(app.kick_peak_N) > app.kick_range_N:
        return f"[app] kick_peak_N: {app.kick_peak_N:g} N is beyond the slider's ±{app.kick_range_N:g} N (kick_range_N)"
    return None
