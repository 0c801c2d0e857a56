"""boom7's reaction arrows: the scene draws the six rows of the arm's reaction −(H_bm θ'' + c_b) (Eq. 1)
at the tip as a force arrow and a moment arrow in the base frame with the stated scale; a planar model
keeps its single arrow (the rows published by the loop: tests/session/test_reaction_wrench.py)."""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pytest
import viser

from rns_viz.model import FsmsModel
from rns_viz.viz import FsmsScene


@pytest.fixture(scope="module")
def server() -> Iterator[viser.ViserServer]:
    srv = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    yield srv
    srv.stop()


def test_boom7_draws_a_force_and_a_moment_arrow(server: viser.ViserServer, boom7: FsmsModel) -> None:
    scene = FsmsScene(server, boom7)
    assert scene.wrench is not None
    st = scene.style
    f, m = np.array([1.0, 2.0, 0.0]), np.array([0.0, 0.0, 0.5])  # N, N m
    scene.set_reaction_force(1.0, "arm reaction", (*f, *m))
    force, moment = (np.asarray(a.points)[0] for a in scene.wrench.arrows)
    assert all(a.visible for a in scene.wrench.arrows) and not scene.force.visible
    assert np.allclose(force[1] - force[0], f * st.force_scale)  # along F, force_scale m per N
    assert np.allclose(moment[1] - moment[0], m * st.force_scale)  # along M's axis, force_scale m per N m
    assert "m per N m" in scene.wrench.labels[1].text and "0.5 N m" in scene.wrench.labels[1].text
    scene.set_reaction_force(0.0, "arm reaction", (0.0,) * 6)
    assert not any(a.visible for a in scene.wrench.arrows)
    scene.set_reaction_force(0.0, "arm reaction", (1e6, 0.0, 0.0, 0.0, 0.0, 0.0))  # clipped
    force = np.asarray(scene.wrench.arrows[0].points)[0]
    assert np.isclose(np.linalg.norm(force[1] - force[0]), st.force_arrow_max)


def test_a_planar_model_keeps_its_single_arrow(server: viser.ViserServer, trep: FsmsModel) -> None:
    scene = FsmsScene(server, trep)
    assert scene.wrench is None
    scene.set_reaction_force(0.5, "arm reaction", (0.5,))
    assert scene.force.visible
