"""The operated run and its shadow: two simulations of one model that get the same inputs and kicks,
with vibration suppression the other way in the shadow, so suppression on and off are compared live
(a dual-arm model's shadow holds its compensating arm instead: compensation on and off).

:class:`RunPair` owns both simulators, their laws and their kick schedules. Only the simulation loop
calls it, between steps.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rns_viz.control import ControlOutput, Gains, JointSample, LawKind, TaskSample
from rns_viz.live.operator.dual_arm import flip_compensation, rehold
from rns_viz.live.runs.divergence_guard import Bounds
from rns_viz.live.runs.kicks import KickSchedule
from rns_viz.live.runs.laws import LiveLaw, build_law
from rns_viz.model import FsmsModel
from rns_viz.sim import ForcePulse, Simulator

DT = 1e-3  # s, control and simulation period
LOG_CAPACITY = 20000  # steps kept for the CSV download (20 s)
SHADOW_LOG_CAPACITY = 10  # the shadow's log is not shown


@dataclass(frozen=True)
class LawChoice:
    """Which law the pair runs and how; the shadow gets ``not suppress`` (dual arms: its compensator held)."""

    kind: LawKind
    gains: Gains
    suppress: bool


class ShadowDiverged(RuntimeError):
    """The shadow run failed; the pair restarts it from the operated state (the message says why)."""


class RunPair:
    def __init__(self, sim: Simulator, shadow: Simulator) -> None:
        self.sim, self.shadow = sim, shadow
        self.kicks, self.kicks_shadow = KickSchedule(sim.force), KickSchedule(shadow.force)
        sim.force, shadow.force = self.kicks, self.kicks_shadow
        sim.resize_log(LOG_CAPACITY)
        shadow.resize_log(SHADOW_LOG_CAPACITY)
        shadow.log_ee = False
        self._live: tuple[LiveLaw, LiveLaw] | None = None  # None: a preset's own laws run

    @classmethod
    def at_rest(cls, name: str | FsmsModel, theta0: np.ndarray) -> RunPair:
        """Two runs of model ``name`` (a model key, or a checked model to copy) at rest at ``theta0``, t = 0,
        with placeholder laws (see :meth:`install`)."""
        sims = []
        for log_capacity in (LOG_CAPACITY, SHADOW_LOG_CAPACITY):
            model = FsmsModel.from_key(name) if isinstance(name, str) else FsmsModel(name.spec)
            law = build_law(model, "acceleration", Gains(), False, JointSample.held(theta0)).law
            sims.append(Simulator(model, law, DT, q0=model.q(theta0), log_capacity=log_capacity))
        return cls(*sims)

    @property
    def model(self) -> FsmsModel:
        return self.sim.model

    @property
    def t(self) -> float:
        return self.sim.t

    @property
    def theta(self) -> np.ndarray:
        return self.sim.q[self.sim.model.m :]

    @property
    def live(self) -> bool:
        """True when the laws follow the operator (False while a preset's own laws run)."""
        return self._live is not None

    # -- laws --------------------------------------------------------------------------------------
    def install(
        self, choice: LawChoice, joint: JointSample, task: TaskSample | None = None, joint_move: bool = False
    ) -> None:
        """Live laws that follow the operator's samples (``task`` for Eq. (24); ``joint_move``: the servo)."""
        pair = tuple(
            build_law(run.model, choice.kind, choice.gains, suppress, joint, task, joint_move, run is self.shadow)
            for run, suppress in ((self.sim, choice.suppress), (self.shadow, not choice.suppress))
        )
        self.sim.law, self.shadow.law = pair[0].law, pair[1].law
        self._live = pair  # type: ignore[assignment]

    def adopt_preset_laws(self) -> LawChoice:
        """Keep a preset's laws; the shadow's suppression (dual arms: compensation) is flipped. Returns what
        the operated run uses."""
        law = self.sim.law
        self.shadow.law.set_suppression(not law.suppress)
        flip_compensation(law, self.shadow.law)
        self._live = None
        return LawChoice(law.kind if law.kind != "servo" else "acceleration", law.gains, law.suppress)

    def retune(self, gains: Gains) -> None:
        self.sim.law.retune(gains)
        self.shadow.law.retune(gains)

    def set_suppression(self, on: bool) -> None:
        self.sim.law.set_suppression(on)
        self.shadow.law.set_suppression(not on)

    # -- inputs and steps --------------------------------------------------------------------------
    def kick(self, pulse: ForcePulse) -> None:
        self.kicks.add(pulse)
        self.kicks_shadow.add(pulse)

    def leave_preset_forces(self) -> None:
        self.kicks.preset = None
        self.kicks_shadow.preset = None

    def step(self, joint: JointSample | None, task: TaskSample | None, shadow: bool) -> ControlOutput:
        """One step of the operated run (and the shadow if ``shadow``), the laws following the samples.

        Raises what the operated step raises (nothing changed then); a failing shadow step raises
        :class:`ShadowDiverged` after the operated step succeeded.
        """
        if self._live is not None and joint is not None:
            t = self.sim.t  # the samples are this step's: a law evaluated at its RK4 stages extrapolates them
            joint, task = joint.taken_at(t), None if task is None else task.taken_at(t)
            for live in self._live:
                live.follow(joint, task)
        out = self.sim.step()
        if shadow:
            try:
                self.shadow.step()
            except Exception as exc:
                raise ShadowDiverged(f"the shadow run diverged ({exc}); restarted from the operated state") from exc
        return out

    def violations(self, bounds: Bounds, shadow: bool) -> tuple[str | None, str | None]:
        """Why the operated run (and the shadow, if shown) left physical bounds; None where it did not."""
        why = bounds.violation(self.sim.q, self.sim.v)
        return why, bounds.violation(self.shadow.q, self.shadow.v) if shadow else None

    def resync_shadow(self) -> None:
        """Restart the shadow from the operated run's state, with the same pending kicks."""
        sim = self.sim
        self.shadow.reset(q0=sim.q.copy(), v0=sim.v.copy(), t0=sim.t)
        rehold(self.shadow.law)
        self.kicks_shadow.pulses = list(self.kicks.pulses)
