"""The live session: one loop owns the simulation; every other thread only sends commands.

A :class:`Session` holds the operated run and a *shadow* run that receives the same operator inputs
and kicks with vibration suppression the other way, so suppression on and off are compared live.
It paces the 1 kHz simulation to the wall clock at a chosen speed (1/8x to 2x), measures the
real-time factor, keeps plot buffers, and hands slow work (reactionless paths, reachable sets,
preset builds) to a background worker whose results it swaps in between steps.

Threads: GUI callbacks call the public methods, which check the input (raising ``ValueError``
subclasses such as :class:`~rns_viz.control.InvalidGain` at once, nothing changed) and queue a
command; the loop applies queued commands between two steps. Readers take :meth:`snapshot`,
:meth:`plot_arrays`, :meth:`overlays` and :meth:`pop_notices`. Nothing here imports viser.

``Session(realtime=False)`` has no loop thread: the caller drives it with :meth:`advance`
(tests run faster than real time that way).
"""

from __future__ import annotations

import math
import threading
import time
import traceback
from collections import deque
from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np

from rns_viz.control import Gains, InvalidGain, JointServo
from rns_viz.live import jobs
from rns_viz.live.commands import CommandHandlers
from rns_viz.live.guard import GUARD_EVERY, Bounds
from rns_viz.live.kicks import KickSchedule, kick_pulse
from rns_viz.live.laws import (
    DEFAULT_LAW,
    LAW_KINDS,
    LawKind,
    build_law,
    checked_gains,
    default_gains,
    gains_of,
    kind_of,
    set_suppression,
    suppression_of,
)
from rns_viz.live.operator import FIG11_FAST_S, FIG11_SLOW_S, Operator
from rns_viz.live.pacing import MAX_BACKLOG_S, SPEEDS, Pacer
from rns_viz.live.path_table import PathTable
from rns_viz.live.plots import PlotBuffers
from rns_viz.live.reach import ReachRegion
from rns_viz.live.readouts import arm_reach, compute_readouts
from rns_viz.live.records import Command, Level, Notice, Overlays, Readouts, Settings, Snapshot
from rns_viz.live.worker import Result, Worker
from rns_viz.model import FsmsModel
from rns_viz.params import MODEL_NAMES
from rns_viz.paths import CouplingField
from rns_viz.scenarios import SCENARIOS
from rns_viz.sim import Simulator

DT = 1e-3  # s, control and simulation period
LOG_CAPACITY = 20000  # steps kept for the CSV download (20 s)
PLOT_EVERY = 20  # steps between plot samples (50 Hz: a 10 s window is 500 samples)
READOUT_EVERY = 50  # steps between readout updates (20 Hz)
SETTLE_EVERY = 100  # steps between checks whether the arm settled on another path
PUBLISH_EVERY = 4  # steps between snapshots (250 Hz; the GUI renders at 60 Hz)
BURST_S = 0.003  # wall s: when ahead, the loop sleeps until this much simulation is due (commands wake it)
DEFAULT_KICK = {"trep": 0.8, "planar3r": 5.0}  # N
FAMILY_SIZE = 24
REACTION_TAU = 0.01  # s, low-pass of the reaction force shown by the arrow
MAX_TARGET_M = 1e3  # m: a farther target is refused outright (clamping it would overflow nothing, but means nothing)


class Session(CommandHandlers):
    def __init__(self, model: str = "trep", realtime: bool = True, shadow: bool = True, speed: float = 1.0) -> None:
        if model not in MODEL_NAMES:
            raise ValueError(f"unknown model {model!r}; choose one of {', '.join(MODEL_NAMES)}")
        if speed not in SPEEDS:
            raise ValueError(f"speed must be one of {SPEEDS}")
        self.dt = DT
        self.realtime = realtime
        self._commands: deque[Command] = deque()
        self._notices: deque[Notice] = deque(maxlen=100)
        self._wake = threading.Event()
        self._lock = threading.Lock()  # held while stepping: log copies are consistent
        self._latencies: deque[float] = deque(maxlen=2000)
        self._awaiting: deque[float] = deque(maxlen=1000)
        self.worker = Worker()
        self._families: dict[str, list[np.ndarray]] = {}
        self._default_tables: dict[str, PathTable] = {}
        self._gain_memory: dict[tuple[str, LawKind], Gains] = {}
        self.plots = PlotBuffers(500)
        self.pacer = Pacer(speed)
        self.epoch = 0
        self.settings_version = 0
        self.target_version = 0
        self.overlay_version = 0
        self.steps = 0
        self.paused = False
        self.diverged: str | None = None
        self.settings = self._default_settings(model, shadow, speed)
        self._reach_points: np.ndarray | None = None
        self._current_path: np.ndarray | None = None
        self._init_live(model)
        self._publish()
        self._thread: threading.Thread | None = None
        self._stop = False
        if realtime:
            self._thread = threading.Thread(target=self._run, name="rns-sim", daemon=True)
            self._thread.start()

    # ================================================================ public API (any thread)
    def snapshot(self) -> Snapshot:
        return self._snapshot

    def overlays(self) -> Overlays:
        return self._overlays

    def plot_arrays(self) -> dict[str, np.ndarray]:
        return self.plots.arrays()

    def pop_notices(self) -> list[Notice]:
        out = []
        while self._notices:
            out.append(self._notices.popleft())
        return out

    def pending_commands(self) -> list[str]:
        """Kinds of the commands queued and not yet applied (tests wait on GUI callbacks with it)."""
        return [c.kind for c in list(self._commands)]

    def latencies(self) -> list[float]:
        """Seconds from an input's arrival to the start of the first step that used it."""
        return list(self._latencies)

    def log_csv(self, last_seconds: float | None = None) -> bytes:
        """The operated run's step log as CSV (StepLog's columns), the newest ``last_seconds``."""
        with self._lock:
            log = self.sim.log
            columns = list(log.columns)
            rows = log.array(None if last_seconds is None else round(last_seconds / self.dt))
        lines = [",".join(columns)]
        fmt = ",".join(["%.10g"] * len(columns))
        lines.extend(fmt % tuple(row) for row in rows)
        return ("\n".join(lines) + "\n").encode()

    def stop(self) -> None:
        self._stop = True
        self._wake.set()
        if self._thread is not None:
            self._thread.join(timeout=5.0)
        self.worker.stop()

    # -- commands: checked here, applied by the loop --------------------------------------------
    def pause(self, client: int | None = None) -> None:
        self._send("pause", (), client)

    def resume(self, client: int | None = None) -> None:
        self._send("resume", (), client)

    def single_step(self, count: int = 1, client: int | None = None) -> None:
        self._send("step", (max(1, int(count)),), client)

    def reset(self, client: int | None = None) -> None:
        self._send("reset", (), client)

    def set_speed(self, speed: float, client: int | None = None) -> None:
        if speed not in SPEEDS:
            raise ValueError(f"speed must be one of {', '.join(f'{s:g}' for s in SPEEDS)}")
        self._send("speed", (speed,), client)

    def kick(self, peak: float, client: int | None = None) -> None:
        kick_pulse(0.0, peak, 0.1, 1)  # checks the value
        self._send("kick", (float(peak),), client)

    def set_suppression(self, on: bool, client: int | None = None) -> None:
        self._send("suppress", (bool(on),), client)

    def set_law(self, kind: str, client: int | None = None) -> None:
        if kind not in LAW_KINDS:
            raise ValueError(f"law must be one of {', '.join(LAW_KINDS)}, got {kind!r}")
        self._send("law", (kind,), client)

    def set_gains(self, client: int | None = None, **changes: float) -> None:
        """Change gains by name (g_b, g_m, G_p, G_d, k_p, k_d, ...); InvalidGain leaves all as they were."""
        checked_gains(self.settings.gains, changes)
        self._send("gains", (dict(changes),), client)

    def set_ubar_speed(self, value: float, client: int | None = None) -> None:
        if not (math.isfinite(value) and 0 < value <= 1e4):
            raise InvalidGain(f"u-bar speed must be a positive number (1/(kg m s)), got {value}")
        self._send("ubar_speed", (float(value),), client)

    def set_target_speed(self, value: float, client: int | None = None) -> None:
        if not (math.isfinite(value) and 0 < value <= 100):
            raise InvalidGain(f"target speed must be a positive number of m/s, got {value}")
        self._send("target_speed", (float(value),), client)

    def set_shadow(self, on: bool, client: int | None = None) -> None:
        self._send("shadow", (bool(on),), client)

    def set_target(self, xy: tuple[float, float] | np.ndarray, final: bool = False, client: int | None = None) -> None:
        """Drag the end-effector target to (x, y) in the base frame, m; ``final`` at the end of a drag."""
        xy = np.asarray(xy, dtype=float)[:2]
        if xy.shape != (2,) or not np.all(np.isfinite(xy)) or float(np.max(np.abs(xy))) > MAX_TARGET_M:
            raise ValueError(f"target must be two finite coordinates within {MAX_TARGET_M:g} m, got {xy}")
        self._send("target", (xy, bool(final)), client)

    def scrub(self, sigma: float, client: int | None = None) -> None:
        """Move the reference along the current reactionless path to sigma (1/(kg m))."""
        if not math.isfinite(sigma):
            raise ValueError(f"path position must be finite, got {sigma}")
        self._send("scrub", (float(sigma),), client)

    def play(self, duration: float, client: int | None = None) -> None:
        """Quintic u-bar to the other end of the path over ``duration`` s (Fig. 11)."""
        if not (math.isfinite(duration) and duration > 0):
            raise ValueError("duration must be positive")
        self._send("play", (float(duration),), client)

    def play_slow(self, client: int | None = None) -> None:
        self.play(FIG11_SLOW_S, client)

    def play_fast(self, client: int | None = None) -> None:
        self.play(FIG11_FAST_S, client)

    def cyclic(self, on: bool, client: int | None = None) -> None:
        self._send("cyclic", (bool(on),), client)

    def point_to_point(self, client: int | None = None) -> None:
        self._send("p2p", (), client)

    def switch_model(self, name: str, client: int | None = None) -> None:
        if name not in MODEL_NAMES:
            raise ValueError(f"unknown model {name!r}; choose one of {', '.join(MODEL_NAMES)}")
        self._send("model", (name,), client)

    def load_preset(self, name: str, client: int | None = None) -> None:
        if name not in SCENARIOS:
            raise ValueError(f"unknown preset {name!r}; choose one of {', '.join(SCENARIOS)}")
        self._send("preset", (name,), client)

    # -- manual driving (realtime=False) --------------------------------------------------------
    def advance(self, seconds: float) -> None:
        """Apply queued commands and run ``seconds`` of simulation now, as fast as possible."""
        if self._thread is not None:
            raise RuntimeError("advance() is for sessions made with realtime=False")
        self._apply_commands()
        self._collect()
        for _ in range(round(seconds / self.dt)):
            if self.paused or self.diverged:
                break
            if self._commands:
                self._apply_commands()
            if self.worker.has_results():
                self._collect()
            self._tick()
        self._apply_commands()
        self._publish()

    def step_now(self, steps: int) -> None:
        self.advance(steps * self.dt)

    def wait_background(self, timeout: float = 30.0) -> bool:
        """Wait until the worker has finished its jobs and the loop has taken the results."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if self.worker.wait_idle(max(0.0, deadline - time.monotonic())):
                if self._thread is None:
                    self._collect()
                    self._publish()
                    if self.worker.idle():
                        return True
                elif not self.worker.has_results():
                    time.sleep(0.01)
                    if self.worker.idle() and not self.worker.has_results():
                        return True
            time.sleep(0.005)
        return False

    # ================================================================ loop thread
    def _send(self, kind: str, args: tuple[Any, ...], client: int | None) -> None:
        self._commands.append(Command(kind, args, client, time.perf_counter()))
        self._wake.set()

    def _notify(self, title: str, body: str, client: int | None = None, level: Level = "info") -> None:
        self._notices.append(Notice(title, body, client, level))

    def _run(self) -> None:
        pacer, dt = self.pacer, self.dt
        samples = 0
        while not self._stop:
            try:
                commanded = bool(self._commands)
                if commanded:
                    self._apply_commands()
                if self.worker.has_results():
                    self._collect()
                if self.paused or self.diverged:
                    self._awaiting.clear()
                    self._publish()
                    self._wake.wait(0.05)
                    self._wake.clear()
                    continue
                now = time.perf_counter()
                backlog = pacer.backlog(self.sim.t + dt, now)
                if backlog < 0.0:  # ahead: sleep until a few steps are due (fewer wake-ups), or a command;
                    # after a command only until the next step is due, so the input takes effect at once
                    self._wake.wait(-backlog if commanded else BURST_S - backlog)
                    self._wake.clear()
                    continue
                if backlog > MAX_BACKLOG_S:
                    pacer.drop_backlog(self.sim.t)
                self._tick()
                samples += 1
                if samples % 20 == 0:
                    pacer.sample(self.sim.t, now)
            except Exception as exc:  # the loop must survive anything
                traceback.print_exc()
                self._fail(f"internal error: {type(exc).__name__}: {exc}")

    def _fail(self, why: str) -> None:
        self.paused = True
        self.diverged = why
        self._notify("Simulation stopped", f"{why}. Press Reset to start again.", None, "error")
        self._publish()

    def _tick(self) -> None:
        sim, t, dt = self.sim, self.sim.t, self.dt
        if self._awaiting:
            now = time.perf_counter()
            self._latencies.extend(now - r for r in self._awaiting)
            self._awaiting.clear()
        op = self.operator
        if op is not None:
            op.advance(t, dt)
            if op.joint_move_changed:
                op.joint_move_changed = False
                self._install_live_laws()
            if op.target_jumped:
                op.target_jumped = False
                self.target_version += 1
        with self._lock:
            try:
                out = sim.step()
            except Exception as exc:  # SimulationDiverged or a law's error: keep the last finite state
                self._fail(f"the simulation diverged at t = {t:.3f} s ({exc})")
                return
            if self.settings.shadow:
                try:
                    self.shadow.step()
                except Exception as exc:
                    self._resync_shadow(f"the shadow run diverged ({exc}); restarted from the operated state")
        self.steps += 1
        if self.steps % GUARD_EVERY == 0 and self._out_of_bounds():
            return
        L = float(out.coupling_momentum[0])
        force = -(L - self._last_L) / dt if self.steps > 1 else 0.0
        self._last_L = L
        self._reaction += (force - self._reaction) * min(1.0, dt / REACTION_TAU)
        self._last_out = out
        k = self.steps
        if k % PLOT_EVERY == 0:
            self._sample_plots(out)
        if k % READOUT_EVERY == 0:
            self._update_readouts()
        if k % SETTLE_EVERY == 0:
            self._check_settled()
        if k % PUBLISH_EVERY == 0:
            self._publish()

    def _out_of_bounds(self) -> bool:
        """Pause with a message if the operated run left physical bounds; restart a stray shadow run."""
        sim = self.sim
        why = self._bounds.violation(sim.q, sim.v)
        if why is not None:
            self._fail(f"the simulation left physical bounds at t = {sim.t:.3f} s: {why}")
            return True
        if self.settings.shadow:
            why = self._bounds.violation(self.shadow.q, self.shadow.v)
            if why is not None:
                self._resync_shadow(f"the shadow run left physical bounds ({why}); restarted from the operated state")
        return False

    # -- set-up ----------------------------------------------------------------------------------
    def _default_settings(self, model: str, shadow: bool, speed: float) -> Settings:
        law = DEFAULT_LAW.get(model, "acceleration")
        return Settings(model, law, default_gains(model, law), True, 30.0, 0.5, shadow, speed, None)

    def _init_live(self, name: str) -> None:
        """A fresh live run of model ``name`` at its default configuration, at rest, t = 0."""
        changed = getattr(self, "aux", None) is None or self.aux.name != name
        if changed:
            self.aux = FsmsModel.from_name(name)  # the loop's own model for references and readouts
            self.field = CouplingField(self.aux)
        aux = self.aux
        theta0 = aux.spec.default_configuration
        st = self.settings
        self.operator: Operator | None = Operator(aux, theta0, st.ubar_speed, st.target_speed)
        self.kicks, self.kicks_shadow = KickSchedule(), KickSchedule()
        m1, m2 = FsmsModel.from_name(name), FsmsModel.from_name(name)
        placeholder = build_law(m1, st.law, st.gains, st.suppress, self.operator.ref)
        self.sim = Simulator(m1, placeholder, DT, self.kicks, q0=m1.q(theta0), log_capacity=LOG_CAPACITY)
        self.shadow = Simulator(m2, placeholder, DT, self.kicks_shadow, q0=m2.q(theta0), log_capacity=10, log_ee=False)
        self._install_live_laws()
        self.settings = replace(st, preset=None)
        self._restart_bookkeeping()
        self._arm_reach = arm_reach(aux)
        self._tol = 1e-4 * aux.arm_mass * self._arm_reach
        if self.operator.on_path:
            table = self._default_tables.get(name)
            if table is not None:
                self.operator.accept_table(table, self._tol)
                self._current_path = table.ee
            else:
                self._request_table(theta0, default=True)
            if name not in self._families:
                self.worker.submit("family", (self.epoch, name), self._family_job(name))
        else:
            self._request_reach(theta0)
        self._overlays_changed()

    def _install_live_laws(self) -> None:
        """The operator's laws; during a point-to-point comparison (15)/(16) give way to a joint servo,
        since their null-space input cannot, by design, make a motion that excites the base."""
        op = self.operator
        assert op is not None
        st = self.settings
        if op.joint_move is not None and st.law != "velocity":
            self.sim.law = JointServo(self.sim.model, st.gains, op.ref)
            self.shadow.law = JointServo(self.shadow.model, st.gains, op.ref)
            return
        task = op.task if not op.on_path else None
        self.sim.law = build_law(self.sim.model, st.law, st.gains, st.suppress, op.ref, task)
        self.shadow.law = build_law(self.shadow.model, st.law, st.gains, not st.suppress, op.ref, task)

    def _restart_bookkeeping(self) -> None:
        self.epoch += 1
        self.settings_version += 1
        self.target_version += 1
        self.paused = False
        self.diverged = None
        self._bounds = Bounds(self.aux)
        self._last_L = 0.0
        self._reaction = 0.0
        self._last_out = None
        self._readouts = Readouts()
        self.plots.clear()
        self.pacer.reanchor(self.sim.t)
        self._reach_points = None
        self._current_path = None
        self._shown_level: np.ndarray | None = None
        self._ee_error = math.nan
        self._update_readouts()

    def _go_live(self) -> None:
        """Leave a preset: live laws from the current state, holding the current configuration."""
        theta = self.sim.q[self.sim.model.m :].copy()
        aux = self.aux
        st = self.settings
        self.operator = Operator(aux, theta, st.ubar_speed, st.target_speed)
        self.kicks.preset = None
        self.kicks_shadow.preset = None
        self._install_live_laws()
        self.settings = replace(st, preset=None)
        self.settings_version += 1
        self.target_version += 1
        if self.operator.on_path:
            self._request_table(theta)
        else:
            self._request_reach(theta)

    def _adopt_preset(self, name: str, sims: tuple[Simulator, Simulator]) -> None:
        sim, shadow = sims
        model = SCENARIOS[name].model
        if self.aux.name != model:
            self.aux = FsmsModel.from_name(model)
            self.field = CouplingField(self.aux)
        self.kicks, self.kicks_shadow = KickSchedule(sim.force), KickSchedule(shadow.force)
        sim.force, shadow.force = self.kicks, self.kicks_shadow
        sim.resize_log(LOG_CAPACITY)
        shadow.resize_log(10)
        shadow.log_ee = False
        suppress = suppression_of(sim.law)
        set_suppression(shadow.law, not suppress)
        self.sim, self.shadow, self.operator = sim, shadow, None
        kind = kind_of(sim.law)
        self.settings = replace(
            self._default_settings(model, self.settings.shadow, self.settings.speed),
            law=kind,
            gains=gains_of(sim.law),
            suppress=suppress,
            preset=name,
        )
        self._restart_bookkeeping()
        self._arm_reach = arm_reach(self.aux)
        self._tol = 1e-4 * self.aux.arm_mass * self._arm_reach
        theta = sim.q[sim.model.m :]
        if self.aux.n - len(self.aux.selected) == 1:
            self._request_table(theta)
            if model not in self._families:
                self.worker.submit("family", (self.epoch, model), self._family_job(model))
        else:
            self._request_reach(theta)
        self._overlays_changed()

    def _resync_shadow(self, why: str | None) -> None:
        sim, shadow = self.sim, self.shadow
        shadow.reset(q0=sim.q.copy(), v0=sim.v.copy(), t0=sim.t)
        self.kicks_shadow.pulses = list(self.kicks.pulses)
        if why:
            self._notify("Shadow run restarted", why, None, "warning")

    # -- background work -------------------------------------------------------------------------
    def _family_job(self, name: str) -> Callable[[], list[np.ndarray]]:
        return lambda: jobs.call("family_curves", name, FAMILY_SIZE)

    def _request_table(self, theta: np.ndarray, default: bool = False) -> None:
        name, seed = self.aux.name, np.array(theta, dtype=float)
        self._shown_level = self.field.potentials(seed[None])[0]
        self.worker.submit("table", (self.epoch, default), lambda: jobs.call("path_table", name, seed))

    def _request_reach(self, theta: np.ndarray) -> None:
        name, seed = self.aux.name, np.array(theta, dtype=float)
        self._shown_level = self.field.potentials(seed[None])[0]
        self.worker.submit("reach", self.epoch, lambda: jobs.call("reach_region", name, seed))

    def _collect(self) -> None:
        for res in self.worker.collect():
            try:
                self._take(res)
            except Exception as exc:
                traceback.print_exc()
                self._notify("Background computation failed", f"{type(exc).__name__}: {exc}", None, "warning")

    def _take(self, res: Result) -> None:
        if res.error is not None:
            self._notify("Background computation failed", f"{res.kind}: {res.error}", None, "warning")
            return
        if res.kind == "preset":
            epoch, name = res.tag
            if epoch == self.epoch:
                self._adopt_preset(name, res.value)
            return
        if res.kind == "family":
            self._families[res.tag[1]] = res.value
            self._overlays_changed()
            return
        tag_epoch = res.tag[0] if isinstance(res.tag, tuple) else res.tag
        if tag_epoch != self.epoch:
            return
        op = self.operator
        if res.kind == "table":
            table: PathTable = res.value
            if res.tag[1]:
                self._default_tables[self.aux.name] = table
            if op is not None and not op.accept_table(table, self._tol):
                self._request_table(op.theta_ref)  # theta_ref moved to another path meanwhile
                return
            self._current_path = table.ee
            self._overlays_changed()
        elif res.kind == "reach":
            region: ReachRegion = res.value
            if op is not None and not op.on_path:
                op.reach = region
            self._reach_points = region.points
            self._overlays_changed()

    def _overlays_changed(self) -> None:
        self.overlay_version += 1
        self._overlays = Overlays(
            self._families.get(self.aux.name), self._current_path, self._reach_points, self.overlay_version
        )

    def _check_settled(self) -> None:
        """Once the arm rests on another level of the coupling potential (e.g. after law (15) absorbed a
        kick), re-anchor the reference there and recompute the current path / reachable set."""
        sim, op = self.sim, self.operator
        m = sim.model.m
        if float(np.max(np.abs(sim.v))) > 1e-3 or float(np.max(np.abs(sim.q[:m]))) > 1e-5 * self._arm_reach:
            return
        if op is not None and (op.busy or self.settings.law == "velocity"):
            return  # (30) pulls the arm back to theta_ref in every direction: nothing to re-anchor
        theta = sim.q[m:].copy()
        level = self.field.potentials(theta[None])[0]
        reference_level = op.level if op is not None else self._shown_level
        if reference_level is None or float(np.max(np.abs(level - reference_level))) <= self._tol:
            return
        if op is not None:
            op.re_anchor(theta)
            self.target_version += 1
        if self.aux.n - len(self.aux.selected) == 1:
            self._request_table(theta)
        else:
            self._request_reach(theta)

    # -- outputs ---------------------------------------------------------------------------------
    def _reference_point(self, out: Any) -> np.ndarray | None:
        if out is None:
            return None
        if out.ee_ref is not None:
            return np.asarray(out.ee_ref)[:2]
        if out.theta_ref is not None:
            return self.aux.ee_position(out.theta_ref)[:2]
        return None

    def _sample_plots(self, out: Any) -> None:
        sim, m = self.sim, self.sim.model.m
        x = self.aux.ee_position(sim.q[m:])[:2]
        ref = self._reference_point(out)
        error = float(np.linalg.norm(ref - x)) if ref is not None else math.nan
        shadow_on = self.settings.shadow
        self.plots.append(
            (
                sim.t,
                sim.q[0] * 1e3,
                self.shadow.q[0] * 1e3 if shadow_on else math.nan,
                float(out.coupling_momentum[0]),
                float(self.shadow.last.coupling_momentum[0]) if shadow_on and self.shadow.last else math.nan,
                error * 1e3,
            )
        )
        self._ee_error = error

    def _update_readouts(self) -> None:
        out = self._last_out
        self._readouts = compute_readouts(
            self.aux,
            self.sim.q,
            float(out.coupling_momentum[0]) if out is not None else 0.0,
            self._ee_error,
            self._reaction,
        )

    def _publish(self) -> None:
        sim, op = self.sim, self.operator
        table = op.table if op is not None and op.on_path else None
        if op is not None:
            mode, target = op.mode, op.target
        else:
            mode, target = f"preset {self.settings.preset}", None
        self._readouts = replace(self._readouts, reaction=self._reaction)
        self._snapshot = Snapshot(
            epoch=self.epoch,
            settings=self.settings,
            settings_version=self.settings_version,
            steps=self.steps,
            t=sim.t,
            q=sim.q.copy(),
            q_shadow=self.shadow.q.copy() if self.settings.shadow else None,
            paused=self.paused,
            diverged=self.diverged,
            rtf=0.0 if self.paused else self.pacer.rtf() if self.realtime else math.nan,
            behind=self.realtime and not self.paused and self.pacer.behind(),
            mode="paused" if self.paused and not self.diverged else mode,
            target=None if target is None else target.copy(),
            target_version=self.target_version,
            sigma=op.sigma if op is not None else None,
            sigma_range=None
            if table is None
            else ((-0.5 * table.period, 0.5 * table.period) if table.closed else (table.lo, table.hi)),
            readouts=self._readouts,
            overlay_version=self.overlay_version,
        )
