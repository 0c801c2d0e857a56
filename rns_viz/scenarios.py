"""The paper's experiments as named presets (Sec. VI, Figs. 3-4; Sec. VII-D, Figs. 10-12), the
same ideas on the spatial model boom7 (m = 6, n = 7; Secs. II-V in general form), and dynamic
redundancy on trep2 (Sec. III-B: a compensating second arm).

Each preset builds a ready :class:`Simulator` with the paper's parameters. Choices the paper
leaves open are documented at the constants below. The boom7 presets are in SPATIAL_SCENARIOS and the
same experiments with the Franka Panda on that boom (boom-panda) in PANDA_SCENARIOS; trep2's are in
DUAL_SCENARIOS; the live app offers all of them (LIVE_SCENARIOS), each model those its parameter file
names (``[app] presets``, :func:`presets_for`); ``run_scenario`` runs all of them.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import cache

import numpy as np

from rns_viz.control import (
    AccelerationLaw,
    FixedReference,
    Gains,
    JointQuintic,
    PathReference,
    TaskQuintic,
    TaskSample,
    TrackEndEffector,
    TrackJointReference,
    VelocityLaw,
)
from rns_viz.control.compensation import CompensatingLaw, TaskCircle
from rns_viz.control.hold import JointServo, Switched
from rns_viz.control.reference import path_integral_to
from rns_viz.defaults import defaults_for
from rns_viz.model import FsmsModel
from rns_viz.param_file import ModelFileError, unknown
from rns_viz.params import param_file_for, source_path
from rns_viz.profiles import CyclicUbar, QuinticUbar
from rns_viz.sim import ForcePulse, Simulator

# "An arbitrary external force" (Sec. VII-D): the kicks of rns_viz.defaults (why these sizes: there).
_TREP, _PLANAR3R = defaults_for("trep"), defaults_for("planar3r")
TREP_KICK = dict(duration=_TREP.kick_duration_s, peak=(_TREP.kick_peak_N,))
# The 3R base "excited due to some external force at t = 1 s" (Sec. VI).
PLANAR3R_KICK = dict(start=1.0, duration=_PLANAR3R.kick_duration_s, peak=(_PLANAR3R.kick_peak_N,))
# Fig. 11: the reactionless path from theta = (90, 0) deg until joint 1 is back at 90 deg, which
# happens at theta_2 = 180 deg (link 2 folded back). The "link 2 only" comparison is the
# joint-space quintic between the same end points over the fast run's duration (the same
# speed): joint 1 stays at 90 deg, link 2 alone turns 180 deg, which is how we read its caption.
FIG11_SLOW_S = 5.0
FIG11_FAST_S = 2.5
FIG12_UBAR = 30.0  # 1/(kg m s), Sec. VII-D-3
FIG12_KICK_AT_S = 4.0
# Fig. 12 states no g_m. The gain map (rns_viz.analysis) predicts a base decay of 0.40 /s at g_m = 20
# (Fig. 10's gain) and 0.14 /s at g_m = 50 (Fig. 11's), the same at every point of the cyclic path
# (|h_bm| stays far above the damped inverse's threshold). The paper calls Fig. 12(a) a "slight
# deterioration" against Fig. 10(a): that fits g_m = 20, not a decay 2.8 times slower.
FIG12_GAINS = Gains(g_b=24.0, g_m=20.0)
# Fig. 4: a 0.71 m straight end-point path, quintic over 3 s, inside the 3R's reactionless set and
# away from rank loss of J-bar (its sigma_min stays at 0.34 m or more along the path).
FIG4_DISPLACEMENT = np.array([-0.5, -0.5])
FIG4_DURATION_S = 3.0


@dataclass(frozen=True)
class Scenario:
    name: str
    model: str
    duration: float  # s
    description: str
    build: Callable[[], Simulator]
    look: str = ""  # what to watch on screen while it runs (plain words; the app shows it)


def _trep() -> FsmsModel:
    return FsmsModel.from_name("trep")


def _planar3r() -> FsmsModel:
    return FsmsModel.from_name("planar3r")


@cache
def fig11_path_end() -> tuple[float, tuple[float, ...]]:
    """sigma = integral of u-bar dt that takes TREP from (90, 0) deg to theta_1 = 90 deg again."""
    model = _trep()
    theta0 = np.deg2rad([90.0, 0.0])
    # theta_1 - 90 deg changes sign first at theta_1 ~ 90 deg on the far side (theta_2 ~ 180 deg).
    start = path_integral_to(model, theta0, lambda th: th[1] - 1.0)  # leave the start first
    sigma, theta = path_integral_to(model, start[1], lambda th: th[0] - np.pi / 2)
    return start[0] + sigma, tuple(theta)


def _trep_kick(start: float) -> ForcePulse:
    return ForcePulse(start=start, **TREP_KICK)


def fig10(suppress: bool) -> Simulator:
    """Vibration suppression at the fixed initial configuration, law (30), g_m = 20, g_b = 24."""
    model = _trep()
    theta0 = np.deg2rad([90.0, 0.0])
    law = VelocityLaw(model, Gains(g_b=24.0, g_m=20.0), FixedReference(theta0), suppress=suppress)
    return Simulator(model, law, force=_trep_kick(0.5), q0=model.q(theta0))


def fig11(mode: str) -> Simulator:
    """Reactionless path at two speeds, versus a point-to-point motion with the same end points."""
    model = _trep()
    theta0 = np.deg2rad([90.0, 0.0])
    sigma, theta_end = fig11_path_end()
    gains = Gains(g_b=24.0, g_m=50.0)
    if mode == "joint2":
        reference = JointQuintic(theta0, np.array(theta_end), FIG11_FAST_S, t0=0.5)
    else:
        duration = FIG11_SLOW_S if mode == "slow" else FIG11_FAST_S
        reference = PathReference(model, theta0, QuinticUbar(sigma, duration, start=0.5))
    return Simulator(model, VelocityLaw(model, gains, reference), q0=model.q(theta0))


def fig12(suppress: bool, moving: bool = True) -> Simulator:
    """Cyclic reactionless motion (u-bar = 30 after a smooth start) with a kick at 4 s."""
    model = _trep()
    theta0 = np.deg2rad([90.0, 0.0])
    if moving:
        reference = PathReference(model, theta0, CyclicUbar(FIG12_UBAR, ramp=1.0, start=0.5))
    else:
        reference = FixedReference(theta0)
    law = VelocityLaw(model, FIG12_GAINS, reference, suppress=suppress)
    return Simulator(model, law, force=_trep_kick(FIG12_KICK_AT_S), q0=model.q(theta0))


def fig3() -> Simulator:
    """3R base vibration: kicked at 1 s, suppression (15) from 3 s, G_m = diag(1,1,1), g_b = 10."""
    model = _planar3r()
    gains = Gains(g_b=10.0, g_m=1.0)
    held = JointServo(model, gains, FixedReference(model.spec.default_configuration))
    law = Switched(held, AccelerationLaw(model, gains), at=3.0)
    return Simulator(model, law, force=ForcePulse(**PLANAR3R_KICK))


def fig4() -> Simulator:
    """3R reactionless end-point tracking of a quintic straight path, G_p = 400, G_d = 200."""
    model = _planar3r()
    theta0 = model.spec.default_configuration
    start = model.ee_position(theta0)[:2]
    task = TaskQuintic(start, start + FIG4_DISPLACEMENT, FIG4_DURATION_S, t0=0.5)
    gains = Gains(g_b=10.0, g_m=0.0, G_p=400.0, G_d=200.0)
    law = AccelerationLaw(model, gains, null_input=TrackEndEffector(model, task, gains.G_p, gains.G_d))
    return Simulator(model, law)


SCENARIOS: dict[str, Scenario] = {
    s.name: s
    for s in (
        Scenario("fig3", "planar3r", 10.0, "3R: kick at 1 s, vibration suppression (15) from 3 s", fig3),
        Scenario("fig4", "planar3r", 5.0, "3R: reactionless end-point tracking (24), quintic path", fig4),
        Scenario("fig10-on", "trep", 10.0, "TREP: kick, suppression on (30), g_m=20, g_b=24", lambda: fig10(True)),
        Scenario("fig10-off", "trep", 10.0, "TREP: kick, joints held, no suppression", lambda: fig10(False)),
        Scenario("fig11-slow", "trep", 7.0, "TREP: reactionless path, quintic u-bar, 5 s", lambda: fig11("slow")),
        Scenario("fig11-fast", "trep", 7.0, "TREP: reactionless path, quintic u-bar, 2.5 s", lambda: fig11("fast")),
        Scenario("fig11-joint2", "trep", 7.0, "TREP: same end points, joint-space quintic", lambda: fig11("joint2")),
        Scenario(
            "fig12-on",
            "trep",
            12.0,
            "TREP: cyclic path u-bar=30, kick at 4 s, suppression on (30), g_m=20, g_b=24",
            lambda: fig12(True),
        ),
        Scenario(
            "fig12-off", "trep", 12.0, "TREP: cyclic path u-bar=30, kick at 4 s, no suppression", lambda: fig12(False)
        ),
    )
}


# -- boom7: a 7-DOF arm on a boom tip with six elastic coordinates (assets/boom7.toml) -------------
# A kick in every direction: half-sine, 0.1 s, forces (N) along the tip's x, y, z and moments (N m)
# about them; about 1.8 mm and 0.8 mrad of tip deflection with the arm held. Law (15) absorbs it by
# moving the arm (joint 5 turns by 19 deg): a kick much larger drives the wrist through its joint limits, since
# the moment rows of H_bm are small (the distance to singularity sigma_min(W S H_bm), moment rows divided
# by the arm's 1.09 m reach, is 0.041 kg m at theta_0).
BOOM7_KICK = dict(start=0.1, duration=0.1, peak=(2.0, 5.0, 5.0, 0.5, 0.5, 0.5))
# (15): g_b = 10 /s on all six modes, G_m = 2 /s; end-effector gains G_p = 400 /s^2, G_d = 40 /s
# (critically damped error, 20 /s); joint reference gains k_p = 400 /s^2, k_d = 40 /s.
BOOM7_GAINS = Gains(g_b=10.0, g_m=2.0, G_p=400.0, G_d=40.0, k_p=400.0, k_d=40.0)
BOOM7_START_S = 0.2  # s: motions start here
BOOM7_MOVE_S = 1.5  # s: duration of every boom7 motion (path, tracking, point to point)
BOOM7_PATH_ARC = 1.5  # rad: joint-space length of the r = 6 path, sigma = arc / |n(theta_0)|
# End-effector displacement (m, tip frame) for forces-only tracking: S selects x, y, z only (r = 3,
# a 4-D RNS), so the three task rows leave one redundant direction; from the default configuration,
# where sigma_min of J-bar is 0.098 m/rad, this path keeps it above 0.05 m/rad.
BOOM7_DISPLACEMENT = np.array([0.08, 0.06, 0.06])
FORCES_ONLY = (1, 1, 1, 0, 0, 0)  # S: reactions x, y, z must vanish; moments rx, ry, rz are free


BOOMS = ("boom7", "boom-panda")  # the same boom, kinematics, limits and theta_0; the arms' inertias differ


def _boom(name: str, selection: tuple[int, ...] | None = None) -> FsmsModel:
    model = FsmsModel.from_name(name)
    return model if selection is None else model.with_selection(selection)


def boom7_kick(suppress: bool, name: str = "boom7") -> Simulator:
    """Kick in all six directions; (15) suppresses all six modes (S = E), or the joints are held."""
    model = _boom(name)
    theta0 = model.spec.default_configuration
    held = JointServo(model, BOOM7_GAINS, FixedReference(theta0))
    law = AccelerationLaw(model, BOOM7_GAINS) if suppress else held
    return Simulator(model, law, force=ForcePulse(**BOOM7_KICK), q0=model.q(theta0))


def boom7_path_reference(model: FsmsModel) -> PathReference:
    """theta_ref' = n u-bar along the r = 6 reactionless path from theta_0, quintic u-bar (Eq. 30's integral)."""
    theta0 = model.spec.default_configuration
    sigma = BOOM7_PATH_ARC / float(np.linalg.norm(model.null_vector(theta0)))
    return PathReference(model, theta0, QuinticUbar(sigma, BOOM7_MOVE_S, start=BOOM7_START_S))


def boom7_path(name: str = "boom7") -> Simulator:
    """r = 6: law (15) tracking the reactionless path in the 1-D RNS (P_RNS u, Eq. 15)."""
    model = _boom(name)
    reference = TrackJointReference(boom7_path_reference(model), BOOM7_GAINS.k_p, BOOM7_GAINS.k_d)
    law = AccelerationLaw(model, BOOM7_GAINS, null_input=reference)
    return Simulator(model, law)


def boom7_track(name: str = "boom7") -> Simulator:
    """r = 3: reactionless end-effector tracking with forces only, Eq. (24), moments left free."""
    model = _boom(name, FORCES_ONLY)
    start = model.ee_position(model.spec.default_configuration)
    task = TaskQuintic(start, start + BOOM7_DISPLACEMENT, BOOM7_MOVE_S, t0=BOOM7_START_S)
    law = AccelerationLaw(
        model, BOOM7_GAINS, null_input=TrackEndEffector(model, task, BOOM7_GAINS.G_p, BOOM7_GAINS.G_d)
    )
    return Simulator(model, law)


@cache
def boom7_track_end(name: str = "boom7") -> tuple[float, ...]:
    """Joint angles (rad) where forces-only tracking ends: the point-to-point motion's end point."""
    sim = boom7_track(name)
    sim.run(BOOM7_START_S + BOOM7_MOVE_S + 0.3)
    return tuple(sim.q[sim.model.m :])


def boom7_point_to_point(selection: tuple[int, ...] = FORCES_ONLY, name: str = "boom7") -> Simulator:
    """The same end points as the tracking, by a joint-space quintic of the same duration."""
    model = _boom(name, selection)
    theta0 = model.spec.default_configuration
    quintic = JointQuintic(theta0, np.array(boom7_track_end(name)), BOOM7_MOVE_S, t0=BOOM7_START_S)
    return Simulator(model, JointServo(model, BOOM7_GAINS, quintic))


BOOM_LOOK = {  # what to watch in each boom preset
    "kick-on": "all six tip deflections (Base coordinates plot) die out; the ghost (suppression off) keeps ringing.",
    "kick-off": "joints held: the boom tip rings in all six directions.",
    "path": "the hand moves along the one reaction-free direction; the boom tip stays below a micrometre.",
    "track": "the hand moves in 3-D; the tip's forces stay near zero, its twists (moments) need not.",
    "p2p": "the same end points by a joint-space motion: the boom tip shakes.",
}


def boom_scenarios(name: str) -> dict[str, Scenario]:
    """The boom's five presets for one of BOOMS, named after it (boom7-path, boom-panda-path, ...)."""
    presets = (
        ("kick-on", 5.0, "kick in 6 directions, (15) suppresses all six modes", lambda: boom7_kick(True, name)),
        ("kick-off", 5.0, "kick in 6 directions, joints held", lambda: boom7_kick(False, name)),
        ("path", 3.0, "reactionless path with r = 6 (1-D RNS), law (15)", lambda: boom7_path(name)),
        ("track", 3.0, "end-effector tracking (24), forces only (r = 3)", lambda: boom7_track(name)),
        ("p2p", 3.0, "same end points, joint-space quintic", lambda: boom7_point_to_point(name=name)),
    )
    return {
        f"{name}-{key}": Scenario(f"{name}-{key}", name, duration, f"{name}: {what}", build, BOOM_LOOK[key])
        for key, duration, what, build in presets
    }


SPATIAL_SCENARIOS: dict[str, Scenario] = boom_scenarios("boom7")
# The Panda's presets: boom7's experiments with the package's arm (needs rns-viz[panda] to build).
PANDA_SCENARIOS: dict[str, Scenario] = boom_scenarios("boom-panda")

# -- trep2: TREP with a compensating second arm (assets/trep2.toml) --------------------------------
# The task arm draws one circle of 40 mm radius, its angle quintic over 4 s from 0.2 s, starting at
# the default end-effector position (arm at (45, 90) deg); the compensator cancels its reaction
# (G_m = 2 /s on the coupling momentum L), or is held (k_p, k_d of the joint servo).
TREP2_GAINS = Gains(g_b=10.0, g_m=2.0)  # (15)'s TREP defaults (rns_viz.defaults), here through the compensator
TREP2_CIRCLE = dict(radius=0.04, duration=4.0, t0=0.2)  # m, s, s
TREP2_KICK_AT_S = 0.5


def trep2_circle(compensate: bool) -> Simulator:
    """Task arm on a circle; the compensator cancels the reaction (L = 0) or is held still."""
    model = FsmsModel.from_name("trep2")
    start = model.ee_position(model.spec.default_configuration)[:2]
    radius = TREP2_CIRCLE["radius"]
    circle = TaskCircle(start - np.array([radius, 0.0]), **TREP2_CIRCLE)
    law = CompensatingLaw(model, TREP2_GAINS, circle, compensate=compensate, suppress=False)
    return Simulator(model, law)


def trep2_kick(suppress: bool) -> Simulator:
    """TREP's kick with the task arm holding its end effector: (15)'s g_b acts through the compensator alone."""
    model = FsmsModel.from_name("trep2")
    target = TaskSample.held(model.ee_position(model.spec.default_configuration)[:2])
    law = CompensatingLaw(model, TREP2_GAINS, target, suppress=suppress)
    return Simulator(model, law, force=_trep_kick(TREP2_KICK_AT_S))


DUAL_SCENARIOS: dict[str, Scenario] = {
    s.name: s
    for s in (
        Scenario(
            "trep2-circle-on", "trep2", 4.6, "trep2: task arm circle, compensator cancels", lambda: trep2_circle(True)
        ),
        Scenario(
            "trep2-circle-off", "trep2", 4.6, "trep2: task arm circle, compensator held", lambda: trep2_circle(False)
        ),
        Scenario(
            "trep2-kick-on", "trep2", 6.0, "trep2: kick, g_b=10 through the compensator", lambda: trep2_kick(True)
        ),
        Scenario(
            "trep2-kick-off", "trep2", 6.0, "trep2: kick, compensator keeps L = 0 only", lambda: trep2_kick(False)
        ),
    )
}
# What to watch in each of the paper's and trep2's presets (the boom's: BOOM_LOOK).
PRESET_LOOK = {
    "fig3": "the base vibration rings after the kick at 1 s and dies out once suppression starts at 3 s.",
    "fig4": "the hand moves 0.71 m in a straight line while the base vibration plot stays near zero.",
    "fig10-on": "after the kick the arm moves against the swing and the base vibration dies out in a few seconds; "
    "the ghost (suppression off) keeps swinging.",
    "fig10-off": "with the joints held nothing damps the base: its vibration keeps the same size.",
    "fig11-slow": "link 2 folds back, yet the base stays still: micrometres (read the factor written beside the base).",
    "fig11-fast": "the same path twice as fast: the base still moves only micrometres (2.8 µm in the paper); "
    "compare fig11-joint2.",
    "fig11-joint2": "the same end points with joint 2 turning alone: the base swings by about a millimetre, "
    "hundreds of times more than fig11-fast.",
    "fig12-on": "the arm goes round the path without shaking the base; the kick at 4 s dies out while the "
    "motion goes on.",
    "fig12-off": "the kick at 4 s leaves the base swinging while the arm keeps going round.",
    "trep2-circle-on": "the task arm draws a circle; the second arm moves so that the beam stays still.",
    "trep2-circle-off": "the same circle with the second arm held still: the beam swings.",
    "trep2-kick-on": "after the kick the second arm damps the beam's swing while the task arm's hand stays put.",
    "trep2-kick-off": "the second arm only cancels the task arm's push: the kicked beam keeps swinging.",
}
ALL_SCENARIOS: dict[str, Scenario] = {
    name: replace(s, look=PRESET_LOOK.get(name, s.look))
    for name, s in {**SCENARIOS, **SPATIAL_SCENARIOS, **PANDA_SCENARIOS, **DUAL_SCENARIOS}.items()
}
LIVE_SCENARIOS: dict[str, Scenario] = dict(ALL_SCENARIOS)  # the app's presets


def presets_for(key: str) -> tuple[str, ...]:
    """The presets a model offers in the app (its parameter file's ``[app] presets``); each runs as written, on
    the model it was written for. ModelFileError (a ValueError) for a name no preset has."""
    names = param_file_for(key).app.presets
    for name in names:
        if name not in LIVE_SCENARIOS:
            raise ModelFileError(f"{source_path(key)}: [app] presets: {unknown(name, list(LIVE_SCENARIOS), 'preset')}")
    return names


def run_scenario(name: str, duration: float | None = None) -> Simulator:
    """Build and run a preset (paper or spatial); returns the simulator (its ``log`` holds every step)."""
    if name not in ALL_SCENARIOS:
        raise KeyError(f"unknown scenario {name!r}; choose one of: {', '.join(ALL_SCENARIOS)}")
    scenario = ALL_SCENARIOS[name]
    sim = scenario.build()
    total = scenario.duration if duration is None else duration
    sim.resize_log(round(total / sim.dt) + 1)
    sim.run(total)
    return sim
