"""The divergence guard in the app: an unstable gain pauses the session, every client is told, and the
offered Reset recovers a finite state."""

from __future__ import annotations

import numpy as np
import pytest

from rns_viz.viz.server.app import start_app
from tests.support.browser import wait_until
from tests.support.protocol_client import ProtocolClient


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
