"""A recording as a folder that plays in viser's own client with no Python running.

:func:`scene_file` draws an immutable recording of the live session (:mod:`rns_viz.live.published.recording`)
frame by frame into a private, unconnected viser server's scene (the same arm, base, ghost and
teaching arrows as the app) while viser's scene serializer records every message with the recorded
time between frames; :func:`player_zip` packs viser's built client (one ``index.html``) and the
``.viser`` file. Served by any static file server it plays (``index.html?playbackPath=rns_scene.viser``,
with viser's own timeline, pause and speed): a demo prepared once, played in class without risk.
"""

from __future__ import annotations

import io
import zipfile
from dataclasses import replace
from pathlib import Path

import numpy as np
import viser

from rns_viz.live.loop.replay_mode import replay_snapshot
from rns_viz.live.published.recording import Recording
from rns_viz.live.published.snapshot import Overlays, ReplayView, Snapshot
from rns_viz.viz.scene.fsms_scene import FsmsScene
from rns_viz.viz.scene.quantities import REACTION
from rns_viz.viz.scene.scene_callouts import SceneCallouts
from rns_viz.viz.scene.teach_scene import TeachScene
from rns_viz.viz.scene.view_toggles import ViewToggles

RECORDING_NAME = "rns_scene.viser"
PLAYER_URL = f"index.html?playbackPath={RECORDING_NAME}"  # open this from a static server of the folder
FRAME_S = 1.0 / 30.0  # s of recorded time between drawn frames (the player's time resolution)


def scene_file(
    recording: Recording,
    template: Snapshot,
    overlays: Overlays | None = None,
    exaggeration: float = 1.0,
    view: ViewToggles | None = None,
) -> bytes:
    """The recording drawn at 30 frames per recorded second as a ``.viser`` file (bytes).

    ``template``: a snapshot of the session (settings and readouts not recorded per step);
    ``overlays``: the reactionless paths or reachable set to draw; ``view``: what is shown (all if None).
    """
    view = view or ViewToggles({})
    server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    try:
        scene = FsmsScene(server, recording.model, trail_frame="base")
        teach = TeachScene(server, recording.model, scene)
        callouts = SceneCallouts(server, scene, teach.ghost, None, None)  # no page: each label at its point
        if overlays is not None:
            _draw_overlays(scene, teach, overlays)
        serializer = server.get_scene_serializer()
        t0, t1 = recording.span
        m = recording.model.m
        for k, t in enumerate(np.arange(t0, t1 + 0.5 * recording.dt, FRAME_S)):
            if k:
                serializer.insert_sleep(FRAME_S)
            frame = replace(template, replay=ReplayView(recording, float(t), 0.0, 1.0, False, 0, True))
            snap = replay_snapshot(frame)
            q = snap.q.copy()
            q[:m] = np.clip(q[:m], -10.0 / max(exaggeration, 1e-9), 10.0 / max(exaggeration, 1e-9))
            with server.atomic():
                scene.update(q, exaggeration)
                wrench = snap.readouts.reaction_wrench  # all six rows on a 6-DOF base: arrows as live
                scene.set_reaction_force(float(np.nan_to_num(snap.readouts.reaction)), REACTION.name, wrench)
                teach.draw(snap, snap.q_shadow, exaggeration, view)
                callouts.frame(float(t), view.on("labels"))
        return serializer.serialize()
    finally:
        server.stop()


def _draw_overlays(scene: FsmsScene, teach: TeachScene, overlays: Overlays) -> None:
    curves = list(overlays.family or [])
    if overlays.current is not None:
        curves.append(overlays.current)
    if curves:
        scene.set_path_family(curves, len(curves) - 1 if overlays.current is not None else None)
    scene.set_reachable_set(overlays.reach)
    teach.set_reach(overlays.reach)
    teach.set_path(overlays.current)


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
