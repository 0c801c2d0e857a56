"""The gain explorer of the live session: which gains damp the base, how fast, and where on the path.

For the law and configuration in force, a background thread linearises the closed loop
(:mod:`rns_viz.analysis`, the simulator's own 1 ms step map, in a helper process) and derives the
g_b x g_m map of decay rates, the root loci through the current gains and the predicted decay along
the current reactionless path (TREP) or over the reactionless-reachable set (3R). After a kick the
loop measures the base deflection along the kick as the map predicts it (time to 10 % of its peak,
decay there), to set beside the prediction.

The loop calls :meth:`GainExplorer.context`, :meth:`retune`, :meth:`along`, :meth:`kicked` and
:meth:`measure`; :meth:`collect` takes finished results. Readers take :attr:`GainExplorer.view`.

The view says what it belongs to (the loop's epoch, the model, the law and the gains), and every part
of it is of those or absent (None while it is computed): a result of another model, law, configuration
or gains is dropped when it arrives, and a change of any of them clears the parts it makes untrue in the
same published view. A measurement names its model, gains, epoch and kick; it is forgotten when any of
them changes (a decay measured at other gains is no test of this prediction).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from rns_viz.analysis import (
    G_M_MEANING,
    PAPER_GAINS,
    Authority,
    GainMap,
    LinearLoop,
    Locus,
    Modes,
    joined,
    measure_kick,
    modes_of,
    root_locus,
)
from rns_viz.control import Gains, LawKind
from rns_viz.live.jobs import helper as jobs
from rns_viz.live.jobs.worker import Worker
from rns_viz.live.operator.kinds import operator_class_of
from rns_viz.sim import Simulator

AUTHORITY_POINTS = 80  # configurations along the path / over the set where the decay is predicted
AUTHORITY_CHUNK = 10  # configurations per helper call: other jobs (a new reachable set) go between calls
FIT_FIRST_S = 4.0  # s after a kick before the measured deflection is first read ...
FIT_EVERY_S = 1.0  # ... and then every this many seconds ...
FIT_UNTIL_S = 20.0  # ... until this long after it


@dataclass(frozen=True)
class Measured:
    """The measured base deflection along the last kick (rns_viz.analysis.measure_kick), and what it was
    measured on."""

    rate: float  # 1/s, ln 10 / settle_time (nan: not under 10 % yet)
    since: float  # s, the kick's time
    seconds: float  # s of log read
    settle_time: float  # s after the kick's end until |y| stays under 10 % of its peak (inf: not yet)
    model: str  # the model key
    law: LawKind
    gains: Gains  # in force from the kick to the end of the log read
    epoch: int  # the loop's epoch (a reset, model switch or preset starts another)


@dataclass(frozen=True)
class GainView:
    """What the explorer shows; a new object whenever something changed (``version`` counts)."""

    version: int
    epoch: int  # the loop's epoch the view belongs to
    model: str
    law: LawKind
    gains: Gains
    g_m_meaning: str  # what g_m means in this law, one line
    map: GainMap | None  # decay rates over the g_b x g_m grid (1/s), of this model and law
    current: Modes | None  # the poles at the gains in force
    locus_g_b: Locus | None  # poles as g_b sweeps at the current g_m
    locus_g_m: Locus | None  # poles as g_m sweeps at the current g_b
    paper: tuple[tuple[str, float, float], ...]  # (label, g_b, g_m) of the paper's gains for this law
    path_points: np.ndarray | None  # (K, 3) end-effector points (base frame, m) where authority is given
    authority: Authority | None  # predicted decay there at the current gains
    measured: Measured | None  # after a kick, at these gains, in this epoch
    analysed: bool = True  # False: no linearisation for this model (a compensating arm's law), nothing predicted

    @property
    def predicted(self) -> float:
        """The base decay rate predicted at the gains in force, 1/s (nan while it is computed)."""
        return float(self.current.base_decay_rate) if self.current is not None else math.nan


class GainExplorer:
    def __init__(self) -> None:
        self.worker = Worker()
        self._loop: LinearLoop | None = None
        self._thetas: np.ndarray | None = None  # the configurations of the authority shown (K, n), rad
        self._key: tuple[str, LawKind, bytes] | None = None
        self.kick_t = math.nan  # s, the last kick (nan: no measurement due)
        self._kick_end = math.nan  # s
        self._kick_output = np.ones(1)  # y = this . x_b: the deflection along the last kick
        self._next_fit = math.inf
        self.view = GainView(0, -1, "", "velocity", Gains(), "", None, None, None, None, (), None, None, None)

    # -- inputs from the loop --------------------------------------------------------------------
    def context(self, epoch: int, model: str, law: LawKind, theta: np.ndarray, gains: Gains) -> None:
        """The loop's epoch, model, law, rest configuration or gains (may have) changed: linearise anew if
        the model, law or configuration did, and forget a measurement of another epoch, model or law. One
        published view: no reader sees the new model beside the old one's map."""
        theta = np.round(np.asarray(theta, dtype=float), 6)
        key = (model, law, theta.tobytes())
        v = self.view
        changes: dict[str, object] = {
            "epoch": epoch,
            "model": model,
            "law": law,
            "g_m_meaning": G_M_MEANING.get(law, ""),
        }
        if (epoch, model, law) != (v.epoch, v.model, v.law):
            changes["measured"] = None
            self._forget_kick()
        if key == self._key:
            self._publish(**changes)
            self.retune(gains)
            return
        self._key, self._loop, self._thetas = key, None, None
        paper = tuple((p.label, p.g_b, p.g_m) for p in PAPER_GAINS.get((model, law), ()))
        if gains != v.gains:
            changes["measured"] = None
            self._forget_kick()
        # a compensating arm's model: its linearised loop would be law (15)'s on all joints, not the compensating law
        analysed = not operator_class_of(model).compensates
        self._publish(gains=gains, paper=paper, analysed=analysed, **changes, **_NOTHING_AT_KEY)
        if not analysed:
            return

        def job() -> tuple[LinearLoop, GainMap, tuple[Modes, Locus, Locus], Gains]:
            loop, grid = jobs.call("loop_and_map", model, law, theta)
            return loop, grid, _at(loop, gains), gains

        self.worker.submit("loop", key, job)

    def retune(self, gains: Gains) -> None:
        """New gains: what was predicted or measured at the old ones goes until it is computed anew."""
        if gains == self.view.gains:
            return
        self._forget_kick()
        self._publish(gains=gains, measured=None, current=None, locus_g_b=None, locus_g_m=None, authority=None)
        self._submit_at(gains)

    def _submit_at(self, gains: Gains) -> None:
        loop, thetas, key = self._loop, self._thetas, self._key
        if loop is not None:
            self.worker.submit("at", (key, gains), lambda: _at(loop, gains))
        if thetas is not None and key is not None:
            self.worker.submit("authority", (key, gains), lambda: self._authority(key, thetas, gains))

    def along(self, model: str, thetas: np.ndarray, ee: np.ndarray) -> None:
        """The configurations (K, n) and end-effector points (K, 3) of model ``model``'s current path or set
        (nothing if the explorer is on another model: the geometry of a model just left)."""
        if self._key is None or self._key[0] != model or len(thetas) == 0:
            return
        pick = np.unique(np.linspace(0, len(thetas) - 1, min(AUTHORITY_POINTS, len(thetas))).astype(int))
        thetas, points = np.asarray(thetas, dtype=float)[pick], np.asarray(ee, dtype=float)[pick]
        key = self._key
        gains = self.view.gains
        self._thetas = None
        self._publish(path_points=points, authority=None)

        def job() -> tuple[np.ndarray, Authority] | None:
            found = self._authority(key, thetas, gains)
            return None if found is None else (thetas, found)

        self.worker.submit("along", key, job)

    def _authority(self, key: tuple[str, LawKind, bytes], thetas: np.ndarray, gains: Gains) -> Authority | None:
        """The authority at ``gains`` over ``thetas``, computed in the helper a few configurations per call (each
        call yields to waiting jobs); None once stale (the model, law or configuration changed)."""
        model, law, _ = key
        parts: list[Authority] = []
        for start in range(0, len(thetas), AUTHORITY_CHUNK):
            if self._key != key:
                return None
            chunk = thetas[start : start + AUTHORITY_CHUNK]
            parts.append(jobs.call("authority_at", model, law, chunk, gains.g_b, gains.g_m))
        return joined(parts)

    def kicked(self, t: float, duration: float, direction: tuple[float, ...] | None, suppress: bool) -> None:
        """A kick started at t (s), lasting ``duration`` s along ``direction`` (None: the first base
        coordinate): read it from FIT_FIRST_S on, if the operated run suppresses (the prediction is of the
        suppressing law; without suppression there is nothing to compare)."""
        self._forget_kick()
        if suppress:
            self.kick_t, self._next_fit, self._kick_end = t, t + FIT_FIRST_S, t + duration
            w = np.asarray(direction if direction is not None and np.any(direction) else (1.0,), dtype=float)
            self._kick_output = w / float(w @ w)
        self._publish(measured=None)

    def forget_measurement(self) -> None:
        """Something the measurement depends on changed (suppression switched): no fit of this kick."""
        self._forget_kick()
        if self.view.measured is not None:
            self._publish(measured=None)

    def _forget_kick(self) -> None:
        self.kick_t, self._next_fit = math.nan, math.inf

    def fit_due(self, t: float) -> bool:
        return t >= self._next_fit

    def measure(self, sim: Simulator) -> None:
        """Read the deflection along the last kick from the operated run's log; call when :meth:`fit_due`."""
        t, log = sim.t, sim.log
        self._next_fit = t + FIT_EVERY_S if t < self.kick_t + FIT_UNTIL_S else math.inf
        rows = min(len(log), round((t - self.kick_t) / sim.dt) + 1)
        times = log.column("t", rows)
        y = sum(w * log.column(f"xb_{i + 1}", rows) for i, w in enumerate(self._kick_output) if w)
        if rows < 3 or not np.any(y):
            return
        got = measure_kick(times, y, self._kick_end)
        v = self.view
        seconds = float(times[-1] - self.kick_t)
        measured = Measured(got.decay_rate, self.kick_t, seconds, got.settle_time, v.model, v.law, v.gains, v.epoch)
        self._publish(measured=measured)

    # -- results -----------------------------------------------------------------------------------
    def collect(self) -> bool:
        """Take finished results of the current model, law, configuration and gains; True if the view changed."""
        changed = False
        gains = self.view.gains
        for res in self.worker.collect():
            if res.error is not None:
                continue  # an equilibrium that cannot be linearised: the view says nothing
            key = res.tag if res.kind in ("loop", "along") else res.tag[0]
            if key != self._key:
                continue
            changed = True
            if res.kind == "loop":
                self._loop, gain_map, at, at_gains = res.value
                if at_gains == gains:
                    self._publish(map=gain_map, **_at_fields(at))
                else:  # the gains changed while the loop was computed: its poles are the old gains'
                    self._publish(map=gain_map)
                    self._submit_at(gains)
            elif res.kind == "at" and res.tag[1] == gains:
                self._publish(**_at_fields(res.value))
            elif res.kind == "along" and res.value is not None:  # None: abandoned when it went stale
                self._thetas, found = res.value
                if (found.g_b, found.g_m) == (gains.g_b, gains.g_m):
                    self._publish(authority=found)
                else:
                    self._submit_at(gains)
            elif res.kind == "authority" and res.tag[1] == gains and res.value is not None:
                self._publish(authority=res.value)
        return changed

    def has_results(self) -> bool:
        return self.worker.has_results()

    def stop(self) -> None:
        self._key = None  # a sweep in flight goes stale: it stops at its next call into the helper
        self.worker.stop()

    def _publish(self, **changes: object) -> None:
        self.view = replace(self.view, version=self.view.version + 1, **changes)  # type: ignore[arg-type]


# What a new model, law or configuration leaves of the view until its loop is linearised again.
_NOTHING_AT_KEY = dict(map=None, current=None, locus_g_b=None, locus_g_m=None, path_points=None, authority=None)


def _at(loop: LinearLoop, gains: Gains) -> tuple[Modes, Locus, Locus]:
    """The poles at the gains in force and the two root loci through them."""
    return (
        modes_of(loop, gains.g_b, gains.g_m),
        root_locus(loop, "g_b", gains.g_m),
        root_locus(loop, "g_m", gains.g_b),
    )


def _at_fields(at: tuple[Modes, Locus, Locus]) -> dict[str, object]:
    return {"current": at[0], "locus_g_b": at[1], "locus_g_m": at[2]}
