"""The layering of pyproject.toml's [tool.importlinter] contracts holds (viz -> live -> sim -> control ->
model; only the viz layer imports viser). On failure, ``lint-imports`` prints the offending imports."""

from __future__ import annotations

import pytest
from importlinter.cli import EXIT_STATUS_SUCCESS, lint_imports

from tests.support.repo import REPO

PYPROJECT = REPO / "pyproject.toml"


def test_import_contracts_are_kept(capsys: pytest.CaptureFixture[str]) -> None:
    status = lint_imports(config_filename=str(PYPROJECT), no_cache=True, no_logo=True)
    assert status == EXIT_STATUS_SUCCESS, capsys.readouterr().out
