"""The joint-space inset of rank loss in the app: shown with the sentence on why, hidden for a model
without one (what it draws: tests/unit/test_rank_inset.py)."""

from __future__ import annotations

import numpy as np

from rns_viz.live.teaching.rank_view import RANK_HINT
from rns_viz.viz.server.app import start_app
from tests.support.browser import wait_until


def test_the_app_shows_the_inset_with_why_and_hides_it_without_one() -> None:
    app = start_app("trep", port=0, realtime=False, verbose=False)
    try:
        panel, s = app.rank_inset, app.session
        s.advance(0.05)
        assert not panel.folder.visible  # the box starts unticked
        app.view.boxes["rank"].value = True
        wait_until(lambda: panel.updates > 0 and panel.folder.visible, 20.0, "the inset")
        assert RANK_HINT in panel.text.content
        snap = s.snapshot()
        assert panel.theta is not None and np.allclose(panel.theta, snap.q[1:])
        s.switch_model("trep2")
        s.advance(0.01)
        wait_until(lambda: not panel.folder.visible, 20.0, "the inset hidden for trep2")
    finally:
        app.stop()
