"""The documentation site builds with warnings as errors (broken references, docstrings that do not
parse, pages outside every toctree), so it cannot rot unnoticed. About 15 s: it runs by default."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from tests.support.repo import REPO


def test_sphinx_builds_the_site_without_warnings(tmp_path: Path) -> None:
    command = [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html", "-d", str(tmp_path / "trees")]
    result = subprocess.run([*command, str(REPO / "docs"), str(tmp_path / "html")], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    index = (tmp_path / "html" / "index.html").read_text()
    assert "rns_viz" in index
    api = (tmp_path / "html" / "api.html").read_text()
    assert "FsmsModel" in api and "AccelerationLaw" in api  # autodoc imported and documented the library
