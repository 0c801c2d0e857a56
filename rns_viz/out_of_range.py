"""A number refused for lying outside its range, and numbers written for people.

The check that refuses a number (a gain's, a command's, a control's) raises :class:`OutOfRange` with the
range and unit it checked against; whoever shows the refusal words it: the library with its own name of
the quantity, the app with the label of the control the number was typed into. Numbers read as people
write them: ``1 000 000`` and ``10⁹``, not ``1e+06`` and ``1e+09``.
"""

from __future__ import annotations

import math
import re

GROUP = "\u202f"  # narrow no-break space between digit groups (SI): 1 000 000, never broken across lines
_SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")
LARGE, SMALL = 1e7, 1e-3  # magnitudes from LARGE up and below SMALL are written with a power of ten


def readable(x: float) -> str:
    """``x`` as a person writes it: 0.25, −5, 10 000, 1 000 000, 10⁹, 2.5 × 10⁻⁷, NaN, ∞ (six digits at most)."""
    if math.isnan(x):
        return "NaN"
    sign = "−" if x < 0 else ""
    x = abs(x)
    if math.isinf(x):
        return sign + "∞"
    if x >= LARGE or 0 < x < SMALL:
        mantissa, exponent = f"{x:.6e}".split("e")
        digits = mantissa.rstrip("0").rstrip(".")
        power = "10" + str(int(exponent)).translate(_SUPERSCRIPT)
        return sign + (power if digits == "1" else f"{digits} × {power}")
    text = f"{x:.7g}" if x >= 1e6 else f"{x:.6g}"  # every integer below LARGE in full
    whole, dot, fraction = text.partition(".")
    if len(whole) > 4:  # 10 000 and up in groups of three (1000 stays whole, as SI allows)
        whole = re.sub(r"(?<=\d)(?=(\d{3})+$)", GROUP, whole)
    return sign + whole + dot + fraction


class OutOfRange(ValueError):
    """``value`` is not a finite number from ``low`` to ``high`` (``unit``); ``low_open``: low itself is refused."""

    def __init__(self, what: str, value: float, low: float, high: float, unit: str = "", low_open: bool = False):
        self.what, self.value, self.low, self.high, self.unit, self.low_open = what, value, low, high, unit, low_open
        super().__init__(self.worded(what, unit))

    def worded(self, name: str, unit: str) -> str:
        """The refusal with ``name`` for the quantity, its range and value in ``unit`` (as a control's label
        names it: "Base damping g_b must be from 0 to 1 000 000 1/s, not 10⁹")."""
        finite = "a finite number " if not math.isfinite(self.value) else ""
        low, high = readable(self.low), with_unit(readable(self.high), unit)
        if unit == "×":  # a factor: 0.1× to 4×
            low = with_unit(low, unit)
        span = f"above {low} and at most {high}" if self.low_open else f"from {low} to {high}"
        return f"{name} must be {finite}{span}, not {readable(self.value)}"

    def for_control(self, label: str) -> str:
        """The refusal as the control labelled ``label`` ("Base damping g_b (1/s)") says it: its name, and the
        unit of its label's brackets (else the check's)."""
        name, unit = split_label(label)
        return self.worded(name, unit or self.unit)


def with_unit(number: str, unit: str) -> str:
    """ "5 N", "2.5×" (a factor), or the number alone."""
    return number + ("" if unit in ("", "×") else " ") + unit


def split_label(label: str) -> tuple[str, str]:
    """A control's label as (name, unit in its closing brackets): "Base damping g_b (1/s)" -> ("Base damping
    g_b", "1/s"); "Position ∫ū dt (1/(kg·m))" -> ("Position ∫ū dt", "1/(kg·m)"); no brackets: no unit."""
    label = label.strip()
    depth = 0
    for i in range(len(label) - 1, -1, -1):  # the bracket that opens the closing one
        depth += {")": 1, "(": -1}.get(label[i], 0)
        if depth == 0:
            if i == len(label) - 1 or label[i] != "(":
                return label, ""
            return label[:i].rstrip(), label[i + 1 : -1]
    return label, ""


def check_range(
    what: str,
    value: float,
    low: float,
    high: float,
    unit: str = "",
    low_open: bool = False,
    error: type[OutOfRange] = OutOfRange,
) -> float:
    """``value`` if it is a finite number in [low, high] (or (low, high]); ``error`` (an OutOfRange) otherwise."""
    if (
        isinstance(value, bool)
        or not isinstance(value, int | float)
        or not math.isfinite(value)
        or not (low < value if low_open else low <= value)
        or not value <= high
    ):
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ValueError(f"{what} must be a number, got {value!r}")
        raise error(what, float(value), low, high, unit, low_open)
    return float(value)
