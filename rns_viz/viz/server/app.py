"""The live app: a viser server showing a :class:`~rns_viz.live.loop.session.Session`.

Four parts, one concern each: :class:`~rns_viz.viz.panels.inputs.Controls` turns GUI input into the
session's command methods; :class:`~rns_viz.viz.clients.connections.Connections` holds the clients, the
operator lock and the password; :class:`~rns_viz.viz.server.render.Renderer` runs the render thread that
sends the session's snapshots, plots, text, overlays and notices to the browsers;
:class:`~rns_viz.viz.server.page_pacing.ClientPace` paces what each browser receives to what it can draw.

    serve()                      # TREP on http://127.0.0.1:8080, blocking
    app = start_app(port=0)      # non-blocking; app.port, app.session, app.gui; app.stop()
"""

from __future__ import annotations

import gc
import threading
import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import viser

from rns_viz.live.loop.session import Session
from rns_viz.live.operator.operator_lock import OperatorLock
from rns_viz.live.reach.region import arm_reach
from rns_viz.model import FsmsModel
from rns_viz.viz.clients.connections import Connections
from rns_viz.viz.panels import presentation
from rns_viz.viz.panels.base_panel import BasePanel
from rns_viz.viz.panels.control_panel import GuiElements, make_gui
from rns_viz.viz.panels.inputs import Controls
from rns_viz.viz.panels.keys import add_key_commands, jog_step
from rns_viz.viz.panels.lesson_panel import LessonPanel
from rns_viz.viz.panels.model_menu import ModelMenu
from rns_viz.viz.panels.path_words import PathWords
from rns_viz.viz.panels.pictures import Pictures
from rns_viz.viz.panels.rank_inset import RankInsetPanel
from rns_viz.viz.panels.replay_panel import ReplayPanel
from rns_viz.viz.scene.fsms_scene import FsmsScene
from rns_viz.viz.scene.view_toggles import first_look, make_view_toggles
from rns_viz.viz.server.page_pacing import ClientPace
from rns_viz.viz.server.render import TARGET_HANDLE, Renderer

# Served only to this machine, the first page to connect is the presenter's and operates at once; served to
# the network (e.g. --host 0.0.0.0), a phone that connects first must not: the seat waits for Take control.
LOOPBACK_HOSTS = ("127.0.0.1", "localhost", "::1")
IDLE_RESTART_S = 60.0  # s of simulated time: a session nobody watched this long restarts for its first visitor


class RnsApp:
    """The GUI and scene of one session on one viser server."""

    def __init__(
        self,
        server: viser.ViserServer,
        session: Session,
        password: str | None = None,
        models: Sequence[str] = (),
        pace: bool = True,
        seat_on_connect: bool = True,
        pause_unwatched: bool = False,
        present: bool = False,
        shared: bool = True,
    ) -> None:
        """``seat_on_connect=False``: nobody operates by connecting first, the seat goes to the first visitor who
        presses Take control (a server open to the network; see :func:`start_app`); ``models``: parameter files
        offered in the model dropdown besides the bundled models;
        ``pace=False``: every page gets every update however slowly it draws; ``pause_unwatched``: the
        simulation pauses while no page is open and runs on when one comes (one student's app: its CPU
        is then ~2 % of a core, not ~12 %); ``present``: the projector's screen
        (rns_viz.viz.panels.presentation); ``shared=False``: the app is one page's own simulation (a visitor's
        in ``--each-visitor`` mode), which that page always operates: no Operator panel to take or release it."""
        self.server = server
        self.session = session
        self.password = password
        self.connections = Connections(server, password, seat_on_connect, shared)
        model = session.snapshot().settings.model
        self.gui: GuiElements = make_gui(server, model, ModelMenu((model, *models)))
        self.controls = Controls(self.gui, session, self.connections)
        with self.gui.controls_tab:  # the folders below go into the docked controls
            self.base_panel = BasePanel(server, self.controls, order=self.gui.readouts.order + 0.5)
            self.view = make_view_toggles(server.gui, self.connections, first_look(session.state.model))
            self.rank_inset = RankInsetPanel(server, self.view)  # shown below the toggles while rank loss is ticked
            self.lessons = LessonPanel(
                server, session, self.connections, self.gui.status.order + 0.5, self.view, self.gui.menu.keys.values()
            )
            self.renderer = Renderer(
                server, session, self.gui, self.controls, self.connections, self.view, base_panel=self.base_panel
            )
            self.path_words = PathWords(server, self.gui.path_folder, order=self.gui.sigma.order + 0.01)
            self.renderer.text_panels += [self.lessons.refresh, self.path_words.refresh]
            self.pictures = Pictures(server, self.connections, lambda: session.snapshot().settings.model)
            self.replay = ReplayPanel(server, session, self.controls, self.connections, self.view)
        self.renderer.text_panels += [self.replay.refresh, self.rank_inset.refresh]
        # each page gets updates at the rate it can draw; told so under the status line when slowed
        self.pace = ClientPace(server, enabled=pace, notice_order=self.gui.status.order + 0.1)
        self.renderer.page_notice = self.pace.noticed  # the scene's labels keep clear of that line
        self.keys = add_key_commands(server.gui, self.gui, self.controls, session, self.frame_robot, self._jog_setup)
        self.gui.frame_robot.on_click(lambda event: self.frame_robot(event.client))
        self.present_style: viser.GuiHtmlHandle | None = None  # the projector's text size (--present)
        if present:
            g = self.gui
            hidden = (self.renderer.explorer.folder, self.replay.folder, g.gains_folder, g.download)
            self.present_style = presentation.present(server.gui, g.plots_panel, hidden)
        start = session.snapshot()
        self._unwatched_since: tuple[int, float] | None = (start.epoch, start.t)  # (epoch, t) the last client left
        self._visitors = threading.Lock()
        self.pause_unwatched = pause_unwatched
        self._paused_unwatched = pause_unwatched  # paused while no page is open (the next page resumes it)
        if pause_unwatched:
            session.pause()
        server.on_client_connect(self._client_joined)
        server.on_client_disconnect(self._client_left)

    @property
    def port(self) -> int:
        return self.server.get_port()

    @property
    def lock(self) -> OperatorLock:
        return self.connections.lock

    @property
    def model(self) -> FsmsModel:
        """The model drawn (the session's model; its own instance)."""
        return self.renderer.model

    @property
    def model_name(self) -> str:
        return self.renderer.model_name

    @property
    def scene(self) -> FsmsScene:
        return self.renderer.scene

    @property
    def handle(self) -> viser.TransformControlsHandle:
        """The draggable target handle in the scene."""
        return self.renderer.handle

    @property
    def scene_updates(self) -> int:
        """Frames in which the scene was sent."""
        return self.renderer.scene_updates

    @property
    def plot_updates(self) -> int:
        return self.renderer.plot_updates

    @property
    def render_thread(self) -> threading.Thread:
        return self.renderer.thread

    def frame_robot(self, client: viser.ClientHandle | None) -> None:
        """Point ``client``'s camera at the robot (every client's for the server's own call, None)."""
        if client is None:
            self.scene.set_initial_camera(clients=True)
        else:
            self.scene.frame_client(client)

    def _jog_setup(self) -> tuple[np.ndarray, float, bool]:
        """For a jog key: the target now (base frame, m), the step (m), whether it is spatial."""
        snap = self.session.snapshot()
        return self.renderer.home(snap), jog_step(arm_reach(self.model)), self.controls.spatial_target

    def good(self, handle: Any) -> Any:
        """The last good value of a GUI control (what the app acts on)."""
        return self.controls.good(handle)

    def start(self) -> RnsApp:
        self.renderer.start()
        return self

    def stop(self) -> None:
        self.pace.stop()
        self.renderer.stop()
        self.session.stop()
        self.server.stop()

    def _client_joined(self, client: viser.ClientHandle) -> None:
        """Register the client. The first visitor of a session nobody watched for over IDLE_RESTART_S of
        simulated time gets it from the start (not "t = 4365 s" of a kick nobody saw); a reload (the page
        back after a moment) keeps the simulation, its recording and, for the operator's page, control."""
        self.connections.client_joined(client)
        self.pace.client_joined(client)
        # the page's camera messages tell its size: framed for it first, and again as scene.follow_page_size says
        client.camera.on_update(lambda _: self.scene.follow_page_size(client))

        with self._visitors:
            since, self._unwatched_since = self._unwatched_since, None
            if since is not None:  # nobody watched since then (a reload's page arrives while the old one is here)
                snap = self.session.snapshot()
                unwatched = snap.t - since[1] if snap.epoch == since[0] else snap.t  # s of simulated time
                if unwatched > IDLE_RESTART_S:
                    self.session.reset()
            if self._paused_unwatched:
                self._paused_unwatched = False
                self.session.resume()
        self.connections.identify_browser(client)  # last: it waits for the page's answer

    def _client_left(self, client: viser.ClientHandle) -> None:
        """End the client's drag while it still counts as the operator, then pass control on (or keep it a
        moment for the operator's reloading page); the last one to leave starts the unwatched time."""
        self.controls.client_left(client.client_id)
        self.connections.client_left(client.client_id)
        self.pace.client_left(client.client_id)
        with self._visitors:
            if self.connections.client_count() == 0:
                snap = self.session.snapshot()
                self._unwatched_since = (snap.epoch, snap.t)
                if self.pause_unwatched and not snap.paused:
                    self._paused_unwatched = True
                    self.session.pause()


def start_app(
    model: str = "trep",
    host: str = "127.0.0.1",
    port: int = 8080,
    password: str | None = None,
    realtime: bool = True,
    verbose: bool = True,
    lesson: int | None = None,
    models: Sequence[str] = (),
    pace: bool = True,
    pause_unwatched: bool = False,
    present: bool = False,
) -> RnsApp:
    """Start server, session and render thread; returns at once. ``port=0`` picks a free port;
    ``lesson``: start at that lesson (1-based) of the model; ``model`` is a bundled name or a parameter
    file (ModelFileError names the element at fault), ``models`` more files for the model dropdown;
    ``pace=False``: every page gets every update however slowly it draws (for comparisons; see
    :mod:`rns_viz.viz.server.page_pacing`); ``pause_unwatched``: see :class:`RnsApp`; ``present``:
    larger text and fewer folders, for a projector."""
    session = Session(model, realtime=realtime, start=False)  # started once the app is built (no backlog)
    server = viser.ViserServer(host=host, port=port, verbose=verbose)
    server.gui.set_panel_label("rns_viz: reaction null-space control")
    try:
        app = RnsApp(
            server,
            session,
            password,
            models,
            pace=pace,
            seat_on_connect=host in LOOPBACK_HOSTS,
            pause_unwatched=pause_unwatched,
            present=present,
        ).start()
        if lesson is not None:
            session.start_lesson(model, lesson)
    except Exception:
        session.stop()
        server.stop()
        raise
    # The long-lived objects built so far (models, meshes, scene, GUI) leave the collector's reach, so
    # a full collection holds the interpreter lock, and with it the simulation, for far less time.
    gc.collect()
    gc.freeze()
    session.start()
    return app


def serve(
    model: str = "trep",
    host: str = "127.0.0.1",
    port: int = 8080,
    password: str | None = None,
    lesson: int | None = None,
    models: Sequence[str] = (),
    pause_unwatched: bool = False,
    present: bool = False,
) -> None:
    """Serve the live app until interrupted (Ctrl+C). Binds 127.0.0.1 unless told otherwise."""
    app = start_app(
        model, host, port, password, lesson=lesson, models=models, pause_unwatched=pause_unwatched, present=present
    )
    print(f"rns_viz live app: http://{host}:{app.port}  (Ctrl+C to stop)")
    serve_until_interrupted(app.stop)


def serve_until_interrupted(stop: Callable[[], None]) -> None:
    """Block this thread (the servers run in their own) until Ctrl+C, then ``stop()``."""
    try:
        while True:
            time.sleep(3600.0)
    except KeyboardInterrupt:
        pass
    finally:
        stop()


__all__ = ["TARGET_HANDLE", "RnsApp", "serve", "serve_until_interrupted", "start_app"]
