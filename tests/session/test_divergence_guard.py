"""The divergence guard: a state outside physical bounds pauses the session, tells everyone, and
Reset recovers a finite state."""

from __future__ import annotations

import numpy as np
import pytest

from rns_viz.live.loop.session import Session
from rns_viz.live.runs.divergence_guard import MAX_JOINT_SPEED, Bounds
from rns_viz.model import FsmsModel
from rns_viz.viz.server.app import start_app
from tests.browser import wait_until
from tests.protocol_client import ProtocolClient


def test_bounds_come_from_the_urdf(trep: FsmsModel) -> None:
    b = Bounds(trep)
    q, v = np.zeros(trep.nv), np.zeros(trep.nv)
    assert b.violation(q, v) is None
    assert "joint limits" in (b.violation(np.array([0.2, 0.0, 0.0]), v) or "")
    assert "rad/s" in (b.violation(q, np.array([0.0, 0.0, 2 * MAX_JOINT_SPEED])) or "")
    assert "finite" in (b.violation(np.array([np.nan, 0.0, 0.0]), v) or "")
    q[1:] = 50.0  # arm joints may wind up: no bound on their angles
    assert b.violation(q, v) is None


def test_base_pushed_past_its_limit_pauses_and_reset_recovers() -> None:
    s = Session("trep", realtime=False)
    try:
        s.advance(0.1)
        s.state.runs.sim.q[0] = 0.15  # as if a huge force had thrown the base beyond its 0.1 m limit
        s.advance(0.1)
        snap = s.snapshot()
        assert snap.paused and snap.diverged and "physical bounds" in snap.diverged
        notices = s.pop_notices()
        assert any(n.client is None and n.level == "error" and "Reset" in n.body for n in notices)
        t = snap.t
        s.resume()  # refused: Reset first
        s.advance(0.1)
        assert s.snapshot().t == t and s.snapshot().diverged
        s.reset()
        s.advance(0.2)
        snap = s.snapshot()
        assert not snap.paused and snap.diverged is None and np.all(np.isfinite(snap.q))
        assert abs(snap.q[0]) < 1e-6
    finally:
        s.stop()


@pytest.mark.parametrize("name", ["trep", "planar3r"])
def test_an_unstable_gain_pauses_and_every_client_is_told(name: str) -> None:
    app = start_app(name, port=0, realtime=False, verbose=False)
    clients = [ProtocolClient(app.port, decode=True) for _ in range(2)]
    try:
        wait_until(lambda: len(app.server.get_clients()) == 2, 10.0, "two clients")
        s = app.session
        before = [c.types["NotificationShowMessage"] for c in clients]
        s.set_gains(g_m=1e6, g_b=1e6)  # allowed by Gains, unstable at 1 kHz
        s.kick(0.8 if name == "trep" else 5.0)
        s.advance(2.0)
        snap = s.snapshot()
        assert snap.paused and snap.diverged
        assert np.all(np.isfinite(snap.q)) and np.all(np.isfinite(s.state.runs.sim.v))
        for c, n in zip(clients, before, strict=True):
            wait_until(lambda c=c, n=n: c.types["NotificationShowMessage"] > n, 10.0, "the divergence notice")
        wait_until(lambda: app.gui.pause.label == "Reset (diverged)", 10.0, "the button to offer a reset")
        app.gui.pause.value = True  # the offered reset
        wait_until(lambda: "Reset" in s.pending_commands(), 10.0, "the reset command")
        s.set_gains(g_m=20.0, g_b=20.0)
        s.advance(0.3)
        snap = s.snapshot()
        assert not snap.paused and snap.diverged is None and np.all(np.isfinite(snap.q))
    finally:
        for c in clients:
            c.close()
        app.stop()
