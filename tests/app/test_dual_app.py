"""trep2 in the app (headless server, no browser): both arms drawn, the compensator's readouts, and
what the app shows when the compensator cannot cancel (its singularity): the notice, the readout in
colour and the residual reaction arrow, checked against an independent evaluation of Eq. (1).
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pytest

from rns_viz.viz.panels.panel_text import BAD_COLOUR, OK_COLOUR, readouts_html
from rns_viz.viz.scene.ghost import GHOST_OFF_COLOUR
from rns_viz.viz.server.app import RnsApp, start_app
from tests.support.browser import wait_until
from tests.support.logs import independent_reaction, log_row


@pytest.fixture
def trep2_app() -> Iterator[RnsApp]:
    app = start_app("trep2", port=0, realtime=False, verbose=False)
    assert app.session.wait_background()
    yield app
    app.stop()


def test_both_arms_are_drawn_and_the_ghost_holds_its_compensator(trep2_app: RnsApp) -> None:
    app, s = trep2_app, trep2_app.session
    nodes = app.scene.robot.node_names
    assert any(name.endswith("c_link1") for name in nodes) and any(name.endswith("link1") for name in nodes)
    comp = app.model.arm_groups["compensating"].index + app.model.m
    start = s.snapshot().q[comp].copy()
    s.set_target((0.06, 0.16), final=True)
    s.advance(1.0)
    snap = s.snapshot()
    assert snap.q_shadow is not None
    assert np.abs(snap.q[comp] - start).max() > 0.05  # rad: the compensator moved to cancel
    np.testing.assert_allclose(snap.q_shadow[comp], start, atol=1e-3)  # the shadow's is held
    ghost = app.renderer.teach.ghost
    wait_until(lambda: ghost.q is not None and abs(ghost.q[0] - snap.q_shadow[0]) < 1e-4, 5.0, "the ghost")
    assert "cancelling" in readouts_html(snap) and OK_COLOUR in readouts_html(snap)
    assert ghost.colour == GHOST_OFF_COLOUR  # the held compensator's run: red, as "compensator held still" plots


def test_a_singular_compensator_is_shown_and_its_residual_reaction_drawn(trep2_app: RnsApp) -> None:
    """Compensator stretched along the beam's swing axis (S H_bm,2 = 0): it cannot cancel."""
    app, s = trep2_app, trep2_app.session
    shown: list[str] = []  # notices the render thread sends to the browsers
    send = app.connections.notify_by_id
    app.connections.notify_by_id = lambda client, title, *rest: (shown.append(title), send(client, title, *rest))
    model = s.state.model
    theta = model.spec.default_configuration.copy()
    theta[model.arm_groups["compensating"].index] = 0.0
    with s._lock:  # test set-up: both runs start in the singular pose
        for run in (s.state.runs.sim, s.state.runs.shadow):
            run.reset(q0=model.q(theta), v0=np.zeros(model.nv), t0=run.t)
    s.set_target((0.06, 0.16), final=True)
    s.advance(0.4)
    snap = s.snapshot()
    r = snap.readouts
    assert r.sigma_hbm < 1e-12 and r.cancel is not None and "singularity" in r.cancel
    assert BAD_COLOUR in readouts_html(snap)
    wait_until(lambda: "Reaction not cancelled" in shown, 5.0, "the notice")
    expected = independent_reaction(s.state.runs.sim.model, log_row(s, r.reaction_t))
    assert abs(expected) > 1e-4  # N: the task arm's reaction reaches the base
    assert abs(r.reaction - expected) < 1e-9
    wait_until(lambda: app.scene._force == s.snapshot().readouts.reaction, 5.0, "the residual reaction arrow")


def test_rank_overlay_toggle_draws_the_rank_deficient_poses() -> None:
    app = start_app("trep", port=0, realtime=False, verbose=False)
    try:
        rank = app.renderer.rank
        assert not app.view.on("rank") and rank.overlay is None  # off by default, not computed
        app.view.boxes["rank"].value = True
        # the render thread computes the overlay, builds its nodes, then shows them
        wait_until(lambda: rank._nodes and all(node.visible for node in rank._nodes), 10.0, "the rank overlay drawn")
        assert rank.overlay is not None and len(rank.overlay.poses) == 4
    finally:
        app.stop()


def test_the_gain_explorer_offers_nothing_it_does_not_compute(trep2_app: RnsApp) -> None:
    """A compensating arm's loop is not analysed: no empty root-locus charts, no quantity to choose for a map."""
    ex = trep2_app.renderer.explorer
    wait_until(lambda: not ex.locus_b.visible and not ex.locus_m.visible, 10.0, "the loci hidden")
    assert not ex.locus_note.visible and ex.quantity.disabled and ex.quantity.hint.startswith("Not for this model")
