"""Shared fixtures: the bundled models, built once per session; stepped apps, boom7's stepped session and a
protocol client."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from rns_viz.live.loop.session import Session
from rns_viz.model import FsmsModel
from rns_viz.viz.server.app import RnsApp
from tests.app_helpers import stepped_app, stepped_session
from tests.browser import wait_for_clients
from tests.protocol_client import ProtocolClient


@pytest.fixture(scope="session")
def trep() -> FsmsModel:
    return FsmsModel.from_name("trep")


@pytest.fixture(scope="session")
def planar3r() -> FsmsModel:
    return FsmsModel.from_name("planar3r")


@pytest.fixture
def trep_app() -> Iterator[RnsApp]:
    """TREP's app, stepped by the test (tests/app_helpers.py)."""
    yield from stepped_app("trep")


@pytest.fixture
def planar_app() -> Iterator[RnsApp]:
    yield from stepped_app("planar3r")


@pytest.fixture
def boom() -> Iterator[Session]:
    """boom7's session, stepped by the test (no server), its path and reachable set computed."""
    yield from stepped_session("boom7")


@pytest.fixture
def client(request: pytest.FixtureRequest) -> Iterator[ProtocolClient]:
    """A protocol-level websocket client of the app fixture named by indirect parametrisation."""
    app: RnsApp = request.getfixturevalue(request.param)
    ws = ProtocolClient(app.port, decode=True)
    wait_for_clients(app, 1, "the websocket client to connect")
    yield ws
    ws.close()
