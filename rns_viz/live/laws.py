"""The live session's control laws: which law, which gains, and how a running law is retuned.

Three laws, as in the paper: acceleration (15), torque (16) and velocity (30). In live operation
the null-space input follows the operator's reference:

- a 1-D RNS (TREP): theta_ref on the reactionless path; (15)/(16) track it inside the RNS
  (:class:`TrackJointReference`), (30) tracks it by position feedback as in the paper;
- a multi-dimensional RNS (planar 3R): (15)/(16) track the end-effector reference with Eq. (24)
  (:class:`TrackEndEffector`); (30) tracks the resolved-rate theta_ref, with theta_ref' fed
  forward so a low position gain g_m (fast vibration decay) still tracks.
"""

from __future__ import annotations

from dataclasses import fields, replace
from typing import Literal

from rns_viz.control import (
    AccelerationLaw,
    ControlLaw,
    DampNullMotion,
    Gains,
    InvalidGain,
    JointServo,
    Switched,
    TorqueLaw,
    TrackEndEffector,
    TrackJointReference,
    VelocityLaw,
)
from rns_viz.control.reference import JointReference
from rns_viz.model import FsmsModel

LawKind = Literal["acceleration", "torque", "velocity"]
LAW_KINDS: tuple[LawKind, ...] = ("acceleration", "torque", "velocity")
LAW_LABELS: dict[LawKind, str] = {
    "acceleration": "acceleration (15)",
    "torque": "torque (16)",
    "velocity": "velocity (30)",
}
GAIN_NAMES = tuple(f.name for f in fields(Gains))
TASK_THRESHOLD = 0.05  # m/rad: damping of J-bar^+ in Eq. (24) starts below this sigma_min

# Per model and law. TREP (30): g_b = 24, g_m = 20 as in Fig. 10. (15)/(16): the base closed loop is
# H_b s^3 + H_b (G_m + g_b) s^2 + k s + k G_m (DESIGN.md section 4): TREP decays fastest near
# g_b = 10, G_m = 2 (about 4/s). The 3R would decay fastest near g_b = 2.5, G_m = 0.4 (0.92/s), but
# then absorbing a 5 N kick shifts w x_cm so far (by about H_b g_b x_b / G_m) that the arm, holding
# its end effector, runs into a singularity of J-bar; G_m = 1 (Fig. 3's value) decays at 0.37/s and
# keeps the end effector on target.
DEFAULT_GAINS: dict[tuple[str, LawKind], Gains] = {
    ("trep", "velocity"): Gains(g_b=24.0, g_m=20.0),
    ("trep", "acceleration"): Gains(g_b=10.0, g_m=2.0),
    ("trep", "torque"): Gains(g_b=10.0, g_m=2.0),
    ("planar3r", "acceleration"): Gains(g_b=2.5, g_m=1.0),
    ("planar3r", "torque"): Gains(g_b=2.5, g_m=1.0),
    ("planar3r", "velocity"): Gains(g_b=2.5, g_m=1.0),
}
DEFAULT_LAW: dict[str, LawKind] = {"trep": "velocity", "planar3r": "acceleration"}


def default_gains(model: str, kind: LawKind) -> Gains:
    return DEFAULT_GAINS.get((model, kind), Gains(g_b=10.0, g_m=1.0))


def checked_gains(gains: Gains, changes: dict[str, float]) -> Gains:
    """``gains`` with ``changes``; raises InvalidGain for unknown names or bad values."""
    unknown = set(changes) - set(GAIN_NAMES)
    if unknown:
        raise InvalidGain(f"unknown gain(s): {', '.join(sorted(unknown))}")
    return replace(gains, **changes)


def build_law(
    model: FsmsModel,
    kind: LawKind,
    gains: Gains,
    suppress: bool,
    joint_ref: JointReference,
    task_ref: object | None = None,
) -> ControlLaw:
    """A live law; ``task_ref`` (x_d, x_d', x_d'') selects Eq. (24) tracking for (15)/(16)."""
    if kind == "velocity":
        return VelocityLaw(model, gains, joint_ref, suppress=suppress, feedforward=task_ref is not None)
    if task_ref is not None:
        null = TrackEndEffector(model, task_ref, gains.G_p, gains.G_d, threshold=TASK_THRESHOLD)  # type: ignore[arg-type]
    else:
        null = TrackJointReference(joint_ref, gains.k_p, gains.k_d)
    cls = AccelerationLaw if kind == "acceleration" else TorqueLaw
    return cls(model, gains, null_input=null, suppress=suppress)


def retune(law: object, gains: Gains) -> None:
    """Give a running law (and its null-space input) new gains, in place."""
    if isinstance(law, Switched):
        retune(law.before, gains)
        retune(law.after, gains)
        return
    if isinstance(law, AccelerationLaw | TorqueLaw | VelocityLaw | JointServo):
        law.gains = gains
    null = getattr(law, "null_input", None)
    if isinstance(null, DampNullMotion):
        null.g_m = gains.g_m
    elif isinstance(null, TrackEndEffector):
        null.G_p, null.G_d = gains.G_p, gains.G_d
    elif isinstance(null, TrackJointReference):
        null.k_p, null.k_d = gains.k_p, gains.k_d


def set_suppression(law: object, on: bool) -> None:
    """Switch the vibration-suppression term (g_b) of a running law on or off."""
    if isinstance(law, Switched):
        set_suppression(law.after, on)
    elif isinstance(law, AccelerationLaw | TorqueLaw | VelocityLaw):
        law.suppress = on


def suppression_of(law: object) -> bool:
    if isinstance(law, Switched):
        return suppression_of(law.after)
    return bool(getattr(law, "suppress", False))


def kind_of(law: object) -> LawKind:
    """Which of the three laws a (preset) law is; a switch counts as the law it switches to."""
    if isinstance(law, Switched):
        return kind_of(law.after)
    if isinstance(law, TorqueLaw):
        return "torque"
    if isinstance(law, VelocityLaw):
        return "velocity"
    return "acceleration"


def gains_of(law: object) -> Gains:
    if isinstance(law, Switched):
        return gains_of(law.after)
    return getattr(law, "gains", Gains())
