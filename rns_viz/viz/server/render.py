"""The render thread: what the session publishes, sent to the browsers (only what changed).

At 60 Hz (33 Hz with a crowd) it reads the session's snapshot and updates the scene when the drawn
state changed, the overlays when the background worker produced new ones, the notifications, the
live plots (15 Hz), the status text and readouts (5 Hz) and the settings shown in the panel.
"""

from __future__ import annotations

import threading
import time
import traceback
from collections.abc import Callable

import numpy as np
import viser

from rns_viz.defaults import defaults_for
from rns_viz.live.loop.replay_mode import replay_snapshot
from rns_viz.live.loop.session import Session
from rns_viz.live.operator.kinds import operator_class
from rns_viz.live.published.snapshot import Snapshot
from rns_viz.live.runs.laws import LAW_LABELS
from rns_viz.live.teaching.rank_view import has_rank_inset
from rns_viz.model import FsmsModel
from rns_viz.viz.clients.connections import Connections
from rns_viz.viz.panels.base_panel import BasePanel
from rns_viz.viz.panels.control_panel import G_M_LABELS, SPEED_LABELS, GuiElements
from rns_viz.viz.panels.gain_panel import GainExplorerView
from rns_viz.viz.panels.inputs import Controls
from rns_viz.viz.panels.live_plots import COMPENSATION_SIDES, SUPPRESSION_SIDES
from rns_viz.viz.panels.model_words import kick_hint, target_text
from rns_viz.viz.panels.panel_text import readouts_html, status_html
from rns_viz.viz.panels.preset_rows import preset_description, show_presets
from rns_viz.viz.scene.fsms_scene import FsmsScene
from rns_viz.viz.scene.quantities import REACTION
from rns_viz.viz.scene.rank_scene import RankScene
from rns_viz.viz.scene.scene_callouts import SceneCallouts
from rns_viz.viz.scene.scene_nodes import node_names, resend_poses
from rns_viz.viz.scene.teach_scene import TeachScene
from rns_viz.viz.scene.view_toggles import ViewToggles, first_look
from rns_viz.viz.server.drawn_factor import DrawnFactor
from rns_viz.viz.server.frame_rate import PLOT_S, TEXT_S, frame_interval

TARGET_HANDLE = f"{FsmsScene.BASE_AT_REST}/target_handle"  # at rest: the page drags it in that frame
KEPT_ACROSS_MODELS = ("gain_map", "labels")  # toggles a model switch leaves as they are
# the names written in the scene that the *Labels* toggle hides (arrows' labels follow their arrows)


class Renderer:
    """The scene of the session's model, the target handle, and the loop that keeps both current."""

    def __init__(
        self,
        server: viser.ViserServer,
        session: Session,
        gui: GuiElements,
        controls: Controls,
        connections: Connections,
        view: ViewToggles | None = None,
        base_panel: BasePanel | None = None,
    ) -> None:
        self.server = server
        self.base_panel = base_panel
        self.view = view or ViewToggles({})
        self.text_panels: list[Callable[[Snapshot], None]] = []  # more panels refreshed with the text (5 Hz)
        self.page_notice: Callable[[int], bool] = lambda client_id: False  # a page's panel shows the slowed line
        self.session = session
        self.gui = gui
        self.controls = controls
        self.connections = connections
        self.scene_updates = 0  # frames in which the scene was sent
        self.plot_updates = 0
        snap = session.snapshot()
        self.model_name = snap.settings.model
        self.explorer = GainExplorerView(server, session, gui, controls, connections)
        self._build_scene(snap)
        self.names_drawn = node_names(server)  # every scene node name drawn so far (for rebuilds)
        self._seen = _Seen()
        self.sync_settings(snap)
        self._stop = threading.Event()
        self.thread = threading.Thread(target=self._loop, name="rns-render", daemon=True)

    def start(self) -> None:
        self.thread.start()

    def stop(self) -> None:
        self._stop.set()
        if self.thread.is_alive():
            self.thread.join(timeout=5.0)

    # ---------------------------------------------------------------- scene
    def _build_scene(self, snap: Snapshot) -> None:
        self.model = FsmsModel.from_key(snap.settings.model)  # drawing only (its own pinocchio data)
        spatial = len(self.model.task_rows) == 3  # the handle moves in 3-D and gives (x, y, z)
        self.scene = FsmsScene(self.server, self.model, trail_frame="base")
        self._reach = self.model.arm_reach
        self.factor = DrawnFactor(self.model, self.gui, self.controls, self.view)  # the base's drawn factor
        self.teach = TeachScene(self.server, self.model, self.scene)
        self.rank = RankScene(self.server, self.model, self.scene.style)
        self.kind = operator_class(self.model)  # what the operator drives: the panel's folders, laws and words
        dual = self.kind.compensates
        self.gui.plots.sides = COMPENSATION_SIDES if dual else SUPPRESSION_SIDES
        st = self.scene.style
        self.handle = self.server.scene.add_transform_controls(
            TARGET_HANDLE,
            scale=10.0 * st.marker_radius,
            active_axes=(True, True, spatial),
            disable_rotations=True,
            depth_test=False,
            position=self.home(snap) + np.array([0.0, 0.0, st.overlay_z]),
        )
        self.handle.on_update(self.controls.on_drag)
        self.controls.spatial_target = spatial
        self.controls.target_lift = np.array([0.0, 0.0, st.overlay_z])
        if self.base_panel is not None:
            self.base_panel.for_model(self.model)
        show_presets(self.gui.presets, self.gui.menu, snap.settings.model)
        self.gui.target_text.content = target_text(self.model)
        self.gui.kick_peak.hint = kick_hint(self.model)
        if "rank" in self.view.boxes:  # only an arm of 2 or 3 joints has the overlay
            self.view.boxes["rank"].visible = has_rank_inset(self.model)
        self.view.fit(self.model)  # toggles with nothing to draw on this model are disabled, saying why
        self.callouts = SceneCallouts(
            self.server,
            self.scene,
            self.teach.ghost,
            self.handle,
            self.connections,
            lambda cid: self.page_notice(cid),
            lambda: self.explorer.scene.texts() if self.explorer.scene is not None else [],
        )
        self.scene.set_target(snap.target)
        self.explorer.build_scene(self.scene.style, self.kind.shows == "path")

    def home(self, snap: Snapshot) -> np.ndarray:
        """Where the target handle rests: the session's target, else the end effector."""
        if snap.target is not None:
            return np.asarray(snap.target, dtype=float)
        return self.model.ee_position(snap.q[self.model.m :])

    def _rebuild_for_model(self, snap: Snapshot) -> None:
        """The scene and controls of the session's model. The model counts as drawn only once all of it is
        built: a failed build (viser's message buffer can raise when a thread's message races its event
        loop) is done again from a reset scene at the next frame, not left half-built for good."""
        self.server.scene.reset()
        self._build_scene(snap)
        built = node_names(self.server)
        resend_poses(self.server, built & self.names_drawn)  # a page may still hold a namesake's pose
        self.names_drawn |= built
        g, controls = self.gui, self.controls
        with controls.quiet():
            defaults = defaults_for(self.model)
            g.kick_peak.min, g.kick_peak.max = -defaults.kick_range_N, defaults.kick_range_N
        controls.show(g.kick_peak, defaults.kick_peak_N)
        controls.show(g.exaggeration, defaults.exaggeration)
        controls.show(g.auto_exaggeration, defaults.auto_exaggeration)
        kept = {name for name in KEPT_ACROSS_MODELS if self.view.on(name)}  # the viewer's choice, not the model's
        self.view.show_only(first_look(self.model) | kept)  # the new model's first look
        self._seen = _Seen()
        self.sync_settings(snap)
        self.model_name = snap.settings.model
        self.session.restart_clock()  # the new model's time runs from when its scene is drawn

    # ---------------------------------------------------------------- the loop
    def _loop(self) -> None:
        next_time = time.perf_counter()
        while not self._stop.is_set():
            try:
                with self.server.atomic():  # the frame's messages leave together: one event-loop wake-up, not one each
                    self._frame(next_time)
                    self.connections.panels.refresh()
            except Exception:  # drawing must never kill the app
                traceback.print_exc()
            next_time += frame_interval(self.connections.client_count())
            delay = next_time - time.perf_counter()
            if delay < -0.1:
                next_time = time.perf_counter()
            self._stop.wait(max(0.0, delay))

    def _frame(self, now: float) -> None:
        live = self.session.snapshot()
        snap = replay_snapshot(live)  # during a replay: the recorded step at the playhead (settings: live's)
        if snap.settings.model != self.model_name:
            self._rebuild_for_model(live)
        seen = self._seen
        jumped = (snap.replay is not None or seen.replaying) and not 0.0 <= snap.t - seen.t < 0.5  # a replay seek
        seen.t, seen.replaying = snap.t, snap.replay is not None
        if snap.epoch != seen.epoch or jumped:
            seen.epoch = snap.epoch
            self.scene.clear_trail()
        exaggeration = self.factor.for_frame(snap)
        self._draw_state(snap, exaggeration)
        q_shadow = None if snap.q_shadow is None else self._drawn(snap.q_shadow, exaggeration)
        self.teach.draw(snap, q_shadow, exaggeration, self.view)
        self._apply_view()
        self.rank.draw(self.view.on("rank"))
        if snap.overlay_version != seen.overlay_version:
            seen.overlay_version = snap.overlay_version
            self._draw_overlays()
        self.explorer.frame(self.model_name)  # the gain map, loci and authority, when the gain view changed
        if self.controls.take_handle_home_request():
            seen.target_version = -1
        self._draw_target(snap)
        self.callouts.frame(now, self.view.on("labels"))
        for notice in self.session.pop_notices():
            self.connections.notify_by_id(notice.client, notice.title, notice.body, notice.level)
        if self.controls.apply_reverts() or snap.settings_version != seen.settings_version:
            seen.settings_version = snap.settings_version
            self.sync_settings(live)
        if now >= seen.next_plot:
            seen.next_plot = now + PLOT_S
            self._update_plots(snap)
        if now >= seen.next_text:
            seen.next_text = now + TEXT_S
            self._update_text(snap)

    def _apply_view(self) -> None:
        """The toggles of *Show in the scene* the render thread owns: other paths, the gain map (the labels:
        the callouts read theirs each frame)."""
        seen, view = self._seen, self.view
        paths = view.on("paths")
        if paths != seen.paths:
            seen.paths = paths
            seen.overlay_version = -1  # redrawn with or without the family
        self.explorer.show(view.on("gain_map"), self.scene)

    def _draw_state(self, snap: Snapshot, exaggeration: float) -> None:
        """The arm, the base and the reaction arrow (and the base label's factor), when what a viewer sees changed."""
        seen = self._seen
        q = self._drawn(snap.q, exaggeration) if np.all(np.isfinite(snap.q)) else seen.q
        if q is not None and (not np.array_equal(q, seen.q) or exaggeration != seen.exaggeration):
            seen.q, seen.exaggeration = q, exaggeration
            with self.server.atomic():
                self.scene.update(q, exaggeration)
                f = snap.readouts.reaction  # N, exactly the readout's (Eq. 1); the label shows 3 digits
                wrench = snap.readouts.reaction_wrench  # N, N m: all six rows for a 6-DOF base
                self.scene.set_reaction_force(f if np.isfinite(f) else 0.0, REACTION.name, wrench)
            self.scene_updates += 1

    def _draw_target(self, snap: Snapshot) -> None:
        """The handle back home when the target moved (or a drag was refused), and the target marker."""
        seen = self._seen
        pose = snap.orientation is not None and snap.orientation.on  # a pose handle: rotation rings too
        if snap.target_version != seen.target_version or pose != seen.pose:
            seen.target_version, seen.pose = snap.target_version, pose
            home = self.home(snap)
            if np.all(np.isfinite(home)):
                self.handle.position = home + np.array([0.0, 0.0, self.scene.style.overlay_z])
            self.handle.disable_rotations, self.controls.pose_target = not pose, pose
            self.handle.wxyz = snap.orientation.wxyz if pose else (1.0, 0.0, 0.0, 0.0)  # type: ignore[union-attr]
        target = None if snap.target is None else tuple(np.round(snap.target, 6))
        if target is not None and not np.all(np.isfinite(target)):
            target = seen.target  # never draw a non-finite target
        if target != seen.target:
            seen.target = target
            self.scene.set_target(None if target is None else np.asarray(target, dtype=float))

    def _drawn(self, q: np.ndarray, exaggeration: float) -> np.ndarray:
        """q rounded to what a viewer can see (1e-4 rad; 1e-4 of the arm's reach as drawn): an unchanged
        picture sends nothing. A diverged state stays drawable (base clipped to +-10 m)."""
        m = self.model.m
        out = np.round(q, 4)
        quantum = 1e-4 * self._reach / max(exaggeration, 1e-9)
        out[:m] = np.clip(np.round(q[:m] / quantum) * quantum, -10.0, 10.0)
        return out

    def _draw_overlays(self) -> None:
        ov = self.session.overlays()
        if ov.model != self.model_name:  # a switch published after this frame's snapshot: drawn once rebuilt
            self._seen.overlay_version = -1
            return
        curves = list(ov.family or []) if self.view.on("paths") else []  # the current path is always drawn
        if ov.current is not None:
            curves.append(ov.current)
        if curves:
            self.scene.set_path_family(curves, len(curves) - 1 if ov.current is not None else None)
        else:  # no family and no current path (yet): the last model's or preset's must not stay lit
            self.scene.paths.visible = False
        self.scene.set_reachable_set(ov.reach)
        self.teach.set_reach(ov.reach)
        self.teach.set_path(ov.current)

    # ---------------------------------------------------------------- the panel
    def _update_plots(self, snap: Snapshot) -> None:
        replay = snap.replay  # during a replay: the recording's plots up to the playhead
        version = self.session.plots.version if replay is None else (replay.version, snap.t)
        if self.gui.plots.mode != self._seen.plot_mode:  # the other scale's charts: send them data now
            self._seen.plot_mode = self.gui.plots.mode
        elif version == self._seen.plot_version:
            return
        self._seen.plot_version = version
        arrays = self.session.plot_arrays() if replay is None else replay.recording.plot_arrays(snap.t)
        if self.gui.plots.update(arrays):
            self.plot_updates += 1
        if self.base_panel is not None and replay is None:
            self.base_panel.update(arrays, version)

    def _update_text(self, snap: Snapshot) -> None:
        g = self.gui
        status, readouts = status_html(snap), readouts_html(snap)
        if g.status.content != status:
            g.status.content = status
        if g.readouts.content != readouts:
            g.readouts.content = readouts
        for refresh in self.text_panels:
            refresh(snap)
        pause_label = "Reset (diverged)" if snap.diverged else "Resume" if snap.paused else "Pause"
        if g.pause.label != pause_label:
            g.pause.label = pause_label
            g.pause.icon = (
                viser.Icon.REFRESH
                if snap.diverged
                else viser.Icon.PLAYER_PLAY
                if snap.paused
                else viser.Icon.PLAYER_PAUSE
            )
        cyclic_label = "Stop cyclic motion" if snap.mode.startswith("cyclic") else "Start cyclic motion"
        if g.cyclic.label != cyclic_label:
            g.cyclic.label = cyclic_label
        self._show_path_position(snap)
        self._handle_follows(snap)

    def _handle_follows(self, snap: Snapshot) -> None:
        """While a preset runs its own motion (no target) the handle stays on the end effector."""
        if snap.settings.preset is None or snap.target is not None or not np.all(np.isfinite(snap.q)):
            return
        home = self.home(snap) + np.array([0.0, 0.0, self.scene.style.overlay_z])
        if np.linalg.norm(home - np.asarray(self.handle.position)) > 0.5 * self.scene.style.marker_radius:
            self.handle.position = home

    def _show_path_position(self, snap: Snapshot) -> None:
        """The path slider: its range and position on the current path; disabled at 0 while there is
        none (a preset runs its own motion, or the path is still being computed)."""
        g = self.gui
        known = snap.sigma_range is not None and np.all(np.isfinite(snap.sigma_range))
        known = known and snap.sigma is not None and np.isfinite(snap.sigma)
        if g.sigma.disabled != (not known):
            g.sigma.disabled = not known
        if not known:
            if g.sigma.min <= 0.0 <= g.sigma.max:
                self.controls.show(g.sigma, 0.0)
            return
        assert snap.sigma_range is not None and snap.sigma is not None
        lo, hi = snap.sigma_range
        if (g.sigma.min, g.sigma.max) != (round(lo, 1), round(hi, 1)):
            g.sigma.min, g.sigma.max = round(lo, 1), round(hi, 1)
        if "scrub" not in snap.mode:
            self.controls.show(g.sigma, float(np.clip(round(snap.sigma, 1), g.sigma.min, g.sigma.max)))

    def sync_settings(self, snap: Snapshot) -> None:
        """Show the settings in force (after presets, law switches, model switches, refused input)."""
        g, st, show = self.gui, snap.settings, self.controls.show
        show(g.law, LAW_LABELS[st.law])
        show(g.suppression, st.suppress)
        for name, slider in g.gains.items():
            show(slider, float(getattr(st.gains, name)))
        if g.gains["g_m"].slider.label != G_M_LABELS[st.law]:  # what g_m does differs by law
            g.gains["g_m"].slider.label = G_M_LABELS[st.law]
        show(g.ubar_speed, st.ubar_speed)
        show(g.target_speed, st.target_speed)
        show(g.shadow, st.shadow)
        show(g.speed, SPEED_LABELS[st.speed])
        show(g.model, g.menu.label(st.model))
        if self.base_panel is not None:
            self.base_panel.sync(snap, self.model)
        g.preset_info.content = preset_description(st.preset)
        on_path = self.kind.follows == "path"
        g.path_folder.visible = on_path
        g.target_folder.visible = not on_path
        task_gains = not on_path and st.law != "velocity"
        joint_gains = on_path and st.law != "velocity"
        g.gains["G_p"].visible = g.gains["G_d"].visible = task_gains
        g.gains["k_p"].visible = g.gains["k_d"].visible = joint_gains
        g.law.disabled = len(self.kind.laws) == 1  # one law for dual arms: the compensating law


class _Seen:
    """What the render thread last sent, to send only changes."""

    def __init__(self) -> None:
        self.epoch = -1
        self.q: np.ndarray | None = None
        self.exaggeration = float("nan")
        self.overlay_version = -1
        self.target_version = -1
        self.pose = False  # the handle shows rotation rings (the orientation is tracked)
        self.target: tuple[float, ...] | None = ()
        self.settings_version = -1
        self.plot_version: object = -1
        self.t = 0.0  # s, the drawn state's time, and whether it was a replay's (a jump restarts the trail)
        self.replaying = False
        self.next_plot = 0.0
        self.next_text = 0.0
        self.plot_mode = ""
        self.paths: bool | None = None
