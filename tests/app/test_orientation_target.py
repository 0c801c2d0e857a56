"""Orientation targets on boom7 in the app: a drag with a NaN or zero quaternion, as a client could send
it, is told to that client and the simulation runs on."""

from __future__ import annotations

import time

import numpy as np
import pytest

from rns_viz.viz.server.app import TARGET_HANDLE
from tests.support.app_helpers import stepped_app
from tests.support.browser import wait_for_clients, wait_until
from tests.support.protocol_client import ProtocolClient

R1 = (True, False, False, False, False, False)


def test_bad_quaternions_from_a_client_are_told_and_the_simulation_runs_on() -> None:
    """The handle's drag with a NaN or zero quaternion, as a client could send it (tests/support/protocol_client.py)."""
    apps = stepped_app("boom7")
    app = next(apps)
    s = app.session
    s.set_selection(R1)
    s.advance(0.01)
    wait_until(lambda: app.controls.pose_target, 20.0, "the pose handle")
    ws = ProtocolClient(app.port, decode=True)
    try:
        wait_for_clients(app, 1, "the websocket client")
        before = np.array(s.snapshot().target, dtype=float)
        goal_R = s.state.operator.tracker.goal_R.copy()  # type: ignore[union-attr]
        lifted = before + app.controls.target_lift + np.array([0.02, 0.0, 0.0])
        for bad in ((np.nan, 0.0, 0.0, 1.0), (0.0, 0.0, 0.0, 0.0)):
            told = ws.types["NotificationShowMessage"]
            # mid-drag updates (at a drag's end viser calls back once more with the handle as it is then)
            ws.drag(TARGET_HANDLE, tuple(lifted), "update", wxyz=bad)
            wait_until(lambda told=told: ws.types["NotificationShowMessage"] > told, 10.0, "a notice")
            # the refused drag sends the handle home (render thread); wait for it before the next drag,
            # whose callback would otherwise read the handle's pose as the renderer set it
            wait_until(lambda: not app.controls._handle_home_requested, 10.0, "the handle sent home")
            time.sleep(0.5)  # the render frame that took the request writes the handle's pose (30 Hz frames)
        assert "DragTarget" not in s.pending_commands()  # refused before anything was queued
        t0 = s.snapshot().t
        s.advance(0.5)
        snap = s.snapshot()
        assert not snap.paused and snap.diverged is None and snap.t == pytest.approx(t0 + 0.5)
        assert np.allclose(snap.target, before)  # the target in force is untouched
        assert np.allclose(s.state.operator.tracker.goal_R, goal_R)  # type: ignore[union-attr]
    finally:
        ws.close()
        apps.close()
