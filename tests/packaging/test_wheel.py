"""The package as a user installs it: an sdist and a wheel built from this tree, the wheel installed
into a fresh virtual environment and run from a temporary folder (not the source tree).

Deselected by default (it builds and installs, about half a minute); CI runs it as its own step:
``python -m pytest -m wheel -n 0 tests/packaging``. The venv sees the system's site-packages so that
pinocchio is not downloaded again; the test checks that ``rns_viz`` itself comes from the wheel.
"""

from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
import time
import urllib.request
import zipfile
from pathlib import Path

import pytest

from rns_viz.params import MODEL_NAMES, missing_extra
from tests.support.repo import REPO

pytestmark = pytest.mark.wheel


def _run(command: list[str], cwd: Path, check: bool = True, timeout: float = 600) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV", "PYTHONHOME")}
    result = subprocess.run(command, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
    if check and result.returncode != 0:
        pytest.fail(f"{' '.join(command)} exited {result.returncode}:\n{result.stdout}\n{result.stderr}")
    return result


@pytest.fixture(scope="module")
def installed(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, Path]:
    """(the venv's bin folder, a working folder outside the tree, the dist folder)."""
    root = tmp_path_factory.mktemp("wheel")
    dist = root / "dist"
    _run([sys.executable, "-m", "build", "--outdir", str(dist), str(REPO)], cwd=root)
    _run([sys.executable, "-m", "twine", "check", "--strict", *map(str, dist.iterdir())], cwd=root)
    venv = root / "venv"
    _run([sys.executable, "-m", "venv", "--system-site-packages", str(venv)], cwd=root)
    bin_dir = venv / "bin"
    (wheel,) = dist.glob("*.whl")
    # --no-index: every dependency must already be satisfied (by the system's site-packages here)
    _run([str(bin_dir / "python"), "-m", "pip", "install", "--no-index", str(wheel)], cwd=root)
    work = root / "work"
    work.mkdir()
    return bin_dir, work, dist


def test_wheel_and_sdist_carry_the_bundled_models(installed: tuple[Path, Path, Path]) -> None:
    _, _, dist = installed
    (wheel,) = dist.glob("*.whl")
    names = set(zipfile.ZipFile(wheel).namelist())
    for model in MODEL_NAMES:
        assert f"rns_viz/assets/{model}.toml" in names
    assert not any(name.startswith(("tests/", "benchmarks/", "native/", "examples/")) for name in names)
    assert any(name.endswith("licenses/LICENSE") or name.endswith("/LICENSE") for name in names)


def test_installed_package_is_the_wheels(installed: tuple[Path, Path, Path]) -> None:
    bin_dir, work, _ = installed
    out = _run([str(bin_dir / "python"), "-c", "import rns_viz; print(rns_viz.__file__)"], cwd=work).stdout
    assert Path(out.strip()).is_relative_to(bin_dir.parent), out


@pytest.mark.parametrize("model", MODEL_NAMES)
def test_every_bundled_model_loads_from_the_wheel(installed: tuple[Path, Path, Path], model: str) -> None:
    bin_dir, work, _ = installed
    result = _run([str(bin_dir / "rns-viz"), "info", "--model", model], cwd=work, check=False)
    extra = missing_extra(model)
    if extra is not None:  # a model of an optional extra: refused with the install command, exit 2
        assert result.returncode == 2 and f"rns-viz[{extra}]" in result.stderr, result.stderr
        return
    assert result.returncode == 0, result.stderr
    info = json.loads(result.stdout)
    assert Path(info["parameters"]).is_relative_to(bin_dir.parent)  # read from the installed package
    assert info["base_dof"] >= 1


def test_a_preset_runs_from_the_wheel(installed: tuple[Path, Path, Path]) -> None:
    bin_dir, work, _ = installed
    _run([str(bin_dir / "rns-viz"), "run", "fig10-on", "--csv", "fig10.csv", "--duration", "0.5"], cwd=work)
    lines = (work / "fig10.csv").read_text().splitlines()
    assert lines[0].startswith("t (s),")
    assert len(lines) == 1 + 500  # a header, then one row per 1 ms step


def test_the_app_serves_from_the_wheel(installed: tuple[Path, Path, Path]) -> None:
    bin_dir, work, _ = installed
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    server = subprocess.Popen(
        [str(bin_dir / "rns-viz"), "serve", "--port", str(port)],
        cwd=work,
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        page = ""
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and server.poll() is None:
            try:
                with urllib.request.urlopen(f"http://127.0.0.1:{port}/", timeout=2) as response:
                    page = response.read().decode()
                break
            except OSError:
                time.sleep(0.5)
        assert server.poll() is None, server.stderr.read() if server.stderr else ""
        assert "<html" in page.lower()  # viser's client page, served by the installed app
    finally:
        server.terminate()
        server.wait(timeout=30)
