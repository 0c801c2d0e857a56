"""What the live session publishes from the runs: plot samples, readouts and the arm's reaction.

:class:`Outputs` is fed by the simulation loop after every step and read by any thread through the
plot buffers and the latest :class:`~rns_viz.live.published.snapshot.Readouts`. Units: the plots carry x_b in
mm, L in kg m/s and the end-effector error in mm; readouts are SI.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace

import numpy as np

from rns_viz.control import ControlOutput
from rns_viz.live.operator.dual_arm import compensation_state, operated_is_better
from rns_viz.live.outputs.readouts import compute_readouts
from rns_viz.live.outputs.recorder import Recorder
from rns_viz.live.published.plot_buffers import BASE_COORDINATES, PlotBuffers
from rns_viz.live.published.snapshot import Readouts
from rns_viz.live.runs.run_pair import RunPair
from rns_viz.model import FsmsModel
from rns_viz.sim.reaction import ReactionProbe

PLOT_EVERY = 20  # steps between plot samples (50 Hz: a 10 s window is 500 samples)
READOUT_EVERY = 50  # steps between readout updates (20 Hz)
HELD = "compensator held in this run (the shadow run's cancels)"
WARN_EVERY = 5000  # steps: at most one "not cancelled" notice per 5 s
REACTION_EVERY = 4  # steps between evaluations of the arm's reaction (250 Hz: every published snapshot)


def reference_point(model: FsmsModel, out: ControlOutput | None) -> np.ndarray | None:
    """Where the law sends the end effector (base frame, m, the model's task axes), or None without a reference."""
    if out is None:
        return None
    if out.ee_ref is not None:
        return np.asarray(out.ee_ref)[: len(model.task_rows)]
    if out.theta_ref is not None:
        return model.ee_position(out.theta_ref)[model.task_rows]
    return None


class Outputs:
    def __init__(self, plot_capacity: int = 500, warn: Callable[[str, str], None] | None = None) -> None:
        self.plots = PlotBuffers(plot_capacity)
        self.recorder = Recorder()  # the last minute of steps, for replay and export
        self.warn = warn  # warn(title, body): tells everyone when a compensating arm stops cancelling
        self.steps = 0  # steps booked since the session started (never reset: readers wait on it)
        self._probe: ReactionProbe | None = None
        self.restart(None)

    def restart(self, model: FsmsModel | None, q: np.ndarray | None = None) -> None:
        """Forget history (reset, model switch, preset load)."""
        self.plots.clear()
        self.recorder.restart()
        self.last: ControlOutput | None = None
        self.reaction = 0.0  # N: the arm's reaction on the base, -(H_bm theta'' + c_b) of Eq. (1), first selected row
        self.reaction_t = math.nan  # s: the step it was evaluated at (its start time)
        self.reaction_wrench: tuple[float, ...] = ()  # N, N m: all m base rows of the same reaction
        self._pre: tuple[float, np.ndarray] | None = None  # (t, x = (q, v)) the next evaluated step starts from
        self.ee_error = math.nan  # m
        self.readouts = Readouts()
        self._warned_step = -WARN_EVERY
        if model is not None and q is not None:
            self._update_readouts(model, q)

    def after_step(
        self, model: FsmsModel, runs: RunPair, out: ControlOutput, shadow_on: bool, suppress: bool = True
    ) -> None:
        """Book one step of the operated run (``model`` is the loop's own instance for kinematics;
        ``suppress``: the operated run has suppression on, so the shadow has it off)."""
        self.steps += 1
        self.last = out
        sim = runs.sim
        if self.steps % REACTION_EVERY == 0 and self._pre is not None and self._pre[0] + sim.dt == sim.t:
            self._evaluate_reaction(runs, out)
        if (self.steps + 1) % REACTION_EVERY == 0:  # the next step is evaluated: keep its start state
            self._pre = (sim.t, np.concatenate((sim.q, sim.v)))
        self.recorder.append(runs, shadow_on, self.reaction_wrench, suppress)
        if self.steps % PLOT_EVERY == 0:
            self._sample_plots(model, runs, out, shadow_on, suppress)
        if self.steps % READOUT_EVERY == 0:
            self._update_readouts(model, runs.sim.q, runs.sim.v, operated_is_better(runs.sim.law, True))

    def _evaluate_reaction(self, runs: RunPair, out: ControlOutput) -> None:
        """The reaction at the step just taken, from its start state, torque and base force."""
        assert self._pre is not None
        sim = runs.sim
        if self._probe is None or self._probe.model is not sim.model:
            self._probe = ReactionProbe(sim.model)
        t, x = self._pre
        nv = sim.model.nv
        f = self._probe.force(x[:nv], x[nv:], out.tau, sim.last_force)
        self.reaction, self.reaction_t = float(f[sim.model.selected[0]]), t
        self.reaction_wrench = tuple(float(x) for x in f)

    def _sample_plots(
        self, model: FsmsModel, runs: RunPair, out: ControlOutput, shadow_on: bool, suppress: bool
    ) -> None:
        sim, shadow = runs.sim, runs.shadow
        x = model.ee_position(sim.q[model.m :])[model.task_rows]
        ref = reference_point(model, out)
        self.ee_error = float(np.linalg.norm(ref - x)) if ref is not None else math.nan
        shadow_out = shadow.last if shadow_on else None
        coordinates = np.zeros(BASE_COORDINATES)
        coordinates[: model.m] = sim.q[: model.m] * 1e3
        self.plots.append(
            (
                sim.t,
                deflection(sim.q, model.m) * 1e3,
                deflection(shadow.q, model.m) * 1e3 if shadow_on else math.nan,
                L_of(out),
                L_of(shadow_out) if shadow_out is not None else math.nan,
                self.ee_error * 1e3,
                float(operated_is_better(sim.law, suppress)),
                *coordinates,
            )
        )

    def _update_readouts(
        self, model: FsmsModel, q: np.ndarray, v: np.ndarray | None = None, compensating: bool = True
    ) -> None:
        L = L_of(self.last) if self.last is not None else 0.0
        readouts = compute_readouts(model, q, L, self.ee_error, self.reaction, self.reaction_t)
        if readouts.dual and v is not None and not compensating:  # a preset holds it on purpose
            readouts = replace(readouts, cancel=HELD, compensating=False)
        elif readouts.dual and v is not None:
            cancel = compensation_state(model, self.last, v, readouts.warn_hbm)
            quiet = self.steps - self._warned_step < WARN_EVERY
            if cancel is not None and self.readouts.cancel is None and self.warn is not None and not quiet:
                self._warned_step = self.steps
                self.warn(
                    "Reaction not cancelled",
                    f"{cancel[0].upper()}{cancel[1:]}; the red arrow is the reaction on the base F_b both arms leave.",
                )
            readouts = replace(readouts, cancel=cancel, compensating=compensating)
        self.readouts = readouts


def deflection(q: np.ndarray, m: int) -> float:
    """The base deflection plotted, m: x_b of a 1-DOF base, else the length of its (first three) translations."""
    return float(q[0]) if m == 1 else float(np.sqrt(q[: min(m, 3)] @ q[: min(m, 3)]))


def L_of(out: ControlOutput) -> float:
    """The coupling momentum plotted (Eq. 8), kg m/s: the selected row of a one-row S, else the length of the
    first three selected rows (the linear momentum when the translations are selected)."""
    L = out.coupling_momentum
    return float(L[0]) if len(L) == 1 else float(np.sqrt(L[:3] @ L[:3]))
