"""Lessons: short guided steps through the paper, each with a task whose completion is measured.

A :class:`Lesson` says what it is about (a sentence or two and the paper's equation), loads a state
(model, law, suppression; the shadow run shown), gives the student a task and checks it
from the simulation: a :class:`Check` observes the run every few steps and says when the task is
done. Checks start afresh when the run restarts (reset, model switch). Nothing here imports viser.
A control the student is to use is named in *italics* exactly as the panel labels it (a test checks
every name against the app's controls). Every lesson has a name; a model's parameter file lists the
lessons it offers, in teaching order (``[app] lessons``).
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np

from rns_viz.live.teaching.lesson_types import Check, Envelope, Lesson, LessonStart, Progress, RunView
from rns_viz.live.teaching.lessons_boom import BOOM7_LESSONS
from rns_viz.param_file import ModelFileError, unknown
from rns_viz.params import MODEL_NAMES, param_file_for, source_path
from rns_viz.scenarios import FIG11_SLOW_S


class KickAndSwing(Check):
    """A kick with nothing damping it: the base swings on, undamped (Eq. 1). Done when, three swings
    after a kick of at least 1 mm, the swing is still above 90 % of its peak (suppression off)."""

    MIN_PEAK_M = 1e-3  # a kick too small to see drawn
    KEEPS_SWINGING = 0.9  # envelope / peak: an undamped base keeps ~100 %, law (30) at g_b = 24 ~50 %

    def restart(self, view: RunView) -> None:
        self.kicks0, self.peak, self.kick_t, self.swing, self.swung = view.kicks, 0.0, math.nan, 0.0, False
        self.env = Envelope(1.2 * self.period)

    def update(self, v: RunView) -> None:
        if v.kicks > self.kicks0 and math.isnan(self.kick_t):
            self.kick_t = v.t
        env = self.env.add(v.t, v.x_b)
        if not math.isnan(self.kick_t):
            self.peak = max(self.peak, abs(v.x_b))
            self.swing, self.swung = env, v.t > self.kick_t + self.period
            later = v.t > self.kick_t + 3 * self.period
            self.done = later and self.peak > self.MIN_PEAK_M and env > self.KEEPS_SWINGING * self.peak

    def progress(self) -> Progress:
        if math.isnan(self.kick_t):
            return Progress(False, "Waiting for a kick.")
        peak, swing = self.peak * 1e3, self.swing * 1e3
        if self.swung and self.peak <= self.MIN_PEAK_M:
            return Progress(False, f"Peak {peak:.2f} mm: kick harder (past 1 mm; about 0.2 N or more).")
        if self.swung and self.swing < self.KEEPS_SWINGING * self.peak:
            return Progress(
                False,
                f"Peak {peak:.2f} mm, swing now {swing:.2f} mm: it is dying out, so something damps it. "
                "Untick *Vibration suppression* and kick again.",
            )
        return Progress(self.done, f"Peak {peak:.2f} mm, swing now {swing:.2f} mm: it keeps swinging.")


class StaysStill(Check):
    """Reach the other side of the path (joint 2 past 150 deg) with |x_b| below 0.1 mm (Eqs. 27, 30)."""

    LIMIT_M = 1e-4

    def restart(self, view: RunView) -> None:
        self.peak, self.theta2_0 = 0.0, float(view.theta[1])

    def update(self, v: RunView) -> None:
        self.peak = max(self.peak, abs(v.x_b))
        turned = abs(float(v.theta[1]) - self.theta2_0)
        self.turned = turned
        self.done = turned > math.radians(150) and self.peak < self.LIMIT_M and "path" not in v.mode

    def progress(self) -> Progress:
        turned = math.degrees(getattr(self, "turned", 0.0))
        if self.peak >= self.LIMIT_M:
            return Progress(False, f"The base moved {self.peak * 1e3:.2f} mm: too much. Press *Reset* and try again.")
        return Progress(self.done, f"Joint 2 turned {turned:.0f} deg; base deflection so far {self.peak * 1e6:.1f} µm.")


class ShakesTheBase(Check):
    """The joint-space motion between the same end points shakes the base (Fig. 11(b))."""

    def restart(self, view: RunView) -> None:
        self.peak, self.started = 0.0, False

    def update(self, v: RunView) -> None:
        self.peak = max(self.peak, abs(v.x_b))
        self.started = self.started or v.mode.startswith("point-to-point")
        self.done = self.started and not v.mode.startswith("point-to-point") and self.peak > 5e-4

    def progress(self) -> Progress:
        return Progress(self.done, f"Peak base deflection {self.peak * 1e3:.2f} mm.")


class SuppressedVersusShadow(Check):
    """After a kick the operated run's swing falls below 10 % while the shadow's stays above 50 %."""

    def restart(self, view: RunView) -> None:
        self.kicks0, self.peak, self.peak_shadow = view.kicks, 0.0, 0.0
        self.env, self.env_shadow = Envelope(1.2 * self.period), Envelope(1.2 * self.period)
        self.ratio, self.ratio_shadow = 1.0, 1.0

    def update(self, v: RunView) -> None:
        env, env_s = self.env.add(v.t, v.x_b), self.env_shadow.add(v.t, v.x_b_shadow)
        if v.kicks <= self.kicks0 or math.isnan(v.x_b_shadow):
            return
        self.peak, self.peak_shadow = max(self.peak, env), max(self.peak_shadow, env_s)
        if self.peak > 1e-4:
            self.ratio, self.ratio_shadow = env / self.peak, env_s / max(self.peak_shadow, 1e-300)
            self.done = self.ratio < 0.1 and self.ratio_shadow > 0.5

    def progress(self) -> Progress:
        if self.peak <= 1e-4:
            return Progress(False, "Waiting for a kick (with the shadow run shown).")
        return Progress(
            self.done, f"Swing now {self.ratio:.0%} of its peak; the shadow's {self.ratio_shadow:.0%} of its own."
        )


class WeakestPoint(Check):
    """Hold the arm where sigma_min(W S H_bm) is at most 65 % of its value at the start configuration."""

    def update(self, v: RunView) -> None:
        self.ratio = v.sigma_hbm / self.sigma0
        self.done = self.ratio <= 0.65 and "path" not in v.mode

    def progress(self) -> Progress:
        ratio = getattr(self, "ratio", 1.0)
        return Progress(self.done, f"σ_min(W S H_bm) here is {ratio:.0%} of its value at the start.")


class CyclicAndKick(Check):
    """Cyclic motion along the path goes on while a kick dies out (Fig. 12)."""

    def restart(self, view: RunView) -> None:
        self.kicks0, self.peak, self.ratio = view.kicks, 0.0, 1.0
        self.env = Envelope(1.2 * self.period)

    def update(self, v: RunView) -> None:
        env = self.env.add(v.t, v.x_b)
        cyclic = v.mode.startswith("cyclic")
        if v.kicks > self.kicks0 and cyclic:
            self.peak = max(self.peak, env)
            self.ratio = env / max(self.peak, 1e-300)
            self.done = self.peak > 1e-4 and self.ratio < 0.2

    def progress(self) -> Progress:
        if self.peak <= 1e-4:
            return Progress(False, "Press *Start cyclic motion*, then *Kick the base*.")
        return Progress(self.done, f"Swing now {self.ratio:.0%} of its peak, the arm still circling.")


class TrackWithoutReaction(Check):
    """Move the end effector 20 cm or more with |x_b| below 0.1 mm and arrive (Eq. 24)."""

    def restart(self, view: RunView) -> None:
        self.start, self.peak, self.moved, self.error = view.ee.copy(), 0.0, 0.0, math.inf

    def update(self, v: RunView) -> None:
        self.peak = max(self.peak, abs(v.x_b))
        self.moved = max(self.moved, float(np.linalg.norm(v.ee - self.start)))
        self.error = math.inf if v.ee_target is None else float(np.linalg.norm(v.ee_target - v.ee))
        self.done = self.moved >= 0.2 and self.peak < 1e-4 and self.error < 5e-3

    def progress(self) -> Progress:
        return Progress(self.done, f"Moved {self.moved * 100:.0f} cm; base deflection so far {self.peak * 1e6:.1f} µm.")


class ClampedTarget(Check):
    """Drag beyond the reactionless-reachable set: the target is moved in, and the arm goes as far as it
    can without reaction (to the moved target, or to a fold curve where J-bar loses rank) and stops."""

    def restart(self, view: RunView) -> None:
        self.moved0, self.clamped, self.settled = view.targets_moved, False, False
        self.trail: deque[tuple[float, np.ndarray]] = deque()

    def update(self, v: RunView) -> None:
        self.clamped = self.clamped or v.targets_moved > self.moved0
        if not self.clamped:
            return
        self.trail.append((v.t, v.ee.copy()))
        while self.trail[0][0] < v.t - 0.5:
            self.trail.popleft()
        span = self.trail[-1][0] - self.trail[0][0]
        still = max(float(np.linalg.norm(p - v.ee)) for _, p in self.trail) < 5e-4
        self.done = span >= 0.45 and still

    def progress(self) -> Progress:
        if not self.clamped:
            return Progress(False, "Drag the target far out of the lilac dots.")
        return Progress(self.done, "The target was moved into the set; the arm went as far as it can.")


class AbsorbKick(Check):
    """A kick of 2 N or more, damped to 10 % of its peak by law (15)."""

    def restart(self, view: RunView) -> None:
        self.kicks0, self.peak, self.ratio = view.kicks, 0.0, 1.0
        self.env = Envelope(1.2 * self.period)

    def update(self, v: RunView) -> None:
        env = self.env.add(v.t, v.x_b)
        if v.kicks > self.kicks0:
            self.peak = max(self.peak, env)
            self.ratio = env / max(self.peak, 1e-300)
            self.done = self.peak > 2e-3 and self.ratio < 0.1

    def progress(self) -> Progress:
        if self.peak <= 2e-3:
            return Progress(False, "Kick harder (the deflection should pass 2 mm).")
        return Progress(self.done, f"Swing now {self.ratio:.0%} of its peak.")


TREP_LESSONS = (
    Lesson(
        "trep-spring",
        "The base is a spring",
        "Eq. (1)",
        "TREP (a two-link arm on a flexible beam) has its arm bolted to the beam's tip: that tip is the **base**. "
        "It moves like a mass on a spring (Eq. (1), the equation of motion), pushed by outside forces and "
        "by the arm's own motion. With the joints held, nothing damps it. Its bend x_b is drawn enlarged "
        "(the factor is written beside the base).",
        "Press *Kick the base* (a push in newtons, N) and watch the red line in *Live plots*: the base's bend "
        "x_b. The blue line is the shadow run, a copy with suppression on: ignore it until lesson 4.",
        LessonStart("trep", "velocity", False),
        KickAndSwing,
        look="the red line of the base vibration plot: the swing after a kick does not die out.",
    ),
    Lesson(
        "trep-pushing-motion",
        "A motion that pushes",
        "Eq. (8): L = H_bm θ'",
        "Every joint motion carries coupling momentum L = H_bm θ' into the base, unless it is reactionless.",
        "Press *Same end points, joint space*: joint 2 turns alone by half a turn. Watch the base.",
        LessonStart("trep", "velocity", True),
        ShakesTheBase,
        look="the bent plates and the base vibration plot while joint 2 turns.",
    ),
    Lesson(
        "trep-reactionless-path",
        "The reactionless path",
        "Eqs. (27), (30): θ' = n ū",
        "Moving along n, the null-space vector of H_bm, keeps L = 0: the base feels nothing. ū (1/(kg m s)) "
        "sets the speed along the path.",
        f"Move along the path (*Play path slowly ({FIG11_SLOW_S:g} s)*, or drag the handle) so the arm reaches "
        "the other side with the base deflection below 0.1 mm.",
        LessonStart("trep", "velocity", True),
        StaysStill,
        look="the base vibration plot: it stays flat while the arm moves across.",
    ),
    Lesson(
        "trep-suppression",
        "Vibration suppression",
        "Eq. (30): θ'_cmd = H_bm⁺ m_b g_b x_b + g_m (θ_ref − θ)",
        "The arm damps the base by a motion outside the reaction null space, proportional to the deflection. "
        "The shadow run gets the same kick with suppression off.",
        "Press *Kick the base* and compare the arm with its shadow.",
        LessonStart("trep", "velocity", True),
        SuppressedVersusShadow,
        look="the arm against its red ghost (suppression off), and the blue line against the red one in the base "
        "vibration plot.",
    ),
    Lesson(
        "trep-weakest-point",
        "Where suppression is weakest",
        "Eq. (30): H_bm⁺",
        "The smaller the distance to singularity σ_min(W S H_bm), the faster the joints must turn for the same "
        "push on the base; where it vanishes the arm has no authority over the base at all.",
        "Move along the path to where σ_min(W S H_bm) (readout) is at most 65 % of its start value, and stop there.",
        LessonStart("trep", "velocity", True),
        WeakestPoint,
        look="the distance to singularity in the readouts, and how fast the joints turn as it shrinks.",
    ),
    Lesson(
        "trep-move-and-suppress",
        "Moving and suppressing at once",
        "Fig. 12",
        "Reactionless motion and vibration suppression add up: the first never reaches the base, the "
        "second acts only on it.",
        "Press *Start cyclic motion* (the arm goes round the path), then *Kick the base*.",
        LessonStart("trep", "velocity", True),
        CyclicAndKick,
        look="the base vibration plot: the kick's swing dies out while the arm keeps going round.",
    ),
)

PLANAR3R_LESSONS = (
    Lesson(
        "3r-tracking",
        "Reactionless end-point tracking",
        "Eq. (24)",
        "Three joints, one base direction: a two-dimensional reaction null space, enough to move the end "
        "effector in the plane without pushing the base.",
        "Drag the target 20 cm or more; the base must stay below 0.1 mm.",
        LessonStart("planar3r", "acceleration", True),
        TrackWithoutReaction,
        look="the base vibration plot (near zero) while the hand follows the handle.",
    ),
    Lesson(
        "3r-reachable-set",
        "The reactionless-reachable set",
        "Sec. V",
        "Without reaction the arm's centre of mass cannot move along the base direction, so only part of "
        "the workspace is reachable: the region of small lilac dots. Its fold curves are where J-bar loses rank.",
        "Drag the target far outside the lilac dots and watch where the arm goes and where it stops.",
        LessonStart("planar3r", "acceleration", True),
        ClampedTarget,
        look="where the hand stops: on the edge of the lilac dots, not at the handle.",
    ),
    Lesson(
        "3r-absorb-kick",
        "Absorbing a kick",
        "Eq. (15)",
        "Law (15) damps the base by moving the arm's centre of mass; the end effector keeps its target, so "
        "the arm swings its elbow to do it.",
        "Press *Kick the base* (2 N or more) and watch the arm absorb it.",
        LessonStart("planar3r", "acceleration", True),
        AbsorbKick,
        look="the elbow swinging while the hand holds its place, and the base vibration dying out.",
    ),
)

__all__ = ["LESSON_LIBRARY", "Check", "Lesson", "LessonStart", "Progress", "RunView", "lessons_for"]

# Every lesson by name; a model offers some of them, in its own order ([app] lessons of its parameter file).
LESSON_LIBRARY: dict[str, Lesson] = {
    lesson.name: lesson for lesson in (*TREP_LESSONS, *PLANAR3R_LESSONS, *BOOM7_LESSONS)
}


def lessons_for(key: str) -> tuple[Lesson, ...]:
    """The lessons a model offers (a bundled name or a parameter file), numbered from 1 in this order; each
    starts the model it was written for. ModelFileError (a ValueError) for a name no lesson has."""
    names = param_file_for(key).app.lessons
    for name in names:
        if name not in LESSON_LIBRARY:
            raise ModelFileError(f"{source_path(key)}: [app] lessons: {unknown(name, list(LESSON_LIBRARY), 'lesson')}")
    return tuple(LESSON_LIBRARY[name] for name in names)


def models_with_lessons() -> tuple[str, ...]:
    """The bundled models that offer lessons."""
    return tuple(name for name in MODEL_NAMES if param_file_for(name).app.lessons)
