"""What must hold in every state the app can reach: everything it publishes belongs to the model, the gains
and the run in force. Each function returns the violations it finds, in words (empty: all hold).

- :func:`published_violations`: the session's records (snapshot, overlays, gain view, plots, recording),
  at once after the loop has taken its background results;
- :func:`drawn_violations`: what the viz layer shows (scene of the model, no node of another model's
  drawing, gain map and panel texts of this view, charts of this run, the lesson list, the model's panel
  words); the render thread catches up at its own pace, so callers wait for these to hold;
- :func:`page_violations`: what a browser tab holds (a protocol client mirroring the scene as viser's page
  does) against the server's scene, node by node, pose and visibility included.
"""

from __future__ import annotations

import html
import math

import numpy as np

from rns_viz.params import BUNDLED_MODELS, model_source
from rns_viz.viz.panels.gain_panel import authority_text, predicted_text
from rns_viz.viz.panels.lesson_panel import chooser_entry, lesson_markdown
from rns_viz.viz.panels.model_menu import label_of
from rns_viz.viz.panels.model_words import kick_hint, target_text
from rns_viz.viz.scene.scene_nodes import node_names
from rns_viz.viz.server.app import RnsApp
from tests.support.protocol_client import ProtocolClient

# How each bundled model is named in words; a panel may name only its own.
MODEL_WORDS = {"trep": "TREP", "planar3r": "3R", "boom7": "boom7", "trep2": "compensat", "boom-panda": "Panda"}
DYNAMIC = ("/gain_map/",)  # nodes drawn when the gain map arrives (ticks, the paper's marks)


def published_violations(app: RnsApp) -> list[str]:
    s = app.session
    snap, st = s.snapshot(), s.snapshot().settings
    model = s.state.model
    out: list[str] = []
    if model.name != st.model:
        out.append(f"the loop runs {model.name} but the settings say {st.model}")
    if snap.q.shape != (model.nv,):
        out.append(f"q has {snap.q.shape} coordinates, {st.model} has {model.nv}")
    if snap.lesson is not None and snap.lesson.model != model_source(st.model):
        out.append(f"lesson of {snap.lesson.model} runs on {st.model}")
    ov = s.overlays()
    if (ov.model, ov.epoch) != (st.model, snap.epoch):
        out.append(f"overlays of {ov.model} epoch {ov.epoch}, the run is {st.model} epoch {snap.epoch}")
    out += _gain_view_violations(app)
    t = s.plot_arrays()["t"]
    if len(t) and float(np.max(t)) > snap.t + 1e-9:
        out.append(f"plot samples up to t = {np.max(t):.3f} s in a run at t = {snap.t:.3f} s (another run's)")
    rec = s.recording(60.0)
    if rec is not None and snap.replay is None:
        if rec.model.name != st.model:
            out.append(f"the recording is of {rec.model.name}, the run of {st.model}")
        if rec.span[1] > snap.t + 1e-9:
            out.append(f"the recording reaches t = {rec.span[1]:.3f} s, the run is at {snap.t:.3f} s")
    return out


def _gain_view_violations(app: RnsApp) -> list[str]:
    s = app.session
    snap, st, view = s.snapshot(), s.snapshot().settings, s.gain_view()
    out: list[str] = []
    said = (view.epoch, view.model, view.law, view.gains)
    if said != (snap.epoch, st.model, st.law, st.gains):
        out.append(f"gain view of {said}, the run is {(snap.epoch, st.model, st.law, st.gains)}")
        return out
    if view.map is not None and (view.map.loop.model_name, view.map.loop.law) != (st.model, st.law):
        out.append(f"gain map of {view.map.loop.model_name}/{view.map.loop.law} shown for {st.model}/{st.law}")
    if view.analysed and s.state.idle() and view.map is None:
        out.append(f"no gain map for {st.model}/{st.law} although nothing is being computed")
    g = st.gains
    for locus, other, fixed in ((view.locus_g_b, "g_m", g.g_m), (view.locus_g_m, "g_b", g.g_b)):
        if locus is not None and locus.fixed != fixed:
            out.append(f"root locus at {other} = {locus.fixed}, in force {fixed}")
    if view.authority is not None and (view.authority.g_b, view.authority.g_m) != (g.g_b, g.g_m):
        out.append(f"authority at ({view.authority.g_b}, {view.authority.g_m}), gains in force ({g.g_b}, {g.g_m})")
    m = view.measured
    if m is not None:
        if (m.model, m.law, m.gains, m.epoch) != (st.model, st.law, g, snap.epoch):
            out.append(f"measured on {(m.model, m.law, m.gains, m.epoch)} shown in {(st.model, st.law, g, snap.epoch)}")
        if not 0.0 <= m.since <= snap.t:
            out.append(f"measured after a kick at t = {m.since} s in a run at t = {snap.t} s")
        if math.isfinite(m.rate) != math.isfinite(m.settle_time):  # a rate only once under 10 % (ln 10 / time)
            out.append(f"measured rate {m.rate} 1/s with time to 10 % {m.settle_time} s")
    return out


def drawn_violations(app: RnsApp, references: dict[str, set[str]]) -> list[str]:
    """``references``: per model source, the scene nodes of a freshly built app of that model."""
    s, r, g = app.session, app.renderer, app.gui
    snap, st = s.snapshot(), s.snapshot().settings
    out: list[str] = []
    if r.model_name != st.model or r.model.name != st.model:
        return [f"the scene is of {r.model_name}, the run of {st.model}"]
    source = model_source(st.model)
    names = node_names(app.server)
    own = references[source]
    foreign = set().union(*(nodes for other, nodes in references.items() if other != source)) - own
    if stray := sorted(n for n in names & foreign if not n.startswith(DYNAMIC)):
        out.append(f"{source}'s scene holds other models' nodes: {stray[:5]}")
    if missing := sorted(n for n in own - names if not n.startswith(DYNAMIC)):
        out.append(f"{source}'s scene lacks its own nodes: {missing[:5]}")
    ex, view = r.explorer, s.gain_view()
    drawn_map = ex.scene.gain_map if ex.scene is not None else None
    if drawn_map is not None and (drawn_map.loop.model_name, drawn_map.loop.law) != (st.model, st.law):
        out.append(f"the drawn gain map is {drawn_map.loop.model_name}/{drawn_map.loop.law}'s")
    ticked = app.view.on("gain_map")  # the map is drawn only while its box in *Show in the scene* is ticked
    if (
        (view.map is None) != (drawn_map is None)
        or ex.scene is None
        or ex.scene.frame.visible != (view.map is not None and ticked)
    ):
        out.append(f"the gain map drawn (or hidden) is not the view's (its box {'ticked' if ticked else 'unticked'})")
    elif not ticked and (ex.scene.authority.visible or ex.scene.authority_lines.visible):
        out.append("the authority overlay is drawn while the gain map's toggle is not ticked")
    on_path = r.model.n - len(r.model.selected) == 1
    texts = {
        "predicted": (ex.predicted.content, predicted_text(view)),
        "authority": (ex.authority.content, authority_text(view, on_path)),
        "lesson": (app.lessons.text.content, lesson_markdown(snap.lesson)),
        "lesson chooser": (app.lessons.chooser.value, chooser_entry(snap.lesson, st.model, app.lessons.choices)),
        "target": (g.target_text.content, target_text(r.model)),
        "kick hint": (g.kick_peak.hint, kick_hint(r.model)),
    }
    out += [f"{what} shows {shown!r}, not {wanted!r}" for what, (shown, wanted) in texts.items() if shown != wanted]
    if html.escape(label_of(st.model)) not in g.status.content:
        out.append(f"the status line does not name {label_of(st.model)}")
    if g.path_folder.visible != on_path or g.target_folder.visible == on_path:
        out.append("the path / target folder shown does not fit the reaction null space")
    if app.base_panel.folder.visible != (r.model.m > 1):
        out.append("the base-coordinates panel is shown for a 1-DOF base or hidden for a spatial one")
    out += _words_violations(app, source, on_path)
    if snap.replay is None:
        out += _chart_violations(app)
    return out


def _words_violations(app: RnsApp, source: str, on_path: bool) -> list[str]:
    """The panel names only what applies to the model: no other model's name, no planar-only words on 3-D."""
    g = app.gui
    shown = [g.path_folder.label if on_path else g.target_folder.label, g.kick_peak.hint]
    shown += [g.target_text.content] if not on_path else []
    shown += [slider.hint or "" for slider in g.gains.values() if slider.visible]
    shown += [f"{box.label} {box.hint or ''}" for box in app.view.boxes.values() if box.visible]
    own = label_of(source)
    others = [w for m, w in MODEL_WORDS.items() if m in BUNDLED_MODELS and w not in own and m != source]
    out = [f"the panel says {w!r} on {source}: {t!r}" for t in shown for w in others if w in t]
    if len(app.renderer.model.task_rows) == 3 and any("x and y only" in t for t in shown):
        out.append(f"'x and y only' on {source}, whose handle moves in 3-D")
    return out


def _chart_violations(app: RnsApp) -> list[str]:
    t = app.session.plot_arrays()["t"]
    chart = app.gui.plots.charts[app.gui.plots.mode]["xb"]
    drawn = np.asarray(chart.data[0])
    if len(t) < 2:
        return [] if not np.any(drawn) else [f"the x_b chart shows {len(drawn)} samples of a run that has none"]
    if len(drawn) != len(t) or not np.allclose(drawn, t):
        return [f"the x_b chart shows t = {drawn[:1]}..{drawn[-1:]}, the run's plots {t[:1]}..{t[-1:]}"]
    return []


def page_violations(app: RnsApp, tab: ProtocolClient) -> list[str]:
    """A tab's scene (as viser's page holds it) against the server's: names, poses and visibility."""
    assert tab.scene is not None
    registry = dict(app.server.scene._handle_from_node_name)  # viser keeps its handles here
    page = tab.scene.snapshot()
    out = [f"the page lacks {n}" for n in sorted(set(registry) - set(page))[:3]]
    out += [f"the page still holds {n}" for n in sorted(set(page) - set(registry))[:3]]
    for name in sorted(set(registry) & set(page)):
        h, p = registry[name], page[name]
        w = np.asarray(p.wxyz)
        if not np.allclose(h.position, p.position, atol=1e-6):
            out.append(f"{name} at {np.round(p.position, 4)} in the page, {np.round(h.position, 4)} on the server")
        elif not (np.allclose(h.wxyz, w, atol=1e-6) or np.allclose(h.wxyz, -w, atol=1e-6)):
            out.append(f"{name} turned {np.round(w, 3)} in the page, {np.round(h.wxyz, 3)} on the server")
        elif bool(h.visible) != p.visible:
            out.append(f"{name} {'shown' if p.visible else 'hidden'} in the page, not on the server")
    return out
