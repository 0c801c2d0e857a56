"""The README as a front page: short, its set-up commands exactly those CI runs, its commands valid,
its library snippet runnable, its links pointing at files that exist."""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

from rns_viz.cli import build_parser
from tests.support.repo import REPO

README = (REPO / "README.md").read_text()
START_COMMAND = "pip install -e . && rns-viz"
TEST_COMMAND = "pip install -e '.[test]' && python -m pytest -q"


def _blocks(language: str) -> list[str]:
    return re.findall(rf"```{language}\n(.*?)```", README, re.S)


def test_readme_is_a_front_page_with_the_two_set_up_commands() -> None:
    assert len(README.splitlines()) <= 150
    assert README.splitlines()[2].startswith("![")  # a picture first, under the title
    bash = [block.strip() for block in _blocks("bash")]
    assert bash[:2] == [START_COMMAND, TEST_COMMAND]
    assert TEST_COMMAND in (REPO / ".ci" / "run").read_text()  # CI runs the README's test command verbatim


def test_readme_commands_parse() -> None:
    commands = [line.split("#")[0].strip() for line in _blocks("bash")[2].splitlines()]
    assert len(commands) == 5
    parser = build_parser()
    for command in commands:
        words = shlex.split(command)
        assert words[0] == "rns-viz"
        parser.parse_args(words[1:])  # argparse exits (status 2) on a command the CLI does not take


def test_readme_library_snippet_runs(tmp_path: Path) -> None:
    (snippet,) = _blocks("python")
    env = {**os.environ, "PYTHONPATH": str(REPO), "MPLBACKEND": "Agg"}
    result = subprocess.run([sys.executable, "-c", snippet], cwd=tmp_path, env=env, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    peak, end = (float(x) for x in re.findall(r"(\d\.\d+e[-+]\d+) m", result.stdout))
    assert 1e-3 < peak < 1e-2 and end < 1e-3 * peak  # TREP's 0.8 N kick (about 5 mm), suppressed by law (15)


def test_readme_links_point_at_files() -> None:
    targets = re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", README)
    missing = [t for t in targets if not t.startswith("http") and not (REPO / t).exists()]
    assert not missing, missing
