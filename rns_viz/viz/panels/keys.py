"""Keyboard commands: the run controls, the camera's *Frame robot* and target jogging, each on a key.

viser lists them in its command palette (the ⌘ icon) with their keys. The keys keep clear of viser's
camera keys (W A S D Q E and the arrows). A key does exactly what its button does: the same session
command, refused for a watcher with the same message (:meth:`Controls.press`). Jogging moves the
target one step per press (JOG_STEPS_PER_REACH steps across the arm's reach, rounded to 1-2-5 mm)
in the base frame: Shift+J/L along x, Shift+I/K along y, Shift+U/O along z (spatial models).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import viser

from rns_viz.live.loop.session import Session
from rns_viz.viz.panels.control_panel import GuiElements
from rns_viz.viz.panels.glossary import KEYS, key_name
from rns_viz.viz.panels.inputs import Controls

JOG_STEPS_PER_REACH = 40  # a jog step is about 1/40 of the arm's reach

JOG_AXES = {"J": (0, -1.0), "L": (0, 1.0), "I": (1, 1.0), "K": (1, -1.0), "U": (2, -1.0), "O": (2, 1.0)}


def jog_step(reach: float) -> float:
    """m per jog press: reach / JOG_STEPS_PER_REACH rounded down to 1, 2 or 5 times a power of ten."""
    raw = reach / JOG_STEPS_PER_REACH
    decade = 10.0 ** math.floor(math.log10(raw))
    return max(m * decade for m in (1.0, 2.0, 5.0) if m * decade <= raw)


@dataclass
class KeyCommands:
    """The registered commands by label (tests trigger them through the protocol)."""

    commands: dict[str, viser.CommandHandle]


def add_key_commands(
    gui_api: viser.GuiApi,
    gui: GuiElements,
    controls: Controls,
    session: Session,
    frame: Callable[[viser.ClientHandle], None],
    jog_setup: Callable[[], tuple[np.ndarray, float, bool]],
) -> KeyCommands:
    """Register every key on ``gui_api`` (the server's, or one visitor's). ``frame(client)`` points that
    client's camera at the robot; ``jog_setup()`` gives the target now (base frame, m), the step (m) and
    whether the target is spatial."""
    commands: dict[str, viser.CommandHandle] = {}
    for label, key, modifier, what in KEYS:
        commands[label] = gui_api.add_command(
            label,
            description=f"{what} [{key_name(key, modifier)}]",
            hotkey=key,
            modifier=modifier,  # type: ignore[arg-type]
        )

    def on(label: str, run: Callable[[viser.ClientHandle | None], None]) -> None:
        commands[label].on_trigger(lambda event: run(event.client))

    on("Pause / resume", lambda client: controls.press(gui.pause, client))
    on("Kick the base", lambda client: controls.press(gui.kick, client))
    on("Reset", lambda client: controls.press(gui.reset, client))
    on(
        "Vibration suppression on/off",
        lambda client: controls.act(
            gui.suppression, client, lambda _, c: session.set_suppression(not session.snapshot().settings.suppress, c)
        ),
    )
    on("Frame robot", lambda client: None if client is None else frame(client))

    def jog(axis: int, sign: float, client: viser.ClientHandle | None) -> None:
        def act(_: object, cid: int | None) -> None:
            target, step, spatial = jog_setup()
            if axis == 2 and not spatial:
                raise ValueError("this model's target moves in the plane: jog with Shift+I/J/K/L")
            moved = np.array(target[: 3 if spatial else 2], dtype=float)
            moved[axis] += sign * step
            session.set_target(moved, True, cid)

        controls.act(gui.kick, client, act)  # (the handle named only for a refusal's revert: a button, no value)

    for label, key, modifier, _ in KEYS:
        if modifier == "shift":
            axis, sign = JOG_AXES[key]
            on(label, lambda client, axis=axis, sign=sign: jog(axis, sign, client))
    return KeyCommands(commands)
