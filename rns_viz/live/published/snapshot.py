"""The records the live session hands out: settings, readouts, snapshots, overlays, notices.

All immutable; the simulation loop makes new ones and readers take the latest.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Literal, NamedTuple

import numpy as np

from rns_viz.control import Gains, LawKind
from rns_viz.defaults import defaults_for
from rns_viz.live.published.recording import Recording
from rns_viz.model import FsmsModel

Level = Literal["info", "warning", "error"]
UBAR_SPEED = 30.0  # 1/(kg m s): default u-bar of scrubbing, drags and cyclic motion (Fig. 12's value)


class Notice(NamedTuple):
    """A message for one client (``client`` = viser client id) or for everyone (None)."""

    title: str
    body: str
    client: int | None
    level: Level


@dataclass(frozen=True)
class Settings:
    """What the operator chose; the GUI shows these."""

    model: str
    law: LawKind
    gains: Gains
    suppress: bool
    ubar_speed: float  # 1/(kg m s): u-bar for scrubbing, drags and cyclic motion (1-D RNS)
    target_speed: float  # m/s: speed limit of the smoothed target (multi-dimensional RNS)
    shadow: bool
    speed: float  # simulated seconds per wall second
    preset: str | None
    preset_tuning: tuple[LawKind, Gains, bool] | None = None  # the preset's law, gains and suppression as loaded

    def with_preset(self, name: str, law: LawKind, gains: Gains, suppress: bool) -> Settings:
        """These settings with preset ``name`` loaded at its law, gains and suppression."""
        return replace(self, law=law, gains=gains, suppress=suppress, preset=name, preset_tuning=(law, gains, suppress))

    def changed_since_preset(self) -> tuple[str, ...]:
        """What the operator changed since the preset loaded ("law", "gains", "suppression"; () if nothing)."""
        if self.preset is None or self.preset_tuning is None:
            return ()
        law, gains, suppress = self.preset_tuning
        now = (("law", self.law != law), ("gains", self.gains != gains), ("suppression", self.suppress != suppress))
        return tuple(name for name, changed in now if changed)

    @classmethod
    def defaults(cls, model: FsmsModel, shadow: bool, speed: float) -> Settings:
        """A loaded model's defaults (rns_viz.defaults: its [app] table), suppression on, no preset."""
        defaults = defaults_for(model)
        law = defaults.law
        gains = defaults.gains_for(law)
        return cls(model.name, law, gains, True, UBAR_SPEED, defaults.target_speed_m_s, shadow, speed, None)


@dataclass(frozen=True)
class OrientationView:
    """The orientation target of a spatial model's reactionless tracking (what the panel and handle show)."""

    offered: bool  # n - r >= 4: the RNS has directions beyond the hand's position
    on: bool  # the reference tracks the goal orientation (secondary task)
    note: str  # how many rotational DOF are free, or why none
    wxyz: tuple[float, float, float, float]  # the goal orientation, base frame (unit quaternion)


@dataclass(frozen=True)
class Readouts:
    sigma_hbm: float = math.nan  # kg m: smallest singular value of S H_bm
    sigma_jbar: float = math.nan  # m/rad: the RNS-rank-th singular value of J-bar = J P_RNS
    warn_hbm: float = math.nan  # kg m: below this sigma_hbm is shown as a warning
    warn_jbar: float = math.nan  # m/rad
    n: tuple[float, ...] | None = None  # kg m: null-space vector of a 1-D RNS (Eq. 27)
    rns_dim: int = 0
    base_dof: int = 1  # m: the base's coordinates
    L: float = 0.0  # kg m/s: coupling momentum S H_bm theta' (first selected row)
    ee_error: float = math.nan  # m: |x_ref - x_e|
    reaction: float = 0.0  # N: the arm's reaction on the base, -(H_bm theta'' + c_b) of Eq. (1)
    reaction_t: float = math.nan  # s: start time of the step it was evaluated at
    reaction_wrench: tuple[float, ...] = ()  # N, N m: every base row of the reaction (drawn for a 6-DOF base)
    dual: bool = False  # a task arm and a compensating arm: sigma_hbm is S H_bm,2's, sigma_jbar J_1's
    cancel: str | None = None  # why the compensating arm cannot cancel the reaction now (None: it does)
    compensating: bool = True  # dual arms: the operated run's compensator cancels (the shadow's is held)


@dataclass(frozen=True)
class LessonStatus:
    """The lesson in progress, for the lesson panel."""

    model: str
    number: int  # 1-based
    count: int  # lessons of this model
    title: str
    equation: str
    text: str
    task: str
    done: bool
    progress: str  # what is measured now
    look: str = ""  # what to watch on screen


@dataclass(frozen=True)
class ReplayView:
    """A replay in progress: the recording and its playhead. The playhead moves with the wall clock
    while playing, so readers compute it (:meth:`position`) and the paused loop need not publish it."""

    recording: Recording
    start: float  # s (simulation time of the recording): the playhead at ``wall``
    wall: float  # time.perf_counter() when the playhead was at ``start``
    speed: float  # recorded seconds per wall second
    playing: bool
    version: int  # bumps at every replay command (a seek restarts the drawn trail)
    was_paused: bool  # the live simulation was paused before the replay (back to live keeps it so)

    def position(self, now: float) -> float:
        """The playhead at wall time ``now`` (s, simulation time of the recording); it stops at the end."""
        t0, t1 = self.recording.span
        if not self.playing:
            return self.start
        return min(max(self.start + self.speed * (now - self.wall), t0), t1)


@dataclass(frozen=True)
class Snapshot:
    """The loop's state for renderers; a new object each time (never mutated)."""

    epoch: int  # bumps on reset, model switch and preset load
    settings: Settings
    settings_version: int  # bumps when settings change other than by the operator's own input
    steps: int
    t: float
    q: np.ndarray
    q_shadow: np.ndarray | None
    paused: bool
    diverged: str | None
    rtf: float
    behind: bool  # the measured rate is under the chosen speed
    skipped: float  # simulated s given up after stalls in the last 2 s (0: none)
    mode: str
    target: np.ndarray | None  # base frame, m: where the arm is going
    target_version: int  # bumps when the target marker or handle should jump there
    sigma: float | None  # scrub slider position (1-D RNS), 1/(kg m)
    sigma_range: tuple[float, float] | None
    readouts: Readouts = field(default_factory=Readouts)
    overlay_version: int = 0
    lesson: LessonStatus | None = None
    replay: ReplayView | None = None  # a replay is shown instead of the (paused) live simulation
    orientation: OrientationView | None = None  # spatial tracking: the orientation target


@dataclass(frozen=True)
class Overlays:
    """Heavy scene overlays; re-read when ``Snapshot.overlay_version`` changes."""

    family: list[np.ndarray] | None  # Fig. 8 end-effector curves (1-D RNS)
    current: np.ndarray | None  # the current reactionless path's end-effector curve
    reach: np.ndarray | None  # reactionless reachable end-effector points (multi-D RNS)
    version: int
    reach_note: str = ""  # the Lie-bracket test where the reachable set was explored from, in words
    model: str = ""  # the model key they belong to ...
    epoch: int = -1  # ... and the loop's epoch (the current path and reachable set are of this run)
