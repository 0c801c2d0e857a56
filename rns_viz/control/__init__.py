"""The paper's control laws, one module each, one call signature: law(t, q, v) -> ControlOutput."""

from rns_viz.control.acceleration import AccelerationLaw, composite_acceleration
from rns_viz.control.common import ControlLaw, ControlOutput, GainOutOfRange, Gains, InvalidGain, LawKind
from rns_viz.control.hold import JointServo, Switched
from rns_viz.control.null_input import (
    DampNullMotion,
    TaskQuintic,
    TrackEndEffector,
    TrackJointReference,
)
from rns_viz.control.reference import (
    FixedReference,
    JointQuintic,
    JointSample,
    PathReference,
    ReferenceSample,
    TaskSample,
)
from rns_viz.control.torque import TorqueLaw
from rns_viz.control.velocity import VelocityLaw

__all__ = [
    "AccelerationLaw",
    "ControlLaw",
    "ControlOutput",
    "DampNullMotion",
    "FixedReference",
    "GainOutOfRange",
    "Gains",
    "InvalidGain",
    "JointQuintic",
    "JointSample",
    "JointServo",
    "LawKind",
    "PathReference",
    "ReferenceSample",
    "Switched",
    "TaskQuintic",
    "TaskSample",
    "TorqueLaw",
    "TrackEndEffector",
    "TrackJointReference",
    "VelocityLaw",
    "composite_acceleration",
]
