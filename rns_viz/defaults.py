"""Per-model defaults of the live app: the law and gains it starts with, kick sizes, drawing scale, target speed.

The numbers are in each model's parameter file, table ``[app]`` (rns_viz.param_file.AppTable: units in
the keys); a file without one gets AppTable's defaults and FALLBACK_GAINS. The paper's experiments
(rns_viz.scenarios) use the paper's gains; these are what the live app offers first. Units: gains as
in :class:`~rns_viz.control.Gains`, forces N, durations s.

Why the bundled models' numbers: in the comments of their ``[app]`` tables (``rns_viz/assets/*.toml``).
"""

from __future__ import annotations

from dataclasses import dataclass

from rns_viz.control import Gains, InvalidGain, LawKind
from rns_viz.model import FsmsModel
from rns_viz.param_file import LAW_NAMES, AppTable, LawGains, ModelFileError
from rns_viz.params import param_file_for


@dataclass(frozen=True)
class ModelDefaults:
    law: LawKind  # the law the app starts with
    gains: dict[LawKind, Gains]  # per law; others get FALLBACK_GAINS
    kick_peak_N: float  # the kick button's default peak force
    kick_duration_s: float  # half-sine duration of a kick
    kick_range_N: float  # the kick slider's half range
    kick_axis: int  # the base coordinate a kick pushes along first (the panel's choice)
    exaggeration: float  # drawn deflection factor (fixed; with auto on: the first one drawn)
    auto_exaggeration: bool  # the factor follows the motion (rns_viz.viz.scene.auto_scale)
    target_speed_m_s: float  # speed limit of the smoothed end-effector target
    # what the scene shows at first (rns_viz.param_file.Overlay): only what a first look needs; the rest is a
    # tick away in *Show in the scene*, and lessons choose their own
    shown: frozenset[str]

    def gains_for(self, law: LawKind) -> Gains:
        return self.gains.get(law, FALLBACK_GAINS)


FALLBACK_GAINS = Gains(g_b=10.0, g_m=1.0)
MANUAL_EXAGGERATION = 10.0  # the fixed factor a file with exaggeration = "auto" starts the box with
# m: a kick about a rotational base coordinate is the moment of the kick's force at this lever arm
# (boom7: the slider's 20 N give 2 N m). A moment equal to the force in N would be a lever of 1 m, and
# 5 N m about the boom's z axis asks the suppressing arm to spin at over 100 rad/s (the run stops).
KICK_LEVER_M = 0.1


def defaults_for(model: str | FsmsModel) -> ModelDefaults:
    """The app's defaults for a model (a loaded one, or a model key: its parameter file is read for them)."""
    if isinstance(model, FsmsModel):
        return defaults_from(model.spec.app, model.spec.base.joints, str(model.spec.param_path))
    file = param_file_for(model)
    return defaults_from(file.app, file.base.joints, model)


def defaults_from(app: AppTable, base_joints: tuple[str, ...], where: str) -> ModelDefaults:
    """ModelDefaults from a parameter file's [app] table (``where`` names the file in an error)."""
    gains = {}
    for law in LAW_NAMES:
        table = getattr(app.gains, law)
        if table is not None:
            gains[law] = _gains(table, f"{where}: [app.gains.{law}]")
    return ModelDefaults(
        law=app.law,
        gains=gains,
        kick_peak_N=app.kick_peak_N,
        kick_duration_s=app.kick_duration_s,
        kick_range_N=app.kick_range_N,
        kick_axis=0 if app.kick_axis is None else base_joints.index(app.kick_axis),
        exaggeration=MANUAL_EXAGGERATION if app.scene.exaggeration == "auto" else app.scene.exaggeration,
        auto_exaggeration=app.scene.exaggeration == "auto",
        target_speed_m_s=app.target_speed_m_per_s,
        shown=frozenset(app.scene.shown),
    )


def _gains(table: LawGains, where: str) -> Gains:
    """Gains from a table whose keys carry units (g_b_per_s -> g_b); a key left out keeps Gains' default."""
    given = {key.rsplit("_per_", 1)[0]: getattr(table, key) for key in table.__struct_fields__}
    try:
        return Gains(**{name: value for name, value in given.items() if value is not None})
    except InvalidGain as exc:
        raise ModelFileError(f"{where}: {exc}") from None
