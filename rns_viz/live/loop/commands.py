"""The live session's inputs as typed commands: one small frozen record per kind of input.

Constructing a command is the one place its input is checked: ``__post_init__`` raises a
``ValueError`` (:class:`~rns_viz.control.InvalidGain` for gains) with a message for the user, and
nothing is queued. The loop applies a command with a ``match`` on its type
(:meth:`rns_viz.live.loop.state.LiveState.apply`), so "go to definition" leads from an input to its effect.
Every command carries the client that sent it (for replies) and when it arrived (for latency).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, fields
from types import MappingProxyType
from typing import Any, get_args

import numpy as np

from rns_viz.control import GainOutOfRange, Gains, InvalidGain, LawKind
from rns_viz.live.loop.wall_clock import SPEEDS
from rns_viz.live.outputs.recorder import MAX_RECORD_S
from rns_viz.live.teaching.lessons import lessons_for, models_with_lessons
from rns_viz.out_of_range import check_range
from rns_viz.param_file import LawName
from rns_viz.params import check_model_key, missing_extra
from rns_viz.scenarios import LIVE_SCENARIOS

LIVE_LAWS: tuple[LawKind, ...] = get_args(LawName)  # the laws a parameter file may give gains for
MAX_KICK_N = 1e4  # N: larger peaks are refused as input errors, not physics
MAX_TARGET_M = 1e3  # m: a farther target is refused outright (it would mean nothing)
MAX_UBAR_SPEED = 1e4  # 1/(kg m s)
MAX_TARGET_SPEED = 100.0  # m/s
REPLAY_SPEEDS = (0.1, 4.0)  # recorded seconds per wall second
GAIN_NAMES = frozenset(f.name for f in fields(Gains))


def _installed(model: str, what: str) -> None:
    """Refuse ``what`` (a model or preset) whose bundled model needs an optional extra that is not installed,
    naming the install command (before anything is queued: the running simulation goes on untouched)."""
    extra = missing_extra(model)
    if extra is not None:
        raise ValueError(
            f"{what} needs rns-viz's optional extra '{extra}', not installed: pip install 'rns-viz[{extra}]'"
        )


@dataclass(frozen=True, kw_only=True)
class Command:
    client: int | None = None  # viser client id of the sender (None: the server itself)
    received: float = field(default_factory=time.perf_counter)  # s, when the input arrived


def _switch(name: str, value: Any) -> None:
    if not isinstance(value, bool | np.bool_):
        raise ValueError(f"{name} must be on or off, got {value!r}")


def _finite(name: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise ValueError(f"{name} must be a finite number, got {value!r}")
    return float(value)


@dataclass(frozen=True)
class Pause(Command):
    pass


@dataclass(frozen=True)
class Resume(Command):
    pass


@dataclass(frozen=True)
class RestartClock(Command):
    pass  # pace from now (a new model's scene was being built); handled by the session, not the state


@dataclass(frozen=True)
class SingleStep(Command):
    count: int = 1  # simulation steps of 1 ms

    def __post_init__(self) -> None:
        if isinstance(self.count, bool) or not isinstance(self.count, int) or not 1 <= self.count <= 100_000:
            raise ValueError(f"step count must be a whole number from 1 to 100000, got {self.count!r}")


@dataclass(frozen=True)
class Reset(Command):
    pass


@dataclass(frozen=True)
class SetSpeed(Command):
    speed: float  # simulated seconds per wall second

    def __post_init__(self) -> None:
        if self.speed not in SPEEDS:
            raise ValueError(f"speed must be one of {', '.join(f'{s:g}' for s in SPEEDS)}, got {self.speed!r}")


@dataclass(frozen=True)
class Kick(Command):
    peak: float  # N (N m on a rotational coordinate), half-sine peak
    direction: tuple[float, ...] | None = None  # weights over the base coordinates (None: the first alone)

    def __post_init__(self) -> None:
        if abs(_finite("kick peak", self.peak)) > MAX_KICK_N:
            raise ValueError(f"kick peak must be a force of at most {MAX_KICK_N:g} N, got {self.peak:g}")
        if self.direction is not None:
            try:
                weights = np.asarray(self.direction, dtype=float).reshape(-1)
            except (TypeError, ValueError) as exc:
                raise ValueError(f"kick direction must be numbers, got {self.direction!r}") from exc
            if not 1 <= weights.size <= 6 or not np.all(np.isfinite(weights)) or float(np.max(np.abs(weights))) > 1:
                raise ValueError(f"kick direction must be 1 to 6 weights within [-1, 1], got {self.direction!r}")
            if not np.any(weights):
                raise ValueError("kick direction must not be all zero")
            object.__setattr__(self, "direction", tuple(float(w) for w in weights))


@dataclass(frozen=True)
class SetSuppression(Command):
    on: bool  # vibration suppression (the g_b term) in the operated run; the shadow gets the opposite

    def __post_init__(self) -> None:
        _switch("vibration suppression", self.on)


@dataclass(frozen=True)
class SetLaw(Command):
    law: LawKind

    def __post_init__(self) -> None:
        if self.law not in LIVE_LAWS:
            raise ValueError(f"law must be one of {', '.join(LIVE_LAWS)}, got {self.law!r}")


@dataclass(frozen=True)
class SetGains(Command):
    """Gains by name (g_b, g_m, G_p, G_d, k_p, k_d, servo_bandwidth), units of :class:`Gains`."""

    changes: MappingProxyType[str, float]

    def __post_init__(self) -> None:
        unknown = set(self.changes) - GAIN_NAMES
        if unknown:
            raise InvalidGain(f"unknown gain(s): {', '.join(sorted(unknown))}")
        Gains(**self.changes)  # each value: finite, within its range (InvalidGain otherwise)
        object.__setattr__(self, "changes", MappingProxyType(dict(self.changes)))

    def applied_to(self, gains: Gains) -> Gains:
        return Gains(**{**{f.name: getattr(gains, f.name) for f in fields(Gains)}, **self.changes})


@dataclass(frozen=True)
class SetUbarSpeed(Command):
    value: float  # 1/(kg m s): u-bar when scrubbing, dragging and in cyclic motion (1-D RNS)

    def __post_init__(self) -> None:
        check_range("u-bar speed", self.value, 0.0, MAX_UBAR_SPEED, "1/(kg·m·s)", low_open=True, error=GainOutOfRange)


@dataclass(frozen=True)
class SetTargetSpeed(Command):
    value: float  # m/s: speed limit of the smoothed target (multi-dimensional RNS)

    def __post_init__(self) -> None:
        check_range("target speed", self.value, 0.0, MAX_TARGET_SPEED, "m/s", low_open=True, error=GainOutOfRange)


@dataclass(frozen=True)
class SetShadow(Command):
    on: bool

    def __post_init__(self) -> None:
        _switch("shadow run", self.on)


@dataclass(frozen=True)
class DragTarget(Command):
    xy: tuple[float, ...]  # m, base frame: (x, y) in the task plane of a planar model, (x, y, z) in space
    final: bool = False  # the end of a drag
    wxyz: tuple[float, ...] | None = None  # goal orientation (unit quaternion, base frame) of a pose handle

    def __post_init__(self) -> None:
        try:
            xy = np.asarray(self.xy, dtype=float).reshape(-1)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"target must be two or three numbers (m), got {self.xy!r}") from exc
        if xy.size not in (2, 3) or not np.all(np.isfinite(xy)) or float(np.max(np.abs(xy))) > MAX_TARGET_M:
            raise ValueError(f"target must be 2 or 3 finite coordinates within {MAX_TARGET_M:g} m, got {self.xy!r}")
        _switch("end of drag", self.final)
        object.__setattr__(self, "xy", tuple(float(v) for v in xy))
        if self.wxyz is not None:
            object.__setattr__(self, "wxyz", _unit_quaternion(self.wxyz))


def _unit_quaternion(wxyz: Any) -> tuple[float, ...]:
    """A target orientation (w, x, y, z), normalised; refused unless four finite numbers of norm ~1."""
    try:
        q = np.asarray(wxyz, dtype=float).reshape(-1)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"target orientation must be a quaternion (w, x, y, z), got {wxyz!r}") from exc
    norm = float(np.sqrt(q @ q)) if q.size == 4 and np.all(np.isfinite(q)) else 0.0
    if not 0.5 < norm < 2.0:
        raise ValueError(f"target orientation must be a unit quaternion (w, x, y, z), got {wxyz!r}")
    return tuple(float(v) for v in q / norm)


@dataclass(frozen=True)
class TrackOrientation(Command):
    on: bool  # spatial models: the end effector also follows the handle's orientation (secondary task)

    def __post_init__(self) -> None:
        _switch("orientation tracking", self.on)


@dataclass(frozen=True)
class Scrub(Command):
    sigma: float  # 1/(kg m): position along the current reactionless path (integral of u-bar dt)

    def __post_init__(self) -> None:
        _finite("path position", self.sigma)


@dataclass(frozen=True)
class Play(Command):
    duration: float  # s: quintic u-bar to the other end of the path (Fig. 11)

    def __post_init__(self) -> None:
        if not _finite("duration", self.duration) > 0:
            raise ValueError(f"duration must be positive, got {self.duration}")


@dataclass(frozen=True)
class Cyclic(Command):
    on: bool  # cyclic motion along a closed path (Fig. 12)

    def __post_init__(self) -> None:
        _switch("cyclic motion", self.on)


@dataclass(frozen=True)
class PointToPoint(Command):
    pass  # joint-space quintic to the end point of Play (Fig. 11(b))


@dataclass(frozen=True)
class SwitchModel(Command):
    model: str  # a model key: a bundled name or a .toml parameter file (read, and refused if bad, by the loop)

    def __post_init__(self) -> None:
        check_model_key(self.model)
        _installed(self.model, f"the model {self.model}")


@dataclass(frozen=True)
class SetSelection(Command):
    flags: tuple[bool, ...]  # S (Sec. III-B): per base coordinate, True = its reaction must vanish

    def __post_init__(self) -> None:
        if not isinstance(self.flags, tuple | list) or not 1 <= len(self.flags) <= 6:
            raise ValueError(f"a selection is 1 to 6 on/off flags, got {self.flags!r}")
        for flag in self.flags:
            _switch("a selection flag", flag)
        object.__setattr__(self, "flags", tuple(bool(f) for f in self.flags))


@dataclass(frozen=True)
class LoadPreset(Command):
    name: str
    paused: bool = False  # adopt it paused at t = 0 (the operator resumes once the plots are in view)

    def __post_init__(self) -> None:
        if self.name not in LIVE_SCENARIOS:
            raise ValueError(f"unknown preset {self.name!r}; choose one of {', '.join(LIVE_SCENARIOS)}")
        _installed(LIVE_SCENARIOS[self.name].model, f"the preset {self.name}")


@dataclass(frozen=True)
class StartLesson(Command):
    model: str  # whose lessons
    number: int  # 1-based

    def __post_init__(self) -> None:
        lessons = lessons_for(check_model_key(self.model))
        if not lessons:
            there = ", ".join(models_with_lessons())
            raise ValueError(f"no lessons for model {self.model!r}; there are some for {there}")
        if isinstance(self.number, bool) or not isinstance(self.number, int) or not 1 <= self.number <= len(lessons):
            raise ValueError(f"{self.model} has lessons 1 to {len(lessons)}, not {self.number!r}")


@dataclass(frozen=True)
class StopLesson(Command):
    pass


@dataclass(frozen=True)
class ReplayCommand(Command):
    """The replay's inputs (:mod:`rns_viz.live.loop.replay_mode` applies them); any other input ends a replay first."""


@dataclass(frozen=True)
class StartReplay(ReplayCommand):
    seconds: float  # s: replay the newest this many seconds of the run (the live simulation waits)

    def __post_init__(self) -> None:
        if not 0.0 < _finite("replay length", self.seconds) <= MAX_RECORD_S:
            raise ValueError(f"replay length must be more than 0 and at most {MAX_RECORD_S:g} s, got {self.seconds:g}")


@dataclass(frozen=True)
class SeekReplay(ReplayCommand):
    t: float  # s, simulation time within the recording (the loop checks it is inside)

    def __post_init__(self) -> None:
        if _finite("replay time", self.t) < 0.0:
            raise ValueError(f"replay time must be a time of the recording (s, not negative), got {self.t}")


@dataclass(frozen=True)
class SetReplaySpeed(ReplayCommand):
    speed: float  # recorded seconds per wall second

    def __post_init__(self) -> None:
        check_range("replay speed", self.speed, *REPLAY_SPEEDS, "×")


@dataclass(frozen=True)
class PlayReplay(ReplayCommand):
    on: bool  # play (from the start again if at the end) or pause the replay

    def __post_init__(self) -> None:
        _switch("replay playing", self.on)


@dataclass(frozen=True)
class StopReplay(ReplayCommand):
    pass  # back to live: the simulation resumes where it was (paused if it was paused)


# Operator inputs whose arrival-to-first-step latency is measured.
TIMED = (
    Kick,
    SetSuppression,
    SetLaw,
    SetGains,
    SetUbarSpeed,
    SetTargetSpeed,
    DragTarget,
    TrackOrientation,
    Scrub,
    Play,
    Cyclic,
    PointToPoint,
    SetSelection,
)
