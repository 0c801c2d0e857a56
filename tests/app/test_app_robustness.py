"""The live app, headless, under bad input: refused gains, a diverging run, a client that leaves
mid-drag, a view-only client. The simulation must stay intact and the server alive."""

from __future__ import annotations

import numpy as np
import pytest

import rns_viz.viz.server.render as render
from rns_viz.control import InvalidGain
from rns_viz.viz.server.app import TARGET_HANDLE, RnsApp, start_app
from tests.support.app_helpers import queued, uuid
from tests.support.browser import wait_for_clients, wait_until
from tests.support.protocol_client import ProtocolClient


@pytest.mark.parametrize("client", ["trep_app"], indirect=True)
def test_invalid_gain_input_is_refused_and_the_old_value_kept(trep_app: RnsApp, client: ProtocolClient) -> None:
    s, slider = trep_app.session, trep_app.gui.gains["g_b"].slider  # (its track: dragged values)
    old = s.snapshot().settings.gains.g_b
    for told, bad in enumerate((float("nan"), -5.0, float("inf")), start=1):
        client.set_value(uuid(slider), bad)
        # The refusal is told first (the slider shows the old value even before the server read the input).
        wait_until(lambda n=told: client.types["NotificationShowMessage"] >= n, 10.0, f"the refusal of {bad} told")
        wait_until(lambda old=old: slider.value == old, 10.0, f"g_b to return to {old} after {bad}")
        s.advance(0.01)
        assert s.snapshot().settings.gains.g_b == old
    with pytest.raises(InvalidGain):
        s.set_gains(g_m=-1.0)
    client.set_value(uuid(slider), 12.0)  # a good value is applied
    queued(trep_app, "SetGains")
    s.advance(0.01)
    assert s.snapshot().settings.gains.g_b == 12.0
    assert s.state.runs.sim.law.gains.g_b == 12.0 and s.state.runs.shadow.law.gains.g_b == 12.0


def test_divergence_pauses_keeps_the_last_finite_state_and_reset_recovers(trep_app: RnsApp) -> None:
    s = trep_app.session
    s.set_gains(g_m=1e6)  # valid per Gains, unstable at 1 kHz once anything moves
    s.kick(0.8)
    s.advance(1.0)
    snap = s.snapshot()
    assert snap.paused and snap.diverged and "diverged" in snap.diverged
    assert np.all(np.isfinite(snap.q))
    wait_until(lambda: trep_app.session.snapshot().diverged is not None, 1.0, "the divergence flag")
    t_stop = snap.t
    s.advance(0.5)
    assert s.snapshot().t == t_stop  # stays paused
    s.set_gains(g_m=20.0)
    s.reset()
    s.advance(0.5)
    snap = s.snapshot()
    assert not snap.paused and snap.diverged is None and snap.t == pytest.approx(0.5)


@pytest.mark.parametrize("client", ["trep_app"], indirect=True)
def test_a_client_leaving_mid_drag_does_not_hurt(
    trep_app: RnsApp, client: ProtocolClient, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr("rns_viz.live.operator.operator_lock.RELOAD_GRACE_S", 0.0)  # no wait for a reload of its page
    s = trep_app.session
    ee = trep_app.model.ee_position(s.snapshot().q[1:])
    client.drag(TARGET_HANDLE, (ee[0] + 0.02, ee[1], ee[2]), "start")
    client.close()  # gone without a drag end
    wait_for_clients(trep_app, 0, "the client to disconnect")
    s.advance(1.0)
    assert not s.snapshot().paused and s.snapshot().t > 0.9
    other = ProtocolClient(trep_app.port, decode=True)
    try:
        wait_for_clients(trep_app, 1, "a new client")
        other.click(uuid(trep_app.gui.kick))
        queued(trep_app, "Kick")
    finally:
        other.close()


def test_with_a_password_unknown_clients_only_watch() -> None:
    app = start_app("trep", port=0, realtime=False, verbose=False, password="s3cret")
    ws = ProtocolClient(app.port, decode=True)
    try:
        wait_for_clients(app, 1, "a client")
        ws.click(uuid(app.gui.kick))
        wait_until(lambda: ws.types["NotificationShowMessage"] >= 1, 10.0, "the 'View only' notice")
        assert app.session.pending_commands() == []
        app.gui.kick.value = True  # the server itself (and tests) may always operate
        queued(app, "Kick")
    finally:
        ws.close()
        app.stop()


def test_a_scene_build_that_fails_once_is_done_again_whole(trep_app: RnsApp, monkeypatch: pytest.MonkeyPatch) -> None:
    """A model switch whose scene build raises half-way (viser's message buffer once raised "deque mutated
    during iteration" there, a message from the render thread racing viser's event loop) is built again
    from a reset scene at the next frame: the app reaches the new model with its overlays, not a scene
    whose labels were removed under it for good."""
    real, failures = render.TeachScene, []

    def flaky(*args: object, **kwargs: object) -> render.TeachScene:
        if not failures:
            failures.append(1)
            raise RuntimeError("deque mutated during iteration")  # what viser raised
        return real(*args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(render, "TeachScene", flaky)
    s = trep_app.session
    s.switch_model("planar3r")
    s.advance(0.1)
    wait_until(lambda: trep_app.model_name == "planar3r", 20.0, "the 3R's scene")
    assert failures == [1]
    drawn = trep_app.renderer
    drawn.teach.null_label.visible = drawn.teach.null_label.visible  # raises on a label removed under the scene
    s.kick(5.0)
    for step in range(3):  # each step moves the arm, and the new scene draws it
        frames = drawn.scene_updates
        s.advance(0.1)
        wait_until(lambda frames=frames: drawn.scene_updates > frames, 10.0, f"the new scene's frame {step + 1}")
