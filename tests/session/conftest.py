"""The session tests' fixtures: boom7's session, stepped by the test, its geometry computed."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from rns_viz.live.loop.session import Session
from tests.support.app_helpers import stepped_session


@pytest.fixture
def boom7_session() -> Iterator[Session]:
    """boom7's session, stepped by the test (no server), its path and reachable set computed."""
    yield from stepped_session("boom7")
