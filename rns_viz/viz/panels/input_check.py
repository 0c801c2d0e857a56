"""Widget conformity of raw GUI values: a value the control itself could hold (type, range, options).

viser casts a client's value with ``type(current)(new)`` before our callbacks run, so NaN, +-inf
and out-of-range numbers still arrive here; anything else odd (a server-side assignment of the
wrong type) too. :func:`check_value` raises ``ValueError`` with a message for the user. What a
value means (a stable gain, a reachable target) is the session's to check, not this module's.
Typed numbers arrive as text: :func:`parse_number` reads them (and only reads them).
"""

from __future__ import annotations

import math
import re
from typing import Any

import viser

from rns_viz.out_of_range import OutOfRange, check_range, split_label

RANGE_SLACK = 1e-9  # relative: a value this close outside a slider's range counts as inside


def check_value(handle: Any, value: Any) -> None:
    """Raise ValueError unless ``value`` is a valid value of the control ``handle`` (OutOfRange for a number
    that is not a finite one in a slider's range, worded with the slider's label)."""
    label = getattr(handle, "label", "input")
    if isinstance(handle, viser.GuiSliderHandle | viser.GuiNumberHandle):
        lo = -math.inf if handle.min is None else handle.min
        hi = math.inf if handle.max is None else handle.max
        slack = RANGE_SLACK * max(1.0, *(abs(b) for b in (lo, hi) if math.isfinite(b)))
        name, unit = split_label(label)
        try:
            check_range(name, value, lo - slack, hi + slack, unit)
        except OutOfRange as exc:  # said with the slider's own range, not the slack's
            raise OutOfRange(name, exc.value, lo, hi, unit) from None
    elif isinstance(handle, viser.GuiCheckboxHandle):
        if not isinstance(value, bool):
            raise ValueError(f"{label}: expected on or off, got {value!r}")
    elif isinstance(handle, viser.GuiDropdownHandle | viser.GuiButtonGroupHandle) and value not in handle.options:
        raise ValueError(f"{label}: {value!r} is not one of the choices")


def parse_number(label: str, text: str) -> float:
    """The number a person typed (``1e9``, ``-0.5``, `` 12 ``; ``-0`` is 0); ValueError if it is none.

    Only the reading: whether the number is finite and in range is checked by what it becomes."""
    try:
        value = float(text.strip())
    except (AttributeError, ValueError):
        shown = text if len(str(text)) <= 40 else f"{str(text)[:40]}…"
        raise ValueError(f"{label}: {shown!r} is not a number (numbers look like 2.5, -0.3 or 1e-3)") from None
    return value + 0.0  # -0.0 becomes 0.0


# A number's beginning that is not yet a number: "", "-", ".", "1e", "2.5e-" (the reading waits longer).
_NUMBER_START = re.compile(r"\s*[+-]?((\d+\.?\d*|\.\d*)([eE][+-]?)?)?\s*")


def is_unfinished_number(text: str) -> bool:
    """``text`` is how a number begins but is not one yet (``1e-`` on the way to ``1e-3``)."""
    if _NUMBER_START.fullmatch(text) is None:
        return False
    try:
        float(text)
    except ValueError:
        return True
    return False
