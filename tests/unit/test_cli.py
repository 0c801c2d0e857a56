"""The console script: JSON info, CSV paths, and one-line errors for bad arguments."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from rns_viz.csvio import read_csv
from tests.support.oracles.closed_forms import trep_ee
from tests.support.repo import ASSETS


def run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "rns_viz.cli", *args], capture_output=True, text=True, timeout=120)


@pytest.mark.parametrize(("model", "m", "n", "hb"), [("trep", 1, 2, 1.225), ("planar3r", 1, 3, 31.0)])
def test_info(model: str, m: int, n: int, hb: float) -> None:
    result = run("info", "--model", model)
    assert result.returncode == 0, result.stderr
    info = json.loads(result.stdout)
    assert info["model"] == model and info["base_dof"] == m and info["arm_dof"] == n
    assert len(info["arm_joints"]) == n and len(info["default_configuration_rad"]) == n
    assert info["H_b_kg"][0] == pytest.approx([hb])
    assert np.array(info["K_b_N_per_m"]).shape == (m, m)
    assert Path(info["urdf"]).is_file()


def test_paths_csv(tmp_path: Path) -> None:
    out = tmp_path / "paths.csv"
    result = run("paths", "--model", "trep", "--count", "6", "--csv", str(out))
    assert result.returncode == 0, result.stderr
    table = read_csv(out)
    assert table.columns == ("path", "s", "theta_1", "theta_2", "ee_x", "ee_y", "ee_z")
    assert table.units == ("index", "rad", "rad", "rad", "m", "m", "m")
    assert set(table.column("path")) == set(range(6))
    for r in table.rows[::7]:
        np.testing.assert_allclose(r[4:7], trep_ee(r[2:4]), atol=1e-12)


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (["info", "--model", "nope"], "invalid choice"),
        (["paths", "--count", "0", "--csv", "x.csv"], "at least 1"),
        (["paths", "--count", "-3", "--csv", "x.csv"], "at least 1"),
        (["paths", "--count", "many", "--csv", "x.csv"], "whole number"),
        (["paths", "--csv", "/no/such/dir/x.csv"], "cannot write"),
        (["paths", "--model", "planar3r", "--csv", "PLACEHOLDER"], "1-D RNS"),
    ],
)
def test_bad_arguments_give_one_clear_line(args: list[str], fragment: str, tmp_path: Path) -> None:
    args = [str(tmp_path / "x.csv") if a == "PLACEHOLDER" else a for a in args]
    result = run(*args)
    assert result.returncode != 0
    assert "Traceback" not in result.stderr
    assert fragment in result.stderr
    assert result.stderr.strip().splitlines()[-1].startswith(("rns-viz", "usage"))


@pytest.mark.parametrize(
    ("urdf", "fragment"),
    [
        ("<robot name='x'><link name='a'/>", "not well-formed XML at line 1"),
        (
            "<robot name='x'><link name='a'/><joint name='j' type='prismatic'><parent link='a'/>"
            "<child link='zz'/><limit lower='-1' upper='1' effort='1' velocity='1'/></joint></robot>",
            "<joint name='j'>: <child link='zz'> names no <link>",
        ),
        (
            "<robot name='x'><link name='a'/><link name='b'/><joint name='j' type='revolute'>"
            "<parent link='a'/><child link='b'/></joint></robot>",
            "a revolute joint needs a <limit>",
        ),
    ],
)
def test_malformed_urdf_names_file_and_element(tmp_path: Path, urdf: str, fragment: str) -> None:
    (tmp_path / "robot.urdf").write_text(urdf)
    params = (ASSETS / "trep.toml").read_text()
    (tmp_path / "robot.toml").write_text(params.replace('urdf = "trep.urdf"', 'urdf = "robot.urdf"'))
    result = run("info", "--model", str(tmp_path / "robot.toml"))
    assert result.returncode == 2
    assert "Traceback" not in result.stderr
    assert "robot.urdf" in result.stderr and fragment in result.stderr


def test_malformed_parameter_file(tmp_path: Path) -> None:
    params = (ASSETS / "trep.toml").read_text()
    bad = tmp_path / "bad.toml"
    bad.write_text(params.replace("stiffness = [[77.9218]]", 'stiffness = [["stiff"]]'))
    result = run("info", "--model", str(bad))
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert "bad.toml: [base] stiffness[0][0]: expected a number, got a string" in result.stderr


def test_model_dir_offers_model_files_and_names_the_others(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    """``serve --model-dir``: a student's folder may hold anything; a model file joins the dropdown, a file that
    is not one is named on stderr and left out (the app still starts)."""
    from rns_viz.cli import _models_in
    from tests.support.app_helpers import user_model

    good = user_model(tmp_path)
    (tmp_path / "pyproject.toml").write_text('[project]\nname = "not-a-model"\n')
    (tmp_path / "notes.txt").write_text("not a parameter file")
    assert _models_in(tmp_path) == [str(good.resolve())]
    assert "pyproject.toml" in capsys.readouterr().err
    assert _models_in(tmp_path / "absent") == []  # no folder yet: nothing offered, no error


def test_jupyter_entry_point_serves_on_loopback_with_the_students_model_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """What jupyter-server-proxy is given: a command on loopback at the proxy's port with the model folder,
    an existing SVG icon for the launcher, and the root redirected to the page (tests/browser runs it)."""
    from rns_viz.cli import build_parser
    from rns_viz.jupyter import setup_rns_viz

    monkeypatch.setenv("RNS_VIZ_MODEL_DIR", str(tmp_path))
    spec = setup_rns_viz()
    command = spec["command"](port=43210)
    args = build_parser().parse_args(command[3:])  # after "python -m rns_viz.cli"
    assert (args.host, args.port, args.model_dir) == ("127.0.0.1", 43210, str(tmp_path))
    icon = Path(spec["launcher_entry"]["icon_path"])
    assert icon.suffix == ".svg" and "<svg" in icon.read_text()
    assert spec["launcher_entry"]["title"] == "rns_viz" and spec["timeout"] >= 30.0
