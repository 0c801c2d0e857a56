"""Record the scene for viser's own player: a button records the next N seconds of the scene (the
arm, the ghost, every overlay, as the browsers see them) with viser's scene serializer and hands the
``.viser`` file to the clicking browser. The file plays in viser's built client from any static file
server (``?playbackPath=...``), with no Python running: a demo prepared once, played in class.

Timing: a small thread inserts the wall-clock time between frames (30 Hz) while recording, so the
file plays at the speed it was seen.
"""

from __future__ import annotations

import threading
import time
import traceback

import viser

from rns_viz.viz.connections import Connections

TICK_S = 1.0 / 30.0  # s between inserted sleeps (the player's time resolution)
MAX_SECONDS = 60.0


class SceneRecorder:
    """The *Record for playback* slider and button; one recording at a time."""

    def __init__(self, server: viser.ViserServer, connections: Connections) -> None:
        self.server, self.connections = server, connections
        self.last: bytes | None = None  # the last finished recording (tests read it)
        self._busy = threading.Lock()
        with server.gui.add_folder("Record for playback", expand_by_default=False):
            self.seconds = server.gui.add_slider(
                "Length (s)",
                min=1.0,
                max=MAX_SECONDS,
                step=1.0,
                initial_value=10.0,
                hint="How many seconds of the scene to record, from the click on.",
            )
            self.button = server.gui.add_button(
                "Record the scene (.viser)",
                icon=viser.Icon.PLAYER_RECORD,
                hint="Records the scene as you see it and downloads a .viser file that viser's own player "
                "plays from any static web server, without Python.",
            )
        self.button.on_click(self._on_click)

    def _on_click(self, event: viser.GuiEvent) -> None:
        value = self.seconds.value
        seconds = float(value) if isinstance(value, int | float) else 10.0
        if not 0.0 < seconds <= MAX_SECONDS:  # a hostile value: the default
            seconds = 10.0
        if not self.record(seconds, event.client):
            self.connections.notify(event.client, "Already recording", "One recording at a time.", "warning")

    def record(self, seconds: float, client: viser.ClientHandle | None) -> bool:
        """Start recording ``seconds`` of the scene in the background; False if one is running."""
        if not self._busy.acquire(blocking=False):
            return False
        threading.Thread(target=self._run, args=(seconds, client), name="rns-record", daemon=True).start()
        return True

    def _run(self, seconds: float, client: viser.ClientHandle | None) -> None:
        try:
            serializer = self.server.get_scene_serializer()
            start = last = time.perf_counter()
            while last - start < seconds:
                time.sleep(TICK_S)
                now = time.perf_counter()
                serializer.insert_sleep(now - last)
                last = now
            data = serializer.serialize()
            self.last = data
            if client is not None:
                client.send_file_download("rns_scene.viser", data, save_immediately=True)
        except Exception as exc:  # a recording must never take the server down
            traceback.print_exc()
            self.connections.notify(client, "Recording failed", f"{type(exc).__name__}: {exc}", "error")
        finally:
            self._busy.release()
