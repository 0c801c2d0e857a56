"""Operator input: every GUI control and the target handle wired to one session command each.

A callback checks only what belongs to the widget (a slider value of the right type within its
bounds, a dropdown value among its options, a finite drag position; see
:mod:`rns_viz.viz.panels.input_check`) and calls the session's command method, which checks the meaning
(gains, speeds, targets) and raises ``ValueError`` if it refuses. A number typed into a
:class:`~rns_viz.viz.panels.number_field.NumberField` is only read here (text that is no number is refused);
its range is the command's to check (or the field's, for a value no command takes at once). Refused
input is reported to its client and the control is shown its last good value again at the next
render frame.
"""

from __future__ import annotations

import threading
import time
import traceback
from collections.abc import Callable, Iterator
from contextlib import contextmanager, suppress
from typing import Any

import numpy as np
import viser

from rns_viz.live.loop.session import Session
from rns_viz.live.runs.laws import LAW_LABELS
from rns_viz.out_of_range import OutOfRange, split_label
from rns_viz.viz.clients.connections import Connections
from rns_viz.viz.panels.control_panel import SPEED_LABELS, GuiElements
from rns_viz.viz.panels.input_check import check_value, parse_number
from rns_viz.viz.panels.live_plots import SCALES
from rns_viz.viz.panels.number_field import NumberField

REFUSAL_REPEAT_S = 2.0  # s: a watcher dragging the handle is told at most this often

_LAW_OF_LABEL = {v: k for k, v in LAW_LABELS.items()}
_SPEED_OF_LABEL = {v: k for k, v in SPEED_LABELS.items()}
_SCALE_OF_LABEL = {v: k for k, v in SCALES.items()}

Act = Callable[[Any, int | None], None]  # act(value, client_id)


class Controls:
    """The panel's callbacks, the last good value of each control and the reverts still to show."""

    def __init__(self, gui: GuiElements, session: Session, connections: Connections) -> None:
        self.gui = gui
        self.session = session
        self.connections = connections
        self._local = threading.local()
        self._good: dict[int, Any] = {}  # id(handle) -> the last good value of a GUI control
        self._reverts: dict[int, Any] = {}  # id(handle) -> a control to set back to its last good value
        self._sync_requested = False
        self._handle_home_requested = False
        self._drags: dict[int, np.ndarray] = {}  # client id -> last target of a drag in progress
        self._told: dict[int, float] = {}  # client id -> when a refused drag was last reported
        # the kick's weights over the base coordinates (None: the first alone), set by the base panel
        self.kick_direction: Callable[[], tuple[float, ...] | None] = lambda: None
        self.spatial_target = False  # the handle gives (x, y, z), not (x, y): set by the renderer per model
        self.target_lift = np.zeros(3)  # m: the handle is drawn this far above the target (base frame)
        self.pose_target = False  # the handle's orientation is the target's too (set by the renderer)
        self._button_acts: dict[int, Act] = {}  # id(button) -> what a click does (a key press does the same)
        self._wire()

    # ---------------------------------------------------------------- values shown vs. values in force
    @contextmanager
    def quiet(self) -> Iterator[None]:
        """Set GUI values from the server without treating them as operator input."""
        self._local.quiet = True
        try:
            yield
        finally:
            self._local.quiet = False

    def show(self, handle: Any, value: Any) -> None:
        """Show ``value`` (a value in force) on ``handle`` and remember it as good."""
        self._good[id(handle)] = value
        with self.quiet():
            if handle.value != value:
                handle.value = value
            if isinstance(handle, NumberField):
                handle.show_text()  # (after a refused typed number the slider still holds the value)

    def good(self, handle: Any) -> Any:
        """The last good value of a GUI control (what the app acts on)."""
        return self._good.get(id(handle), handle.value)

    def _revert(self, handle: Any) -> None:
        """Show the last good value of ``handle`` again (and the settings in force) at the next frame.

        Not at once: viser runs callbacks concurrently and an event carries no value of its own, so
        a revert here could be read by the callback of a later input as that input's value."""
        self._reverts[id(handle)] = handle
        self._sync_requested = True

    def apply_reverts(self) -> bool:
        """Show the reverted controls' good values (render thread); True if the settings need showing."""
        while self._reverts:
            _, handle = self._reverts.popitem()
            self.show(handle, self.good(handle))
        requested, self._sync_requested = self._sync_requested, False
        return requested

    def take_handle_home_request(self) -> bool:
        """True once after a drag was refused: the target handle must go back where it belongs."""
        requested, self._handle_home_requested = self._handle_home_requested, False
        return requested

    # ---------------------------------------------------------------- wiring
    def _on_input(self, handle: Any, act: Act, button: bool = False) -> None:
        """Wire ``handle`` to ``act(value, client_id)``; refused input is reported and reverted."""
        if isinstance(handle, NumberField):
            self._on_number(handle, act)
            return

        def callback(event: viser.GuiEvent) -> None:
            if getattr(self._local, "quiet", False):
                return
            checked = not button or isinstance(handle, viser.GuiButtonGroupHandle)
            self._apply(handle, event.client, event.target.value, act, check=checked, keep=not button)

        if button:
            self._button_acts[id(handle)] = act
            handle.on_click(callback)
        else:
            self._good[id(handle)] = handle.value
            handle.on_update(callback)

    def _on_number(self, field: NumberField, act: Act) -> None:
        """A number field: its slider dragged (a value in the slider's range) or a number typed in its box
        (read here; checked against the field's range if ``field.bounded``, else by the command)."""
        self._good[id(field)] = field.value

        def dragged(event: viser.GuiEvent) -> None:
            if not getattr(self._local, "quiet", False):
                self._apply(field, event.client, event.target.value, act, check=True, keep=True)

        def typed(client: viser.ClientHandle, text: str) -> None:
            if not self.connections.allowed(client):
                self.connections.refuse_watcher(client)
            elif text.strip():  # (a cleared box: nothing was typed; it shows the value again)
                try:
                    value = parse_number(split_label(field.label)[0], text)
                except ValueError as exc:
                    self.connections.notify(client, "Input not applied", str(exc), "warning")
                else:
                    self._apply(field, client, value, act, check=field.bounded, keep=True)
            self._reverts[id(field)] = field  # the box shows the value in force (a typed one written plainly)

        field.slider.on_update(dragged)
        field.on_typed(typed)

    def _apply(self, handle: Any, client: viser.ClientHandle | None, value: Any, act: Act, check: bool,
               keep: bool) -> None:  # fmt: skip
        """Act on one input of ``client``: refused (a watcher, a value the control cannot hold, or the
        command's ValueError) it is reported and the control shows its last good value again."""
        notify = self.connections.notify
        if not self.connections.allowed(client):
            self.connections.refuse_watcher(client)
            self._revert(handle)
            return
        try:
            if check:
                check_value(handle.slider if isinstance(handle, NumberField) else handle, value)
            act(value, None if client is None else client.client_id)
            if keep:
                self._good[id(handle)] = value
        except ValueError as exc:  # InvalidGain, InputRefused, values the widget cannot hold
            # a number out of its range is said as the control names it: its label's words and unit
            said = exc.for_control(handle.label) if isinstance(exc, OutOfRange) and hasattr(handle, "label") else exc
            notify(client, "Input not applied", str(said), "warning")
            self._revert(handle)  # show the value still in force
        except Exception as exc:
            traceback.print_exc()
            notify(client, "Input not applied", f"{type(exc).__name__}: {exc}", "error")
            self._revert(handle)

    on_input = _on_input  # for panels built elsewhere (viz/panels/gain_panel.py)

    def press(self, button: viser.GuiButtonHandle, client: viser.ClientHandle | None) -> None:
        """Do what a click on ``button`` by ``client`` does (a keyboard command): the same session command,
        refused for a watcher the same way."""
        self._apply(button, client, None, self._button_acts[id(button)], check=False, keep=False)

    def act(self, handle: Any, client: viser.ClientHandle | None, act: Act) -> None:
        """Run ``act(None, client_id)`` as ``client``'s input on ``handle`` (refused for a watcher)."""
        self._apply(handle, client, None, act, check=False, keep=False)

    def _wire(self) -> None:
        g, s = self.gui, self.session
        self._on_input(
            g.kick, lambda _, c: s.kick(float(self.good(g.kick_peak)), c, self.kick_direction()), button=True
        )
        self._on_input(g.kick_peak, lambda v, c: None)  # read at the next kick
        # read by the render thread; a factor typed or dragged is a fixed one
        self._on_input(g.exaggeration, lambda v, c: self.show(g.auto_exaggeration, False))
        self._on_input(g.auto_exaggeration, lambda v, c: None)  # read by the render thread
        self._on_input(g.suppression, lambda v, c: s.set_suppression(bool(v), c))
        self._on_input(g.pause, lambda _, c: self._pause_button(c), button=True)
        self._on_input(g.step, lambda _, c: s.single_step(1, c), button=True)
        self._on_input(g.reset, lambda _, c: s.reset(c), button=True)
        self._on_input(g.speed, lambda v, c: s.set_speed(_SPEED_OF_LABEL[v], c))
        self._on_input(g.sigma, lambda v, c: s.scrub(float(v), c))
        self._on_input(g.play_slow, lambda _, c: s.play_slow(c), button=True)
        self._on_input(g.play_fast, lambda _, c: s.play_fast(c), button=True)
        self._on_input(g.cyclic, lambda _, c: s.cyclic(not s.snapshot().mode.startswith("cyclic"), c), button=True)
        self._on_input(g.point_to_point, lambda _, c: s.point_to_point(c), button=True)
        self._on_input(g.ubar_speed, lambda v, c: s.set_ubar_speed(float(v), c))
        self._on_input(g.target_speed, lambda v, c: s.set_target_speed(float(v), c))
        self._on_input(g.law, lambda v, c: s.set_law(_LAW_OF_LABEL[v], c))
        for name, slider in g.gains.items():
            self._on_input(slider, lambda v, c, name=name: s.set_gains(c, **{name: float(v)}))
        self._on_input(g.preset_paused, lambda v, c: None)  # read at the next preset
        for group in g.presets.values():
            self._on_input(group, lambda v, c: s.load_preset(v, c, bool(self.good(g.preset_paused))), button=True)
        self._on_input(g.plots.scale, lambda v, c: g.plots.show_mode(_SCALE_OF_LABEL[v]))
        self._on_input(g.model, lambda v, c: s.switch_model(g.menu.key_of(v), c))
        self._on_input(g.shadow, lambda v, c: s.set_shadow(bool(v), c))
        g.download.on_click(self._on_download)

    def _pause_button(self, client: int | None) -> None:
        """One button, three labels: reset after a divergence, else resume or pause."""
        snap = self.session.snapshot()
        if snap.diverged:
            self.session.reset(client)
        elif snap.paused:
            self.session.resume(client)
        else:
            self.session.pause(client)

    def _on_download(self, event: viser.GuiEvent) -> None:
        if not self.connections.allowed(event.client):
            return
        data = self.session.log_csv()
        name = f"rns_{self.session.snapshot().settings.model}_log.csv"
        for client in self.connections.recipients(event.client):
            client.send_file_download(name, data, save_immediately=True)

    # ---------------------------------------------------------------- the target handle
    def on_drag(self, event: viser.TransformControlsEvent) -> None:
        """A drag of the target handle: its x, y (and z for a spatial model) become the session's target."""
        client = event.client
        cid = None if client is None else client.client_id
        if not self.connections.allowed(client):
            self._handle_home_requested = True
            now = time.monotonic()
            if cid is not None and now - self._told.get(cid, -1e9) > REFUSAL_REPEAT_S:
                self._told[cid] = now
                self.connections.refuse_watcher(client)
            return
        end = event.phase == "end"
        try:
            position = np.asarray(event.target.position, dtype=float)
            xy = (position - self.target_lift)[:3] if self.spatial_target else position[:2]
            if xy.shape != ((3,) if self.spatial_target else (2,)) or not np.all(np.isfinite(position)):
                raise ValueError(f"the target must be finite coordinates, got {position}")
            self.session.set_target(xy, end, cid, event.target.wxyz if self.pose_target else None)
        except ValueError as exc:
            self._handle_home_requested = True
            self.connections.notify(client, "Target not applied", str(exc), "warning")
            return
        if cid is not None:
            if end:
                self._drags.pop(cid, None)
            else:
                self._drags[cid] = xy.copy()

    def client_left(self, client_id: int) -> None:
        """A client left (maybe mid-drag): end its drag where it was if it was operating."""
        xy = self._drags.pop(client_id, None)
        self._told.pop(client_id, None)
        if xy is not None and self.connections.lock.is_operator(client_id):
            with suppress(ValueError):
                self.session.set_target(xy, True, None)
