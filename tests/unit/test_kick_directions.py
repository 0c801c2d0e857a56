"""boom7's kick directions as the base panel weighs them: the force along a translation, its moment at
KICK_LEVER_M about a rotation (each direction kicked in a session: tests/session/test_kick_directions.py)."""

from __future__ import annotations

import pytest

from rns_viz.defaults import KICK_LEVER_M
from rns_viz.model import FsmsModel
from rns_viz.viz.panels.base_panel import kick_weights


@pytest.fixture(scope="module")
def turns(boom7: FsmsModel) -> tuple[bool, ...]:
    return boom7.base_rotational


def test_the_weights_are_the_force_on_translations_and_its_moment_on_rotations(turns: tuple[bool, ...]) -> None:
    assert turns == (False, False, False, True, True, True)  # x y z, then rx ry rz
    assert kick_weights(turns, None) == (1.0, 1.0, 1.0, KICK_LEVER_M, KICK_LEVER_M, KICK_LEVER_M)
    assert kick_weights(turns, 1) == (0.0, 1.0, 0.0, 0.0, 0.0, 0.0)
    assert kick_weights(turns, 5) == (0.0, 0.0, 0.0, 0.0, 0.0, KICK_LEVER_M)
