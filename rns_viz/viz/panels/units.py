"""Numbers for people: SI prefixes, three significant digits, and no "-1.2e-42" for a zero."""

from __future__ import annotations

import math

_PREFIXES = ((1e-9, "n"), (1e-6, "µ"), (1e-3, "m"), (1.0, ""), (1e3, "k"), (1e6, "M"))


def si(value: float, unit: str, floor: float = 1e-12, sign: bool = False) -> str:
    """``value`` (SI units) with an SI prefix: si(2.1e-6, "m") == "2.1 µm"; magnitudes below ``floor``
    print as 0; "—" if not finite; ``sign``: a leading + on positive values."""
    if not math.isfinite(value):
        return "—"
    if abs(value) < floor:
        return f"0 {unit}"
    scale, prefix = _PREFIXES[0]
    for s, p in _PREFIXES:
        if abs(value) >= s:
            scale, prefix = s, p
    text = f"{value / scale:.3g}"
    if float(text) == 1000.0 and scale < _PREFIXES[-1][0]:  # 999.7e-6 rounds to "1e+03 µ": one prefix up
        return si(math.copysign(scale * 1000.0, value), unit, floor, sign)
    return f"{'+' if sign and value > 0 else ''}{text} {prefix}{unit}"
