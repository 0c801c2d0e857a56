"""Shared fixtures: the bundled models, built once per session."""

from __future__ import annotations

import pytest

from rns_viz.model import FsmsModel


@pytest.fixture(scope="session")
def trep() -> FsmsModel:
    return FsmsModel.from_name("trep")


@pytest.fixture(scope="session")
def planar3r() -> FsmsModel:
    return FsmsModel.from_name("planar3r")
