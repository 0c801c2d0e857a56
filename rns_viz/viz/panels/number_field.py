"""A number the operator can drag or type: a viser slider for dragging, a text box for typing.

viser's slider carries a Mantine number box that drops the characters it does not take: ``1e9`` reaches
the server as 19, ``1e-3`` as 13, and ``NaN`` or ``abc`` empty the box while the old value silently
stays. The server cannot tell. So the slider's own box is hidden (:data:`SLIDER_BOX_CSS`) and the number
is typed into a text box under the track, read on the server (:func:`rns_viz.viz.panels.input_check.parse_number`):
text that is not a number is refused with a message, never turned into another number.

A text box sends every keystroke, so the text is read once the typing pauses (:data:`TYPING_PAUSE_S`),
not at ``1`` on the way to ``1e9``; a number's beginning such as ``1e-`` waits longer
(:data:`UNFINISHED_PAUSE_S`). (Enter cannot be used: viser sends a form's submit through the same
throttled channel as the text, and a submit within 50 ms of the last keystroke replaces the keystroke.)
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

import viser

from rns_viz.viz.panels.input_check import is_unfinished_number

TYPING_PAUSE_S = 0.8  # s: typed text is read this long after its last keystroke
# s: ... or this long if it is a number's beginning ("1e-"): someone is typing an exponent, or a busy
# machine delivered the keys late; a half-typed number is not refused as "not a number" after a short pause
UNFINISHED_PAUSE_S = 3.0
UNTAKEN_S = 2.0  # s: a client's text the box's callback has not taken by then never will be (the page left)
# Hides the number box viser puts beside every slider (it mangles typed numbers); each slider of the
# app is a NumberField, whose text box shows and takes the value instead.
SLIDER_BOX_CSS = "<style>.mantine-Slider-root + .mantine-NumberInput-root { display: none; }</style>"

Typed = Callable[[viser.ClientHandle, str], None]  # typed(client, text) once the typing pauses


def hide_slider_boxes(gui: viser.GuiApi) -> viser.GuiHtmlHandle:
    """Add the style that hides every slider's own number box (once per server)."""
    return gui.add_html(SLIDER_BOX_CSS)


def shown(value: float) -> str:
    """The text a field shows for ``value``: six significant digits (the value itself stays exact)."""
    return f"{value:.6g}"


class NumberField:
    """A slider (its track; drag) with a text box under it (type); ``value`` is the slider's.

    ``bounded``: a typed number must lie in the field's range (nothing else checks it: the value is read
    later, or only drawn). Otherwise the command it becomes checks it, and a number it accepts beyond the
    slider's range widens the slider to show it.
    """

    def __init__(
        self,
        gui: viser.GuiApi,
        label: str,
        *,
        min: float,
        max: float,
        step: float,
        initial_value: float,
        hint: str,
        bounded: bool,
        disabled: bool = False,
    ) -> None:
        self.slider = gui.add_slider(
            label, min=min, max=max, step=step, initial_value=initial_value, hint=hint, disabled=disabled
        )
        self.box = gui.add_text(
            "",
            shown(initial_value),
            hint="Type a number (2.5, -0.3 and 1e-3 are numbers); it applies when you stop typing.",
            disabled=disabled,
            order=self.slider.order + 1e-3,
        )
        self.bounded = bounded
        self._range = (float(min), float(max))  # the slider's range when no value lies beyond it
        self._lock = threading.Lock()
        self._timers: dict[int, threading.Timer] = {}  # client id -> the pause it waits for
        # The box's update time (viser's) when the server last wrote it or took a client's text: a later one is
        # a client's text not yet taken, which the server must not write over (see on_typed).
        self._box_seen = self.box.update_timestamp

    # ------------------------------------------------------------------ what the field shows
    @property
    def value(self) -> float:
        return float(self.slider.value)

    @value.setter
    def value(self, value: float) -> None:
        self._fit_range(value)
        self.slider.value = value
        self._write_box(shown(value))

    def show_text(self) -> None:
        """Write the value in the box again (after a refused or a canonicalised typed number)."""
        if self.box.value != shown(self.value):
            self._write_box(shown(self.value))

    def _write_box(self, text: str) -> None:
        """Write ``text`` in the box unless it is a client's: typed text waiting for its pause, or just arrived
        and not taken yet (viser sets the box's value, then runs its callbacks)."""
        with self._lock:
            stamp = self.box.update_timestamp
            # (a text whose callback never ran, its page gone in between, is the server's again after a while)
            untaken = stamp > self._box_seen and time.time() - stamp < UNTAKEN_S
            if self._timers or untaken:
                return
            self.box.value = text
            self._box_seen = self.box.update_timestamp

    def typing(self) -> bool:
        """A client's typed text waits for its pause: the box is theirs until then."""
        with self._lock:
            return bool(self._timers)

    def _fit_range(self, value: float) -> None:
        lo, hi = self._range
        lo, hi = min(lo, value), max(hi, value)
        if (self.slider.min, self.slider.max) != (lo, hi):
            self.slider.min, self.slider.max = lo, hi

    @property
    def min(self) -> float:
        return float(self.slider.min)

    @min.setter
    def min(self, value: float) -> None:
        self._range = (float(value), self._range[1])
        self._fit_range(self.value)

    @property
    def max(self) -> float:
        return float(self.slider.max)

    @max.setter
    def max(self, value: float) -> None:
        self._range = (self._range[0], float(value))
        self._fit_range(self.value)

    @property
    def label(self) -> str:
        return self.slider.label

    @property
    def order(self) -> float:
        """The order of the field's last element (what comes after the field goes above this)."""
        return self.box.order

    @property
    def hint(self) -> str | None:
        return self.slider.hint

    @hint.setter
    def hint(self, value: str) -> None:
        self.slider.hint = value

    @property
    def visible(self) -> bool:
        return self.slider.visible

    @visible.setter
    def visible(self, value: bool) -> None:
        self.slider.visible = self.box.visible = value

    @property
    def disabled(self) -> bool:
        return self.slider.disabled

    @disabled.setter
    def disabled(self, value: bool) -> None:
        self.slider.disabled = self.box.disabled = value

    # ------------------------------------------------------------------ typed text
    def on_typed(self, typed: Typed) -> None:
        """Call ``typed(client, text)`` once a client's typing in the box has paused."""

        # Run on viser's event loop right after it set the box's value (a coroutine: not queued to its thread
        # pool, where the render thread could write the box over the text before it is read here).
        async def keystroke(event: viser.GuiEvent) -> None:
            client = event.client
            if client is None:  # the server wrote the box
                return
            with self._lock:
                waiting = self._timers.pop(client.client_id, None)
                if waiting is not None:
                    waiting.cancel()
                text = str(event.target.value)  # now: the server may write the box before the pause ends
                self._box_seen = max(self._box_seen, self.box.update_timestamp)
                pause = UNFINISHED_PAUSE_S if is_unfinished_number(text) else TYPING_PAUSE_S
                timer = threading.Timer(pause, self._paused, (client, typed, text))
                timer.daemon = True
                self._timers[client.client_id] = timer
                timer.start()

        self.box.on_update(keystroke)

    def _paused(self, client: viser.ClientHandle, typed: Typed, text: str) -> None:
        with self._lock:
            if self._timers.get(client.client_id) is not threading.current_thread():
                return  # a later keystroke of this client started its own pause
            del self._timers[client.client_id]
        typed(client, text)
