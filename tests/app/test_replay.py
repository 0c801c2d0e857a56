"""Record and replay in the app: the scene, ghost, timeline and plots show the replayed step, and hostile
replay values are set back while the server lives (the recording and replay in a session:
tests/session/test_replay.py)."""

from __future__ import annotations

import time

import numpy as np

from rns_viz.live.loop import commands as c
from rns_viz.viz.server.app import RnsApp
from tests.support.browser import wait_until


def test_app_draws_the_replayed_step_and_plots(trep_app: RnsApp) -> None:
    app, s = trep_app, trep_app.session
    s.kick(0.8)
    s.advance(1.0)
    s.start_replay(1.0)
    s.play_replay(False)
    s.advance(0.0)
    rec = s.snapshot().replay.recording
    t = rec.t[400]
    s.seek_replay(float(t))
    s.advance(0.0)
    drawn = app.renderer._drawn  # q as drawn at a factor (the auto factor follows the replayed motion)
    wait_until(
        lambda: np.array_equal(app.scene.q, drawn(rec.q(400), app.scene.exaggeration)),
        5.0,
        "the scene to show the replayed step",
    )
    ghost = app.renderer.teach.ghost
    wait_until(lambda: np.array_equal(ghost.q, drawn(rec.q_shadow(400), ghost.exaggeration)), 5.0, "ghost")
    wait_until(lambda: not app.replay.timeline.disabled, 5.0, "the timeline")
    wait_until(lambda: app.replay.timeline.value == round(t, 2), 5.0, "the timeline at the playhead")
    wait_until(lambda: float(app.gui.plots.xb.data[0][-1]) <= t + 1e-9, 5.0, "the plots up to the playhead")
    s.stop_replay()
    s.advance(0.0)
    wait_until(lambda: app.replay.timeline.disabled, 5.0, "the timeline to be disabled back live")


def test_hostile_replay_values_are_set_back_and_the_server_lives(trep_app: RnsApp) -> None:
    from tests.support.browser import wait_for_clients
    from tests.support.protocol_client import ProtocolClient, gui_uuid

    app, s = trep_app, trep_app.session
    s.advance(0.5)
    with ProtocolClient(app.port, decode=True) as ws:
        wait_for_clients(app, 1, "the websocket client to connect")
        ws.click(gui_uuid(app.replay.start))
        wait_until(lambda: s.pending_commands() == ["StartReplay"], 5.0, "the replay command")
        s.advance(0.0)
        ws.set_value(gui_uuid(app.replay.speed.slider), float("nan"))
        ws.set_value(gui_uuid(app.replay.speed.slider), 100.0)
        ws.set_value(gui_uuid(app.replay.timeline.slider), 1e9)
        ws.set_value(gui_uuid(app.replay.seconds.slider), -5.0)
        time.sleep(1.0)
        wait_until(lambda: app.replay.speed.value == 1.0, 5.0, "the speed to be set back")
        # Nothing hostile is queued. viser's callback reads the slider when it runs, so on a loaded machine
        # the render thread may have shown the playhead again first: a seek to it is queued (harmless).
        replay = s.snapshot().replay
        assert replay is not None and replay.speed == 1.0
        t0, t1 = replay.recording.span
        queued = list(s._commands)
        assert all(isinstance(cmd, c.SeekReplay) and t0 - 0.01 <= cmd.t <= t1 + 0.01 for cmd in queued), queued
        assert app.render_thread.is_alive()
        ws.click(gui_uuid(app.replay.live))
        wait_until(lambda: s.pending_commands() == ["StopReplay"], 5.0, "back to live")
        s.advance(0.05)
        assert s.snapshot().replay is None and np.all(np.isfinite(s.snapshot().q))
