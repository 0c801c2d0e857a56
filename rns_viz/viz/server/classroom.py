"""A simulation for every visitor: one viser server, one :class:`~rns_viz.live.loop.session.Session` and one
:class:`~rns_viz.viz.server.app.RnsApp` per browser page (``rns-viz serve --each-visitor``).

Each visitor's app is built on a :class:`~rns_viz.viz.clients.client_view.ClientView`, so its panel, scene
and plots live in viser's per-client scope: no other page sees them, and the app's code is the same as
when one simulation is shared. The rules of the room:

- At most ``max_visitors`` simulations run at once (default :func:`default_visitor_cap`). A page that comes
  when all are taken is told so and waits; it gets a simulation as soon as one is free, without a reload.
- A visitor who gives no input (a GUI change, a drag, a click, a camera move) for ``idle_pause_s`` has the
  simulation paused (their next input resumes it); after ``idle_close_s`` it is closed and its place given
  to the next waiting page, and the page offers to start a new one.
- A page that leaves frees its simulation: the render and simulation threads end and the session is
  released.
- The page opened on the server's machine is the presenter's: it may show its simulation on every other
  page (:mod:`rns_viz.viz.server.presenter`).
"""

from __future__ import annotations

import os
import threading
import time
import warnings
from collections.abc import Callable, Sequence
from contextlib import suppress
from typing import Any, cast

import viser
import viser._messages as viser_messages

from rns_viz.live.loop.session import Session
from rns_viz.sim import native as native_step
from rns_viz.viz.clients.client_view import ClientView
from rns_viz.viz.server.app import RnsApp, serve_until_interrupted
from rns_viz.viz.server.page_pacing import LateGate, gate_buffer
from rns_viz.viz.server.presenter import WatchedSession, add_show_switch, add_watching_line, is_loopback, refuser
from rns_viz.viz.server.visitor import CLOSED_TEXT, FULL_TEXT, Visitor

# Simulations that keep real time with every page sent the scene at >= 30 Hz (benchmarks/bench_visitors.py,
# TREP with its shadow run, 2 quiet cores): with the Python step 31 % of a core per visitor, 2 kept it and 3
# did not; with the native step 20 %, 5 kept it. No more than one interpreter runs, however many cores
# (every visitor's threads share its lock): hence a cap per process too.
VISITORS_PER_CORE = 1.0  # (visitors per core, visitors per process) with the Python step
VISITORS_PER_PROCESS = 3
VISITORS_PER_CORE_NATIVE = 2.5  # ... and with the native step
VISITORS_PER_PROCESS_NATIVE = 5
IDLE_PAUSE_S = 5 * 60.0  # wall s without input before a visitor's simulation is paused
IDLE_CLOSE_S = 20 * 60.0  # wall s without input before it is closed and its place freed
IDLE_CHECK_S = 5.0  # wall s between looks for idle visitors
# What a person's hand sends: any GUI change, a drag or click in the scene, a camera move.
INPUT_NAMES = "GuiUpdateMessage TransformControlsUpdateMessage TransformControlsDragStartMessage SceneNodeClickMessage"
INPUT_MESSAGES: tuple[type, ...] = tuple(
    kind
    for name in (*INPUT_NAMES.split(), "SceneNodeDragMessage", "ViewerCameraMessage")
    if isinstance(kind := getattr(viser_messages, name, None), type)
)


def default_visitor_cap(cores: int | None = None, native: bool | None = None) -> int:
    """How many simulations this machine runs at once in real time: so many per core, at most so many per
    process, more with the native step (``native`` None: whether it is installed)."""
    native = native_step.available() if native is None else native
    per_core, most = (
        (VISITORS_PER_CORE_NATIVE, VISITORS_PER_PROCESS_NATIVE) if native else (VISITORS_PER_CORE, VISITORS_PER_PROCESS)
    )
    return max(1, min(most, int(per_core * (cores or os.cpu_count() or 1))))


class Classroom:
    """The visitors of one server and the rules above."""

    def __init__(
        self,
        server: viser.ViserServer,
        model: str = "trep",
        models: Sequence[str] = (),
        max_visitors: int | None = None,
        idle_pause_s: float = IDLE_PAUSE_S,
        idle_close_s: float = IDLE_CLOSE_S,
        make_session: Callable[[str], Session] | None = None,
        is_presenter: Callable[[int], bool] | None = None,
    ) -> None:
        """``make_session``: how a visitor's session is made (default: real time; tests step their own);
        ``is_presenter(client_id)``: whose page may show its simulation to all (default: this machine's)."""
        self.server = server
        self.model = model
        self.models = tuple(models)
        self.max_visitors = max_visitors or default_visitor_cap()
        self.idle_pause_s = idle_pause_s
        self.idle_close_s = idle_close_s
        self.make_session = make_session or (lambda name: Session(name, realtime=True, start=False))
        self.is_presenter = is_presenter or (lambda cid: is_loopback(server, cid))
        self.showing: int | None = None  # the presenter whose simulation every page shows
        self.visitors: dict[int, Visitor] = {}
        self.waiting: list[int] = []  # pages without a place, in order of arrival
        self._guard = threading.RLock()
        self._switching = threading.Lock()
        self._stop = threading.Event()
        self._watcher = threading.Thread(target=self._watch_idle, name="rns-idle", daemon=True)
        self._gates: dict[int, LateGate] = {}  # each page's own stream, paced by its app (a slow page gets less)
        server._websock_server.on_client_connect(self._gate_stream)  # before the page's stream starts
        for kind in INPUT_MESSAGES:
            server._websock_server.register_handler(kind, self._input)  # every page's input, by client id
        server.on_client_connect(self._joined)
        server.on_client_disconnect(self._left)
        self._watcher.start()

    # ---------------------------------------------------------------- readers
    def apps(self) -> dict[int, RnsApp]:
        """The running apps by client id."""
        with self._guard:
            return {cid: v.app for cid, v in self.visitors.items() if v.app is not None}

    def running(self) -> int:
        """Places taken: simulations running or being started."""
        with self._guard:
            return sum(v.app is not None or v.opening for v in self.visitors.values())

    def notice_text(self, client_id: int) -> str | None:
        """The waiting / closed message a page shows (None: it has a simulation)."""
        with self._guard:
            visitor = self.visitors.get(client_id)
            notice = None if visitor is None else visitor.notice
        return None if notice is None else notice.content

    def stop(self) -> None:
        self._stop.set()
        with self._guard:
            visitors = list(self.visitors.values())
        for visitor in visitors:
            self._close(visitor)
        self.server.stop()

    @property
    def port(self) -> int:
        return self.server.get_port()

    # ---------------------------------------------------------------- arrivals and departures
    def _gate_stream(self, connection: Any) -> None:
        """Put a gate on a new page's own stream (its app's scene, panel and plots), for its app to pace."""
        gate = LateGate()
        with suppress(AttributeError):  # a viser without per-client buffers: that page goes unpaced
            if gate_buffer(connection.get_message_buffer(), gate.wait_s, gate.sent):
                self._gates[connection.client_id] = gate

    def _joined(self, client: viser.ClientHandle) -> None:
        visitor = Visitor(ClientView(self.server, client), presenter=self.is_presenter(client.client_id))
        with self._guard:
            self.visitors[client.client_id] = visitor
            self.waiting.append(client.client_id)
        self._admit_waiting()

    def _left(self, client: viser.ClientHandle) -> None:
        with self._guard:
            visitor = self.visitors.pop(client.client_id, None)
            with suppress(ValueError):
                self.waiting.remove(client.client_id)
            self._gates.pop(client.client_id, None)
        if visitor is not None:
            visitor.view.client_left()  # the app's own disconnect handling (a drag ended, control passed on)
            self._close(visitor)
        if self.showing == client.client_id:
            self.show(None)
        self._admit_waiting()

    def _admit_waiting(self) -> None:
        """Give free places to waiting pages, first come first served; tell the rest where they stand."""
        while True:
            with self._guard:
                if not self.waiting or self.running() >= self.max_visitors:
                    break
                visitor = self.visitors[self.waiting.pop(0)]
                visitor.opening = True  # holds the place while the app is built (outside the lock)
                visitor.last_input, visitor.idle_paused = time.monotonic(), False
            try:
                self._open(visitor)
            finally:
                visitor.opening = False
        with self._guard:
            queue = [self.visitors[cid] for cid in self.waiting]
        for place, visitor in enumerate(queue, start=1):
            self._show(visitor, FULL_TEXT.format(cap=self.max_visitors, place=place))

    def _open(self, visitor: Visitor) -> None:
        """Make the visitor's session and the app its page shows."""
        self._clear_notice(visitor)
        visitor.session = self.make_session(self.model)
        try:
            self._build(visitor)
        except Exception:
            self._close(visitor)
            raise
        visitor.session.start()  # its clock from now: the page's app being built is no simulated time due
        with self._guard:
            gone = visitor.view.client.client_id not in self.visitors
        if gone:  # the page left while its app was built
            self._close(visitor)

    def _build(self, visitor: Visitor) -> None:
        """The app on the visitor's page (its panel and scene, on that page only): on its own session, or,
        while a presenter shows theirs, on the presenter's, view only."""
        assert visitor.session is not None
        client = visitor.view.client
        with self._guard:
            source = self.visitors.get(self.showing) if self.showing not in (None, client.client_id) else None
        watched = source.session if source is not None else None
        session: Any = visitor.session
        if watched is not None:
            if not visitor.watching:  # its own simulation pauses while it watches
                visitor.resume_after_watch = not visitor.session.snapshot().paused
                visitor.session.pause()
            session = WatchedSession(watched, refuser(client))
        gate = self._gates.get(client.client_id)
        # a fresh view for each app (the old app's callbacks stay with the old one)
        visitor.view = ClientView(self.server, client, None if gate is None else gate.attach)
        view = cast(viser.ViserServer, visitor.view)  # the app uses only what ClientView provides
        app = RnsApp(view, session, password=None, models=self.models, pace=gate is not None, shared=False).start()
        with suppress(Exception):  # the page may have gone
            if watched is not None:
                visitor.extra = add_watching_line(client)
            elif visitor.presenter:
                cid = client.client_id
                visitor.extra = add_show_switch(client, self.showing == cid, lambda on: self.show(cid if on else None))
        with self._guard:
            visitor.app, visitor.watching = app, watched is not None

    def _detach(self, visitor: Visitor) -> None:
        """Take the app off the visitor's page (its threads stopped, its panel and scene removed); the
        visitor's session is left as it is."""
        with self._guard:
            app, visitor.app = visitor.app, None
        if app is None:
            return
        app.pace.stop()
        app.renderer.stop()
        visitor.extra = None
        if visitor.view.connected:
            with suppress(Exception):
                visitor.view.gui.reset()
                visitor.view.scene.reset()

    def _close(self, visitor: Visitor) -> None:
        """End the visitor's simulation: its app taken off the page and its session stopped."""
        self._detach(visitor)
        with self._guard:
            session, visitor.session, visitor.watching = visitor.session, None, False
        if session is not None:
            session.stop()

    # ---------------------------------------------------------------- the presenter
    def show(self, presenter: int | None) -> None:
        """Show the simulation of ``presenter`` (a client id) on every other page, or nobody's (None)."""
        with self._switching:  # one switch at a time: a double click must not build two apps on a page
            self._switch(presenter)

    def _switch(self, presenter: int | None) -> None:
        with self._guard:
            if presenter is not None and not (presenter in self.visitors and self.visitors[presenter].presenter):
                return
            if presenter == self.showing:
                return
            before, self.showing = self.showing, presenter
            others = [v for cid, v in self.visitors.items() if cid not in (presenter, before) and v.app is not None]
        for visitor in others:
            was_watching = visitor.watching
            self._detach(visitor)
            if visitor.session is None:
                continue
            if presenter is None and was_watching:
                visitor.watching = False
                if visitor.resume_after_watch:
                    visitor.session.resume()
            self._build(visitor)

    # ---------------------------------------------------------------- idle visitors
    def _input(self, client_id: int, _message: object) -> None:
        """A page sent input: it is not idle; a simulation paused for idleness runs again."""
        with self._guard:
            visitor = self.visitors.get(client_id)
            if visitor is None:
                return
            visitor.last_input = time.monotonic()
            resume, visitor.idle_paused = visitor.idle_paused, False
            session = None if visitor.watching else visitor.session
        if resume and session is not None:
            session.resume()

    def _watch_idle(self) -> None:
        while not self._stop.wait(IDLE_CHECK_S):
            self.check_idle()

    def check_idle(self, now: float | None = None) -> None:
        """Pause the simulations idle for ``idle_pause_s``, close those idle for ``idle_close_s``."""
        now = time.monotonic() if now is None else now
        with self._guard:
            visitors = [v for v in self.visitors.values() if v.app is not None]
        closed = False
        for visitor in visitors:
            idle = now - visitor.last_input
            session = visitor.session
            if session is None:
                continue
            if idle >= self.idle_close_s:
                self._close(visitor)
                self._offer_start_again(visitor)
                closed = True
            elif idle >= self.idle_pause_s and not visitor.idle_paused and not visitor.watching:
                visitor.idle_paused = True
                session.pause()
                minutes = self.idle_pause_s / 60.0
                with suppress(Exception):
                    visitor.view.client.add_notification(
                        "Paused", f"Paused after {minutes:g} minutes without input; any input resumes it.", color="blue"
                    )
        if closed:
            self._admit_waiting()

    def _offer_start_again(self, visitor: Visitor) -> None:
        self._show(visitor, CLOSED_TEXT.format(minutes=self.idle_close_s / 60.0))
        with suppress(Exception):
            button = visitor.view.gui.add_button("Start a new simulation")
            visitor.start_again = button
            button.on_click(lambda _: self._start_again(visitor))

    def _start_again(self, visitor: Visitor) -> None:
        cid = visitor.view.client.client_id
        with self._guard:
            if cid not in self.visitors or visitor.app is not None or cid in self.waiting:
                return
            self.waiting.append(cid)
        self._admit_waiting()

    # ---------------------------------------------------------------- the page's message
    def _show(self, visitor: Visitor, text: str) -> None:
        with suppress(Exception):  # the page may have gone
            if visitor.notice is None:
                visitor.notice = visitor.view.gui.add_markdown(text)
            elif visitor.notice.content != text:
                visitor.notice.content = text

    def _clear_notice(self, visitor: Visitor) -> None:
        for handle in (visitor.notice, visitor.start_again):
            if handle is not None:
                with suppress(Exception):
                    handle.remove()
        visitor.notice = visitor.start_again = None


def start_classroom(
    model: str = "trep",
    host: str = "127.0.0.1",
    port: int = 8080,
    models: Sequence[str] = (),
    max_visitors: int | None = None,
    idle_pause_s: float = IDLE_PAUSE_S,
    idle_close_s: float = IDLE_CLOSE_S,
    verbose: bool = True,
    make_session: Callable[[str], Session] | None = None,
) -> Classroom:
    """Start a server that gives every visitor their own simulation; returns at once (``port=0``: a free
    port)."""
    server = viser.ViserServer(host=host, port=port, verbose=verbose)
    server.gui.set_panel_label("rns_viz: reaction null-space control")
    try:
        return Classroom(server, model, models, max_visitors, idle_pause_s, idle_close_s, make_session)
    except Exception:
        server.stop()
        raise


def serve_classroom(
    model: str = "trep",
    host: str = "127.0.0.1",
    port: int = 8080,
    models: Sequence[str] = (),
    max_visitors: int | None = None,
    idle_minutes: float = IDLE_CLOSE_S / 60.0,
) -> None:
    """Serve a simulation per visitor until interrupted (Ctrl+C)."""
    close_s = idle_minutes * 60.0
    # A page that leaves may be sent a frame after its connection closed and before its app hears of it
    # (viser warns once per page): expected here, not worth a line in the teacher's terminal per student.
    warnings.filterwarnings("ignore", message="Queued a .* on a closed connection", category=UserWarning)
    room = start_classroom(model, host, port, models, max_visitors, min(IDLE_PAUSE_S, close_s / 4.0), close_s)
    print(
        f"rns_viz, a simulation per visitor (at most {room.max_visitors}): http://{host}:{room.port}  (Ctrl+C to stop)"
    )
    serve_until_interrupted(room.stop)
