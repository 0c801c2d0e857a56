"""A reachable set asked for while the gain explorer sweeps boom7's path goes first in the shared helper
process (rns_viz.live.jobs.helper): it waits for the one explorer call in flight, not the whole sweep; the
explorer finishes after it, and both results equal the same computations made directly."""

from __future__ import annotations

import threading
import time

import numpy as np
import pytest

from rns_viz.analysis import authority, loops_along
from rns_viz.control import Gains
from rns_viz.live.explorer.gain_explorer import AUTHORITY_CHUNK, GainExplorer
from rns_viz.live.jobs import helper as jobs
from rns_viz.live.jobs.background import Background, ReachReady
from rns_viz.live.reach.region import build_reach_region
from rns_viz.model import FsmsModel
from rns_viz.params import model_key

FORCES_ONLY_KEY = "boom7#S=111000"  # r = 3: its reachable set is a volume (a 4-D RNS)
SWEEP = 4 * AUTHORITY_CHUNK  # configurations: four explorer calls


def test_selection_key_names_forces_only() -> None:
    assert model_key("boom7", (1, 1, 1, 0, 0, 0)) == FORCES_ONLY_KEY


def test_a_reach_request_overtakes_the_gain_explorers_sweep(monkeypatch: pytest.MonkeyPatch, boom7: FsmsModel) -> None:
    theta0 = boom7.spec.default_configuration
    thetas = theta0 + np.outer(np.linspace(0.0, 0.4, SWEEP), np.ones(boom7.n))  # rad, inside the limits
    assert np.all(thetas < boom7.upper) and np.all(thetas > boom7.lower)
    ee = np.array([boom7.ee_position(t) for t in thetas])
    gains = Gains(g_b=10.0, g_m=2.0)

    started: list[str] = []  # the helper's jobs in the order they got it
    mid_sweep = threading.Event()
    run = jobs._Helper._run
    ours: set[threading.Thread] = set()  # the explorer's and the background's threads (in the suite's worker, a
    # session an earlier test stopped may still send a request it had waiting for the helper)

    def watched(helper: jobs._Helper, name: str, request: bytes) -> bytes:
        if threading.current_thread() not in ours:
            return run(helper, name, request)
        started.append(name)
        if name == "authority_at" and started.count("authority_at") == 2:
            mid_sweep.set()  # the sweep's second call holds the helper until the reach request waits
            deadline = time.monotonic() + 120.0
            while not helper.urgent_waiting and time.monotonic() < deadline:
                time.sleep(0.005)
        return run(helper, name, request)

    monkeypatch.setattr(jobs._Helper, "_run", watched)
    monkeypatch.setattr(jobs._helper, "cache", jobs.ReplyCache())  # every request computed here
    explorer, background = GainExplorer(), Background()
    ours.update({explorer.worker._thread, background.worker._thread})
    try:
        explorer.context(0, "boom7", "acceleration", theta0, gains)
        explorer.along("boom7", thetas, ee)
        assert mid_sweep.wait(300.0)
        asked = len(started)
        background.reach(0, FORCES_ONLY_KEY, theta0)
        assert background.wait_idle(300.0) and explorer.worker.wait_idle(300.0)
        reach_at = started.index("reach_region")
        # Bound in explorer calls: none got the helper between the request and the reachable set ...
        assert started[asked:reach_at] == []
        # ... and the sweep was not starved: it went on after it, to its end.
        assert started[reach_at + 1 :].count("authority_at") == SWEEP // AUTHORITY_CHUNK - 2
        (ready,) = [r for r in background.results(lambda: 0) if isinstance(r, ReachReady)]
        direct = build_reach_region(FsmsModel.from_key(FORCES_ONLY_KEY), theta0)
        np.testing.assert_array_equal(ready.region.points, direct.points)
        np.testing.assert_array_equal(ready.region.thetas, direct.thetas)
        assert explorer.collect()
        found = explorer.view.authority
        assert found is not None
        expected = authority(loops_along(boom7, "acceleration", thetas), gains.g_b, gains.g_m)
        for field in ("base_decay_rate", "arm_decay_rate", "coupling_norm"):
            np.testing.assert_allclose(getattr(found, field), getattr(expected, field), rtol=1e-9, atol=1e-12)
    finally:
        explorer.stop()
        background.stop()
