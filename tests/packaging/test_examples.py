"""Every script of the gallery (examples/) runs headless from a temporary folder and does what its
docstring says; the viser one serves, draws and stops, leaving no server behind."""

from __future__ import annotations

import os
import re
import socket
import subprocess
import sys
from pathlib import Path

import pytest

from tests.support.repo import REPO

EXAMPLES = sorted((REPO / "examples").glob("[0-9][0-9]_*.py"))


def _run(script: str, tmp_path: Path, *args: str) -> str:
    env = {**os.environ, "PYTHONPATH": str(REPO), "MPLBACKEND": "Agg"}
    command = [sys.executable, str(REPO / "examples" / script), *args]
    result = subprocess.run(command, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    return result.stdout


def _numbers(text: str) -> list[float]:
    return [float(x) for x in re.findall(r"[-+]?\d+\.?\d*(?:e[-+]?\d+)?", text)]


def test_the_gallery_is_numbered_and_documented() -> None:
    assert [p.name[:2] for p in EXAMPLES] == [f"{i:02d}" for i in range(1, len(EXAMPLES) + 1)]
    gallery = (REPO / "docs" / "gallery.md").read_text()
    for path in EXAMPLES:
        assert path.read_text().startswith('"""'), path.name  # a docstring says what it shows
        assert f"examples/{path.name}" in gallery, path.name  # and the docs show it


def test_01_reactionless_paths(tmp_path: Path) -> None:
    out = _run("01_reactionless_paths.py", tmp_path, "--out", str(tmp_path))
    assert _numbers(out)[0] == 16 and (tmp_path / "01_reactionless_paths.png").stat().st_size > 0


def test_02_kick_decays_only_with_suppression(tmp_path: Path) -> None:
    out = _run("02_kick_with_and_without_suppression.py", tmp_path, "--out", str(tmp_path))
    on, held = (line for line in out.splitlines() if "last second" in line)
    on_late, held_late = _numbers(on.split("mm,")[1])[0], _numbers(held.split("mm,")[1])[0]
    assert on_late < 0.1 * held_late  # law (30) damps the beam; held, it rings on (no structural damping)


def test_03_gain_map_at_the_papers_gains(tmp_path: Path) -> None:
    out = _run("03_gain_map.py", tmp_path, "--out", str(tmp_path))
    assert "10 % in 6.0 s, sigma_b 0.383 1/s" in out  # Fig. 10's gains, as the gain explorer and the docs state


def test_04_custom_model_loads_and_suppresses(tmp_path: Path) -> None:
    out = _run("04_custom_model.py", tmp_path, "--out", str(tmp_path))
    assert (tmp_path / "two_link.toml").is_file() and (tmp_path / "two_link.urdf").is_file()
    h_b = float(re.search(r"H_b = ([\d.]+) kg", out).group(1))
    assert h_b == pytest.approx(3.0 + 1.0 + 0.6, abs=0.005)  # platform + both links along x
    peak, end = (float(x) for x in re.search(r"peak ([\d.]+) mm, after 4 s ([\d.]+) mm", out).groups())
    assert end < 0.01 * peak


def test_05_recording_round_trips(tmp_path: Path) -> None:
    out = _run("05_recording.py", tmp_path, "--out", str(tmp_path))  # asserts the CSV gives back the floats
    fast, joint2 = (float(re.search(r"peak \|x_b\| (\S+) m", line).group(1)) for line in out.splitlines())
    assert fast < 0.01 * joint2  # the reactionless path hardly moves the base (Fig. 11)


def test_06_boom_3d_serves_and_stops(tmp_path: Path) -> None:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    out = _run("06_boom_3d.py", tmp_path, "--port", str(port), "--seconds", "1")
    assert "boom7-kick-on" in out
    with socket.socket() as probe:  # the script returned, so its server let go of the port
        probe.bind(("127.0.0.1", port))
