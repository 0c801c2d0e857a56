"""The live session's control laws: which law tracks which of the operator's references.

Three laws, as in the paper: acceleration (15), torque (16) and velocity (30). In live operation
the null-space input follows the operator's reference, handed to the law at every step with
``law.follow(sample)``:

- a 1-D RNS (TREP): theta_ref on the reactionless path; (15)/(16) track it inside the RNS
  (:class:`TrackJointReference`), (30) tracks it by position feedback as in the paper;
- a multi-dimensional RNS (planar 3R): (15)/(16) track the end-effector reference with Eq. (24)
  (:class:`TrackEndEffector`); (30) tracks the resolved-rate theta_ref, with theta_ref' fed
  forward so a low position gain g_m (fast vibration decay) still tracks.

During the point-to-point comparison (Fig. 11(b)) (15)/(16) give way to a joint servo: their
null-space input cannot, by design, make a motion that excites the base.
"""

from __future__ import annotations

from dataclasses import dataclass

from rns_viz.control import (
    AccelerationLaw,
    ControlLaw,
    Gains,
    JointSample,
    JointServo,
    LawKind,
    TaskSample,
    TorqueLaw,
    TrackEndEffector,
    TrackJointReference,
    VelocityLaw,
)
from rns_viz.live.operator.dual_arm import dual_law
from rns_viz.live.operator.kinds import operator_class
from rns_viz.model import FsmsModel

LAW_LABELS: dict[LawKind, str] = {
    "acceleration": "acceleration (15)",
    "torque": "torque (16)",
    "velocity": "velocity (30)",
}
TASK_THRESHOLD = 0.05  # m/rad: damping of J-bar^+ in Eq. (24) starts below this sigma_min


@dataclass(frozen=True)
class LiveLaw:
    """A law and which of the operator's samples it follows at each step."""

    law: ControlLaw
    follows_task: bool  # Eq. (24): the end-effector sample; otherwise the joint sample

    def follow(self, joint: JointSample, task: TaskSample | None) -> None:
        self.law.follow(task if self.follows_task and task is not None else joint)


def build_law(
    model: FsmsModel,
    kind: LawKind,
    gains: Gains,
    suppress: bool,
    joint: JointSample,
    task: TaskSample | None = None,
    joint_move: bool = False,
    shadow: bool = False,
) -> LiveLaw:
    """A live law; a ``task`` sample selects Eq. (24) tracking for (15)/(16); ``joint_move`` the servo.

    A dual-arm model (:mod:`rns_viz.live.operator.dual_arm`) runs the compensating law whatever ``kind`` (the
    operator's law choice is refused there), its compensator held still in the ``shadow`` run.
    """
    if operator_class(model).compensates:
        return LiveLaw(dual_law(model, gains, suppress, task, shadow), follows_task=True)
    if joint_move and kind != "velocity":
        return LiveLaw(JointServo(model, gains, joint), follows_task=False)
    if kind == "velocity":
        return LiveLaw(VelocityLaw(model, gains, joint, suppress=suppress, feedforward=task is not None), False)
    if task is not None:
        null = TrackEndEffector(model, task, gains.G_p, gains.G_d, threshold=TASK_THRESHOLD)
    else:
        null = TrackJointReference(joint, gains.k_p, gains.k_d)
    cls = AccelerationLaw if kind == "acceleration" else TorqueLaw
    return LiveLaw(cls(model, gains, null_input=null, suppress=suppress), follows_task=task is not None)
