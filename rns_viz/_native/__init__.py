"""The compiled part of rns_viz (``closed_loop.cpp`` next to this file), when it was built.

``core`` is the extension module ``rns_viz._closed_loop`` or None (no C++ compiler at install
time, or built against other pinocchio libraries); ``why`` then says what happened. pinocchio is
imported first: it loads the libraries the extension links and registers ``pin.Model``.
"""

from __future__ import annotations

from types import ModuleType

import pinocchio  # noqa: F401

core: ModuleType | None
why: str | None
try:
    from rns_viz import _closed_loop as core
except ImportError as exc:
    core, why = None, f"rns_viz._closed_loop did not import ({exc})"
else:
    why = None
