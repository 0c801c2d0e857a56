"""The *Record and replay* folder: replay the last N seconds in the app, export them for viser's player
and as CSV.

The session always keeps the last minute (:mod:`rns_viz.live.outputs.recorder`). *Replay* shows the newest N
seconds in the scene and the plots while the simulation waits: a timeline to scrub, play / pause, a
speed from 0.1× to 4×, and *Back to live*, after which the simulation goes on where it was. Every
input is a session command (:mod:`rns_viz.live.loop.replay_mode` applies them in the loop). The exports run in
a thread of their own and download to the clicking browser: a zip of viser's client and the scene
drawn from the recording (plays from any static file server, no Python), or the steps as CSV.
"""

from __future__ import annotations

import math
import threading
import time
import traceback

import viser

from rns_viz.live.loop.commands import REPLAY_SPEEDS
from rns_viz.live.loop.replay_mode import replay_snapshot
from rns_viz.live.loop.session import Session
from rns_viz.live.outputs.recorder import MAX_RECORD_S
from rns_viz.live.published.recording import Recording
from rns_viz.live.published.snapshot import Snapshot
from rns_viz.viz.clients.connections import Connections
from rns_viz.viz.panels.inputs import Controls
from rns_viz.viz.panels.number_field import NumberField
from rns_viz.viz.scene.player_export import PLAYER_URL, player_zip, scene_file
from rns_viz.viz.scene.view_toggles import ViewToggles

DEFAULT_SECONDS = 20.0


class ReplayPanel:
    """Widgets of the folder, their callbacks and the exports (one at a time)."""

    def __init__(
        self,
        server: viser.ViserServer,
        session: Session,
        controls: Controls,
        connections: Connections,
        view: ViewToggles,
    ) -> None:
        self.session, self.controls, self.connections, self.view = session, controls, connections, view
        self.last_scene: bytes | None = None  # the last exported .viser file (tests read it)
        self.last_csv: bytes | None = None
        self._busy = threading.Lock()
        self._shown_version = -1
        gui = server.gui
        with gui.add_folder("Record and replay", expand_by_default=False) as self.folder:
            self.seconds = NumberField(
                gui,
                "Last N seconds (s)",
                min=1.0,
                max=MAX_RECORD_S,
                step=1.0,
                initial_value=DEFAULT_SECONDS,
                hint="How much of the run, up to now, to replay or export, in seconds of simulated time. The app "
                "always keeps the last minute (it starts afresh at Reset, a preset or another model).",
                bounded=True,  # read at the next replay or export
            )
            self.start = gui.add_button(
                "Replay the last N s",
                icon=viser.Icon.PLAYER_PLAY,
                hint="Shows the last N seconds again in the scene and the plots; the simulation waits meanwhile.",
            )
            self.timeline = NumberField(
                gui,
                "Replay time t (s)",
                min=0.0,
                max=1.0,
                step=0.01,
                initial_value=0.0,
                disabled=True,
                hint="Where the replay is, in seconds of simulated time (the time axis of the plots). Drag to scrub.",
                bounded=False,  # the loop checks it is a time of the recording
            )
            self.play = gui.add_button(
                "Pause replay",
                icon=viser.Icon.PLAYER_PAUSE,
                disabled=True,
                hint="Pause or play the replay (from the start again at its end).",
            )
            lo, hi = REPLAY_SPEEDS
            self.speed = NumberField(
                gui,
                "Replay speed (×)",
                min=lo,
                max=hi,
                step=0.1,
                initial_value=1.0,
                hint="Recorded seconds shown per second of your time: 0.1× is ten times slower than it happened.",
                bounded=False,
            )
            self.live = gui.add_button(
                "Back to live",
                icon=viser.Icon.PLAYER_TRACK_NEXT,
                disabled=True,
                hint="Ends the replay; the simulation goes on from where it was when the replay started.",
            )
            self.player = gui.add_button(
                "Download for viser's player (.zip)",
                icon=viser.Icon.DOWNLOAD,
                hint="The last N seconds drawn in 3-D as a folder with viser's own player: unzip, serve it with any "
                f"static web server (python -m http.server) and open {PLAYER_URL}. No rns_viz needed to play it.",
            )
            self.csv = gui.add_button(
                "Download recording (CSV)",
                icon=viser.Icon.TABLE,
                hint="The last N seconds, one row per 1 ms step of both runs, units in the header (s, m, rad, N, "
                "kg·m/s); 17 digits, so it reads back exactly.",
            )
        self._wire()

    # ---------------------------------------------------------------- inputs
    def _length(self) -> float:
        return float(self.controls.good(self.seconds))

    def _wire(self) -> None:
        s, on = self.session, self.controls.on_input
        on(self.seconds, lambda v, c: None)  # read at the next replay or export
        on(self.start, lambda _, c: s.start_replay(self._length(), c), button=True)
        on(self.timeline, lambda v, c: s.seek_replay(float(v), c))
        on(self.play, lambda _, c: self._toggle_play(c), button=True)
        on(self.speed, lambda v, c: s.set_replay_speed(float(v), c))
        on(self.live, lambda _, c: s.stop_replay(c), button=True)
        self.player.on_click(lambda event: self._export(event, "player"))
        self.csv.on_click(lambda event: self._export(event, "csv"))

    def _toggle_play(self, client: int | None) -> None:
        replay = self.session.snapshot().replay
        if replay is None:
            raise ValueError("no replay is running: press 'Replay the last N s' first")
        moving = replay.playing and replay.position(time.perf_counter()) < replay.recording.span[1]
        self.session.play_replay(not moving, client)

    # ---------------------------------------------------------------- exports
    def _export(self, event: viser.GuiEvent, kind: str) -> None:
        client = event.client
        if not self.connections.allowed(client):
            self.connections.refuse_watcher(client)
            return
        if not self._busy.acquire(blocking=False):
            self.connections.notify(client, "Export running", "One export at a time; it is being prepared.", "info")
            return
        exaggeration = float(self.controls.good(self.controls.gui.exaggeration))  # as the scene draws it
        args = (kind, self._length(), client, self.session.snapshot(), exaggeration)
        threading.Thread(target=self._run_export, args=args, name="rns-export", daemon=True).start()

    def _run_export(
        self, kind: str, seconds: float, client: viser.ClientHandle | None, snap: Snapshot, exaggeration: float
    ) -> None:
        try:
            recording = self.session.recording(seconds)
            if recording is None:
                self.connections.notify(client, "Nothing to export", "Let the simulation run a moment first.", "info")
                return
            name, data = self.export(recording, kind, snap, exaggeration)
            for c in self.connections.recipients(client):
                c.send_file_download(name, data, save_immediately=True)
        except Exception as exc:  # an export must never take the server down
            traceback.print_exc()
            self.connections.notify(client, "Export failed", f"{type(exc).__name__}: {exc}", "error")
        finally:
            self._busy.release()

    def export(self, recording: Recording, kind: str, snap: Snapshot, exaggeration: float) -> tuple[str, bytes]:
        """The file name and bytes of an export (``kind``: "player" or "csv")."""
        model = recording.model.name
        if kind == "csv":
            self.last_csv = recording.csv()
            return f"rns_{model}_recording.csv", self.last_csv
        self.last_scene = scene_file(recording, snap, self.session.overlays(), exaggeration, self.view)
        return f"rns_{model}_player.zip", player_zip(self.last_scene)

    # ---------------------------------------------------------------- shown state (render thread, 5 Hz)
    def refresh(self, live: Snapshot) -> None:
        """The timeline, its range and the buttons for the replay in progress (or none)."""
        replay = live.replay
        replaying = replay is not None
        for handle in (self.timeline, self.play, self.live):
            if handle.disabled == replaying:
                handle.disabled = not replaying
        if replay is None:
            self._shown_version = -1
            return
        t0, t1 = replay.recording.span
        t0, t1 = math.floor(100.0 * t0) / 100.0, math.ceil(100.0 * t1) / 100.0  # the slider's 0.01 s grid
        if (self.timeline.min, self.timeline.max) != (t0, t1):
            with self.controls.quiet():
                self.timeline.min, self.timeline.max = t0, t1
        snap = replay_snapshot(live)
        self.controls.show(self.timeline, float(min(max(round(snap.t, 2), t0), t1)))
        if self._shown_version != replay.version:
            self._shown_version = replay.version
            self.controls.show(self.speed, float(round(replay.speed, 1)))
        playing = replay.playing and snap.t < replay.recording.span[1]
        label = "Pause replay" if playing else "Play replay"
        if self.play.label != label:
            self.play.label = label
            self.play.icon = viser.Icon.PLAYER_PAUSE if playing else viser.Icon.PLAYER_PLAY
