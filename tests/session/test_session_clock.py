"""A real-time session's clock starts when its loop starts: time spent before (an app built around the
session) is neither simulated in a burst nor dropped as a stall (rns_viz.live.loop.session)."""

from __future__ import annotations

import time

from rns_viz.live.loop.session import Session
from rns_viz.live.loop.wall_clock import MAX_BACKLOG_S
from tests.support.browser import wait_until


def test_a_session_made_unstarted_waits_and_then_runs_without_a_backlog() -> None:
    s = Session("trep", realtime=True, start=False)
    try:
        time.sleep(2 * MAX_BACKLOG_S)  # longer than a stall the loop would catch up
        assert s.snapshot().t == 0.0  # nothing ran
        s.start()
        # the wait before start is not due: no backlog to run in a burst or to drop as a stall
        assert s.pacer.backlog(0.0, time.perf_counter()) < MAX_BACKLOG_S
        wait_until(lambda: s.snapshot().t > 0.2, 10.0, "the simulation to run")
        thread = s._thread
        s.start()  # a second start changes nothing
        assert s._thread is thread
    finally:
        s.stop()
