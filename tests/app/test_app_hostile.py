"""Hostile input, property-based: random NaN, +-inf, huge, negative, zero and wrong-typed values fed to
every control of the running app (server-side ``handle.value`` and a protocol client's GUI updates
and target drags, from the operator and from a watcher), the session advanced between inputs.
Afterwards the server and its threads are alive and every state value, plot and pose is finite.
"""

from __future__ import annotations

import math
import time
from collections.abc import Iterator
from contextlib import suppress
from dataclasses import fields
from typing import Any

import numpy as np
import pytest
import viser
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rns_viz.viz.panels.control_panel import GuiElements
from rns_viz.viz.panels.number_field import NumberField
from rns_viz.viz.server.app import TARGET_HANDLE, RnsApp, start_app
from tests.support.browser import wait_for_clients, wait_until
from tests.support.protocol_client import ProtocolClient, gui_uuid

EXAMPLES = 40  # per model: ~15 s each
INPUT_TYPES = (
    viser.GuiSliderHandle,
    viser.GuiNumberHandle,
    viser.GuiCheckboxHandle,
    viser.GuiDropdownHandle,
    viser.GuiButtonHandle,
    viser.GuiButtonGroupHandle,
)
SPECIAL = [math.nan, math.inf, -math.inf, 1e308, -1e308, 1e9, -1e9, 0.0, -0.0, -1.0, 5e-324, 1e-300]
WRONG = ["", "abc", "nan", "1e999", None, True, False, [], {}, [1.0, 2.0], -1, 2**40]

numbers = st.sampled_from(SPECIAL) | st.floats(allow_nan=True, allow_infinity=True)
values = numbers | st.sampled_from(WRONG)
positions = st.tuples(numbers, numbers, numbers)


def controls(gui: GuiElements, app: RnsApp | None = None) -> list[Any]:
    """Every input control of the panel, from the GuiElements fields (each number field's slider and typed
    box, gains included), and the base panel's (kick direction, selection S; hidden for a 1-DOF base, but a
    client can still send to them)."""
    out: list[Any] = []
    for f in fields(gui):
        value = getattr(gui, f.name)
        for handle in value.values() if isinstance(value, dict) else [value]:
            if isinstance(handle, NumberField):
                out += [handle.slider, handle.box]
            elif isinstance(handle, INPUT_TYPES):
                out.append(handle)
    if app is not None:
        out += [app.base_panel.direction, *app.base_panel.boxes]
    return out


@pytest.fixture(scope="module", params=["trep", "planar3r", "boom7"])
def hostile_app(request: pytest.FixtureRequest) -> Iterator[tuple[RnsApp, ProtocolClient, ProtocolClient]]:
    app = start_app(request.param, port=0, realtime=False, verbose=False)
    assert app.session.wait_background()
    operator = ProtocolClient(app.port)
    wait_for_clients(app, 1, "the operator's client")
    watcher = ProtocolClient(app.port)
    wait_for_clients(app, 2, "a watcher")
    assert app.lock.operator is not None
    yield app, operator, watcher
    for c in (operator, watcher):
        c.close()
    app.stop()


def send(client: ProtocolClient, handle: Any, value: Any) -> None:
    with suppress(TypeError, OverflowError, ValueError):  # not encodable as msgpack: no browser sends it
        client.gui_update(gui_uuid(handle), value=value)


def assert_finite_everywhere(app: RnsApp) -> None:
    s = app.session
    for run in (s.state.runs.sim, s.state.runs.shadow):
        assert np.all(np.isfinite(run.q)) and np.all(np.isfinite(run.v)), (run.q, run.v)
    snap = s.snapshot()
    assert np.all(np.isfinite(snap.q)) and math.isfinite(snap.t)
    assert snap.q_shadow is None or np.all(np.isfinite(snap.q_shadow))
    assert snap.target is None or np.all(np.isfinite(snap.target))
    assert snap.sigma is None or math.isfinite(snap.sigma)
    r = snap.readouts
    for name in ("sigma_hbm", "sigma_jbar", "L", "ee_error", "reaction"):
        assert not math.isinf(getattr(r, name)), name  # nan means "not defined here", never inf
    assert math.isfinite(r.L) and math.isfinite(r.reaction)
    arrays = s.plot_arrays()
    assert np.all(np.isfinite(arrays["t"])) and np.all(np.isfinite(arrays["xb"]))
    assert not any(np.any(np.isinf(a)) for a in arrays.values())
    g = app.gui
    for plot in (g.plot_xb, g.plot_L, g.plot_error):  # what was sent to the browsers
        assert all(np.all(np.isfinite(np.asarray(a, dtype=float))) for a in plot.data)
    assert np.all(np.isfinite(app.handle.position))
    for field in number_fields(app):
        assert math.isfinite(app.good(field)) and math.isfinite(field.value), field.label


def number_fields(app: RnsApp) -> list[NumberField]:
    g = app.gui
    found = []
    for f in fields(g):
        value = getattr(g, f.name)
        found += [x for x in (value.values() if isinstance(value, dict) else [value]) if isinstance(x, NumberField)]
    return found


actions = st.lists(
    st.tuples(st.sampled_from(["server", "operator", "watcher", "drag"]), st.integers(0, 10_000), values, positions),
    min_size=1,
    max_size=6,
)


@settings(max_examples=EXAMPLES, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(batch=actions)
def test_hostile_values_to_every_control(
    hostile_app: tuple[RnsApp, ProtocolClient, ProtocolClient], batch: list[tuple[str, int, Any, tuple]]
) -> None:
    app, operator, watcher = hostile_app
    s = app.session
    handles = controls(app.gui, app)
    for via, index, value, position in batch:
        handle = handles[index % len(handles)]
        if via == "server":
            with suppress(Exception):  # viser may refuse the assignment itself
                handle.value = value
        elif via == "drag":
            phase = ("start", "update", "end")[index % 3]
            if phase != "update":
                operator.drag_phase(TARGET_HANDLE, phase)
            with suppress(TypeError, OverflowError, ValueError):
                operator.drag(TARGET_HANDLE, position)
        else:
            send(operator if via == "operator" else watcher, handle, value)
        time.sleep(0.003)  # let viser's thread pool run the callbacks
        s.advance(0.02)
        if s.snapshot().diverged:  # a legal but unstable setting: the guard paused; start again
            s.reset()
            s.advance(0.0)
    time.sleep(0.05)
    s.advance(0.05)
    # a refused drag's handle goes home at the next render frame (viser moved it to the client's value first):
    # wait for that frame, however busy the machine
    wait_until(lambda: np.all(np.isfinite(app.handle.position)), 10.0, "the render thread to send the handle home")
    # a refused value sent to a box is written back once viser's thread pool has run its callback, which a busy
    # machine may not have done yet (messages travel through the websocket): wait for every box to be written
    boxes = number_fields(app)
    wait_until(lambda: all(math.isfinite(b.value) for b in boxes), 10.0, "every refused box to be written back")
    assert_finite_everywhere(app)


def test_afterwards_the_app_is_alive(hostile_app: tuple[RnsApp, ProtocolClient, ProtocolClient]) -> None:
    app, _, _ = hostile_app
    s = app.session
    assert app.render_thread.is_alive() and s.state.background.worker._thread.is_alive()
    late = ProtocolClient(app.port)
    try:
        wait_for_clients(app, 3, "a new client to connect")
    finally:
        late.close()
    s.reset()
    s.advance(0.2)
    assert_finite_everywhere(app)
    assert not s.snapshot().paused or s.snapshot().diverged is None
