"""The headless figures: files are written, are real PNG images, and the CLI draws a subset."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
from PIL import Image

from rns_viz.csvio import read_csv
from rns_viz.figures import FIGURES, draw_all


def test_fig8_and_fig10_are_drawn(tmp_path: Path) -> None:
    written = draw_all(tmp_path, ["fig8", "fig10"])
    assert [p.name for p in written] == ["fig8.png", "fig10.png"]
    for path in written:
        image = np.asarray(Image.open(path).convert("L"))
        assert min(image.shape) >= 350
        assert image.std() > 10  # not a blank canvas: curves and text were drawn


def test_every_paper_figure_has_a_drawer() -> None:
    paper = {"fig3", "fig4", "fig8", "fig10", "fig11", "fig12"}
    assert set(FIGURES) == paper | {"gain_map_trep", "gain_map_planar3r"}  # and the gain maps


def test_cli_figures_rejects_unknown_names(tmp_path: Path) -> None:
    result = subprocess.run(
        [sys.executable, "-m", "rns_viz.cli", "figures", "--out", str(tmp_path), "--only", "fig99"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert result.returncode == 2
    assert "unknown figure fig99" in result.stderr and "Traceback" not in result.stderr


def test_cli_run_writes_the_documented_columns(tmp_path: Path) -> None:
    out = tmp_path / "fig10.csv"
    result = subprocess.run(
        [sys.executable, "-m", "rns_viz.cli", "run", "fig10-on", "--csv", str(out), "--duration", "1"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 0, result.stderr
    table = read_csv(out)
    header, data = list(table.columns), table.rows
    required = ["t", "xb_1", "xbdot_1", "theta_1", "theta_2", "thetadot_1", "thetadot_2", "tau_1", "tau_2"]
    required += ["fext_1", "ee_x", "ee_y", "ee_z"]
    assert header[: len(required)] == required
    assert table.units[: len(required)] == (
        "s",
        "m",
        "m/s",
        "rad",
        "rad",
        "rad/s",
        "rad/s",
        "N m",
        "N m",
        "N",
        "m",
        "m",
        "m",
    )
    assert data.shape == (1000, len(header))
    np.testing.assert_allclose(np.diff(data[:, 0]), 1e-3, atol=1e-9)
    peak_force = data[:, header.index("fext_1")].max()
    assert 0.7 < peak_force <= 0.8  # the kick of the preset (0.8 N half-sine) is in the log
