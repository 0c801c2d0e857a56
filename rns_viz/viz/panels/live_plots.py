"""The live plots: base deflection, coupling momentum and tracking error, and each curve's peak.

Every chart's options (title, series, scales, axes) are fixed when it is built: viser's uPlot
component rebuilds a chart whose options change, and when that rebuild lands in the same browser
frame as new data it keeps the destroyed chart's x range as a *relative* zoom, which pins the time
axis far outside the data (e.g. 50-150 s) in every tab until a reload. So nothing but data is ever
sent to a chart; the meaning of the colours is fixed (blue: suppression on, red: off, whichever run
is operated; for a model with a compensating arm, blue: compensation on, red: compensator held
still), the y scale and the legend's names are chosen by showing one of the prebuilt charts (a new
chart mounts fresh), and the peaks are HTML beside them.
"""

from __future__ import annotations

import html
import math

import numpy as np
import viser
import viser.uplot

from rns_viz.viz.panels.units import si

ON_COLOUR, OFF_COLOUR, ERROR_COLOUR = "#1f6fd1", "#e0503a", "#2a9d4b"
SCALES = {"linear": "linear, fits the data", "symlog": "symmetric log, fixed range"}
# Display units: x_b in µm and L in mN·s (= g·m/s) keep tick labels readable from the 3R's
# centimetres down to fig11-fast's micrometres; the error in mm.
XB_UM_PER_MM = 1e3  # the plot buffers carry x_b in mm
L_MNS_PER_SI = 1e3
# symmetric-log charts: fixed range and linear threshold (uPlot distr 4, asinh), display units
XB_SYMLOG = (1e5, 0.1)  # ±100 mm, linear below 0.1 µm
L_SYMLOG = (1e4, 1e-3)  # ±10 kg·m/s, linear below 1 µN·s


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
) -> viser.GuiUplotHandle:
    series: list[viser.uplot.Series] = [{"label": "t (s)"}]
    series += [{"label": label, "stroke": colour, "width": 1.5} for label, colour in curves]
    return gui.add_uplot(
        data=tuple(np.zeros(2) for _ in range(len(curves) + 1)),
        series=tuple(series),
        title=title,
        scales={"x": {"time": False, "auto": True}, "y": y_scale},
        # px; time in s (the legend's first entry); a log axis draws no tick marks (uPlot packs the
        # negative half's minor ones into a solid bar)
        axes=({"size": 28}, {"label": y_label, "size": 64, "ticks": {"show": y_scale.get("distr") != 4}}),
        legend={"show": True, "live": False},
        cursor={"show": False},
        aspect=2.1,
        padding=(4, 16, 0, 0),
        visible=visible,
    )


PLOTS_CAPTION = (
    '<div style="font-size:0.75em;opacity:0.8">The last 10 s: how far the base is bent, x_b (µm); the momentum '
    "the arm's joints hand to the base, L (mN·s = g·m/s); how far the hand is from where it is sent, |e| (mm). "
    "{runs}</div>"
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
        self.caption = gui.add_html(PLOTS_CAPTION.format(runs=RUNS_SENTENCE["suppression"]))
        # runs -> scale -> chart: one set of charts per legend (a chart's series names cannot change)
        self.chart_sets: dict[str, dict[str, dict[str, viser.GuiUplotHandle]]] = {runs: {} for runs in RUNS}
        for runs in RUNS:
            for mode in SCALES:
                xb_scale, L_scale = linear, linear
                if mode == "symlog":
                    xb_scale = _symlog(XB_SYMLOG)
                    L_scale = _symlog(L_SYMLOG)
                self.chart_sets[runs][mode] = {
                    "xb": _chart(gui, "Base deflection", "x_b (µm)", LEGEND[runs], xb_scale, visible=False),
                    "L": _chart(gui, "Coupling momentum", "L (mN·s)", LEGEND[runs], L_scale, visible=False),
                }
        self.error = _chart(gui, "End-effector error", "|e| (mm)", (("|x_ref − x_e|", ERROR_COLOUR),), linear)
        self.peaks = gui.add_html(peaks_html(None))
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
        self.show_mode("linear")

    @property
    def charts(self) -> dict[str, dict[str, viser.GuiUplotHandle]]:
        """The charts of the model's two runs, by scale."""
        return self.chart_sets[self.runs]

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
        for runs, sets in self.chart_sets.items():
            for name, charts in sets.items():
                for chart in charts.values():
                    chart.visible = name == mode and runs == self.runs

    def update(self, arrays: dict[str, np.ndarray]) -> bool:
        """Send the arrays (PLOT_SERIES of the session) to the shown charts; False if too few samples."""
        t = arrays["t"]
        if len(t) < 2 or not np.all(np.isfinite(t)):
            self.clear()  # a run restarted (reset, model, preset): its predecessor's curves must not stay
            return False
        self.empty = False
        xb_on, xb_off = on_off(arrays, "xb")
        L_on, L_off = on_off(arrays, "L")
        shown = self.charts[self.mode]
        shown["xb"].data = (t, _clean(xb_on * XB_UM_PER_MM), _clean(xb_off * XB_UM_PER_MM))
        shown["L"].data = (t, _clean(L_on * L_MNS_PER_SI), _clean(L_off * L_MNS_PER_SI))
        self.error.data = (t, _clean(arrays["ee_error"]))
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
        for chart in (self.error, *(c for sets in self.chart_sets.values() for s in sets.values() for c in s.values())):
            chart.data = tuple(np.zeros(2) for _ in chart.data)
        self.peaks.content = peaks_html(None, self.sides)


def _symlog(limits: tuple[float, float]) -> viser.uplot.Scale:
    """A fixed symmetric-log scale: (range, linear threshold) in display units."""
    return {"auto": False, "distr": 4, "asinh": limits[1], "range": (-limits[0], limits[0])}


def _clean(x: np.ndarray) -> np.ndarray:
    """No NaN or inf ever reaches a chart (a missing shadow run is drawn at 0)."""
    return np.nan_to_num(x, nan=0.0, posinf=0.0, neginf=0.0)


_ROWS = (("xb", "|x_b|", "m"), ("L", "|L|", "N·s"), ("e", "|e|", "m"))
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
