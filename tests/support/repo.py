"""Where the repository is, and where the installed package keeps its bundled models."""

from __future__ import annotations

from pathlib import Path

from rns_viz.params import ASSETS_DIR

REPO = Path(__file__).resolve().parents[2]
ASSETS = ASSETS_DIR  # the bundled URDFs and parameter files (package data of rns_viz)
