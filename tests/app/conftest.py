"""The app tests' fixtures: stepped apps of TREP and the 3R, and a protocol client of one."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from rns_viz.viz.server.app import RnsApp
from tests.support.app_helpers import stepped_app
from tests.support.browser import wait_for_clients
from tests.support.protocol_client import ProtocolClient


@pytest.fixture
def trep_app() -> Iterator[RnsApp]:
    """TREP's app, stepped by the test (tests/support/app_helpers.py)."""
    yield from stepped_app("trep")


@pytest.fixture
def planar_app() -> Iterator[RnsApp]:
    yield from stepped_app("planar3r")


@pytest.fixture
def client(request: pytest.FixtureRequest) -> Iterator[ProtocolClient]:
    """A protocol-level websocket client of the app fixture named by indirect parametrisation."""
    app: RnsApp = request.getfixturevalue(request.param)
    ws = ProtocolClient(app.port, decode=True)
    wait_for_clients(app, 1, "the websocket client to connect")
    yield ws
    ws.close()
