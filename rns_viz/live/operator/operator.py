"""What the operator drives in live mode: the joint reference (and, for a target, the end-effector reference)
that the operated and the shadow law both follow.

The operator owns its references and hands out immutable samples (:attr:`Operator.joint`,
:attr:`Operator.task`), which the loop passes to both laws at every step; :meth:`Operator.advance`
returns what changed for the loop to act on.

What the operator moves depends on the model, and is chosen once, when the model loads
(:func:`rns_viz.live.operator.kinds.operator_class`): one subclass of :class:`Operator` per kind.

- A reactionless path (a 1-D RNS: TREP, boom7 with r = 6): theta_ref lives on the current path
  (:class:`~rns_viz.live.operator.path_operator.PathOperator`).
- A reactionless-reachable set (a multi-dimensional RNS: the planar 3R, boom7 with r <= 5): a target
  clamped to the set, followed by Eq. (24)'s reference
  (:class:`~rns_viz.live.operator.target_operators.ReachOperator`).
- A task arm (trep2: compensating arms, ``[arms]``): a target in the task arm's workspace; the compensating
  arm cancels the reaction (:class:`~rns_viz.live.operator.target_operators.TaskArmOperator`).

The rest of the app asks the kind (its class attributes) instead of testing the model again.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import ClassVar, Literal, get_args

import numpy as np

from rns_viz.control import JointSample, LawKind, TaskSample
from rns_viz.live.published.snapshot import OrientationView
from rns_viz.live.reach.region import ReachRegion
from rns_viz.model import FsmsModel
from rns_viz.param_file import LawName
from rns_viz.paths import PathTable
from rns_viz.profiles import QuinticSegment
from rns_viz.scenarios import FIG11_FAST_S


@dataclass(frozen=True)
class OperatorChange:
    """What one :meth:`Operator.advance` changed that the loop must act on."""

    joint_move_changed: bool = False  # a point-to-point move started or ended: other laws apply
    target_jumped: bool = False  # the target moved other than by a drag: the handle follows it


UNCHANGED = OperatorChange()


def orientation_note(model: FsmsModel) -> str:
    """How many rotational DOF the RNS leaves beyond the hand's position (shown on the panel)."""
    free = model.n - len(model.selected) - len(model.task_rows)
    if len(model.task_rows) < 3:
        return "orientation: not offered (a planar task)"
    dim = model.n - len(model.selected)
    if free <= 0:
        return f"orientation: not offered (n − r = {dim} ≤ 3: the hand's position takes every RNS direction)"
    least = "" if free >= 3 else ", tracked by least squares"
    return f"orientation: {min(free, 3)} of 3 rotational DOF free (n − r = {dim}){least}"


class InputRefused(ValueError):
    """An operator input that cannot be applied now; the message says why (shown to that client)."""


class PathNotReady(InputRefused):
    """The current reactionless path is still being computed: the input can wait for it."""


class Operator(ABC):
    """The live references of one model; owned and advanced by the simulation loop.

    The class attributes describe the kind for the rest of the app (panels, laws, overlays, readouts).
    """

    kind: ClassVar[str]  # in words: "reactionless path", "reachable set", "task arm"
    follows: ClassVar[Literal["path", "target"]]  # the operator moves along a path (scrub, play) or drags a target
    shows: ClassVar[Literal["path", "reachable set", "workspace"]]  # the geometry computed around the arm
    compensates: ClassVar[bool] = False  # compensating arms cancel the task arm's reaction (Sec. III-B)
    laws: ClassVar[tuple[LawKind, ...]] = get_args(LawName)  # the laws the operator's model may run
    law_words: ClassVar[str] = "laws (15), (16) and (30)"  # the same, in the paper's words

    def __init__(self, model: FsmsModel, theta0: np.ndarray, ubar_speed: float, target_speed: float) -> None:
        self.model = model
        theta0 = np.array(theta0, dtype=float)
        self.joint = JointSample.held(theta0)  # theta_ref with its rates, for the laws
        self.ee_z = float(model.ee_position(theta0)[2])
        self.target: np.ndarray | None = None  # where the arm is going, base frame (m)
        self.target_raw: np.ndarray | None = None  # where the operator put the target
        self.table: PathTable | None = None  # the current reactionless path (a path operator's; else None)
        self.joint_move: QuinticSegment | None = None  # a point-to-point comparison in progress
        self.task: TaskSample | None = None  # x_d with its rates (a target), for the laws
        self.mode = "holding"
        self.dragging = False

    @classmethod
    def check_law(cls, model: str, law: str) -> None:
        """Refuse a law the model does not run (trep2 runs the compensating law only)."""
        if law not in cls.laws:
            raise ValueError(f"{model} runs {cls.law_words}; law {law!r} is not offered")

    # -- state ---------------------------------------------------------------------------------
    @property
    @abstractmethod
    def theta_ref(self) -> np.ndarray: ...

    @property
    @abstractmethod
    def level(self) -> np.ndarray:
        """The coupling potential of theta_ref, kg m (which path or reachable set it is on)."""

    @property
    @abstractmethod
    def busy(self) -> bool:
        """The reference is moving (a re-anchor now would fight the operator)."""

    @property
    def sigma(self) -> float | None:
        """Path position shown on the scrub slider (centred for closed paths), or None."""
        return None

    @property
    def orienting(self) -> bool:
        """The reference also tracks the target's orientation (spatial models with n - r >= 4)."""
        return False

    def _point(self, xy: np.ndarray) -> np.ndarray:
        """A base-frame point (m): (x, y) of a planar task at the end effector's height, or (x, y, z)."""
        return np.array([xy[0], xy[1], xy[2] if len(xy) > 2 else self.ee_z], dtype=float)

    @abstractmethod
    def set_speeds(self, ubar_speed: float, target_speed: float) -> None: ...

    # -- new configuration or overlays ---------------------------------------------------------
    def re_anchor(self, theta: np.ndarray) -> None:
        """Hold at ``theta`` (the arm's configuration) from now on; forgets the path table. The mode says so: the
        hand's miss is measured from here on (its plot falls to about zero although the hand did not move)."""
        theta = np.array(theta, dtype=float)
        self.joint = JointSample.held(theta)
        self.joint_move = None
        self._hold_at(theta)
        self.mode = "holding where it came to rest (the reference moved there: the hand's miss restarts from 0)"

    @abstractmethod
    def _hold_at(self, theta: np.ndarray) -> None: ...

    def accept_table(self, table: PathTable, tol: float) -> bool:
        """Use ``table`` if it is the path theta_ref is on; sigma is re-expressed on it."""
        return False

    def take_reach(self, region: ReachRegion) -> None:
        """A reachable set computed around the arm arrived (a reachable-set operator clamps targets to it)."""
        return None  # a path or a task arm's workspace does not depend on it

    # -- operator inputs -----------------------------------------------------------------------
    def law_task(self, kind: str) -> TaskSample | None:
        """The task sample the laws follow (None: they follow theta_ref)."""
        return self.task

    def orientation_view(self) -> OrientationView | None:
        """The orientation target as the panel and the handle show it (spatial tracking only)."""
        return None

    def set_orientation(self, on: bool) -> str:
        """Track the target's orientation or not; what to tell the operator."""
        raise InputRefused(orientation_note(self.model))

    def drag(self, point: np.ndarray, final: bool = True, wxyz: tuple[float, ...] | None = None) -> bool:
        """Send the arm toward a target (x, y) or (x, y, z) in the base frame; True if the target had to be moved
        (onto the current reactionless path, or into the reachable set or workspace). ``wxyz``: the goal
        orientation (base frame), followed when the orientation is tracked.

        ``final`` is False while the operator still holds the handle (it is then never moved under them).
        """
        point = np.asarray(point, dtype=float)
        self.dragging = not final
        self.target_raw = self._point(point)
        return self._go_to(point, wxyz)

    @abstractmethod
    def _go_to(self, point: np.ndarray, wxyz: tuple[float, ...] | None) -> bool: ...

    def _held_mm(self) -> float:
        """How far (mm) the target in force is from where the operator put it."""
        k = len(self.model.task_rows)
        return 1e3 * float(np.linalg.norm(self.target[:k] - self.target_raw[:k]))  # type: ignore[index]

    def _target_words(self) -> str:
        return ", ".join(f"{v:.2f}" for v in self.target[: len(self.model.task_rows)])  # type: ignore[index]

    @abstractmethod
    def why_moved(self) -> str:
        """What to tell the operator when :meth:`drag` moved their target."""

    def _no_path(self) -> InputRefused:
        rns = self.model.n - len(self.model.selected)
        return InputRefused(f"No reactionless path to move along here ({self.kind}, a {rns}-D RNS): drag the target.")

    def scrub(self, sigma: float) -> None:
        """Move along the path to the slider's sigma (a path operator's input)."""
        raise self._no_path()

    def play(self, t: float, duration: float) -> None:
        """Quintic u-bar over ``duration`` s to the other end of the path (a path operator's input)."""
        raise self._no_path()

    def cyclic(self, t: float, on: bool, level: float) -> None:
        """Cyclic motion along a closed path (a path operator's input)."""
        raise self._no_path()

    def point_to_point(self, t: float, duration: float = FIG11_FAST_S) -> None:
        """The joint-space comparison between the path's end points (a path operator's input)."""
        raise self._no_path()

    # -- per step --------------------------------------------------------------------------------
    @abstractmethod
    def advance(self, t: float, dt: float) -> OperatorChange:
        """Set the references for time t (call once, before the simulation step at t)."""
