"""What every level of the tests shares: markers applied by folder, and the bundled models, each loaded once
per test session (``trep``, ``planar3r``, ``boom7``, ``trep2``, ``boom_panda``, or ``bundled_model(name)``
for a parametrised name; boom-panda skips without its extra, and ``panda_not_installed`` hides the extra).

Folders are levels: ``unit`` (pure functions and physics: the developer's loop, ``python -m pytest
tests/unit``), ``session`` (a headless Session), ``app`` (a viser server, protocol clients), ``browser``
(Chromium). Each test gets its folder's marker, so ``-m unit`` works from anywhere; a browser test also
gets the browser's skip-or-fail rule (tests/support/browser.py). The fixtures of one level live in its
folder's conftest.py.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Callable, Iterator
from dataclasses import replace
from pathlib import Path

import pytest

from rns_viz import robots
from rns_viz.model import FsmsModel
from rns_viz.params import missing_extra

LEVELS = ("unit", "session", "app", "browser")
TESTS = Path(__file__).resolve().parent


def pytest_xdist_auto_num_workers(config: pytest.Config) -> int | None:
    """``-n auto`` (pyproject's addopts): a worker per core, and one more when the run goes beyond tests/unit.
    The session, app and browser tests spend much of their time waiting (for simulated time in real time, a
    page, a helper process); the extra worker computes meanwhile. PYTEST_XDIST_AUTO_NUM_WORKERS still rules."""
    if os.environ.get("PYTEST_XDIST_AUTO_NUM_WORKERS"):
        return None  # xdist's own hook reads it
    cores = len(os.sched_getaffinity(0))
    unit = TESTS / "unit"
    paths = [Path(str(arg).split("::")[0]).resolve() for arg in config.args] or [TESTS]
    return cores if all(path.is_relative_to(unit) for path in paths) else cores + 1


@pytest.hookimpl(tryfirst=True)  # before xdist reads the groups and -m selects by marker
def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        level = item.path.relative_to(TESTS).parts[0] if item.path.is_relative_to(TESTS) else None
        if level not in LEVELS:
            continue
        item.add_marker(getattr(pytest.mark, level))
        if level == "browser":
            for mark in _browser_marks():
                item.add_marker(mark)


def pytest_sessionfinish() -> None:
    """Close the test process's shared Chromium, if a browser test started one (tests/support/browser.py)."""
    browser = sys.modules.get("tests.support.browser")
    if browser is not None:
        browser.CHROMIUMS.close()


def _browser_marks() -> list[pytest.MarkDecorator]:
    """The browser marker and its skip-or-fail rule (imported only when browser tests are collected:
    Playwright and the app are not needed below that level)."""
    from tests.support.browser import browser_marks

    return browser_marks


@pytest.fixture(scope="session")
def bundled_model() -> Callable[[str], FsmsModel]:
    """A bundled model by name, loaded once per test session and shared: a test that changes its model
    loads its own. A model whose optional extra is missing (boom-panda) skips the test."""
    loaded: dict[str, FsmsModel] = {}

    def load(name: str) -> FsmsModel:
        extra = missing_extra(name)
        if extra is not None:
            pytest.skip(f"{name} needs the optional extra: pip install 'rns-viz[{extra}]'")
        if name not in loaded:
            loaded[name] = FsmsModel.from_name(name)
        return loaded[name]

    return load


@pytest.fixture(scope="session")
def trep(bundled_model: Callable[[str], FsmsModel]) -> FsmsModel:
    return bundled_model("trep")


@pytest.fixture(scope="session")
def planar3r(bundled_model: Callable[[str], FsmsModel]) -> FsmsModel:
    return bundled_model("planar3r")


@pytest.fixture(scope="session")
def boom7(bundled_model: Callable[[str], FsmsModel]) -> FsmsModel:
    return bundled_model("boom7")


@pytest.fixture(scope="session")
def trep2(bundled_model: Callable[[str], FsmsModel]) -> FsmsModel:
    return bundled_model("trep2")


@pytest.fixture(scope="session")
def boom_panda(bundled_model: Callable[[str], FsmsModel]) -> FsmsModel:
    """The Franka Panda on boom7's boom; skips without example-robot-data (rns-viz[panda])."""
    return bundled_model("boom-panda")


@pytest.fixture
def panda_not_installed(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """example-robot-data as if absent: boom-panda's arm names a distribution that does not exist."""
    panda = "example-robot-data/panda"
    arm = robots.packaged_arm(panda)
    monkeypatch.setitem(robots.PACKAGED_ARMS, panda, replace(arm, distribution="rns-viz-no-such-distribution"))
    robots.is_installed.cache_clear()
    yield
    robots.is_installed.cache_clear()
