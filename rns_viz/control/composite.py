"""What the composite laws (15) and (16) share: gains, a null-space input and the switch of the G_b term."""

from __future__ import annotations

from typing import ClassVar

from rns_viz.control.common import CouplingEvaluator, Gains, LawKind
from rns_viz.control.null_input import DampNullMotion, NullInput
from rns_viz.control.reference import ReferenceSample
from rns_viz.model import FsmsModel


class CompositeLaw:
    """Base of :class:`~rns_viz.control.AccelerationLaw` (15) and :class:`~rns_viz.control.TorqueLaw` (16).

    ``null_input`` defaults to u = -G_m theta' (Fig. 3); ``suppress=False`` drops the G_b term, and
    ``suppress_after`` (s) switches it on at that time (Fig. 3).
    """

    kind: ClassVar[LawKind]

    def __init__(
        self,
        model: FsmsModel,
        gains: Gains,
        null_input: NullInput | None = None,
        suppress: bool = True,
        suppress_after: float = float("-inf"),
    ) -> None:
        self.model = model
        self.gains = gains
        self.null_input = null_input or DampNullMotion(gains.g_m)
        self.suppress = suppress
        self.suppress_after = suppress_after
        self.coupling = CouplingEvaluator(model)

    def suppression_gain(self, t: float) -> float:
        """g_b in force at time t, 1/s (0 before ``suppress_after`` or without suppression)."""
        return self.gains.g_b if self.suppress and t >= self.suppress_after else 0.0

    def sampled(self, t: float) -> bool:
        """A digital controller while g_b is in force; without it a joint servo (see ControlLaw.sampled)."""
        return self.suppression_gain(t) != 0.0

    def retune(self, gains: Gains) -> None:
        """New gains for the law and its null-space input, from the next step on."""
        self.gains = gains
        self.null_input.retune(gains)

    def set_suppression(self, on: bool) -> None:
        """Switch the G_b term on or off."""
        self.suppress = on

    def follow(self, sample: ReferenceSample) -> None:
        """The reference the null-space input tracks from the next step on."""
        self.null_input.follow(sample)
