"""Model parameter files: one TOML file per model, beside its URDF (the bundled ones in ``rns_viz/assets``).

The URDF holds geometry and mass (the single source for dynamics and drawing); the parameter
file holds what a URDF cannot say: which joints are the elastic base coordinates x_b, their
stiffness K_b and damping D_b, the selection S of the selective RNS (Sec. III-B), arm joint
damping D_m, the task axes of the end-effector Jacobian and the default configuration, and for
arms branching from the base (``[arms]``) which joints form the task arm and the compensating arms.
A file may take another file's tables as defaults (``extends = "boom7.toml"``, keys of its own win)
and may name a packaged arm that replaces its URDF's arm (``[model] arm``, see :mod:`rns_viz.robots`).

Units are SI: K_b in N/m (prismatic base coordinate) or N m/rad (revolute), D_b in N s/m or
N m s/rad, D_m in N m s/rad; angles in the file are degrees where the key ends in ``_deg``.
"""

from __future__ import annotations

import importlib.resources
import math
import tomllib
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from rns_viz.robots import RobotPackageMissing, composed_urdf, is_installed, packaged_arm


def _package_data(folder: str) -> Path:
    """A folder of rns_viz's package data, found through :mod:`importlib.resources` wherever the
    package is installed. Pinocchio and the parameter files' relative URDF names need real files, so
    a package imported from a zip archive is refused with that reason."""
    path = importlib.resources.files("rns_viz") / folder
    if not isinstance(path, Path):
        raise ImportError(f"rns_viz's {folder} are not files on disk ({path}); install rns_viz unzipped")
    return path


ASSETS_DIR = _package_data("assets")  # the bundled URDFs and parameter files
MODEL_NAMES = ("trep", "planar3r", "boom7", "trep2", "boom-panda")  # the bundled models the live app serves
BUNDLED_MODELS = MODEL_NAMES  # every model in ASSETS_DIR, for FsmsModel.from_name
# Bundled models whose arm comes from an optional package: name -> the packaged arm (rns_viz.robots).
PACKAGED_MODELS = {"boom-panda": "example-robot-data/panda"}
SELECTION_MARK = "#S="  # a model key's selection suffix: "boom7#S=111000"
TASK_AXES = ("x", "y", "z")


class ModelFileError(ValueError):
    """A URDF or parameter file that cannot be used; the message names the file and element."""


@dataclass(frozen=True)
class BaseSpec:
    """Elastic base: x_b coordinates with H_b x_b'' + D_b x_b' + K_b x_b = ... (Eq. 1)."""

    joints: tuple[str, ...]
    stiffness: np.ndarray  # K_b, (m, m), N/m or N m/rad
    damping: np.ndarray  # D_b, (m, m), N s/m or N m s/rad
    selection: np.ndarray  # diag of S, (m,), bool: True = zero reaction required

    @property
    def dof(self) -> int:
        return len(self.joints)


@dataclass(frozen=True)
class ArmGroups:
    """Arms branching from the base (a tree): the task arm's joints, each compensating arm's, frames.

    Sec. III-B's dynamic redundancy: compensating arms only cancel the task arm's reaction.
    """

    task: tuple[str, ...]
    compensating: tuple[tuple[str, ...], ...]  # one tuple of joint names per compensating arm
    ee_frames: dict[str, str]  # "task", "compensating" (or "compensating_2", ...): frame names


@dataclass(frozen=True)
class ModelSpec:
    """Everything needed to build an FSMS model besides the URDF itself."""

    name: str
    urdf_path: Path
    param_path: Path
    ee_frame: str
    task_axes: tuple[str, ...]
    default_configuration: np.ndarray  # theta_0, rad
    gravity: np.ndarray  # m/s^2, world frame
    base: BaseSpec
    joint_damping: np.ndarray  # D_m diagonal, N m s/rad
    arms: ArmGroups | None = None  # [arms]: None for a single serial arm

    def with_selection(self, selection: Sequence[int | bool]) -> ModelSpec:
        """The same system with another selection S (Sec. III-B): 0/1 flags over the m base coordinates."""
        flags = np.asarray(selection)
        m = self.base.dof
        if flags.shape != (m,) or not np.all((flags == 0) | (flags == 1)) or not flags.any():
            raise ModelFileError(
                f"{self.name}: a selection needs {m} flags of 0 or 1, at least one 1; got {selection!r}"
            )
        return replace(self, base=replace(self.base, selection=flags.astype(bool)))


def model_key(source: str, selection: Sequence[int | bool] | None = None) -> str:
    """The one string that names a live model: a bundled name or a parameter file's absolute path,
    with ``#S=`` and the 0/1 flags of S when S is not the file's own (Sec. III-B)."""
    source = model_source(source)
    if source not in BUNDLED_MODELS:
        source = str(Path(source).resolve())
    if selection is None:
        return source
    return source + SELECTION_MARK + "".join("1" if flag else "0" for flag in selection)


def model_source(key: str) -> str:
    """The bundled name or parameter file of a model key (its selection suffix removed)."""
    return key.split(SELECTION_MARK, 1)[0]


def key_selection(key: str) -> tuple[int, ...] | None:
    """The selection flags a model key carries, or None (the parameter file's own S)."""
    if SELECTION_MARK not in key:
        return None
    flags = key.split(SELECTION_MARK, 1)[1]
    if not flags or any(f not in "01" for f in flags):
        raise ModelFileError(f"{key!r}: a selection is written as 0/1 flags, e.g. #S=111000")
    return tuple(int(f) for f in flags)


def check_model_key(key: object) -> str:
    """A model key's form (a bundled name, or a .toml file, optionally with #S=...); the file is read later."""
    if not isinstance(key, str) or not key:
        raise ModelFileError(f"a model is a bundled name or a .toml parameter file, got {key!r}")
    source = model_source(key)
    if source not in BUNDLED_MODELS and not source.endswith(".toml"):
        raise ModelFileError(f"unknown model {source!r}; choose one of {', '.join(MODEL_NAMES)} or a .toml file")
    key_selection(key)
    return key


def spec_for_key(key: str) -> ModelSpec:
    """Read and check the model a key names; the spec's name is the key (caches and jobs use it)."""
    source = model_source(check_model_key(key))
    spec = load_spec(param_path_for(source) if source in BUNDLED_MODELS else source)
    flags = key_selection(key)
    if flags is not None:
        spec = spec.with_selection(flags)
    return replace(spec, name=key)


def missing_extra(name: str) -> str | None:
    """The optional extra a bundled model still needs (``"panda"``), or None when it can load."""
    arm = PACKAGED_MODELS.get(model_source(name))
    return None if arm is None or is_installed(arm) else packaged_arm(arm).extra


def param_path_for(name: str) -> Path:
    """The parameter file of a bundled model, by name."""
    if name not in BUNDLED_MODELS:
        raise ModelFileError(f"unknown model {name!r}; choose one of: {', '.join(BUNDLED_MODELS)}")
    return ASSETS_DIR / f"{name}.toml"


def _get(table: dict, key: str, where: str, path: Path) -> object:
    if key not in table:
        raise ModelFileError(f"{path}: missing [{where}] {key}")
    return table[key]


def _matrix(value: object, shape: tuple[int, int], element: str, path: Path) -> np.ndarray:
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ModelFileError(f"{path}: {element} must be numbers ({exc})") from None
    if arr.shape != shape:
        raise ModelFileError(f"{path}: {element} must have shape {shape}, got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ModelFileError(f"{path}: {element} must be finite")
    return arr


def load_spec(param_path: str | Path) -> ModelSpec:
    """Read and check a parameter file; the URDF path inside is relative to the file."""
    path = Path(param_path)
    data = _read_toml(path)
    parent = data.pop("extends", None)
    if parent is not None:  # the other file's tables are defaults, key by key
        if not isinstance(parent, str):
            raise ModelFileError(f"{path}: extends must be a parameter file's name")
        defaults = _read_toml(path.parent / parent)
        defaults.pop("extends", None)  # one level: a chain of files would hide where a number comes from
        for name, table in data.items():
            if isinstance(table, dict) and isinstance(defaults.get(name), dict):
                defaults[name] = {**defaults[name], **table}
            else:
                defaults[name] = table
        data = defaults
    model = _get(data, "model", "", path)
    base = _get(data, "base", "", path)
    arm = data.get("arm", {})
    if not isinstance(model, dict) or not isinstance(base, dict) or not isinstance(arm, dict):
        raise ModelFileError(f"{path}: [model], [base] and [arm] must be tables")

    joints = _get(base, "joints", "base", path)
    if not (isinstance(joints, list) and joints and all(isinstance(j, str) for j in joints)):
        raise ModelFileError(f"{path}: [base] joints must be a non-empty list of joint names")
    m = len(joints)
    if m > 6:
        raise ModelFileError(f"{path}: [base] joints: at most 6 elastic base coordinates, got {m}")
    stiffness = _matrix(_get(base, "stiffness", "base", path), (m, m), "[base] stiffness", path)
    damping = _matrix(base.get("damping", np.zeros((m, m)).tolist()), (m, m), "[base] damping", path)
    selection = _matrix([base.get("selection", [1] * m)], (1, m), "[base] selection", path)[0]
    if not np.all((selection == 0) | (selection == 1)) or not selection.any():
        raise ModelFileError(f"{path}: [base] selection must be 0/1 flags with at least one 1")

    theta0_deg = np.array(_get(model, "default_configuration_deg", "model", path), dtype=float)
    n = theta0_deg.size
    joint_damping = _matrix([arm.get("joint_damping", [0.0] * n)], (1, n), "[arm] joint_damping", path)[0]
    axes = tuple(model.get("task_axes", ["x", "y"]))
    if not axes or any(a not in TASK_AXES for a in axes) or len(set(axes)) != len(axes):
        raise ModelFileError(f"{path}: [model] task_axes must be distinct names from {TASK_AXES}")
    gravity = _matrix([model.get("gravity_m_per_s2", [0.0, 0.0, 0.0])], (1, 3), "[model] gravity_m_per_s2", path)[0]
    urdf = _get(model, "urdf", "model", path)
    if not isinstance(urdf, str):
        raise ModelFileError(f"{path}: [model] urdf must be a file name")
    if not np.all(np.isfinite(theta0_deg)):
        raise ModelFileError(f"{path}: [model] default_configuration_deg must be finite")
    urdf_path = (path.parent / urdf).resolve()
    if "arm" in model:
        urdf_path = _with_packaged_arm(urdf_path, model["arm"], path)
    return ModelSpec(
        name=str(model.get("name", path.stem)),
        urdf_path=urdf_path,
        param_path=path.resolve(),
        ee_frame=str(_get(model, "ee_frame", "model", path)),
        task_axes=axes,
        default_configuration=np.deg2rad(theta0_deg),
        gravity=gravity,
        base=BaseSpec(tuple(joints), stiffness, damping, selection.astype(bool)),
        joint_damping=joint_damping,
        arms=_arm_groups(data.get("arms"), path),
    )


def _read_toml(path: Path) -> dict:
    try:
        return tomllib.loads(path.read_text())
    except OSError as exc:
        raise ModelFileError(f"{path}: cannot read ({exc.strerror})") from None
    except tomllib.TOMLDecodeError as exc:
        raise ModelFileError(f"{path}: not valid TOML ({exc})") from None


def _with_packaged_arm(urdf_path: Path, arm: object, path: Path) -> Path:
    """[model] arm: the URDF with its arm replaced by a packaged robot's (composed now, cached)."""
    try:
        return composed_urdf(urdf_path, str(arm))
    except KeyError as exc:
        raise ModelFileError(f"{path}: [model] arm: {exc.args[0]}") from None
    except RobotPackageMissing as exc:
        raise ModelFileError(f"{path}: [model] arm = {arm!r}: {exc}") from None
    except (OSError, ValueError, ET.ParseError) as exc:
        raise ModelFileError(f"{path}: [model] arm = {arm!r}: cannot compose the URDF ({exc})") from None


def _names(value: object, element: str, path: Path) -> tuple[str, ...]:
    if not (isinstance(value, list) and value and all(isinstance(v, str) for v in value)):
        raise ModelFileError(f"{path}: {element} must be a non-empty list of joint names")
    return tuple(value)


def _arm_groups(table: object, path: Path) -> ArmGroups | None:
    """[arms]: task = [...], compensating = [...] (or a list of such lists), ee_frames = {...}."""
    if table is None:
        return None
    if not isinstance(table, dict):
        raise ModelFileError(f"{path}: [arms] must be a table")
    task = _names(_get(table, "task", "arms", path), "[arms] task", path)
    raw = _get(table, "compensating", "arms", path)
    groups = raw if isinstance(raw, list) and raw and all(isinstance(g, list) for g in raw) else [raw]
    compensating = tuple(_names(g, "[arms] compensating", path) for g in groups)
    every = [*task, *(j for g in compensating for j in g)]
    if len(set(every)) != len(every):
        raise ModelFileError(f"{path}: [arms] a joint belongs to two arms")
    frames = table.get("ee_frames", {})
    if not isinstance(frames, dict) or not all(isinstance(v, str) for v in frames.values()):
        raise ModelFileError(f"{path}: [arms] ee_frames must map arm names to frame names")
    return ArmGroups(task, compensating, dict(frames))


def natural_frequency_hz(stiffness: float, mass: float) -> float:
    """Undamped frequency sqrt(k/m)/(2 pi) of a locked-arm base, Hz."""
    return math.sqrt(stiffness / mass) / (2.0 * math.pi)
