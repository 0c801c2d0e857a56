"""Record the scene for viser's own player: a button records the next N seconds of the scene (the
arm, the ghost, every overlay, as the browsers see them) with viser's scene serializer and hands the
clicking browser a zip of a folder: viser's built client and the ``.viser`` file. Served by any static
file server it plays (``index.html?playbackPath=rns_scene.viser``) with no Python running: a demo
prepared once, played in class.

Timing: a small thread inserts the wall-clock time between frames (30 Hz) while recording, so the
file plays at the speed it was seen.
"""

from __future__ import annotations

import io
import threading
import time
import traceback
import zipfile
from pathlib import Path

import viser

from rns_viz.viz.connections import Connections

RECORDING_NAME = "rns_scene.viser"
PLAYER_URL = f"index.html?playbackPath={RECORDING_NAME}"  # open this from a static server of the folder
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
                hint="Records the scene as you see it and downloads a zip: a folder with viser's player and the "
                f"recording; serve it with any static web server and open {PLAYER_URL}. No Python needed.",
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
                client.send_file_download("rns_scene_player.zip", player_zip(data), save_immediately=True)
        except Exception as exc:  # a recording must never take the server down
            traceback.print_exc()
            self.connections.notify(client, "Recording failed", f"{type(exc).__name__}: {exc}", "error")
        finally:
            self._busy.release()


def player_files(data: bytes) -> dict[str, bytes]:
    """The files of a playable folder: viser's built client (one HTML file) and the recording."""
    client = Path(viser.__file__).parent / "client" / "build" / "index.html"
    return {"index.html": client.read_bytes(), RECORDING_NAME: data}


def write_player_folder(data: bytes, folder: Path) -> Path:
    """Write the playable folder; returns the page to open (relative: :data:`PLAYER_URL`)."""
    folder.mkdir(parents=True, exist_ok=True)
    for name, content in player_files(data).items():
        (folder / name).write_bytes(content)
    return folder / "index.html"


def player_zip(data: bytes) -> bytes:
    """The playable folder as a zip (what the button downloads)."""
    with io.BytesIO() as buf:
        with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as z:
            for name, content in player_files(data).items():
                z.writestr(f"rns_scene_player/{name}", content)
        return buf.getvalue()
