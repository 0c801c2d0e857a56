"""Numbers typed into the app's fields: each field's text box is read on the server, so a number is either
applied exactly or refused with a message, never turned into another number (viser's own number box
turned ``1e9`` into 19). Text is sent as a browser sends it, by a protocol-level client."""

from __future__ import annotations

import asyncio
import math
import time
from collections.abc import Iterator
from dataclasses import fields

import pytest
import viser

from rns_viz.live.loop.commands import Scrub
from rns_viz.out_of_range import OutOfRange, readable, split_label
from rns_viz.viz.panels import number_field
from rns_viz.viz.panels.input_check import is_unfinished_number, parse_number
from rns_viz.viz.panels.number_field import NumberField, shown
from rns_viz.viz.server.app import RnsApp, start_app
from tests.support.browser import wait_for_clients, wait_until
from tests.support.protocol_client import ProtocolClient, gui_uuid

Told = list[tuple[str, str]]  # (title, body) of what the app told the typing client


def number_fields(app: RnsApp) -> list[NumberField]:
    """Every number field of the app: the panel's (gains included) and the replay folder's."""
    out: list[NumberField] = []
    for f in fields(app.gui):
        value = getattr(app.gui, f.name)
        out += [h for h in (value.values() if isinstance(value, dict) else [value]) if isinstance(h, NumberField)]
    return out + [h for h in vars(app.replay).values() if isinstance(h, NumberField)]


@pytest.fixture
def typing_app(monkeypatch: pytest.MonkeyPatch) -> Iterator[tuple[RnsApp, ProtocolClient, Told]]:
    """TREP's stepped app, one operating client and what the app tells it; typed text is read 0.05 s after
    it arrives (the client sends whole strings, not keystrokes)."""
    monkeypatch.setattr(number_field, "TYPING_PAUSE_S", 0.05)
    app = start_app("trep", port=0, realtime=False, verbose=False)
    told: Told = []
    original = app.connections.notify

    def record(client, title, body, level):  # type: ignore[no-untyped-def]
        told.append((title, body))
        original(client, title, body, level)

    app.connections.notify = record  # type: ignore[method-assign]
    client = ProtocolClient(app.port)
    wait_for_clients(app, 1, "the operator")
    yield app, client, told
    client.close()
    app.stop()


def type_into(app: RnsApp, client: ProtocolClient, told: Told, field: NumberField, text: str) -> str | None:
    """Type ``text`` into ``field``'s box; the message the app then gave (None if it applied the number),
    once the box shows the field's value in force again."""
    before = len(told)
    applied = app.controls.good(field)
    client.set_value(gui_uuid(field.box), text)

    def settled() -> bool:
        app.session.advance(0.0)  # the loop takes a queued command
        good = app.controls.good(field)
        return (len(told) > before or good != applied) and field.box.value == shown(good) and not field.typing()

    wait_until(settled, 10.0, f"{field.label} to settle after {text!r}")
    return told[before][1] if len(told) > before else None


def test_every_slider_of_the_app_is_a_number_field_with_a_box(typing_app: tuple[RnsApp, ProtocolClient, Told]) -> None:
    app, _, _ = typing_app
    ours = {id(f.slider) for f in number_fields(app)}
    handles = app.server.gui._gui_input_handle_from_uuid.values()  # (viser's registry of input handles)
    sliders = [h for h in handles if type(h).__name__ == "GuiSliderHandle"]
    assert sliders and all(id(s) in ours for s in sliders), [s.label for s in sliders if id(s) not in ours]
    assert len(number_fields(app)) >= 14  # 6 gains, kick, path, 2 speeds, drawn x, 3 replay fields


def test_a_typed_number_is_applied_exactly_or_refused_with_a_message(
    typing_app: tuple[RnsApp, ProtocolClient, Told],
) -> None:
    app, client, told = typing_app
    app.session.advance(0.5)  # a path to scrub along: the helper's path table, taken by the stepped loop
    assert app.session.wait_background(60.0), "the path table"  # (seconds beside other tests' workers)
    wait_until(lambda: not app.gui.sigma.disabled, 10.0, "the path field")
    checked = 0
    replay_only = (app.replay.speed, app.replay.timeline)  # (inputs to a replay running: tested below)
    for field in number_fields(app):
        if field in replay_only:
            continue
        old = app.controls.good(field)
        name = split_label(field.label)[0]
        for text, words in (("1e9", "10⁹"), ("NaN", "finite"), ("abc", "is not a number"), ("1,5", "not a number")):
            message = type_into(app, client, told, field, text)
            assert message is not None and words in message, (field.label, text, message)
            assert message.startswith(name) and "e+" not in message, (field.label, text, message)  # as labelled
            assert app.controls.good(field) == old and field.value == old, (field.label, text)
        # A number in the field's range, typed in exponent form: applied as typed, shown plainly.
        lo, hi = field.min, field.max
        text = f"{lo + 0.37 * (hi - lo):.4e}"
        if field is app.gui.sigma:  # the path field shows where the arm is until the loop takes the scrub:
            client.set_value(gui_uuid(field.box), text)  # the command is what the typing made
            wait_until(lambda: "Scrub" in app.session.pending_commands(), 10.0, "the typed scrub")
            assert [cmd.sigma for cmd in app.session._commands if isinstance(cmd, Scrub)] == [float(text)]
            app.session.advance(0.01)
            checked += 1
            continue
        assert type_into(app, client, told, field, text) is None, (field.label, text, told[-1:])
        assert app.controls.good(field) == float(text) == field.value
        assert field.box.value == shown(float(text))
        checked += 1
    assert checked >= 12
    # ... and reaches the session as typed
    settings = app.session.snapshot().settings
    assert settings.gains.g_b == app.controls.good(app.gui.gains["g_b"])
    assert settings.ubar_speed == app.controls.good(app.gui.ubar_speed)


G = "\u202f"  # the narrow no-break space between digit groups


def test_out_of_range_numbers_are_refused_naming_the_control_its_unit_and_the_range(
    typing_app: tuple[RnsApp, ProtocolClient, Told],
) -> None:
    """The gains' range is checked by Gains (once); the panel words its refusal with the box's label and unit,
    numbers as people write them (it said "gain g_b must be from 0 to 1e+06, got 1e+09")."""
    app, client, told = typing_app
    g = app.gui
    assert g.gains["g_b"].label == "Base damping g_b (1/s)"
    for text, said in (
        ("1e9", "10⁹"),
        ("-5", "−5"),
        ("NaN", "NaN"),
    ):
        finite = "a finite number " if text == "NaN" else ""
        expected = f"Base damping g_b must be {finite}from 0 to 1{G}000{G}000 1/s, not {said}"
        assert type_into(app, client, told, g.gains["g_b"], text) == expected
    message = type_into(app, client, told, g.gains["g_m"], "1e12")
    assert message == f"{split_label(g.gains['g_m'].label)[0]} must be from 0 to 1{G}000{G}000 1/s, not 10¹²"
    lo, hi = g.kick_peak.min, g.kick_peak.max
    message = type_into(app, client, told, g.kick_peak, "1e9")
    assert message == f"Kick strength, peak force must be from −{-lo:g} to {hi:g} N, not 10⁹"
    message = type_into(app, client, told, g.ubar_speed, "-1")
    assert message == f"Speed along the path ū must be above 0 and at most 10{G}000 1/(kg·m·s), not −1"


def test_numbers_are_written_for_people() -> None:
    cases = {1e6: f"1{G}000{G}000", 1e9: "10⁹", -5.0: "−5", 0.25: "0.25", 1e4: f"10{G}000", 1234.5: "1234.5"}
    cases |= {2.5e-7: "2.5 × 10⁻⁷", 1.5e9: "1.5 × 10⁹", 0.001: "0.001", 0.0: "0", math.inf: "∞", math.nan: "NaN"}
    for value, text in cases.items():
        assert readable(value) == text, value
    assert split_label("Position along the path ∫ū dt (1/(kg·m))") == ("Position along the path ∫ū dt", "1/(kg·m)")
    assert split_label("Base deflection drawn ×") == ("Base deflection drawn ×", "")
    assert OutOfRange("replay speed", 9.0, 0.1, 4.0, "×").for_control("Replay speed (×)") == (
        "Replay speed must be from 0.1× to 4×, not 9"
    )


def test_typed_replay_speed_and_time(typing_app: tuple[RnsApp, ProtocolClient, Told]) -> None:
    app, client, told = typing_app
    s = app.session
    s.advance(2.0)
    s.start_replay(1.0)
    s.advance(0.0)
    replay = s.snapshot().replay
    assert replay is not None
    assert type_into(app, client, told, app.replay.speed, "1e9") == "Replay speed must be from 0.1× to 4×, not 10⁹"
    assert type_into(app, client, told, app.replay.speed, "2.5e0") is None
    s.advance(0.0)
    assert s.snapshot().replay.speed == 2.5  # type: ignore[union-attr]
    before = len(told)  # a time is checked by the loop, against the recording: its refusal comes from there
    type_into(app, client, told, app.replay.timeline, "1e9")

    def refused() -> bool:
        s.advance(0.0)
        return any("within the recording" in body and "1e+09" in body for _, body in told[before:])

    wait_until(refused, 10.0, "the loop to refuse a time outside the recording")
    wait_until(lambda: app.replay.timeline.value < 1e9, 10.0, "the timeline to show the playhead again")
    t = replay.recording.span[0] + 0.5
    assert type_into(app, client, told, app.replay.timeline, f"{t!r}") is None
    s.advance(0.0)
    assert s.snapshot().replay.start == t  # type: ignore[union-attr]


def test_negative_zero_and_small_exponents_are_the_numbers_they_name(
    typing_app: tuple[RnsApp, ProtocolClient, Told],
) -> None:
    app, client, told = typing_app
    g_b = app.gui.gains["g_b"]
    assert type_into(app, client, told, g_b, "1e-3") is None
    app.session.advance(0.01)
    assert app.session.snapshot().settings.gains.g_b == 0.001 and g_b.box.value == "0.001"
    assert type_into(app, client, told, g_b, "-0") is None
    app.session.advance(0.01)
    g = app.session.snapshot().settings.gains.g_b
    assert g == 0.0 and math.copysign(1.0, g) == 1.0 and g_b.box.value == "0"
    # Beyond the slider's range but accepted by the command: applied, and the slider widens to show it.
    assert type_into(app, client, told, g_b, "2.5e2") is None
    assert g_b.value == 250.0 and g_b.max >= 250.0


def g_b_applied(app: RnsApp, monkeypatch: pytest.MonkeyPatch) -> list[float]:
    """The g_b of every gain change the panel sends the session from here on (the session still applies them)."""
    applied: list[float] = []
    original = app.session.set_gains

    def spy(client_id, **changes):  # type: ignore[no-untyped-def]
        applied.append(changes.get("g_b", math.nan))
        original(client_id, **changes)

    monkeypatch.setattr(app.session, "set_gains", spy)
    return applied


def test_text_is_read_when_the_typing_pauses_not_per_keystroke(
    typing_app: tuple[RnsApp, ProtocolClient, Told], monkeypatch: pytest.MonkeyPatch
) -> None:
    """'1', '1e', '1e9' sent as keystrokes: only the whole text is read (refused), 1 is never applied."""
    app, client, told = typing_app
    monkeypatch.setattr(number_field, "TYPING_PAUSE_S", 0.8)
    g_b = app.gui.gains["g_b"]
    old = app.controls.good(g_b)
    applied = g_b_applied(app, monkeypatch)
    before = len(told)
    for text in ("1", "1e", "1e9"):
        client.set_value(gui_uuid(g_b.box), text)
    wait_until(lambda: len(told) > before and not g_b.typing(), 10.0, "the typed text to be read")
    assert applied == [1e9] and app.controls.good(g_b) == old
    assert [body for _, body in told[before:]] == [f"Base damping g_b must be from 0 to 1{G}000{G}000 1/s, not 10⁹"]


def test_parse_number_reads_numbers_only() -> None:
    assert parse_number("x", " 1e9 ") == 1e9 and parse_number("x", "1e-3") == 0.001
    assert math.copysign(1.0, parse_number("x", "-0")) == 1.0
    assert math.isnan(parse_number("x", "NaN"))  # a number to Python: refused by what it becomes (finite)
    for text in ("abc", "1,5", "", "1e", "-", "0x10"):
        with pytest.raises(ValueError, match="is not a number"):
            parse_number("g_b (1/s)", text)


def test_a_half_typed_number_is_not_refused_after_a_short_pause(
    typing_app: tuple[RnsApp, ProtocolClient, Told], monkeypatch: pytest.MonkeyPatch
) -> None:
    """'2e-' (an exponent on its way) waits for the longer pause: no 'not a number' after the short one,
    and '2e-3' typed next is applied as 0.002 without a word."""
    app, client, told = typing_app
    monkeypatch.setattr(number_field, "TYPING_PAUSE_S", 0.3)
    monkeypatch.setattr(number_field, "UNFINISHED_PAUSE_S", 60.0)  # longer than this test: never reached
    g_b = app.gui.gains["g_b"]
    applied = g_b_applied(app, monkeypatch)
    before = len(told)
    client.set_value(gui_uuid(g_b.box), "2e-")
    wait_until(lambda: g_b.typing(), 10.0, "the keystroke to arrive")
    time.sleep(1.0)  # well past the short pause
    assert applied == [] and told[before:] == [] and g_b.typing()
    client.set_value(gui_uuid(g_b.box), "2e-3")
    wait_until(lambda: applied == [0.002] and not g_b.typing(), 10.0, "2e-3 to be read")
    assert told[before:] == []


def test_a_numbers_beginning_is_told_from_text_that_is_no_number() -> None:
    for text in ("", "-", "+", ".", "1e", "1e-", "2.5E+", " 3e "):
        assert is_unfinished_number(text), text
    for text in ("1", "1.", "-0", "1e-3", "abc", "NaN", "e", "--", "1e-3x", "0x"):
        assert not is_unfinished_number(text), text


def test_text_just_typed_is_not_written_over_before_it_is_read(
    typing_app: tuple[RnsApp, ProtocolClient, Told], monkeypatch: pytest.MonkeyPatch
) -> None:
    """viser sets a box's value when a client's text arrives and runs the box's callbacks after: the server
    writing the box in between (the render thread shows values every frame) must not replace the text the
    callback then reads. Played in that order here: the client's text set as viser sets it, the render
    thread's write, then the callback."""
    app, _, told = typing_app
    g_b = app.gui.gains["g_b"]
    applied = g_b_applied(app, monkeypatch)
    before = len(told)
    state = g_b.box._impl  # what viser's handler sets before it runs the callbacks
    state.value, state.update_timestamp = "1e9", time.time()
    g_b.show_text()  # the render thread, between the two
    app.controls.show(g_b, app.controls.good(g_b))  # (and the settings shown again)
    assert g_b.box.value == "1e9", "the server wrote over a client's text not yet read"
    client = next(iter(app.server.get_clients().values()))
    (keystroke,) = [cb for cb in state.update_cb if cb.__name__ == "keystroke"]
    event = viser.GuiEvent(client, client.client_id, g_b.box)
    asyncio.run_coroutine_threadsafe(keystroke(event), app.server._event_loop).result(10.0)
    wait_until(lambda: len(told) > before and not g_b.typing(), 10.0, "the typed text to be read")
    assert applied == [1e9] and "not 10⁹" in told[-1][1]
    # A text whose callback never ran (its page left in between) is written over once it is that old.
    state.value, state.update_timestamp = "7", time.time() - number_field.UNTAKEN_S
    g_b.show_text()
    assert g_b.box.value == shown(g_b.value)
