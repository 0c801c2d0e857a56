"""The state of a live session, owned by its simulation loop: one object, touched by one thread. The loop
calls :meth:`LiveState.apply` per command (a ``match``; replay's in live/loop/replay_mode.py), :meth:`tick` per step,
:meth:`collect` for background results; :meth:`publish` makes the snapshot readers take. No viser here."""

from __future__ import annotations

import math
from collections import deque
from dataclasses import replace

import numpy as np

from rns_viz.control import Gains, LawKind
from rns_viz.defaults import defaults_for
from rns_viz.live.explorer.gain_explorer import GainExplorer
from rns_viz.live.jobs.background import Background, FamilyReady, JobFailed, PresetReady, ReachReady, TableReady
from rns_viz.live.loop import commands as c
from rns_viz.live.loop.loop_model import LoopModel, key_of, selection_key
from rns_viz.live.loop.publish import make_snapshot
from rns_viz.live.loop.replay_mode import apply_replay
from rns_viz.live.loop.settle import settled_elsewhere
from rns_viz.live.loop.shown_geometry import Geometry
from rns_viz.live.loop.wall_clock import Pacer
from rns_viz.live.operator.operator import InputRefused, Operator, PathNotReady
from rns_viz.live.outputs.step_outputs import Outputs
from rns_viz.live.published.snapshot import Level, Notice, ReplayView, Settings, Snapshot
from rns_viz.live.runs.divergence_guard import GUARD_EVERY
from rns_viz.live.runs.kicks import kick_pulse
from rns_viz.live.runs.run_pair import LawChoice, RunPair, ShadowDiverged
from rns_viz.live.teaching.lesson_run import OBSERVE_EVERY, LessonRun, run_view
from rns_viz.model import FsmsModel
from rns_viz.params import model_source
from rns_viz.paths import PathTable
from rns_viz.scenarios import LIVE_SCENARIOS

SETTLE_EVERY = 100  # steps between checks whether the arm settled on another path


class LiveState:
    def __init__(self, model: str, shadow: bool, pacer: Pacer) -> None:
        self.pacer = pacer
        self.notices: deque[Notice] = deque(maxlen=100)
        self.background = Background()
        self.geometry = Geometry(self.background)
        self.explorer = GainExplorer()
        self.outputs = Outputs(warn=lambda title, body: self.notify(title, body, None, "warning"))
        self._gain_memory: dict[tuple[str, LawKind], Gains] = {}
        self.epoch = self.settings_version = self.target_version = 0
        self.paused = False
        self.diverged: str | None = None
        self.replay: ReplayView | None = None  # a replay shown while the simulation waits (live/loop/replay_mode.py)
        self.aux: FsmsModel | None = None
        self._use_model(model)  # a bad model file raises here
        self.settings = Settings.defaults(self.model, shadow, pacer.speed)
        self.lesson: LessonRun | None = None
        self.kicks_sent = self.targets_moved = 0  # kicks, dragged targets moved onto the path / into the set
        self._preset_paused = False  # the preset being built starts paused
        self.start_live(model)

    # ================================================================ set-up
    def _use_model(self, name: str) -> None:
        """Make model ``name`` (a model key) the loop's model; a bad model file raises before any change."""
        if self.aux is None or self.aux.name != name:
            loaded = LoopModel.load(name)
            self.aux, self.field, self.bounds = loaded.model, loaded.field, loaded.bounds
            self.operator_kind, self.reach_m, self.tol = loaded.kind, loaded.reach_m, loaded.tol

    @property
    def model(self) -> FsmsModel:
        assert self.aux is not None
        return self.aux

    def _choice(self) -> LawChoice:
        return LawChoice(self.settings.law, self.settings.gains, self.settings.suppress)

    def start_live(self, name: str, theta: np.ndarray | None = None) -> None:
        """A fresh live run of model ``name`` (a model key) at rest at ``theta`` (default: the model's
        default configuration), t = 0. A bad model file raises before anything changes."""
        self._use_model(name)
        theta0 = self.model.spec.default_configuration if theta is None else np.array(theta, dtype=float)
        self.runs = RunPair.at_rest(self.model, theta0)
        self._new_operator(theta0)
        self.settings = replace(self.settings, preset=None)
        self._restart_bookkeeping()
        self._explore(theta0)  # before any geometry is taken: the explorer is on this model from here on
        table = self.geometry.default_tables.get(name) if theta is None else None
        if table is not None and self.operator is not None and self.operator.accept_table(table, self.tol):
            self._took_table(table, default=True)
        else:
            self._request_geometry(theta0, default=True)
        self._overlays_changed()

    def _new_operator(self, theta: np.ndarray) -> None:
        st = self.settings
        self.operator: Operator | None = self.operator_kind(self.model, theta, st.ubar_speed, st.target_speed)
        self._install_live_laws()

    def _install_live_laws(self) -> None:
        op = self.operator
        assert op is not None
        self.runs.install(self._choice(), op.joint, op.law_task(self.settings.law), op.joint_move is not None)

    def _restart_bookkeeping(self) -> None:
        """A new epoch (reset, model switch, preset, selection); a lesson goes on only on its own model."""
        self.epoch += 1
        if self.lesson is not None and model_source(self.model.name) != self.lesson.home:
            self.lesson = None
        self.settings_version += 1
        self.target_version += 1
        self.paused, self.diverged = False, None
        self.pacer.reanchor(self.runs.t)
        self.geometry.restart()
        self._waiting_for_path: c.Command | None = None
        self.outputs.restart(self.model, self.runs.sim.q)

    def _go_live(self) -> Operator:
        """The operator; after a preset, live laws holding the current configuration first."""
        if self.operator is None:
            self.hold_here()
        assert self.operator is not None
        return self.operator

    def hold_here(self) -> None:
        """Live laws from the current state, holding the current configuration (leaves a preset)."""
        theta = self.runs.theta.copy()
        self.runs.leave_preset_forces()
        self._new_operator(theta)
        self.settings = replace(self.settings, preset=None)
        self.settings_version += 1
        self.target_version += 1
        self._request_geometry(theta)

    def _adopt_preset(self, name: str, runs: RunPair) -> None:
        self._use_model(key_of(runs.model))  # the preset's model with its own S (boom7-track: forces only)
        self.runs, self.operator = runs, None
        choice = runs.adopt_preset_laws()
        st = self.settings
        defaults = Settings.defaults(self.model, st.shadow, st.speed)
        self.settings = defaults.with_preset(name, choice.kind, choice.gains, choice.suppress)
        self._restart_bookkeeping()
        self.paused = self._preset_paused
        self._request_geometry(runs.theta)
        self._overlays_changed()

    def _request_geometry(self, theta: np.ndarray, default: bool = False) -> None:
        """The path or reachable set through ``theta``, and the gain analysis about it."""
        self.geometry.request(self.operator_kind, self.model, self.field, self.epoch, theta, default)
        self._explore(theta)

    def _explore(self, theta: np.ndarray) -> None:
        self.explorer.context(self.epoch, self.model.name, self.settings.law, theta, self.settings.gains)

    def _took_table(self, table: PathTable, default: bool) -> None:
        self.geometry.took_table(self.model.name, table, default)
        self.explorer.along(self.model.name, table.theta, table.ee)

    def notify(self, title: str, body: str, client: int | None = None, level: Level = "info") -> None:
        self.notices.append(Notice(title, body, client, level))

    def fail(self, why: str) -> None:
        self.paused, self.diverged = True, why
        self.notify("Simulation stopped", f"{why}. Press Reset to start again.", None, "error")

    # ================================================================ commands
    def apply(self, cmd: c.Command) -> None:
        """Apply one command; InputRefused/ValueError leave everything as it was and tell the sender. A path
        motion asked for while the path is being computed waits for it (the latest wins) and runs then."""
        try:
            if not apply_replay(self, cmd):  # replay commands; any other input ends a replay first
                self._apply(cmd)
        except PathNotReady:
            self._waiting_for_path = cmd
            self.notify("Waiting for the path", "It starts as soon as the reactionless path is computed.", cmd.client)
        except ValueError as exc:  # InputRefused included
            self.notify("Input not applied", str(exc), cmd.client, "warning")
            self.settings_version += 1  # the GUI shows the values actually in force

    def _apply(self, cmd: c.Command) -> None:
        st = self.settings
        match cmd:
            case c.Pause():
                self.paused = True
            case c.Resume():
                if self.diverged:
                    raise InputRefused(f"the simulation stopped ({self.diverged}); press Reset to start again")
                self.paused = False
                self.pacer.reanchor(self.runs.t)
            case c.SingleStep(count=count):
                self.paused = True
                for _ in range(count):
                    if self.diverged:
                        break
                    self.tick()
            case c.Reset():
                if st.preset is not None:
                    self._apply(c.LoadPreset(st.preset, client=cmd.client))
                else:
                    self.start_live(st.model)
            case c.SetSpeed(speed=speed):
                self.pacer.set_speed(speed, self.runs.t)
                self.settings = replace(st, speed=speed)
            case c.Kick(peak=peak, direction=direction):
                duration = defaults_for(self.model).kick_duration_s
                self.runs.kick(kick_pulse(self.runs.t, peak, duration, self.runs.model.m, direction))
                self.kicks_sent += 1
                self.explorer.kicked(self.runs.t, duration, direction, st.suppress)
            case c.SetSuppression(on=on):
                self.runs.set_suppression(on)
                if on != st.suppress:  # the runs swap roles: both, and the plots, restart from here
                    self.runs.resync_shadow()
                    self.outputs.plots.clear()
                    self.explorer.forget_measurement()
                self.settings = replace(st, suppress=on)
            case c.SetLaw(law=law):
                self.operator_kind.check_law(self.model.name, law)
                self._gain_memory[(st.model, st.law)] = st.gains
                gains = self._gain_memory.get((st.model, law), defaults_for(self.model).gains_for(law))
                self.settings = replace(st, law=law, gains=gains)
                if self.operator is None:
                    self._go_live()
                else:
                    self._install_live_laws()
                    self._explore(self.operator.theta_ref)
                self.settings_version += 1
            case c.SetGains():
                gains = cmd.applied_to(st.gains)
                self.runs.retune(gains)
                self.explorer.retune(gains)
                self.settings = replace(st, gains=gains)
            case c.SetUbarSpeed(value=value) | c.SetTargetSpeed(value=value):
                field = "ubar_speed" if isinstance(cmd, c.SetUbarSpeed) else "target_speed"
                self.settings = replace(st, **{field: value})
                if self.operator is not None:
                    self.operator.set_speeds(self.settings.ubar_speed, self.settings.target_speed)
            case c.SetShadow(on=on):
                if on and not st.shadow:
                    self.runs.resync_shadow()
                self.settings = replace(st, shadow=on)
            case c.DragTarget(xy=xy, final=final, wxyz=wxyz):
                self._drag(np.array(xy), final, cmd.client, wxyz)
            case c.TrackOrientation(on=on):
                self.notify("Orientation", self._go_live().set_orientation(on), cmd.client, "info")
                self._install_live_laws()  # (15)/(16) follow theta_ref while the orientation is tracked
            case c.Scrub(sigma=sigma):
                self._go_live().scrub(sigma)
                self.target_version += 1
            case c.Play(duration=duration):
                self._go_live().play(self.runs.t, duration)
                self.target_version += 1
            case c.Cyclic(on=on):
                self._go_live().cyclic(self.runs.t, on, st.ubar_speed)
            case c.PointToPoint():
                self._go_live().point_to_point(self.runs.t)
                self.target_version += 1
            case c.SwitchModel(model=name):
                self._use_model(name)  # a bad file stops here, the running model untouched
                self.settings = Settings.defaults(self.model, st.shadow, st.speed)
                self.start_live(name)
            case c.SetSelection(flags=flags):  # the same system with another S, at rest where the arm is
                key, note = selection_key(self.model, flags, self.runs.theta)
                self.settings = replace(st, model=key, preset=None)
                self.start_live(key, self.runs.theta.copy())
                self.notify("Selection S", note, cmd.client, "warning" if not all(flags) else "info")
            case c.StartLesson(model=model, number=number):
                lesson = LessonRun(model, number)
                start = lesson.lesson.start
                loads = (c.SwitchModel(start.model), c.SetLaw(start.law), c.SetSuppression(start.suppress))
                for step in (*loads, c.SetShadow(True)):
                    self._apply(step)
                self.lesson = lesson
            case c.StopLesson():
                self.lesson = None
            case c.LoadPreset(name=name, paused=paused):
                self._preset_paused = paused
                self.background.preset(self.epoch, name)
                self.notify("Loading preset", f"{name}: {LIVE_SCENARIOS[name].description}", cmd.client, "info")
            case _:
                raise TypeError(f"unknown command {cmd!r}")

    def _drag(self, xy: np.ndarray, final: bool, client: int | None, wxyz: tuple[float, ...] | None) -> None:
        moved = (op := self._go_live()).drag(xy, final, wxyz)
        if final:
            self.targets_moved += int(moved)
            self.target_version += 1
            if moved:
                self.notify("Target moved", op.why_moved(), client, "warning")

    # ================================================================ steps
    def tick(self) -> bool:
        """One simulation step; False if the simulation stopped (diverged or left physical bounds)."""
        runs, op, t = self.runs, self.operator, self.runs.t
        if op is not None:
            change = op.advance(t, runs.sim.dt)
            if change.joint_move_changed:
                self._install_live_laws()
            if change.target_jumped:
                self.target_version += 1
        shadow_on = self.settings.shadow
        try:
            out = runs.step(op.joint if op else None, op.task if op else None, shadow_on)
        except ShadowDiverged as exc:
            out = runs.sim.last
            runs.resync_shadow()
            self.notify("Shadow run restarted", str(exc), None, "warning")
        except Exception as exc:  # SimulationDiverged or a law's error: the last finite state is kept
            self.fail(f"the simulation diverged at t = {t:.3f} s ({exc})")
            return False
        assert out is not None
        self.outputs.after_step(self.model, runs, out, shadow_on, self.settings.suppress)
        k = self.outputs.steps
        if k % GUARD_EVERY == 0 and self._out_of_bounds():
            return False
        if k % SETTLE_EVERY == 0:
            self._check_settled()
            if self.explorer.fit_due(runs.t):
                self.explorer.measure(runs.sim)
        if self.lesson is not None and k % OBSERVE_EVERY == 0:
            counts, sigma = (self.kicks_sent, self.targets_moved), self.outputs.readouts.sigma_hbm
            view = run_view(self.model, self.epoch, runs, op, self.settings.shadow, counts, sigma)
            self.lesson.observe(self.model, view)
        return True

    def _out_of_bounds(self) -> bool:
        """Stop with a message if the operated run left physical bounds; restart a stray shadow run."""
        why, why_shadow = self.runs.violations(self.bounds, self.settings.shadow)
        if why is not None:
            self.fail(f"the simulation left physical bounds at t = {self.runs.t:.3f} s: {why}")
            return True
        if why_shadow is not None:
            self.runs.resync_shadow()
            msg = f"the shadow run left physical bounds ({why_shadow}); restarted from the operated state"
            self.notify("Shadow run restarted", msg, None, "warning")
        return False

    def _check_settled(self) -> None:
        """Once the arm rests on another level of the coupling potential (e.g. after law (15) absorbed a
        kick), re-anchor the reference there and recompute the current path / reachable set."""
        st, op = self.settings, self.operator
        theta = settled_elsewhere(
            self.runs.sim, op, st.law, self.field, self.reach_m, self.tol, self.geometry.shown_level
        )
        if theta is None:
            return
        if op is not None:
            op.re_anchor(theta)
            self.target_version += 1
        self._request_geometry(theta)

    # ================================================================ background results
    def has_results(self) -> bool:
        return self.background.has_results() or self.explorer.has_results()

    def idle(self) -> bool:
        return self.background.idle() and self.explorer.worker.idle()

    def wait_idle(self, timeout: float) -> bool:
        return self.background.wait_idle(timeout) and self.explorer.worker.wait_idle(timeout)

    def stop(self) -> None:
        self.background.stop()
        self.explorer.stop()

    def collect(self) -> None:
        for ready in self.background.results(lambda: self.epoch):
            match ready:
                case JobFailed(kind=kind, error=error):
                    self.notify("Background computation failed", f"{kind}: {error}", None, "warning")
                case PresetReady(name=name, sims=sims):
                    self._adopt_preset(name, RunPair(*sims))
                case FamilyReady():
                    self._overlays_changed()
                case TableReady(table=table, default=default):
                    op = self.operator
                    if op is not None and not op.accept_table(table, self.tol):
                        self._request_geometry(op.theta_ref)  # theta_ref moved to another path meanwhile
                        continue
                    self._took_table(table, default)
                    self._overlays_changed()
                    waiting, self._waiting_for_path = self._waiting_for_path, None
                    if waiting is not None:
                        self.apply(waiting)
                case ReachReady(region=region):
                    if self.operator is not None:
                        self.operator.take_reach(region)
                    self.geometry.took_reach(region)
                    self.explorer.along(self.model.name, region.thetas, region.points)
                    self._overlays_changed()
        self.explorer.collect()

    # ================================================================ outputs
    def _overlays_changed(self) -> None:
        self.overlays = self.geometry.overlays(self.model.name, self.epoch)

    def publish(self, realtime: bool) -> Snapshot:
        versions = (self.epoch, self.settings_version, self.target_version, self.geometry.version)
        lesson = self.lesson.status() if self.lesson is not None else None
        rtf = 0.0 if self.paused else self.pacer.rtf() if realtime else math.nan
        flags = (self.paused, self.diverged, rtf, *self.pacer.lateness(realtime and not self.paused))
        out = (self.runs, self.operator, self.outputs)
        return make_snapshot(self.settings, versions, *out, flags, lesson, self.replay)
