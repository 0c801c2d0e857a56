"""One client's view of a viser server, shaped like the server, so that an app built on it draws to that
client alone.

The app (:class:`~rns_viz.viz.server.app.RnsApp`) uses a server's ``gui`` and ``scene``, ``atomic()``,
``get_clients()``, ``initial_camera``, ``get_port()``, ``stop()``, the connect / disconnect callbacks and
the gate that paces a page's stream (here: the client's own stream, rns_viz.viz.server.page_pacing).
:class:`ClientView` answers each for one :class:`viser.ClientHandle`: ``gui`` and ``scene`` are the
client's own (viser's per-client scope: what is added there reaches no other page), ``get_clients()``
lists this client while it is connected, the initial camera is the client's camera, and the connect
callbacks run for this client once it is registered. So one server holds one app per visitor
(:mod:`rns_viz.viz.server.classroom`) with the app's code unchanged.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from contextlib import AbstractContextManager

import viser

ClientCallback = Callable[[viser.ClientHandle], None]
PaceGate = Callable[[Callable[[int, float], float], Callable[[int], None]], bool]


class ClientView:
    """The part of a :class:`viser.ViserServer` one client sees."""

    def __init__(
        self, server: viser.ViserServer, client: viser.ClientHandle, pace_gate: PaceGate | None = None
    ) -> None:
        """``pace_gate``: attaches an app's pace to this client's own stream (False: it cannot be paced)."""
        self.shared = server  # the server every visitor shares (it outlives this view)
        self.client = client
        self.gui = client.gui
        self.scene = client.scene
        self.initial_camera = client.camera  # a new view's camera is this page's camera
        self._guard = threading.Lock()
        self._connected = True
        self._left_callbacks: list[ClientCallback] = []
        self._pace_gate = pace_gate

    def attach_pace_gate(self, wait_s: Callable[[int, float], float], sent: Callable[[int], None]) -> bool:
        """Pace this client's own stream (rns_viz.viz.server.page_pacing asks; False: it cannot be)."""
        return self._pace_gate is not None and self._pace_gate(wait_s, sent)

    @property
    def connected(self) -> bool:
        return self._connected

    def get_clients(self) -> dict[int, viser.ClientHandle]:
        """This client, while it is connected (the server's own listing, reduced to it)."""
        return {self.client.client_id: self.client} if self._connected else {}

    def on_client_connect(self, callback: ClientCallback) -> ClientCallback:
        """Run ``callback`` for this client, which is already connected (viser does the same for a callback
        registered after its client arrived): on its own thread, as viser's thread pool would, since a
        callback may wait for the page (a localStorage round trip)."""
        if self._connected:
            threading.Thread(target=callback, args=(self.client,), name="rns-visitor-join", daemon=True).start()
        return callback

    def on_client_disconnect(self, callback: ClientCallback) -> ClientCallback:
        with self._guard:
            self._left_callbacks.append(callback)
        return callback

    def client_left(self) -> None:
        """The client's page closed: it is no longer listed, and the disconnect callbacks run (once)."""
        with self._guard:
            if not self._connected:
                return
            self._connected = False
            callbacks = list(self._left_callbacks)
        for callback in callbacks:
            callback(self.client)

    def atomic(self) -> AbstractContextManager[None]:
        return self.client.atomic()

    def flush(self) -> None:
        self.client.flush()

    def get_port(self) -> int:
        return self.shared.get_port()

    def stop(self) -> None:
        """Nothing: the shared server stays up for the other visitors."""
