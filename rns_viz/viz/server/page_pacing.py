"""Every browser gets the scene and the plots at the rate it can draw them.

The problem: a page that draws slowly (software WebGL on a 2-core machine, a throttled background
tab) receives the server's ~60 scene windows a second into its own queue faster than it applies
them, and falls further and further behind. The server cannot see this on the socket: viser's
client reads the websocket in a web worker that never stalls, so the backlog grows inside the
page, not in TCP.

The signal: a round trip through the page's own message queue. Every client is asked, about four
times a second, for a localStorage value (viser's public ``client.local_storage.get_item``). The
page answers only after it has applied every message that arrived before the question, so the
answer time measures how far it is behind (tens of ms for a page that keeps up). A question is
asked only while there is something to keep up with: the broadcast stream sent the page a window that
touches the 3-D scene since the last answer, or the page is still paced or told so. viser's page draws a
burst of 3-D frames for every message that is not GUI-only, a question included, and applies GUI-only
messages at once without a frame, so a page with no new scene to show is left alone: a paused app's page
draws no frames (software WebGL at 4 questions a second drew ~17 a second), nor does a running app's page
while the arms rest and only the panel's numbers change (it drew ~9 a second, for the questions alone).
:class:`~rns_viz.viz.server.page_rate.PaceController` turns answer times into a rate per client.

The means: the scene, the plots and the text are broadcast (``server.scene`` / ``server.gui``),
one stream that viser sends to each client from a persistent buffer in which a newer message for
the same node property or GUI property replaces the older one. A client whose stream is read
less often therefore gets the newest state of everything, never a backlog: that is how viser
already treats a client on a slow link. :func:`install_gate` makes the per-client reader of that
buffer wait between windows for a paced client (and wait altogether while a question has gone
unanswered for a few seconds: a frozen or hidden tab gets nothing until it answers, then the latest
state). This wraps one method of viser's broadcast buffer (``window_generator``, viser 1.1.1);
if viser changes it the app warns and runs unpaced. The per-client stream (notifications,
operator panel, the questions themselves) and everything the browser sends (buttons, drags,
the operator lock) are never delayed. A fast client's stream is not touched.

The page is told: a line "Display slowed to N Hz to keep up" under the status line of its own
panel once it is paced below NOTICE_BELOW_HZ (or held), hidden when it is back at NOTICE_GONE_HZ
or more. (A line in the panel, not a toast: a toast sits over the scene, where the gain map is.)
"""

from __future__ import annotations

import asyncio
import threading
import time
import traceback
import warnings
from collections.abc import AsyncGenerator, Callable, Sequence
from contextlib import suppress
from typing import Any

import viser
import viser._messages as viser_messages

from rns_viz.viz.server.page_rate import FULL_HZ, PaceController

PING_KEY = "rns_viz_pace"  # the localStorage key asked for (its value does not matter)
PING_GAP_S = 0.25  # s between an answer and the next question
NOTICE_UPDATE_S = 2.0  # s: the notice's rate is restated at most this often
GATE_POLL_S = 0.05  # s: a held stream checks this often whether it may send again
SLOWED_TITLE = "Display slowed to {hz} Hz to keep up"
SLOWED_HTML = (
    '<div style="font-size:0.85em;border-left:4px solid #e8a600;padding:2px 6px;margin:2px 0">'
    '<b>{title}</b><br><span style="opacity:0.8">{body}</span></div>'
)
SLOWED_BODY = (
    "This browser draws more slowly than the simulation runs, so the server sends it fewer "
    "updates, always the latest state. The simulation and other viewers are unaffected; "
    "buttons and drags work as usual."
)


class PagePace:
    """One client's controller and the thread that asks its page questions."""

    def __init__(
        self, client: viser.ClientHandle, is_connected: Callable[[int], bool], order: float | None = None
    ) -> None:
        self.client = client
        self._order = order  # where the slowed-display line goes in the client's panel
        self.control = PaceController()
        self.answered_once = False  # unpaced until the page has answered once (its first scene)
        self._is_connected = is_connected
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._notice: viser.GuiHtmlHandle | None = None  # the slowed-display line, once shown
        self._notice_hz = 0
        self._notice_time = 0.0
        self._stream_moved = threading.Event()  # set when the broadcast stream sends this page a window
        self.thread = threading.Thread(target=self._run, name=f"rns-pace-{client.client_id}", daemon=True)

    def start(self) -> None:
        self.thread.start()

    def stop(self) -> None:
        self._stop.set()

    def window_sent(self) -> None:
        """The broadcast stream just sent this page a window that touches the 3-D scene (called from the
        gate)."""
        self._stream_moved.set()

    def wait_s(self, since_last_send_s: float) -> float:
        """How long the client's broadcast stream should wait before its next window."""
        if not self.answered_once:
            return 0.0
        with self._lock:
            return self.control.wait_s(time.monotonic(), since_last_send_s)

    def state(self) -> dict[str, float | bool]:
        """Rate (Hz), last answer time (s), held, notice shown: for benchmarks and tests."""
        with self._lock:
            c = self.control
            return {"hz": c.hz, "answer_s": c.last_answer_s, "held": c.held(time.monotonic()), "notice": c.noticed}

    def _run(self) -> None:
        try:
            while not self._stop.is_set() and self._is_connected(self.client.client_id):
                self._ask_once()
        except Exception:  # pacing must never cost the page its updates: it goes unpaced
            traceback.print_exc()
        finally:
            self.answered_once = False  # a page nobody asks any more is never held

    def _question_due(self) -> bool:
        """Whether the page has something to keep up with: it has never answered, the stream sent it
        a scene window since the last question, or it is still paced or told that it is slowed."""
        if not self.answered_once or self._stream_moved.is_set():
            return True
        with self._lock:
            return self.control.hz < FULL_HZ or self.control.noticed

    def _ask_once(self) -> None:
        """One question (once one is due), its answer timed into the controller; the notice brought up
        to date."""
        while not self._question_due():  # only a window from the stream can make it due here
            if self._stop.is_set() or not self._is_connected(self.client.client_id):
                return
            self._stream_moved.wait(GATE_POLL_S)
        self._stream_moved.clear()  # windows from now on are for the next question
        with self._lock:
            self.control.ping_sent(time.monotonic())
        try:  # no time limit: a frozen tab answers when it thaws, and until then it is held
            self.client.local_storage.get_item(PING_KEY)
        except RuntimeError:  # the client left, or its browser refused localStorage (still an answer)
            if not self._is_connected(self.client.client_id):
                return
        with self._lock:
            self.control.ping_answered(time.monotonic())
        self.answered_once = True
        self._refresh_notice()
        self._stop.wait(PING_GAP_S)

    def notice_text(self) -> str | None:
        """The slowed-display line as this client's panel shows it, None while hidden."""
        line = self._notice
        return None if line is None or not line.visible else line.content

    def _refresh_notice(self) -> None:
        """Show, restate or hide the slowed-display line in this client's panel (under the status
        line; a panel line, not a toast, so it never covers the scene)."""
        if not self._is_connected(self.client.client_id):
            return
        now = time.monotonic()
        with self._lock:
            show = self.control.update_notice(now)
            hz = self.control.shown_hz()
        with suppress(Exception):  # the client may have gone
            hidden = self._notice is None or not self._notice.visible
            restate = hz != self._notice_hz and now - self._notice_time >= NOTICE_UPDATE_S
            if show and (hidden or restate):
                self._show_notice(hz, now)
            elif not show and self._notice is not None and self._notice.visible:
                self._notice.visible = False

    def _show_notice(self, hz: int, now: float) -> None:
        content = SLOWED_HTML.format(title=SLOWED_TITLE.format(hz=hz), body=SLOWED_BODY)
        if self._notice is None:
            self._notice = self.client.gui.add_html(content, order=self._order)
        else:
            self._notice.content = content
            self._notice.visible = True
        self._notice_hz, self._notice_time = hz, now


class ClientPace:
    """The pace of every connected client, and the gate on the server's broadcast stream."""

    def __init__(self, server: viser.ViserServer, enabled: bool = True, notice_order: float | None = None) -> None:
        self.server = server
        self.notice_order = notice_order  # panel order of each client's slowed-display line
        self.pages: dict[int, PagePace] = {}
        self.enabled = enabled and install_gate(server, self._wait_s, self._window_sent)

    def client_joined(self, client: viser.ClientHandle) -> None:
        if not self.enabled:
            return
        page = PagePace(client, lambda cid: cid in self.server.get_clients(), self.notice_order)
        self.pages[client.client_id] = page
        page.start()

    def noticed(self, client_id: int) -> bool:
        """Whether the page's panel shows the slowed-display line now."""
        page = self.pages.get(client_id)
        return page is not None and bool(page.state()["notice"])

    def client_left(self, client_id: int) -> None:
        page = self.pages.pop(client_id, None)
        if page is not None:
            page.stop()

    def stop(self) -> None:
        for page in list(self.pages.values()):
            page.stop()

    def state(self, client_id: int) -> dict[str, float | bool] | None:
        page = self.pages.get(client_id)
        return None if page is None else page.state()

    def _wait_s(self, client_id: int, since_last_send_s: float) -> float:
        page = self.pages.get(client_id)
        return 0.0 if page is None else page.wait_s(since_last_send_s)

    def _window_sent(self, client_id: int) -> None:
        page = self.pages.get(client_id)
        if page is not None:
            page.window_sent()


# What viser's page applies without drawing a 3-D frame: its client's GUI-only set (messageQueue.ts in
# viser 1.1.1), by the Python names of those messages. A name this viser lacks is left out, which only
# makes a question due more often.
GUI_ONLY_NAMES = (
    "_CreateGuiComponentMessage",
    "GuiUpdateMessage",
    "GuiRemoveMessage",
    "GuiModalMessage",
    "GuiCloseModalMessage",
    "GuiPanelMessage",
    "GuiPanelRemoveMessage",
    "GuiSetPanelCollapsedMessage",
    "GuiSetPanelHeightMessage",
    "GuiSetPanelPositionMessage",
    "GuiSetPanelWidthMessage",
    "SetGuiPanelLabelMessage",
    "NotificationShowMessage",
    "NotificationUpdateMessage",
    "RemoveNotificationMessage",
)
GUI_ONLY: tuple[type, ...] = tuple(
    kind for name in GUI_ONLY_NAMES if isinstance(kind := getattr(viser_messages, name, None), type)
)


def touches_scene(window: Sequence[Any]) -> bool:
    """Whether a window of messages makes viser's page draw 3-D frames (any message not GUI-only)."""
    return not all(isinstance(message, GUI_ONLY) for message in window)


def install_gate(server: viser.ViserServer, wait_s: Callable[[int, float], float], sent: Callable[[int], None]) -> bool:
    """Make each client's reader of the broadcast buffer wait ``wait_s(client, s since its last
    window)`` before taking its next window, and call ``sent(client)`` for each window it takes that
    touches the 3-D scene. False (with a warning) if this viser has no such buffer. A one-client view
    (:class:`~rns_viz.viz.clients.client_view.ClientView`) paces that client's own stream instead."""
    attach = getattr(server, "attach_pace_gate", None)
    if attach is not None:
        return bool(attach(wait_s, sent))
    try:
        buffer = server._websock_server._broadcast_buffer  # type: ignore[attr-defined]
    except AttributeError:
        warnings.warn("rns_viz: this viser has no broadcast buffer to pace; slow pages are not paced", stacklevel=2)
        return False
    return gate_buffer(buffer, wait_s, sent)


def gate_buffer(buffer: Any, wait_s: Callable[[int, float], float], sent: Callable[[int], None]) -> bool:
    """The gate of :func:`install_gate` on one of viser's message buffers (the broadcast one, or a client's
    own, patched before the client's reader starts). False (with a warning) if it has no window generator."""
    try:
        original = buffer.window_generator
    except AttributeError:
        warnings.warn("rns_viz: this viser's message buffer cannot be paced; slow pages are not paced", stacklevel=2)
        return False

    def window_generator(client_id: int, backlog_done_message: Any = None) -> AsyncGenerator[Sequence[Any], None]:
        windows = original(client_id, backlog_done_message=backlog_done_message)
        return _paced(windows, client_id, wait_s, buffer.max_window_size, sent)

    buffer.window_generator = window_generator
    return True


class LateGate:
    """A gate put on a client's own stream when it connects, before any app paces it: it lets every window
    through until :meth:`attach` gives it an app's pace (the app of a page is built after its stream starts)."""

    def __init__(self) -> None:
        self._wait_s: Callable[[int, float], float] = lambda _client, _since: 0.0
        self._sent: Callable[[int], None] = lambda _client: None

    def attach(self, wait_s: Callable[[int, float], float], sent: Callable[[int], None]) -> bool:
        self._wait_s, self._sent = wait_s, sent
        return True

    def wait_s(self, client_id: int, since_last_send_s: float) -> float:
        return self._wait_s(client_id, since_last_send_s)

    def sent(self, client_id: int) -> None:
        self._sent(client_id)


async def _paced(
    windows: AsyncGenerator[Sequence[Any], None],
    client_id: int,
    wait_s: Callable[[int, float], float],
    max_window: int,
    sent: Callable[[int], None] = lambda _: None,
) -> AsyncGenerator[Sequence[Any], None]:
    """viser's windows for one client, each taken only once the gate opens. While this waits, viser's
    buffer keeps only the newest message per node and property, so the next window is the latest state.
    A full window (viser splits a large update into windows of ``max_window`` messages) is followed
    at once by the rest of that update, so a page never waits an interval on half a picture."""
    last_sent, window_size = 0.0, 0  # s (monotonic), messages
    try:
        while True:
            while window_size < max_window and (wait := wait_s(client_id, time.monotonic() - last_sent)) > 0.0:
                await asyncio.sleep(min(wait, GATE_POLL_S))
            try:
                window = await windows.__anext__()
            except StopAsyncIteration:
                return
            last_sent, window_size = time.monotonic(), len(window)
            if touches_scene(window):
                sent(client_id)
            yield window
    finally:
        await windows.aclose()
