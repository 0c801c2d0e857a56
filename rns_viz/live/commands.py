"""How the live session applies queued commands: one handler per command kind, run by the loop.

:class:`CommandHandlers` is a mixin of :class:`rns_viz.session.Session`; handlers run only on the
simulation loop's thread, between two steps. A handler that raises ``ValueError`` (including
:class:`~rns_viz.live.operator.InputRefused` and :class:`~rns_viz.control.InvalidGain`) leaves
everything as it was and the requesting client is told why.
"""

from __future__ import annotations

import traceback
from dataclasses import replace
from typing import TYPE_CHECKING

from rns_viz.live.kicks import kick_pulse
from rns_viz.live.laws import LawKind, checked_gains, default_gains, retune, set_suppression
from rns_viz.live.operator import InputRefused, Operator
from rns_viz.live.records import Command
from rns_viz.scenarios import SCENARIOS
from rns_viz.sim import Simulator

if TYPE_CHECKING:
    from rns_viz.session import Session

KICK_DURATION = {"trep": 0.1, "planar3r": 0.2}  # s, as the presets' kicks
TIMED_INPUTS = frozenset(
    {"kick", "suppress", "gains", "ubar_speed", "target_speed", "target", "scrub", "play", "cyclic", "p2p", "law"}
)  # operator inputs whose arrival-to-first-step latency is measured


class CommandHandlers:
    def _apply_commands(self: Session) -> None:
        while self._commands:
            cmd = self._commands.popleft()
            try:
                getattr(self, f"_cmd_{cmd.kind}")(cmd)
            except (InputRefused, ValueError) as exc:
                self._notify("Input not applied", str(exc), cmd.client, "warning")
                self.settings_version += 1  # the GUI shows the values actually in force
            except Exception as exc:
                traceback.print_exc()
                self._notify("Input not applied", f"{type(exc).__name__}: {exc}", cmd.client, "error")
                self.settings_version += 1
            if cmd.kind in TIMED_INPUTS:
                self._awaiting.append(cmd.received)
        self._publish()

    def _cmd_pause(self: Session, cmd: Command) -> None:
        self.paused = True

    def _cmd_resume(self: Session, cmd: Command) -> None:
        if self.diverged:
            raise InputRefused(f"the simulation stopped ({self.diverged}); press Reset to start again")
        self.paused = False
        self.diverged = None
        self.pacer.reanchor(self.sim.t)

    def _cmd_step(self: Session, cmd: Command) -> None:
        self.paused = True
        for _ in range(cmd.args[0]):
            if self.diverged:
                break
            self._tick()

    def _cmd_reset(self: Session, cmd: Command) -> None:
        if self.settings.preset is not None:
            self._cmd_preset(Command("preset", (self.settings.preset,), cmd.client, cmd.received))
        else:
            self._init_live(self.settings.model)

    def _cmd_speed(self: Session, cmd: Command) -> None:
        self.pacer.set_speed(cmd.args[0], self.sim.t)
        self.settings = replace(self.settings, speed=cmd.args[0])

    def _cmd_kick(self: Session, cmd: Command) -> None:
        model = self.settings.model
        duration = KICK_DURATION.get(model, 0.1)
        pulse = kick_pulse(self.sim.t, cmd.args[0], duration, self.sim.model.m)
        self.kicks.add(pulse)
        self.kicks_shadow.add(pulse)

    def _cmd_suppress(self: Session, cmd: Command) -> None:
        on = cmd.args[0]
        set_suppression(self.sim.law, on)
        set_suppression(self.shadow.law, not on)
        self.settings = replace(self.settings, suppress=on)

    def _cmd_law(self: Session, cmd: Command) -> None:
        kind: LawKind = cmd.args[0]
        model = self.settings.model
        self._gain_memory[(model, self.settings.law)] = self.settings.gains
        gains = self._gain_memory.get((model, kind), default_gains(model, kind))
        self.settings = replace(self.settings, law=kind, gains=gains)
        if self.operator is None:
            self._go_live()
        else:
            self._install_live_laws()
        self.settings_version += 1

    def _cmd_gains(self: Session, cmd: Command) -> None:
        gains = checked_gains(self.settings.gains, cmd.args[0])
        retune(self.sim.law, gains)
        retune(self.shadow.law, gains)
        self.settings = replace(self.settings, gains=gains)

    def _cmd_ubar_speed(self: Session, cmd: Command) -> None:
        self.settings = replace(self.settings, ubar_speed=cmd.args[0])
        if self.operator is not None:
            self.operator.set_speeds(self.settings.ubar_speed, self.settings.target_speed)

    def _cmd_target_speed(self: Session, cmd: Command) -> None:
        self.settings = replace(self.settings, target_speed=cmd.args[0])
        if self.operator is not None:
            self.operator.set_speeds(self.settings.ubar_speed, self.settings.target_speed)

    def _cmd_shadow(self: Session, cmd: Command) -> None:
        on = cmd.args[0]
        if on and not self.settings.shadow:
            self._resync_shadow(None)
        self.settings = replace(self.settings, shadow=on)

    def _live_operator(self: Session) -> Operator:
        if self.operator is None:
            self._go_live()
        assert self.operator is not None
        return self.operator

    def _cmd_target(self: Session, cmd: Command) -> None:
        xy, final = cmd.args
        op = self._live_operator()
        moved = op.drag(xy, final)
        if final:
            self.target_version += 1
            if moved:
                x, y = op.target[:2]  # type: ignore[index]
                self._notify(
                    "Target clamped",
                    f"That target is outside the set reachable without reaction from this configuration; "
                    f"the arm goes to the nearest reachable point ({x:.2f}, {y:.2f}) m instead.",
                    cmd.client,
                    "warning",
                )

    def _cmd_scrub(self: Session, cmd: Command) -> None:
        self._live_operator().scrub(cmd.args[0])
        self.target_version += 1

    def _cmd_play(self: Session, cmd: Command) -> None:
        self._live_operator().play(self.sim.t, cmd.args[0])
        self.target_version += 1

    def _cmd_cyclic(self: Session, cmd: Command) -> None:
        self._live_operator().cyclic(self.sim.t, cmd.args[0], self.settings.ubar_speed)

    def _cmd_p2p(self: Session, cmd: Command) -> None:
        self._live_operator().point_to_point(self.sim.t)
        self.target_version += 1

    def _cmd_model(self: Session, cmd: Command) -> None:
        name = cmd.args[0]
        self.settings = self._default_settings(name, self.settings.shadow, self.settings.speed)
        self._init_live(name)

    def _cmd_preset(self: Session, cmd: Command) -> None:
        name = cmd.args[0]
        self.worker.submit("preset", (self.epoch, name), lambda: _build_preset(name))
        self._notify("Loading preset", f"{name}: {SCENARIOS[name].description}", cmd.client, "info")


def _build_preset(name: str) -> tuple[Simulator, Simulator]:
    """The preset's operated run and a second copy for the shadow (suppression flipped on adoption)."""
    scenario = SCENARIOS[name]
    return scenario.build(), scenario.build()
