"""Many clients, real time: 8 protocol-level clients come and go at random while one drags the target.

No exception reaches the server log and the operator lock passes on when the operator's connection
dies mid-drag (the target stays where it was). That the simulation keeps real time meanwhile is a
separate test marked ``perf`` (not in the default run: a busy machine must not fail it).

The six churning clients run in a process of their own, as browser tabs do: in this process their
websocket threads would compete with the server for the interpreter lock, which no real client does.
"""

from __future__ import annotations

import logging
import math
import random
import subprocess
import sys
import threading
import time
from dataclasses import dataclass
from unittest import mock

import numpy as np
import pytest

from rns_viz.viz.server.app import TARGET_HANDLE, start_app
from tests.support.browser import wait_until
from tests.support.protocol_client import ProtocolClient, gui_uuid
from tests.support.repo import REPO

DURATION_S = 30.0  # wall seconds of churn when the real-time factor is asserted (the issue asks for 30 s)
BEHAVIOUR_S = 10.0  # wall seconds of churn for the behaviour alone: some 60 connects and deaths of clients
CHURNERS = 6  # plus the dragging operator and one steady watcher: 8 clients
MIN_RTF = 0.95


def churn(port: int, stop: threading.Event, seed: int, errors: list[BaseException]) -> None:
    rng = random.Random(seed)
    while not stop.is_set():
        try:
            c = ProtocolClient(port)
            stop.wait(rng.uniform(0.1, 1.5))
            c.abort() if rng.random() < 0.3 else c.close()
            stop.wait(rng.uniform(0.0, 0.5))
        except Exception as exc:  # the test fails on any client-side trouble too
            errors.append(exc)
            return


def churn_process(port: int, seconds: float) -> None:
    """Run CHURNERS churning clients for ``seconds``; exit 1 with the errors if any client failed."""
    stop = threading.Event()
    errors: list[BaseException] = []
    threads = [threading.Thread(target=churn, args=(port, stop, k, errors)) for k in range(CHURNERS)]
    for t in threads:
        t.start()
    time.sleep(seconds)
    stop.set()
    for t in threads:
        t.join(10.0)
    if errors:
        print(f"churning clients failed: {errors!r}", file=sys.stderr)
        sys.exit(1)


def new_client(app: object, port: int) -> tuple[ProtocolClient, int]:
    """A connected client, once the server's connect handler has registered it with the lock."""
    before = set(app.server.get_clients())  # type: ignore[attr-defined]
    c = ProtocolClient(port)
    wait_until(lambda: set(app.server.get_clients()) - before, 10.0, "the client to register")  # type: ignore[attr-defined]
    (cid,) = set(app.server.get_clients()) - before  # type: ignore[attr-defined]
    wait_until(lambda: cid in app.lock.clients(), 10.0, "the connect handler to run")  # type: ignore[attr-defined]
    return c, cid


@dataclass
class Churn:
    """What one run of the churn measured: overall and windowed real-time factors."""

    wall: float
    rtf: float
    windows: list[float]


def eight_clients_come_and_go_while_one_drags(capfd: pytest.CaptureFixture[str], seconds: float) -> Churn:
    """Run the churn for ``seconds`` (wall) on a fresh real-time app; assert what must hold whatever the machine's load.

    No divergence or pause during the churn; the operator's tab dying mid-drag ends the drag where it
    was and passes control on; the new operator's input counts; no traceback reaches the server log."""
    app = start_app("trep", port=0, realtime=True, verbose=False)
    s = app.session
    churners: subprocess.Popen[str] | None = None
    try:
        assert s.wait_background()
        dragger, dragger_id = new_client(app, app.port)
        assert app.lock.is_operator(dragger_id)
        watcher, watcher_id = new_client(app, app.port)
        churners = subprocess.Popen(
            [
                sys.executable,
                "-c",
                f"from tests.app.test_app_clients import churn_process; churn_process({app.port}, {seconds})",
            ],
            cwd=REPO,
            stderr=subprocess.PIPE,
            text=True,
        )
        ee = app.model.ee_position(s.snapshot().q[1:])
        wall0, sim0 = time.perf_counter(), s.snapshot().t
        rtfs: list[float] = []
        k = 0
        dragger.drag_phase(TARGET_HANDLE, "start")
        while time.perf_counter() - wall0 < seconds:
            phase = 2 * math.pi * k / 200
            dragger.drag(TARGET_HANDLE, (ee[0] + 0.05 * math.sin(phase), ee[1] + 0.05 * math.cos(phase), ee[2]))
            if k % 50 == 49:
                dragger.drag_phase(TARGET_HANDLE, "end")
                dragger.drag_phase(TARGET_HANDLE, "start")
            snap = s.snapshot()
            if math.isfinite(snap.rtf):
                rtfs.append(snap.rtf)
            assert snap.diverged is None and not snap.paused
            k += 1
            time.sleep(0.02)
        wall, sim = time.perf_counter() - wall0, s.snapshot().t - sim0
        churn = Churn(wall, sim / wall, rtfs)
        with capfd.disabled():
            print(f"\n8 clients for {wall:.1f} s: real-time factor {churn.rtf:.3f}", end="")
            print(f" (windows {min(rtfs):.3f}..{max(rtfs):.3f})" if rtfs else "")
        assert sim > 0.0

        # The operator's tab dies mid-drag: the drag ends where it was, the watcher gets control once the
        # grace for a reload of the operator's page is over (shortened here).
        dragger.drag(TARGET_HANDLE, (ee[0] + 0.03, ee[1] - 0.02, ee[2]))
        time.sleep(0.3)
        target = s.snapshot().target
        with mock.patch("rns_viz.live.operator.operator_lock.RELOAD_GRACE_S", 1.0):
            dragger.abort()
            wait_until(lambda: dragger_id not in app.server.get_clients(), 10.0, "the operator to be gone")
            wait_until(lambda: app.lock.operator not in (None, dragger_id), 10.0, "control to pass on")
        assert app.lock.operator != dragger_id and app.lock.operator in app.server.get_clients()
        time.sleep(0.3)
        assert target is not None and np.allclose(s.snapshot().target, target, atol=1e-6)
        _, churn_err = churners.communicate(timeout=30.0)
        assert churners.returncode == 0, churn_err[-3000:]
        wait_until(lambda: app.lock.operator == watcher_id, 10.0, "the steady watcher to operate")
        kicks = s.state.kicks_sent  # a count: a pulse may be over (and dropped) before a busy test looks
        watcher.gui_update(gui_uuid(app.gui.kick), value=True)  # the new operator's input counts
        wait_until(lambda: s.state.kicks_sent > kicks, 10.0, "the new operator's kick")
        watcher.close()
    finally:
        if churners is not None and churners.poll() is None:
            churners.kill()
        app.stop()
    out, err = capfd.readouterr()
    assert "Traceback" not in out + err, err[-3000:]
    return churn


def test_eight_clients_come_and_go_while_one_drags(
    capfd: pytest.CaptureFixture[str], caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level(logging.WARNING)
    eight_clients_come_and_go_while_one_drags(capfd, BEHAVIOUR_S)
    bad = [r for r in caplog.records if r.levelno >= logging.ERROR]
    assert not bad, [r.getMessage() for r in bad]


@pytest.mark.perf
def test_eight_clients_keep_real_time(capfd: pytest.CaptureFixture[str]) -> None:
    churn = eight_clients_come_and_go_while_one_drags(capfd, DURATION_S)
    assert churn.rtf >= MIN_RTF and np.median(churn.windows) >= MIN_RTF
