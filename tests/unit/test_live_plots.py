"""The live plots' pure parts: SI units, the display unit a window is shown in, the on/off colouring sample
by sample, the peaks table."""

from __future__ import annotations

import math

import numpy as np

from rns_viz.live.published.plot_buffers import PLOT_SERIES
from rns_viz.viz.panels.live_plots import LENGTH_UNITS, MOMENTUM_UNITS, display_unit, on_off, peaks_html
from rns_viz.viz.panels.units import si


def test_si_prefixes_and_zeros() -> None:
    assert si(2.1e-6, "m") == "2.1 µm"
    assert si(0.00132, "m") == "1.32 mm"
    assert si(0.45, "N·s") == "450 mN·s"
    assert si(-1.2e-42, "N", floor=1e-6) == "0 N"  # not "-1.2e-42 N"
    assert si(0.9997e-3, "m") == "1 mm"  # not "1e+03 µm"
    assert si(3.0, "N", sign=True) == "+3 N" and si(math.nan, "m") == "—"


def test_display_units_suit_the_window() -> None:
    """The unit a linear chart shows: its peak reads 1 to 1000 of it, kept from 0.5 to 2000 (no flapping)."""
    assert display_unit(2e-10, LENGTH_UNITS, "mm") == "nm"  # below 1 nm: drawn as 0, in nm
    assert display_unit(2e-7, LENGTH_UNITS, "mm") == "nm"  # 200 nm, not 0.0002 mm ("0" five times)
    assert display_unit(2.5e-2, LENGTH_UNITS, "µm") == "mm"  # 25 mm, not 25,000 µm
    assert display_unit(3.0, LENGTH_UNITS, "mm") == "m"
    assert display_unit(1.5e-3, LENGTH_UNITS, "µm") == "µm"  # 1500 µm: kept (four digits)
    assert display_unit(0.6e-6, LENGTH_UNITS, "µm") == "µm" and display_unit(0.4e-6, LENGTH_UNITS, "µm") == "nm"
    assert display_unit(5e-9, MOMENTUM_UNITS, "mN·s") == "nN·s" and display_unit(30.0, MOMENTUM_UNITS, "mN·s") == "N·s"
    assert display_unit(0.0, LENGTH_UNITS, "µm") == "µm" and display_unit(math.nan, LENGTH_UNITS, "mm") == "mm"


def test_curves_are_coloured_by_suppression_sample_by_sample() -> None:
    a = {k: np.zeros(4) for k in PLOT_SERIES}
    a["xb"], a["xb_shadow"] = np.array([1.0, 2.0, 3.0, 4.0]), np.array([-1.0, -2.0, -3.0, -4.0])
    a["suppress"] = np.array([1.0, 1.0, 0.0, 0.0])  # suppression switched off after two samples
    on, off = on_off(a, "xb")
    assert on.tolist() == [1.0, 2.0, -3.0, -4.0] and off.tolist() == [-1.0, -2.0, 3.0, 4.0]


def test_peaks_table_carries_si_values() -> None:
    text = peaks_html({"xb": (2.8e-6, 1.3e-3), "L": (0.02, math.nan), "e": (4e-3, math.nan)})
    assert 'data-peak="xb-on" data-si="2.8e-06"' in text and "2.8 µm" in text and "1.3 mm" in text
    assert 'data-peak="L-off" data-si="nan"' in text and "—" in text
    assert "suppression on" in text and "suppression off" in text
