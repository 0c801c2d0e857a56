"""boom7's lessons: a 7-DOF arm on a boom tip with six elastic coordinates (Sec. II, "generally m = 6").

Three tasks, each checked from the simulation: a kick suppressed in all six modes by law (15); the
1-D reaction null space of r = 6 (the hand moves, the boom stays still); forces only (r = 3): the
selected rows of the coupling momentum stay near zero while the moment rows move.
"""

from __future__ import annotations

import math

import numpy as np

from rns_viz.live.teaching.lesson_types import Check, Envelope, Lesson, LessonStart, Progress, RunView

TRANSLATIONS, ROTATIONS = slice(0, 3), slice(3, 6)  # x_b = (x, y, z in m; rx, ry, rz in rad)


def _six(x: np.ndarray) -> str:
    """The six tip coordinates in mm and mrad."""
    mm = ", ".join(f"{1e3 * v:+.3f}" for v in x[TRANSLATIONS])
    mrad = ", ".join(f"{1e3 * v:+.3f}" for v in x[ROTATIONS])
    return f"({mm}) mm, ({mrad}) mrad"


class SixModesSuppressed(Check):
    """A kick of at least 0.05 mm; 1.5 s later every coordinate of the operated run has stayed below 5 %
    of the shadow's peak (translations and rotations apart) for 0.5 s, while the shadow still swings."""

    MIN_PEAK_M = 5e-5
    SETTLE_S = 1.5  # s after the kick
    RESIDUAL = 0.05  # operated envelope / shadow peak

    def restart(self, view: RunView) -> None:
        self.kicks0, self.kick_t = view.kicks, math.nan
        self.peak = np.zeros(2)  # shadow's peak |translation| (m), |rotation| (rad)
        self.now = np.zeros(6) if view.base is None else view.base.copy()
        self.env_t, self.env_r = Envelope(0.5), Envelope(0.5)
        self.left = np.full(2, math.inf)
        self.shadow_on = view.base_shadow is not None

    def update(self, v: RunView) -> None:
        if v.base is None:
            return
        self.now, self.shadow_on = v.base, v.base_shadow is not None
        if v.kicks > self.kicks0 and math.isnan(self.kick_t):
            self.kick_t = v.t
        if math.isnan(self.kick_t) or v.base_shadow is None:
            return
        shadow = v.base_shadow
        self.peak = np.maximum(self.peak, [np.abs(shadow[TRANSLATIONS]).max(), np.abs(shadow[ROTATIONS]).max()])
        self.left = np.array(
            [
                self.env_t.add(v.t, np.abs(v.base[TRANSLATIONS]).max()),
                self.env_r.add(v.t, np.abs(v.base[ROTATIONS]).max()),
            ]
        )
        settled = v.t > self.kick_t + self.SETTLE_S and bool(np.all(self.left <= self.RESIDUAL * self.peak))
        self.done = settled and self.peak[0] > self.MIN_PEAK_M

    def progress(self) -> Progress:
        if math.isnan(self.kick_t):
            return Progress(False, f"Waiting for a kick. Tip now {_six(self.now)}.")
        if not self.shadow_on:
            return Progress(False, "Tick *Ghost run* to compare with suppression off, and kick again.")
        if self.peak[0] <= self.MIN_PEAK_M:
            return Progress(False, f"The shadow's peak is {self.peak[0] * 1e3:.3f} mm: kick harder (5 N or more).")
        share = 100 * self.left / np.maximum(self.peak, 1e-12)
        return Progress(
            self.done,
            f"Tip now {_six(self.now)}; left of the shadow's peak: {share[0]:.1f} % (translations), "
            f"{share[1]:.1f} % (rotations).",
        )


class BoomStaysStill(Check):
    """The hand moves 3 cm or more while no base coordinate ever passes 1 µm or 1 µrad (r = 6, 1-D RNS)."""

    MOVE_M = 0.03
    LIMIT = 1e-6  # m and rad

    def restart(self, view: RunView) -> None:
        self.ee0 = self.model.ee_position(view.theta)
        self.moved, self.peak = 0.0, 0.0

    def update(self, v: RunView) -> None:
        if v.base is None:
            return
        self.moved = max(self.moved, float(np.linalg.norm(self.model.ee_position(v.theta) - self.ee0)))
        self.peak = max(self.peak, float(np.abs(v.base).max()))
        self.done = self.moved >= self.MOVE_M and self.peak < self.LIMIT

    def progress(self) -> Progress:
        if self.peak >= self.LIMIT:
            return Progress(
                False,
                f"The boom moved {self.peak * 1e6:.2f} µm or µrad: too much (a kick?). Press *Reset* and try again.",
            )
        return Progress(
            self.done,
            f"Hand moved {self.moved * 100:.1f} cm; largest boom deflection so far {self.peak * 1e9:.1f} nm or nrad.",
        )


class ForcesStayZero(Check):
    """Forces only (r = 3): the hand moves 4 cm or more while the force rows of L = H_bm θ' (Eq. 8) stay
    below 5 % of the arm's own momentum scale (its mass times the hand's peak speed), kg m/s."""

    MOVE_M = 0.04
    SHARE = 0.05

    def restart(self, view: RunView) -> None:
        self.ee0 = self.model.ee_position(view.theta)
        self.last: tuple[float, np.ndarray] = (view.t, self.ee0)
        self.moved, self.forces, self.moments, self.speed = 0.0, 0.0, 0.0, 0.0

    def update(self, v: RunView) -> None:
        if v.thetadot is None or self.model.m != 6:
            return
        L = self.model.mass_matrix(self.model.q(v.theta))[:6, 6:] @ v.thetadot  # every row of H_bm theta'
        self.forces = max(self.forces, float(np.abs(L[TRANSLATIONS]).max()))
        self.moments = max(self.moments, float(np.abs(L[ROTATIONS]).max()))
        ee = self.model.ee_position(v.theta)
        if v.t > self.last[0]:
            self.speed = max(self.speed, float(np.linalg.norm(ee - self.last[1])) / (v.t - self.last[0]))
        self.last = (v.t, ee)
        self.moved = max(self.moved, float(np.linalg.norm(ee - self.ee0)))
        self.done = self.moved >= self.MOVE_M and self.forces < self.SHARE * self.model.arm_mass * self.speed

    def progress(self) -> Progress:
        if self.model.m != 6 or list(self.model.selected) != [0, 1, 2]:
            return Progress(False, "This lesson needs boom7 with S = forces only (x, y, z): restart the lesson.")
        scale = self.model.arm_mass * self.speed  # kg m/s
        share = 100 * self.forces / scale if scale > 0 else float("nan")
        return Progress(
            self.done,
            f"Hand moved {self.moved * 100:.1f} cm. Peak coupling momentum: forces {self.forces:.2e} kg m/s "
            f"({share:.1f} % of the arm's mass × hand speed, {scale:.2f} kg m/s), moments {self.moments:.2e} kg m²/s.",
        )


BOOM7_LESSONS = (
    Lesson(
        "boom7-six-modes",
        "A kick in six directions",
        "Eqs. (13), (15)",
        "boom7: a 7-joint arm on the tip of a 4 m boom. The tip has six elastic coordinates: three "
        "translations and three small rotations. Law (15) moves the arm so that every one of them is damped, "
        "x_b'' + G_b x_b' + H_b⁻¹ K_b x_b = 0 (Eq. 13). The red ghost is the shadow run, suppression off.",
        "Kick the base (5 N or more, any direction in *Base coordinates*) and read the six deflections: the "
        "operated boom stops while the shadow rings. Untick *Vibration suppression* to see it the other way.",
        LessonStart("boom7", "acceleration", True),
        SixModesSuppressed,
        look="the Base coordinates plot: six deflections dying out, while the ghost keeps ringing.",
    ),
    Lesson(
        "boom7-path",
        "A reactionless path in 3-D",
        "Eqs. (9), (11): θ' = n ū",
        "With all six reactions selected (r = 6) seven joints leave a one-dimensional reaction null space: "
        "one direction of joint motion, n, pushes the boom neither way nor turns it.",
        "Scrub ū (*Reactionless path*) or drag the handle so the hand moves 3 cm or more; the boom must stay "
        "below 1 µm and 1 µrad.",
        LessonStart("boom7", "acceleration", True),
        BoomStaysStill,
        look="the base vibration plot (micrometres) while the hand moves.",
    ),
    Lesson(
        "boom7-forces-only",
        "Forces only",
        "Sec. III-B: S H_bm",
        "Select only the forces (S = x, y, z): the reaction null space grows to four dimensions, enough to "
        "steer the hand in 3-D by Eq. (24). The moments are left free: the arm may twist the boom.",
        "Drag the handle 4 cm or more. The force rows of the coupling momentum stay near zero while the "
        "moment rows move. Then load the preset *boom7-p2p*: the same end points by a joint-space motion "
        "shake the boom.",
        LessonStart("boom7#S=111000", "acceleration", True),
        ForcesStayZero,
        look="the momentum handed to the base (L): its force rows stay near zero, the moment rows move.",
    ),
)
