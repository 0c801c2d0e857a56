"""The live session: one loop owns the simulation; every other thread only sends commands.

A :class:`Session` runs the operated run and a *shadow* run that receives the same operator inputs
and kicks with vibration suppression the other way (:mod:`rns_viz.live.runs.run_pair`), paced to the wall
clock at a chosen speed (1/8x to 2x), with slow geometry in the background
(:mod:`rns_viz.live.jobs.background`).

The path of an input: a GUI callback calls a public method here, which builds the typed command
(:mod:`rns_viz.live.loop.commands`; its constructor is the one check, raising ``ValueError`` at once,
nothing queued) and queues it; the loop thread applies it between two steps
(:meth:`rns_viz.live.loop.state.LiveState.apply`). Readers take :meth:`snapshot`, :meth:`plot_arrays`,
:meth:`overlays` and :meth:`pop_notices`. Nothing here imports viser.

``Session(realtime=False)`` has no loop thread: the caller drives it with :meth:`advance`
(tests run faster than real time that way).
"""

from __future__ import annotations

import threading
import time
import traceback
from collections import deque
from types import MappingProxyType
from typing import Any

import numpy as np

from rns_viz.csvio import csv_text
from rns_viz.live.explorer.gain_explorer import GainView
from rns_viz.live.loop import commands as c
from rns_viz.live.loop.state import LiveState
from rns_viz.live.loop.wall_clock import MAX_BACKLOG_S, SPEEDS, Pacer
from rns_viz.live.published.plot_buffers import PlotBuffers
from rns_viz.live.published.recording import Recording
from rns_viz.live.published.snapshot import Notice, Overlays, Snapshot
from rns_viz.params import check_model_key
from rns_viz.scenarios import FIG11_FAST_S, FIG11_SLOW_S

PUBLISH_EVERY = 8  # steps between snapshots (125 Hz: two or more per 60 Hz frame)
BURST_S = 0.003  # wall s: when ahead, the loop sleeps until this much simulation is due (commands wake it)


class Session:
    def __init__(
        self, model: str = "trep", realtime: bool = True, shadow: bool = True, speed: float = 1.0, start: bool = True
    ) -> None:
        """``realtime``: a loop thread runs the simulation at wall-clock pace (else :meth:`advance` drives it);
        ``start=False``: that thread waits for :meth:`start` (an app starts it once its pages can be served)."""
        check_model_key(model)  # a bad model file raises ModelFileError (a ValueError) when the state loads it
        if speed not in SPEEDS:
            raise ValueError(f"speed must be one of {SPEEDS}")
        self.realtime = realtime
        self._commands: deque[c.Command] = deque()
        self._wake = threading.Event()
        self._lock = threading.Lock()  # held while stepping: log copies are consistent
        self._latencies: deque[float] = deque(maxlen=2000)
        self._awaiting: deque[float] = deque(maxlen=1000)
        self.pacer = Pacer(speed)
        self.state = LiveState(model, shadow, self.pacer)
        self.dt = self.state.runs.sim.dt
        self._publish()
        self._thread: threading.Thread | None = None
        self._stop = False
        if realtime and start:
            self.start()

    def start(self) -> None:
        """Run the real-time loop from now: the time spent before (building an app around the session) is not
        simulated time due, so the loop starts without a backlog to catch up or to skip."""
        if self.realtime and self._thread is None and not self._stop:
            self.pacer.reanchor(self.state.runs.t)
            self._thread = threading.Thread(target=self._run, name="rns-sim", daemon=True)
            self._thread.start()

    # ================================================================ readers (any thread)
    def snapshot(self) -> Snapshot:
        return self._snapshot

    def overlays(self) -> Overlays:
        return self._overlays

    def gain_view(self) -> GainView:
        """The gain explorer's map, root loci, authority along the path and measured decay (``version`` counts)."""
        return self.state.explorer.view

    @property
    def plots(self) -> PlotBuffers:
        """The live plots' buffers (read them with ``arrays()``; ``version`` bumps on each change)."""
        return self.state.outputs.plots

    def plot_arrays(self) -> dict[str, np.ndarray]:
        return self.plots.arrays()

    def pop_notices(self) -> list[Notice]:
        notices, out = self.state.notices, []
        while notices:
            out.append(notices.popleft())
        return out

    def pending_commands(self) -> list[str]:
        """Names of the commands queued and not yet applied (tests wait on GUI callbacks with it)."""
        return [type(cmd).__name__ for cmd in list(self._commands)]

    def latencies(self) -> list[float]:
        """Seconds from an input's arrival to the start of the first step that used it."""
        return list(self._latencies)

    def log_csv(self, last_seconds: float | None = None) -> bytes:
        """The operated run's step log as CSV (rns_viz.csvio: units in the header, 17 significant digits),
        the newest ``last_seconds``."""
        with self._lock:  # the rows copied under the lock, written out after it
            log = self.state.runs.sim.log
            rows = log.array(None if last_seconds is None else round(last_seconds / self.dt))
        return csv_text(log.columns, log.units, rows).encode()

    def recording(self, seconds: float) -> Recording | None:
        """The newest ``seconds`` (at most 60) of the run as an immutable recording (None: nothing yet).
        During a replay: the recording being replayed (what the viewer sees is what is exported)."""
        replay = self._snapshot.replay
        if replay is not None:
            return replay.recording
        with self._lock:
            return self.state.outputs.recorder.take(seconds, self.state.model)

    @property
    def stopped(self) -> bool:
        """True once :meth:`stop` was called (the loop ends)."""
        return self._stop

    def restart_clock(self) -> None:
        """Pace from now on, forgetting a backlog and the time skipped so far (a page's view of a new model
        was being built: the time that took is not simulated time anyone missed)."""
        self.send(c.RestartClock())

    def stop(self) -> None:
        self._stop = True
        self._wake.set()
        if self._thread is not None:
            self._thread.join(timeout=5.0)
        self.state.stop()

    # ================================================================ inputs (any thread)
    def send(self, command: c.Command) -> None:
        """Queue a typed command for the loop (it was checked when it was made)."""
        self._commands.append(command)
        self._wake.set()

    def pause(self, client: int | None = None) -> None:
        self.send(c.Pause(client=client))

    def resume(self, client: int | None = None) -> None:
        self.send(c.Resume(client=client))

    def single_step(self, count: int = 1, client: int | None = None) -> None:
        self.send(c.SingleStep(count, client=client))

    def reset(self, client: int | None = None) -> None:
        self.send(c.Reset(client=client))

    def set_speed(self, speed: float, client: int | None = None) -> None:
        self.send(c.SetSpeed(speed, client=client))

    def kick(self, peak: float, client: int | None = None, direction: tuple[float, ...] | None = None) -> None:
        """A half-sine push on the base (N), of the model's default duration, weighted over the base
        coordinates by ``direction`` (None: the first coordinate alone)."""
        self.send(c.Kick(peak, direction, client=client))

    def set_suppression(self, on: bool, client: int | None = None) -> None:
        self.send(c.SetSuppression(on, client=client))

    def set_law(self, kind: str, client: int | None = None) -> None:
        self.send(c.SetLaw(kind, client=client))  # type: ignore[arg-type]

    def set_gains(self, client: int | None = None, **changes: float) -> None:
        """Change gains by name (g_b, g_m, G_p, G_d, k_p, k_d, ...); InvalidGain leaves all as they were."""
        self.send(c.SetGains(MappingProxyType(changes), client=client))

    def set_ubar_speed(self, value: float, client: int | None = None) -> None:
        self.send(c.SetUbarSpeed(value, client=client))

    def set_target_speed(self, value: float, client: int | None = None) -> None:
        self.send(c.SetTargetSpeed(value, client=client))

    def set_shadow(self, on: bool, client: int | None = None) -> None:
        self.send(c.SetShadow(on, client=client))

    def set_target(
        self, xy: tuple[float, ...] | np.ndarray, final: bool = False, client: int | None = None, wxyz: Any = None
    ) -> None:
        """Drag the end-effector target to (x, y) (planar) or (x, y, z) in the base frame, m; ``final`` at the
        end of a drag; ``wxyz`` the goal orientation of a pose handle (base frame)."""
        self.send(c.DragTarget(xy, final, wxyz, client=client))  # type: ignore[arg-type]

    def track_orientation(self, on: bool, client: int | None = None) -> None:
        """Spatial models: the end effector also follows the target's orientation (n - r >= 4)."""
        self.send(c.TrackOrientation(on, client=client))

    def scrub(self, sigma: float, client: int | None = None) -> None:
        """Move the reference along the current reactionless path to sigma (1/(kg m))."""
        self.send(c.Scrub(sigma, client=client))

    def play(self, duration: float, client: int | None = None) -> None:
        """Quintic u-bar to the other end of the path over ``duration`` s (Fig. 11)."""
        self.send(c.Play(duration, client=client))

    def play_slow(self, client: int | None = None) -> None:
        self.play(FIG11_SLOW_S, client)

    def play_fast(self, client: int | None = None) -> None:
        self.play(FIG11_FAST_S, client)

    def cyclic(self, on: bool, client: int | None = None) -> None:
        self.send(c.Cyclic(on, client=client))

    def point_to_point(self, client: int | None = None) -> None:
        self.send(c.PointToPoint(client=client))

    def switch_model(self, name: str, client: int | None = None) -> None:
        """Another model: a bundled name or a parameter file (refused with the element at fault if bad)."""
        self.send(c.SwitchModel(name, client=client))

    def set_selection(self, flags: tuple[bool, ...], client: int | None = None) -> None:
        """Selection S (Sec. III-B): which base reactions must vanish; the runs restart at rest where the arm is."""
        self.send(c.SetSelection(tuple(flags), client=client))

    def load_preset(self, name: str, client: int | None = None, paused: bool = False) -> None:
        """Build preset ``name`` off the loop and adopt it at t = 0 (``paused``: waiting for Resume)."""
        self.send(c.LoadPreset(name, paused=paused, client=client))

    def start_lesson(self, model: str, number: int, client: int | None = None) -> None:
        """Lesson ``number`` (1-based) of ``model``: loads its state; the snapshot reports its progress."""
        self.send(c.StartLesson(model, number, client=client))

    def stop_lesson(self, client: int | None = None) -> None:
        self.send(c.StopLesson(client=client))

    def start_replay(self, seconds: float, client: int | None = None) -> None:
        """Replay the newest ``seconds`` (at most 60) of the run; the simulation waits until back to live."""
        self.send(c.StartReplay(seconds, client=client))

    def seek_replay(self, t: float, client: int | None = None) -> None:
        """Move the replay's playhead to simulation time ``t`` (s) of the recording."""
        self.send(c.SeekReplay(t, client=client))

    def set_replay_speed(self, speed: float, client: int | None = None) -> None:
        """Replay at ``speed`` recorded seconds per wall second (0.1 to 4)."""
        self.send(c.SetReplaySpeed(speed, client=client))

    def play_replay(self, on: bool, client: int | None = None) -> None:
        self.send(c.PlayReplay(on, client=client))

    def stop_replay(self, client: int | None = None) -> None:
        """Back to live: the simulation goes on where it was (paused if it was paused)."""
        self.send(c.StopReplay(client=client))

    # ================================================================ manual driving (realtime=False)
    def advance(self, seconds: float) -> None:
        """Apply queued commands and run ``seconds`` of simulation now, as fast as possible."""
        if self._thread is not None:
            raise RuntimeError("advance() is for sessions made with realtime=False")
        state = self.state
        self._apply_commands()
        state.collect()
        for _ in range(round(seconds / self.dt)):
            if state.paused or state.diverged:
                break
            if self._commands:
                self._apply_commands()
            if state.has_results():
                state.collect()
            self._tick()
        self._apply_commands()
        self._publish()

    def wait_background(self, timeout: float = 30.0) -> bool:
        """Wait until the background jobs have finished and the loop has taken the results."""
        state = self.state
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if state.wait_idle(max(0.0, deadline - time.monotonic())):
                if self._thread is None:
                    state.collect()
                    self._publish()
                    if state.idle() and not state.has_results():
                        return True
                elif not state.has_results():
                    time.sleep(0.01)
                    if state.idle() and not state.has_results():
                        return True
            time.sleep(0.005)
        return False

    # ================================================================ the loop thread
    def _apply_commands(self) -> None:
        state = self.state
        while self._commands:
            cmd = self._commands.popleft()
            if isinstance(cmd, c.RestartClock):  # the pacing's, not the simulation's
                self.pacer.restart(state.runs.t)
                continue
            try:
                with self._lock:
                    state.apply(cmd)
            except Exception as exc:  # a bug, not an input error: report it, keep running
                traceback.print_exc()
                state.notify("Input not applied", f"{type(exc).__name__}: {exc}", cmd.client, "error")
                state.settings_version += 1
            if isinstance(cmd, c.TIMED):
                self._awaiting.append(cmd.received)
        self._publish()

    def _tick(self) -> None:
        if self._awaiting:
            now = time.perf_counter()
            self._latencies.extend(now - r for r in self._awaiting)
            self._awaiting.clear()
        with self._lock:
            running = self.state.tick()
        if not running or self.state.outputs.steps % PUBLISH_EVERY == 0:
            self._publish()

    def _publish(self) -> None:
        self._overlays = self.state.overlays
        self._snapshot = self.state.publish(self.realtime)

    def _run(self) -> None:
        state, pacer, dt = self.state, self.pacer, self.dt
        samples = 0
        while not self._stop:
            try:
                commanded = bool(self._commands)
                if commanded:
                    self._apply_commands()
                if state.has_results():
                    state.collect()
                    self._publish()
                if state.paused or state.diverged:
                    self._awaiting.clear()
                    self._publish()
                    self._wake.wait(0.05)
                    self._wake.clear()
                    continue
                now = time.perf_counter()
                sim_t = state.runs.t
                backlog = pacer.backlog(sim_t + dt, now)
                if backlog < 0.0:  # ahead: sleep until a few steps are due (fewer wake-ups), or a command;
                    # after a command only until the next step is due, so the input takes effect at once
                    self._wake.wait(-backlog if commanded else BURST_S - backlog)
                    self._wake.clear()
                    continue
                if backlog > MAX_BACKLOG_S:
                    pacer.drop_backlog(sim_t)
                self._tick()
                samples += 1
                if samples % 20 == 0:
                    pacer.sample(state.runs.t, now)
            except Exception as exc:  # the loop must survive anything
                traceback.print_exc()
                state.fail(f"internal error: {type(exc).__name__}: {exc}")
                self._publish()
