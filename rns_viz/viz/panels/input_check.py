"""Widget conformity of raw GUI values: a value the control itself could hold (type, range, options).

viser casts a client's value with ``type(current)(new)`` before our callbacks run, so NaN, +-inf
and out-of-range numbers still arrive here; anything else odd (a server-side assignment of the
wrong type) too. :func:`check_value` raises ``ValueError`` with a message for the user. What a
value means (a stable gain, a reachable target) is the session's to check, not this module's.
"""

from __future__ import annotations

import math
from typing import Any

import viser

RANGE_SLACK = 1e-9  # relative: a value this close outside a slider's range counts as inside


def _number(label: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ValueError(f"{label}: expected a number, got {value!r}")
    if not math.isfinite(value):
        raise ValueError(f"{label}: {value} is not a finite number")
    return float(value)


def check_value(handle: Any, value: Any) -> None:
    """Raise ValueError unless ``value`` is a valid value of the control ``handle``."""
    label = getattr(handle, "label", "input")
    if isinstance(handle, viser.GuiSliderHandle | viser.GuiNumberHandle):
        x = _number(label, value)
        lo, hi = handle.min, handle.max
        slack = RANGE_SLACK * max(1.0, abs(lo or 0.0), abs(hi or 0.0))
        if (lo is not None and x < lo - slack) or (hi is not None and x > hi + slack):
            raise ValueError(f"{label}: {x:g} is outside the allowed range [{lo:g}, {hi:g}]")
    elif isinstance(handle, viser.GuiCheckboxHandle):
        if not isinstance(value, bool):
            raise ValueError(f"{label}: expected on or off, got {value!r}")
    elif isinstance(handle, viser.GuiDropdownHandle | viser.GuiButtonGroupHandle) and value not in handle.options:
        raise ValueError(f"{label}: {value!r} is not one of the choices")
