"""Sphinx configuration of rns_viz's documentation (furo theme, MyST Markdown, autodoc)."""

from __future__ import annotations

import importlib.metadata

project = "rns_viz"
author = "rns_viz contributors"
copyright = "2026, rns_viz contributors"
release = importlib.metadata.version("rns_viz")

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
myst_enable_extensions = ["colon_fence", "dollarmath", "deflist"]
myst_heading_anchors = 3
exclude_patterns = ["_build", "screenshots/README.md"]

html_theme = "furo"
html_title = "rns_viz"
html_static_path: list[str] = []

autodoc_default_options = {"members": True, "show-inheritance": True}
autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_preserve_defaults = True
napoleon_google_docstring = True
napoleon_numpy_docstring = False
