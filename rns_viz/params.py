"""Model parameter files: one TOML file per model, beside its URDF (the bundled ones in ``rns_viz/assets``).

The URDF holds geometry and mass (the single source for dynamics and drawing); the parameter
file holds what a URDF cannot say: which joints are the elastic base coordinates x_b, their
stiffness K_b and damping D_b, the selection S of the selective RNS (Sec. III-B), arm joint
damping D_m, the task axes of the end-effector Jacobian and the default configuration, and for
arms branching from the base (``[arms]``) which joints form the task arm and the compensating arms.
A file may take another file's tables as defaults (``extends = "boom7.toml"``, keys of its own win)
and may name a packaged arm that replaces its URDF's arm (``[model] arm``, see :mod:`rns_viz.robots`).
Its ``[app]`` table says how the live app offers the model (label, law and gains, kick, drawing, presets,
lessons); a bundled model is a file in ``assets/`` with an ``[app]`` table of its own. Every table and
key is typed and checked in :mod:`rns_viz.param_file`.

Units are SI: K_b in N/m (prismatic base coordinate) or N m/rad (revolute), D_b in N s/m or
N m s/rad, D_m in N m s/rad; angles in the file are degrees where the key ends in ``_deg``.
"""

from __future__ import annotations

import importlib.resources
import math
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from functools import cache
from pathlib import Path

import numpy as np

from rns_viz.param_file import AppTable, ArmsTable, ModelFileError, ParamFile, own_tables, read_param_file
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
SELECTION_MARK = "#S="  # a model key's selection suffix: "boom7#S=111000"


def _bundled(folder: Path) -> tuple[str, ...]:
    """The bundled models: the parameter files in ``folder`` with an [app] table of their own, in menu order."""
    files = [path for path in folder.glob("*.toml") if "app" in own_tables(path)]
    found = {path.stem: read_param_file(path).app.menu_order for path in files}
    return tuple(sorted(found, key=lambda name: (found[name], name)))


MODEL_NAMES = _bundled(ASSETS_DIR)  # the bundled models the live app serves
BUNDLED_MODELS = MODEL_NAMES  # every model in assets/, for FsmsModel.from_name


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
    app: AppTable = field(default_factory=AppTable)  # [app]: how the live app offers the model

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
    """The optional extra a bundled model still needs (``"panda"``: its packaged arm is not installed), or None
    (a parameter file is read, and a missing arm refused with the install command, when the model loads)."""
    source = model_source(name)
    arm = _bundled_file(source).model.arm if source in BUNDLED_MODELS else None
    return None if arm is None or is_installed(arm) else packaged_arm(arm).extra


def param_path_for(name: str) -> Path:
    """The parameter file of a bundled model, by name."""
    if name not in BUNDLED_MODELS:
        raise ModelFileError(f"unknown model {name!r}; choose one of: {', '.join(BUNDLED_MODELS)}")
    return ASSETS_DIR / f"{name}.toml"


def source_path(key: str) -> Path:
    """The parameter file a model key names (a bundled model's in ``assets/``)."""
    source = model_source(check_model_key(key))
    return param_path_for(source) if source in BUNDLED_MODELS else Path(source)


def param_file_for(key: str) -> ParamFile:
    """The checked parameter file a model key names (no URDF read): a bundled one once, a file each time."""
    source = model_source(check_model_key(key))
    return _bundled_file(source) if source in BUNDLED_MODELS else read_param_file(Path(source))


@cache
def _bundled_file(name: str) -> ParamFile:
    return read_param_file(param_path_for(name))


def load_spec(param_path: str | Path) -> ModelSpec:
    """Read and check a parameter file (rns_viz.param_file); the URDF path inside is relative to the file."""
    path = Path(param_path)
    file = read_param_file(path)
    model, base = file.model, file.base
    m, n = len(base.joints), len(model.default_configuration_deg)
    urdf_path = (path.parent / model.urdf).resolve()
    if model.arm is not None:
        urdf_path = _with_packaged_arm(urdf_path, model.arm, path)
    return ModelSpec(
        name=model.name or path.stem,
        urdf_path=urdf_path,
        param_path=path.resolve(),
        ee_frame=model.ee_frame,
        task_axes=tuple(model.task_axes),
        default_configuration=np.deg2rad(np.array(model.default_configuration_deg, dtype=float)),
        gravity=np.array(model.gravity_m_per_s2, dtype=float),
        base=BaseSpec(
            tuple(base.joints),
            np.array(base.stiffness, dtype=float),
            np.zeros((m, m)) if base.damping is None else np.array(base.damping, dtype=float),
            np.ones(m, dtype=bool) if base.selection is None else np.array(base.selection, dtype=bool),
        ),
        joint_damping=np.zeros(n) if file.arm.joint_damping is None else np.array(file.arm.joint_damping, float),
        arms=None if file.arms is None else _arm_groups(file.arms, path),
        app=file.app,
    )


def _with_packaged_arm(urdf_path: Path, arm: str, path: Path) -> Path:
    """[model] arm: the URDF with its arm replaced by a packaged robot's (composed now, cached)."""
    try:
        return composed_urdf(urdf_path, arm)
    except KeyError as exc:
        raise ModelFileError(f"{path}: [model] arm: {exc.args[0]}") from None
    except RobotPackageMissing as exc:
        raise ModelFileError(f"{path}: [model] arm = {arm!r}: {exc}") from None
    except (OSError, ValueError, ET.ParseError) as exc:
        raise ModelFileError(f"{path}: [model] arm = {arm!r}: cannot compose the URDF ({exc})") from None


def _arm_groups(table: ArmsTable, path: Path) -> ArmGroups:
    """[arms]: task = [...], compensating = [...] (or a list of such lists), ee_frames = {...}."""
    raw = table.compensating
    compensating = tuple(tuple(g) for g in raw) if isinstance(raw[0], tuple) else (tuple(raw),)
    every = [*table.task, *(j for g in compensating for j in g)]
    if len(set(every)) != len(every):
        raise ModelFileError(f"{path}: [arms] a joint belongs to two arms")
    return ArmGroups(tuple(table.task), compensating, dict(table.ee_frames))  # type: ignore[arg-type]


def natural_frequency_hz(stiffness: float, mass: float) -> float:
    """Undamped frequency sqrt(k/m)/(2 pi) of a locked-arm base, Hz."""
    return math.sqrt(stiffness / mass) / (2.0 * math.pi)
