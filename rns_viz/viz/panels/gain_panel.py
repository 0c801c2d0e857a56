"""The gain explorer in the app: panel folder, root loci, and the map in the scene.

:class:`GainExplorerView` is built once with the panel; the renderer hands it each model's scene
(:meth:`build_scene`) and calls :meth:`frame` every frame, which redraws only when
``session.gain_view().version`` changed. A click on the map applies the clicked grid point's
(g_b, g_m) through ``Session.set_gains``; only the operator's clicks count.
"""

from __future__ import annotations

import math
import time
import traceback

import numpy as np
import viser
import viser.uplot

from rns_viz.analysis import GAIN_RANGE, Locus, Modes
from rns_viz.live.explorer.gain_explorer import GainView
from rns_viz.live.loop.session import Session
from rns_viz.viz.clients.connections import Connections
from rns_viz.viz.panels.control_panel import GAIN_SLIDERS, GuiElements
from rns_viz.viz.panels.inputs import Controls
from rns_viz.viz.panels.model_menu import label_of
from rns_viz.viz.scene.fsms_scene import FsmsScene
from rns_viz.viz.scene.gain_scene import GainScene, Quantity
from rns_viz.viz.scene.style import SceneStyle

QUANTITIES: dict[str, Quantity] = {
    "base decay σ_b (1/s)": "base",
    "base time to 10 % (s)": "time",
    "arm mode σ_a (1/s)": "arm",
}
RIGHT = 0.15  # the locus plots show Re λ up to this fraction of their left reach (unstable poles)
TALL = 20.0  # ... and Im λ within this multiple of it
BASE_COLOUR, ARM_COLOUR, NOW_COLOUR = "#e0503a", "#1f6fd1", "#111111"
CHECK_S = 0.1  # s: the view is checked at 10 Hz (its changes come in bursts: gains, poles, authority)
_SLIDER_MAX = {name: hi for name, _, _, hi, _, _ in GAIN_SLIDERS}
_G_M_HINT = next(h for name, *_, h in GAIN_SLIDERS if name == "g_m")
_QUANTITY_HINT = (
    "Base: how a kick decays, σ_b = ln 10 / the time it takes to fall to 10 % of its peak; arm mode: the slowest "
    "pole a kick hardly shows (Sec. VIII: two subsystems)."
)
_NOT_ANALYSED = (
    "Not for this model: the gain map is computed for one arm damping the base's swing, not for a second arm "
    "that cancels the reaction."
)


def _locus_plot(gui: viser.GuiApi, title: str) -> viser.GuiUplotHandle:
    series: list[viser.uplot.Series] = [{"label": "Re λ (1/s)"}]
    for label, colour, size in (("base mode", BASE_COLOUR, 4), ("arm modes", ARM_COLOUR, 4), ("now", NOW_COLOUR, 9)):
        series.append(
            {
                "label": label,
                "stroke": colour,
                "width": 0,
                "points": {"show": True, "size": size, "stroke": colour, "fill": colour},
            }
        )
    return gui.add_uplot(
        data=tuple(np.zeros(2) for _ in range(4)),
        series=tuple(series),
        title=title,
        scales={"x": {"time": False, "auto": False, "range": (-1.0, 0.1)}, "y": {"auto": False, "range": (-1.0, 1.0)}},
        axes=({"label": "decay rate Re λ (1/s)"}, {"label": "ringing Im λ (1/s)", "size": 60}),
        legend={"show": True, "live": False},
        cursor={"show": False},
        aspect=1.3,
    )


def locus_data(locus: Locus, now: Modes | None, reach: float) -> tuple[np.ndarray, ...]:
    """uPlot data (x, base, arm, now) of a root locus: x sorted Re λ (1/s), NaN where a series has no point."""
    re, im = locus.poles.real.ravel(), locus.poles.imag.ravel()
    base = locus.is_base.ravel()
    n_re = np.zeros(0) if now is None else now.poles.real.ravel()
    n_im = np.zeros(0) if now is None else now.poles.imag.ravel()
    x = np.concatenate([re, n_re])
    cols = np.full((3, len(x)), np.nan)
    cols[0, : len(re)] = np.where(base, im, np.nan)
    cols[1, : len(re)] = np.where(base, np.nan, im)
    cols[2, len(re) :] = n_im
    keep = np.isfinite(x) & (x >= -reach) & (x <= RIGHT * reach)
    order = np.argsort(x[keep], kind="stable")
    return (x[keep][order], *(c[keep][order] for c in cols))


class GainExplorerView:
    """The explorer's panel folder and scene; redrawn when the session's gain view changes."""

    def __init__(self, server: viser.ViserServer, session: Session, gui: GuiElements, controls: Controls,
                 connections: Connections) -> None:  # fmt: skip
        self.server, self.session, self.gui = server, session, gui
        self.controls, self.connections = controls, connections
        g = server.gui
        with g.add_folder(
            "Gain explorer", order=gui.download.order - 0.5, expand_by_default=True
        ) as self.folder:  # above Download
            g.add_markdown(
                "**Gain map** in the scene (above the robot; tick *Gain map* in *Show in the scene*): each cell is a "
                "(g_b, g_m) setting, coloured by how fast the closed loop, linearised about the current pose, damps a "
                "kick (the one in the map's title; faded, hatched cells: it cannot say). "
                "**Click a cell** to apply its gains."
            )
            self.quantity = g.add_dropdown(
                "Map shows",
                tuple(QUANTITIES),
                initial_value=next(iter(QUANTITIES)),
                hint=_QUANTITY_HINT,
            )
            self.meaning = g.add_markdown("")
            self.predicted = g.add_markdown("")
            self.authority = g.add_markdown("")
            self.locus_b = _locus_plot(g, "Root locus, g_b sweeps")
            self.locus_m = _locus_plot(g, "Root locus, g_m sweeps")
            self.locus_note = g.add_markdown(
                "Closed-loop poles λ (1/s); further left decays faster. Fast poles off the left edge are not shown."
            )
        controls.on_input(self.quantity, lambda v, c: None)  # read below; watchers are refused and reverted
        self.scene: GainScene | None = None
        self.on_path = True
        self._version = -1
        self._quantity = ""
        self._law = ""
        self.clicks_applied = 0
        self._next_check = 0.0
        self._drawn: dict[str, object] = {}
        self._loci_of: tuple[str, str] | None = None  # (model, law) of the root loci drawn
        self._clicked: tuple[float, float] | None = None  # gains of a map click, for the sliders to show

    def show(self, on: bool, robot_scene: FsmsScene) -> None:
        """Show or hide the map and the authority overlay in the scene (the *Gain map* toggle). Every camera
        then frames what is shown: the robot, with the map while it is shown (it stands above the robot,
        out of a view framed on the robot alone); *Frame robot* does the same."""
        if self.scene is None or not self.scene.set_shown(on):
            return
        robot_scene.frame_also(self.scene.framed_corners() if on else None)
        if on:
            self._version, self._drawn, self._next_check = -1, {}, 0.0  # draw the view now

    def build_scene(self, style: SceneStyle, on_path: bool) -> None:
        """The model's scene was (re)built: add the map to it."""
        self.scene = GainScene(self.server, style, self._on_point)
        self.on_path = on_path
        self._version = -1
        self._drawn = {}

    # -- per frame -------------------------------------------------------------------------------
    def frame(self, model: str) -> None:
        """Draw the session's gain view if it changed and is of ``model``, the model whose scene is built
        (a view of the next model waits for its scene)."""
        now = time.perf_counter()
        if now < self._next_check:
            return
        self._next_check = now + CHECK_S
        view = self.session.gain_view()
        quantity = QUANTITIES.get(self.controls.good(self.quantity), "base")
        if self.scene is None or view.model != model or (view.version == self._version and quantity == self._quantity):
            return
        map_changed = view.map is not self.scene.gain_map or quantity != self._quantity
        self._version, self._quantity = view.version, quantity
        if map_changed:
            self.scene.show_map(view, quantity)
        else:
            self.scene.show_now(view)
        drawn = self._drawn  # send only what changed: the parts of a view are new objects when they change
        last = drawn.get("authority")
        # new gains: the path keeps its colours the few ms until the authority at them arrives (no blinking
        # while a slider is dragged); a new path, model or map is drawn at once
        recolouring = view.authority is None and isinstance(last, tuple) and last[1] is view.path_points
        if map_changed or not (_same((view.authority, view.path_points), last) or recolouring):
            drawn["authority"] = (view.authority, view.path_points)
            self.scene.show_authority(view, self.on_path)
        self._show_text(view)
        if not _same((view.locus_g_b, view.locus_g_m, view.current), drawn.get("loci")):
            drawn["loci"] = (view.locus_g_b, view.locus_g_m, view.current)
            self._show_loci(view)
        self._widen_sliders(view)
        clicked = self._clicked
        if clicked is not None and clicked == (view.gains.g_b, view.gains.g_m):
            self._clicked = None  # in force: the sliders show it (the session only re-syncs them after
            self.controls.show(self.gui.gains["g_b"], clicked[0])  # input other than the operator's)
            self.controls.show(self.gui.gains["g_m"], clicked[1])

    def _show_text(self, view: GainView) -> None:
        if view.law != self._law and view.g_m_meaning:
            self._law = view.law
            self.meaning.content = f"*{view.g_m_meaning}.*"
            self.gui.gains["g_m"].hint = f"{_G_M_HINT} Here: {view.g_m_meaning}."
        for handle, text in (
            (self.predicted, predicted_text(view)),
            (self.authority, authority_text(view, self.on_path)),
        ):
            if handle.content != text:
                handle.content = text

    def _show_loci(self, view: GainView) -> None:
        """The root loci of the view. While new ones are computed the plots keep the last ones of this model
        and law (their titles name the gains they are at); another model's or law's are cleared."""
        reach = _reach(view)
        if (view.model, view.law) != self._loci_of:
            self._loci_of = (view.model, view.law)
            for plot in (self.locus_b, self.locus_m):
                plot.data = tuple(np.zeros(2) for _ in range(4))
                plot.title = "Root locus: being computed…"
            # a compensating arm's loop is not analysed: no loci, and no map to choose a quantity of
            for handle in (self.locus_b, self.locus_m, self.locus_note):
                handle.visible = view.analysed
            self.quantity.disabled = not view.analysed
            self.quantity.hint = _QUANTITY_HINT if view.analysed else _NOT_ANALYSED
        for plot, locus, other in ((self.locus_b, view.locus_g_b, "g_m"), (self.locus_m, view.locus_g_m, "g_b")):
            if locus is None:
                continue
            data = locus_data(locus, view.current, reach)
            if len(data[0]) < 2:
                continue
            # The y range fits the poles inside the x range up to TALL x reach (the 1 ms hold's poles
            # near |Im| = pi/dt would squeeze the rest flat).
            ims = np.abs(np.concatenate([d[np.isfinite(d)] for d in data[1:]]))
            ims = ims[ims <= TALL * reach]
            top = 1.1 * max(float(np.max(np.abs(ims))) if len(ims) else 0.0, 0.1 * reach)
            plot.scales = {
                "x": {"time": False, "auto": False, "range": (-reach, RIGHT * reach)},
                "y": {"auto": False, "range": (-top, top)},
            }
            plot.data = data
            lo, hi = locus.values[0], locus.values[-1]
            plot.title = f"Root locus: {locus.sweep} {lo:g}…{hi:g} 1/s at {other} = {locus.fixed:.4g} 1/s"

    def _widen_sliders(self, view: GainView) -> None:
        """A map click can apply gains beyond a slider's default range: widen it to the map's range."""
        top = GAIN_RANGE.get(view.law, (0.0, 3000.0))[1]
        for name in ("g_b", "g_m"):
            slider, value = self.gui.gains[name], float(getattr(view.gains, name))
            wanted = _SLIDER_MAX[name] if value <= _SLIDER_MAX[name] else top
            if slider.max != wanted:
                slider.max = wanted

    # -- a click on the map ----------------------------------------------------------------------
    def _on_point(self, client: viser.ClientHandle | None, origin: object, direction: object) -> None:
        """A scene click on the map image: apply its grid point's gains if the client operates."""
        try:
            if not self.connections.allowed(client):
                self.connections.refuse_watcher(client)
                return
            scene = self.scene
            point = None if scene is None else scene.clicked_gains(origin, direction)
            if point is None:
                self.connections.notify(client, "Gains not applied", "The click was not on the gain map.", "warning")
                return
            g_b, g_m = point
            self._clicked = point
            self.session.set_gains(None if client is None else client.client_id, g_b=g_b, g_m=g_m)
            self.clicks_applied += 1
        except ValueError as exc:
            self.connections.notify(client, "Gains not applied", str(exc), "warning")
        except Exception as exc:  # a click must never take the server down
            traceback.print_exc()
            self.connections.notify(client, "Gains not applied", f"{type(exc).__name__}: {exc}", "error")


def _same(parts: tuple[object, ...], drawn: object) -> bool:
    """The very objects drawn last (identity: the view's parts are immutable, new when changed)."""
    return (
        isinstance(drawn, tuple) and len(drawn) == len(parts) and all(a is b for a, b in zip(parts, drawn, strict=True))
    )


def _reach(view: GainView) -> float:
    """How far left the locus plots reach (1/s): six times the base mode's decay rate now, at least 1/s
    (the slow poles are the interesting ones; the arm's fast ones are off the left edge)."""
    rate = view.predicted
    return float(max(1.0, 6.0 * rate)) if math.isfinite(rate) else 10.0


def _fmt_rate(rate: float) -> str:
    if not math.isfinite(rate):
        return "…"
    if rate <= 0:
        return f"{rate:.3g} 1/s (grows)"
    return f"{rate:.3g} 1/s"


def _fmt_time(seconds: float) -> str:
    return f"10 % in {seconds:.3g} s after the kick" if math.isfinite(seconds) else "not under 10 % yet"


def _prediction(view: GainView) -> str:
    """The predicted decay at the gains in force, or why there is none (what follows "Base decay at ...: ")."""
    now = view.current
    if now is None:
        return "predicted …"
    if not bool(now.stable):
        return f"no prediction, the loop is unstable (σ_b {_fmt_rate(float(now.base_decay_rate))})"
    why = now.why_not()
    if why:
        return f"**no prediction**, {why}"
    return f"predicted σ_b {_fmt_rate(float(now.base_decay_rate))}, {_fmt_time(float(now.base_time_to_10pct))}"


def predicted_text(view: GainView) -> str:
    """One line: the predicted base decay at the gains in force (or why there is none), for which kick, and
    after a kick the measured one, naming what it measured (model, gains, kick); only a measurement of the
    view's model, law, gains and run is shown."""
    gains = f"g_b = {view.gains.g_b:.4g}, g_m = {view.gains.g_m:.4g} 1/s"
    if view.analysed:
        pred = f"**Base decay** at {gains}: {_prediction(view)}"
        if view.map is not None and view.current is not None and bool(view.current.stable):
            pred += f" ({view.map.loop.regime}; the arm swings {float(view.current.swing):.2g} rad)"
    else:
        pred = f"**Base decay** at {gains}: not predicted for this model (no linearisation of its compensating law)"
    m = view.measured
    if m is None or (m.model, m.law, m.gains, m.epoch) != (view.model, view.law, view.gains, view.epoch):
        return f"{pred}; *kick the base with suppression on to measure it* (read 4–20 s after the kick)."
    what = f"{label_of(m.model)}, g_b = {m.gains.g_b:.4g}, g_m = {m.gains.g_m:.4g} 1/s"
    rate = f", σ {_fmt_rate(m.rate)}" if math.isfinite(m.rate) else ""
    read = f"{m.seconds:.1f} s of log after the kick at t = {m.since:.1f} s"
    return f"{pred}; **measured** {_fmt_time(m.settle_time)}{rate} ({what}, {read})."


def authority_text(view: GainView, on_path: bool) -> str:
    """One line: the range of the predicted base decay rate along the path (1-D RNS) or over the set."""
    where = "along the current reactionless path" if on_path else "over the reactionless-reachable set (dots)"
    if not view.analysed:
        return f"Authority {where}: not predicted for this model."
    auth = view.authority
    if auth is None or len(auth.base_decay_rate) == 0:
        return f"Authority {where}: being computed…"
    r = auth.base_decay_rate
    return (
        f"**Authority** {where}, coloured as the base mode's map: σ_b {np.min(r):.3g} … {np.max(r):.3g} 1/s "
        "at the gains in force — flat except where the distance to singularity σ_min(W S H_bm) is small, where "
        "suppression fades."
    )
