"""The live plots: base deflection, coupling momentum and tracking error, and each curve's peak.

Every chart's options (title, series, scales, axes) are fixed when it is built: viser's uPlot
component rebuilds a chart whose options change, and when that rebuild lands in the same browser
frame as new data it keeps the destroyed chart's x range as a *relative* zoom, which pins the time
axis far outside the data (e.g. 50-150 s) in every tab until a reload. So nothing but data is ever
sent to a chart; the meaning of the colours is fixed (blue: suppression on, red: off, whichever run
is operated; for a model with a compensating arm, blue: compensation on, red: compensator held
still), the y scale, the display unit and the legend's names are chosen by showing one of the prebuilt charts
(a new chart mounts fresh), and the peaks are HTML beside them.

Tick labels: uPlot prints numbers with at most three decimals and thousands separators, so a window of
0.2 nm shown in mm read "0" five times and centimetres in µm "10,000". Each linear chart exists once per
display unit and the one shown suits the window's peak (:func:`display_unit`); the symmetric-log charts
have fixed ticks labelled with their own prefixes (``100 mm``, ``10 µm``).
"""

from __future__ import annotations

import html
import math

import numpy as np
import viser
import viser.uplot

from rns_viz.viz.panels.units import si
from rns_viz.viz.scene.quantities import BASE_VIBRATION, HAND_MISS, MOMENTUM

ON_COLOUR, OFF_COLOUR, ERROR_COLOUR = "#1f6fd1", "#e0503a", "#2a9d4b"
# chart titles: plain words first, the symbol of the axis second
XB_TITLE, L_TITLE, E_TITLE = (q.name[0].upper() + q.name[1:] for q in (BASE_VIBRATION, MOMENTUM, HAND_MISS))
SCALES = {"linear": "linear, fits the data", "symlog": "symmetric log, fixed range"}
# Display units of the linear charts (name, SI value): one chart per unit, the one shown suits the data.
LENGTH_UNITS = (("nm", 1e-9), ("µm", 1e-6), ("mm", 1e-3), ("m", 1.0))
MOMENTUM_UNITS = (("nN·s", 1e-9), ("µN·s", 1e-6), ("mN·s", 1e-3), ("N·s", 1.0))
UNITS = {"xb": LENGTH_UNITS, "L": MOMENTUM_UNITS, "e": LENGTH_UNITS}
FIRST_UNIT = {"xb": "µm", "L": "mN·s", "e": "mm"}
SI_PER_BUFFER = {"xb": 1e-3, "L": 1.0, "e": 1e-3}  # the plot buffers carry x_b and |e| in mm, L in N·s
KEEP_UNIT = (0.5, 2000.0)  # a unit is kept while the window's peak reads this many of it (no flapping)
# Symmetric-log charts: fixed range and linear threshold (uPlot distr 4, asinh) in their display unit,
# and fixed ticks labelled with prefixes (uPlot would print 100,000 µm).
XB_SYMLOG = (1e5, 0.1)  # µm: ±100 mm, linear below 0.1 µm
L_SYMLOG = (1e4, 1e-3)  # mN·s: ±10 N·s, linear below 1 µN·s
XB_SYMLOG_TICKS = ((1e5, "100 mm"), (1e3, "1 mm"), (10.0, "10 µm"))
L_SYMLOG_TICKS = ((1e4, "10 N·s"), (1e2, "100 mN·s"), (1.0, "1 mN·s"))


def display_unit(peak_si: float, units: tuple[tuple[str, float], ...], current: str) -> str:
    """The unit to show a window whose largest magnitude is ``peak_si`` (SI) in: ``current`` while the
    peak reads KEEP_UNIT of it, else the one it reads 1 to 1000 of (the smallest unit for anything less,
    the largest for more). A zero window keeps ``current``."""
    if not (math.isfinite(peak_si) and peak_si > 0.0):
        return current
    lo, hi = KEEP_UNIT
    if lo <= peak_si / dict(units)[current] < hi:
        return current
    fitting = [name for name, size in units if peak_si >= size]
    return fitting[-1] if fitting else units[0][0]


def peak(x: np.ndarray) -> float:
    """Largest magnitude of the finite samples, NaN if there are none."""
    x = x[np.isfinite(x)]
    return float(np.max(np.abs(x))) if len(x) else math.nan


def on_off(arrays: dict[str, np.ndarray], key: str) -> tuple[np.ndarray, np.ndarray]:
    """Series ``key`` of the run with suppression on and of the run with it off, sample by sample."""
    on = arrays["suppress"] > 0.5
    ours, shadow = arrays[key], arrays[f"{key}_shadow"]
    return np.where(on, ours, shadow), np.where(on, shadow, ours)


def _chart(
    gui: viser.GuiApi,
    title: str,
    y_label: str,
    curves: tuple[tuple[str, str], ...],
    y_scale: viser.uplot.Scale,
    visible: bool = True,
    ticks: tuple[tuple[float, str], ...] = (),
) -> viser.GuiUplotHandle:
    """A chart; ``ticks``: fixed (value, label) pairs of the positive half of a symmetric y axis."""
    series: list[viser.uplot.Series] = [{"label": "t (s)"}]
    series += [{"label": label, "stroke": colour, "width": 1.5} for label, colour in curves]
    # px; a log axis draws no tick marks (uPlot packs the negative half's minor ones into a solid bar)
    y_axis: viser.uplot.Axis = {"label": y_label, "size": 64, "ticks": {"show": y_scale.get("distr") != 4}}
    if ticks:
        y_axis["splits"] = (*(-v for v, _ in ticks), 0.0, *(v for v, _ in reversed(ticks)))
        y_axis["values"] = (*(f"−{label}" for _, label in ticks), "0", *(label for _, label in reversed(ticks)))
    return gui.add_uplot(
        data=tuple(np.zeros(2) for _ in range(len(curves) + 1)),
        series=tuple(series),
        title=title,
        scales={"x": {"time": False, "auto": True}, "y": y_scale},
        axes=({"size": 28}, y_axis),  # time in s (the legend's first entry)
        legend={"show": True, "live": False},
        cursor={"show": False},
        aspect=2.1,
        padding=(4, 16, 0, 0),
        visible=visible,
    )


PLOTS_CAPTION = (
    '<div style="font-size:0.75em;opacity:0.8">The last 10 s: how far the base is bent, x_b; the momentum '
    "the arm's joints hand to the base, L (1 mN·s = 1 g·m/s); how far the hand is from where it is sent, |e| "
    "(when a kicked arm comes to rest on another reactionless path it is sent to where it rests, and |e| "
    "falls to about 0: the status line then says so). "
    "Each axis is in the unit its numbers read best in; less than 1 nm or 1 nN·s is drawn as 0. {runs}</div>"
)
# (blue header, red header, note) of the peaks table, the legend's two names and the caption's sentence on
# the two runs: one arm (suppression) or two (compensation)
SUPPRESSION_SIDES = (
    "suppression on",
    "suppression off",
    "|e|: the operated run. Blue is always suppression on, red off; the other run is the shadow run.",
)
COMPENSATION_SIDES = (
    "compensating",
    "compensator held",
    "|e|: the operated run. Blue is always the run whose second arm cancels the reaction, red the one whose "
    "second arm is held still; the other run is the shadow run.",
)
RUNS = ("suppression", "compensation")
LEGEND = {
    "suppression": (("suppression on", ON_COLOUR), ("suppression off", OFF_COLOUR)),
    "compensation": (("compensation on", ON_COLOUR), ("compensator held still", OFF_COLOUR)),
}
RUNS_SENTENCE = {
    "suppression": "Blue: vibration suppression on; red: off (one of them is the shadow run).",
    "compensation": "Blue: the second arm cancels the task arm's reaction (compensation on); red: the same task "
    "with the second arm held still (one of them is the shadow run).",
}
SIDES = {"suppression": SUPPRESSION_SIDES, "compensation": COMPENSATION_SIDES}


class LivePlots:
    """The charts, the scale choice and the peaks table; :meth:`update` sends new data."""

    def __init__(self, gui: viser.GuiApi) -> None:
        linear: viser.uplot.Scale = {"auto": True}
        # charts take no hint: their meaning in plain words
        # (runs, scale, quantity, unit) -> chart: one per legend (a chart's series names cannot change),
        # scale and display unit (nor can its axis); the error chart's runs and scale are None
        self.chart_set: dict[tuple[str | None, str | None, str, str], viser.GuiUplotHandle] = {}
        titles = {"xb": (XB_TITLE, "x_b"), "L": (L_TITLE, "L")}
        for runs in RUNS:
            for name, (title, symbol) in titles.items():
                for unit, _ in UNITS[name]:
                    self.chart_set[runs, "linear", name, unit] = _chart(
                        gui, title, f"{symbol} ({unit})", LEGEND[runs], linear, visible=False
                    )
            self.chart_set[runs, "symlog", "xb", "µm"] = _chart(
                gui, XB_TITLE, "x_b", LEGEND[runs], _symlog(XB_SYMLOG), False, XB_SYMLOG_TICKS
            )
            self.chart_set[runs, "symlog", "L", "mN·s"] = _chart(
                gui, L_TITLE, "L", LEGEND[runs], _symlog(L_SYMLOG), False, L_SYMLOG_TICKS
            )
        for unit, _ in LENGTH_UNITS:
            self.chart_set[None, None, "e", unit] = _chart(
                gui, E_TITLE, f"|e| ({unit})", (("|x_ref − x_e|", ERROR_COLOUR),), linear, False
            )
        self.peaks = gui.add_html(peaks_html(None))
        self.caption = gui.add_html(PLOTS_CAPTION.format(runs=RUNS_SENTENCE["suppression"]))  # below: plots first
        self.scale = gui.add_dropdown(
            "Plot scale",
            tuple(SCALES.values()),
            initial_value=SCALES["linear"],
            hint="Symmetric log: the same fixed axes for every preset, so micrometres look small next to "
            "millimetres (fig11-fast against fig11-joint2).",
        )
        self.mode = "linear"
        self.runs = "suppression"  # what the two runs are: the app sets it per model (``sides``)
        self.empty = True  # the charts show no run (as built, or cleared since)
        self.units = dict(FIRST_UNIT)  # quantity -> the display unit of its linear chart shown
        self.show_mode("linear")

    def _key(self, name: str, mode: str | None = None) -> tuple[str | None, str | None, str, str]:
        """The chart of quantity ``name`` shown in scale ``mode`` (default: the one shown)."""
        if name == "e":
            return None, None, "e", self.units["e"]
        mode = mode or self.mode
        unit = self.units[name] if mode == "linear" else ("µm" if name == "xb" else "mN·s")
        return self.runs, mode, name, unit

    @property
    def charts(self) -> dict[str, dict[str, viser.GuiUplotHandle]]:
        """The x_b and L charts of the model's two runs that each scale shows now, by scale."""
        return {mode: {name: self.chart_set[self._key(name, mode)] for name in ("xb", "L")} for mode in SCALES}

    @property
    def error(self) -> viser.GuiUplotHandle:
        """The end-effector error chart shown now."""
        return self.chart_set[self._key("e")]

    def all_charts(self) -> list[viser.GuiUplotHandle]:
        return list(self.chart_set.values())

    @property
    def sides(self) -> tuple[str, str, str]:
        """The peaks table's headers and note."""
        return SIDES[self.runs]

    @sides.setter
    def sides(self, sides: tuple[str, str, str]) -> None:
        """Name the two runs for the model served: the peaks table, the caption and the charts' legend."""
        self.show_runs(next(runs for runs, s in SIDES.items() if s == sides))

    def show_runs(self, runs: str) -> None:
        """Show the charts whose legend names ``runs`` ('suppression' or 'compensation') and say it above them."""
        if runs == self.runs:
            return
        self.runs = runs
        self.caption.content = PLOTS_CAPTION.format(runs=RUNS_SENTENCE[runs])
        self.peaks.content = peaks_html(None, self.sides)  # the new runs' names until their first data
        self.show_mode(self.mode)

    @property
    def xb(self) -> viser.GuiUplotHandle:
        return self.charts["linear"]["xb"]

    @property
    def L(self) -> viser.GuiUplotHandle:
        return self.charts["linear"]["L"]

    def show_mode(self, mode: str) -> None:
        """Show the charts of scale ``mode`` (a hidden chart unmounts; shown again it mounts fresh)."""
        self.mode = mode
        shown = {self._key(name) for name in ("xb", "L", "e")}
        for key, chart in self.chart_set.items():
            if chart.visible != (key in shown):
                chart.visible = key in shown

    def update(self, arrays: dict[str, np.ndarray]) -> bool:
        """Send the arrays (PLOT_SERIES of the session) to the shown charts; False if too few samples."""
        t = arrays["t"]
        if len(t) < 2 or not np.all(np.isfinite(t)):
            self.clear()  # a run restarted (reset, model, preset): its predecessor's curves must not stay
            return False
        self.empty = False
        curves = {"xb": on_off(arrays, "xb"), "L": on_off(arrays, "L"), "e": (arrays["ee_error"],)}
        si_peaks = {name: _largest(cs) * SI_PER_BUFFER[name] for name, cs in curves.items()}
        units = {name: display_unit(si_peaks[name], UNITS[name], self.units[name]) for name in curves}
        if units != self.units:
            self.units = units
            self.show_mode(self.mode)
        for name, cs in curves.items():
            unit = self._key(name)[3]
            scale = SI_PER_BUFFER[name] / dict(UNITS[name])[unit]  # buffer -> display unit
            if not si_peaks[name] >= UNITS[name][0][1]:  # (below 1 nm or 1 nN·s: 0, as the readouts)
                scale = 0.0
            self.chart_set[self._key(name)].data = (t, *(_clean(c * scale) for c in cs))
        xb_on, xb_off = curves["xb"]
        L_on, L_off = curves["L"]
        e = peak(arrays["ee_error"]) * 1e-3  # m, the operated run's
        content = peaks_html(
            {
                "xb": (peak(xb_on) * 1e-3, peak(xb_off) * 1e-3),
                "L": (peak(L_on), peak(L_off)),
                "e": (e, math.nan) if arrays["suppress"][-1] > 0.5 else (math.nan, e),
            },
            self.sides,
        )
        if self.peaks.content != content:
            self.peaks.content = content
        return True

    def clear(self) -> None:
        """Empty every chart and the peaks table (once: nothing is sent while they are empty)."""
        if self.empty:
            return
        self.empty = True
        for chart in self.chart_set.values():
            chart.data = tuple(np.zeros(2) for _ in chart.data)
        self.peaks.content = peaks_html(None, self.sides)


def _largest(curves: tuple[np.ndarray, ...]) -> float:
    """The largest magnitude of the finite samples of ``curves``, NaN if there are none."""
    peaks = [p for p in map(peak, curves) if math.isfinite(p)]
    return max(peaks) if peaks else math.nan


def _symlog(limits: tuple[float, float]) -> viser.uplot.Scale:
    """A fixed symmetric-log scale: (range, linear threshold) in display units."""
    return {"auto": False, "distr": 4, "asinh": limits[1], "range": (-limits[0], limits[0])}


def _clean(x: np.ndarray) -> np.ndarray:
    """No NaN or inf ever reaches a chart (a missing shadow run is drawn at 0)."""
    return np.nan_to_num(x, nan=0.0, posinf=0.0, neginf=0.0)


_ROWS = (
    ("xb", f"{BASE_VIBRATION.words} |{BASE_VIBRATION.symbol}|", BASE_VIBRATION.unit),
    ("L", f"{MOMENTUM.words} |{MOMENTUM.symbol}|", MOMENTUM.unit),
    ("e", HAND_MISS.name, HAND_MISS.unit),
)
_ROW_HINTS = {
    "xb": "largest bend of the base from rest in the last 10 s",
    "L": "largest momentum the joints handed to the base (1 N·s = 1 kg·m/s)",
    "e": "largest distance of the hand from where the law sends it",
}


def peaks_html(peaks: dict[str, tuple[float, float]] | None, sides: tuple[str, str, str] = SUPPRESSION_SIDES) -> str:
    """The peak of every curve over the plotted window (SI values in ``data-si`` for tests and tools)."""
    on_label, off_label, note = sides
    head = (
        f'<tr><th style="text-align:left">peak, last 10 s</th><th style="color:{ON_COLOUR}">{on_label}</th>'
        f'<th style="color:{OFF_COLOUR}">{off_label}</th></tr>'
    )
    rows = []
    for key, label, unit in _ROWS:
        on, off = peaks[key] if peaks is not None else (math.nan, math.nan)
        cells = "".join(
            f'<td data-peak="{key}-{side}" data-si="{v!r}" style="text-align:right">{html.escape(si(v, unit))}</td>'
            for side, v in (("on", on), ("off", off))
        )
        rows.append(f'<tr title="{_ROW_HINTS[key]}"><td>{html.escape(label)}</td>{cells}</tr>')
    return (
        '<table style="font-size:0.8em;width:100%">' + head + "".join(rows) + "</table>"
        f'<div style="font-size:0.75em;opacity:0.75">{note}</div>'
    )
