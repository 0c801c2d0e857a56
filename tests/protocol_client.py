"""A protocol-level viser client: speaks the websocket protocol like a browser tab, without one.

It connects with the subprotocol ``viser-v<version>``, sends client->server messages exactly as
the browser does (msgpack dicts built by viser's own message classes: GUI updates, transform
drags) and drains what the server sends on a background thread, counting messages and bytes.
Used by load, latency and robustness tests; only connects to loopback addresses.
"""

from __future__ import annotations

import threading
import time
from typing import Any

import msgspec.msgpack
import viser
from viser import _messages
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import ClientConnection, connect


class ProtocolClient:
    """One simulated browser tab connected to a local viser server."""

    def __init__(self, port: int, host: str = "127.0.0.1", timeout: float = 10.0) -> None:
        if not (host.startswith("127.") or host in ("localhost", "::1")):
            raise ValueError("protocol clients only connect to this machine")
        self._ws: ClientConnection = connect(
            f"ws://{host}:{port}",
            subprotocols=[f"viser-v{viser.__version__}"],  # type: ignore[list-item]
            open_timeout=timeout,
            max_size=None,
        )
        self.messages = 0
        self.bytes = 0
        self.last_message_time = 0.0
        self.closed = threading.Event()
        self._lock = threading.Lock()
        self._reader = threading.Thread(target=self._drain, daemon=True)
        self._reader.start()
        # viser registers a client (get_clients, on_client_connect) at its first camera message.
        self.camera((0.0, 0.0, 0.0, 1.0), (0.5, 0.5, 0.5))

    def camera(self, wxyz: tuple[float, ...], position: tuple[float, float, float]) -> None:
        """A viewer camera report, as the browser sends when it starts and when the view moves."""
        self._send(
            _messages.ViewerCameraMessage(
                wxyz=tuple(wxyz),  # type: ignore[arg-type]
                position=position,
                fov=1.0,
                near=0.01,
                far=100.0,
                image_height=720,
                image_width=1280,
                look_at=(0.0, 0.0, 0.0),
                up_direction=(0.0, 0.0, 1.0),
            )
        )

    def _drain(self) -> None:
        try:
            for frame in self._ws:
                self.messages += 1
                self.bytes += len(frame)
                self.last_message_time = time.monotonic()
        except (ConnectionClosed, OSError):
            pass
        finally:
            self.closed.set()

    def _send(self, message: _messages.Message) -> None:
        payload = msgspec.msgpack.encode(message.as_serializable_dict())
        with self._lock:
            self._ws.send(payload)

    def gui_update(self, uuid: str, **updates: Any) -> None:
        """What the browser sends when a control changes (value=..., or value=True for a click)."""
        self._send(_messages.GuiUpdateMessage(uuid, updates))

    def drag(self, name: str, position: tuple[float, float, float], wxyz: tuple[float, ...] = (1.0, 0, 0, 0)) -> None:
        """A transform-controls drag event on scene node ``name`` (position in the parent frame)."""
        self._send(_messages.TransformControlsUpdateMessage(name, tuple(wxyz), tuple(position)))  # type: ignore[arg-type]

    def drag_phase(self, name: str, phase: str) -> None:
        """Drag start/end markers (viser's TransformControlsDragStart/EndMessage) if this viser has them."""
        cls = {"start": "TransformControlsDragStartMessage", "end": "TransformControlsDragEndMessage"}[phase]
        message_type = getattr(_messages, cls, None)
        if message_type is not None:
            self._send(message_type(name))

    def close(self) -> None:
        self._ws.close()
        self.closed.wait(5.0)

    def abort(self) -> None:
        """Drop the connection without a closing handshake (a tab killed mid-drag)."""
        self._ws.socket.close()
        self.closed.wait(5.0)

    def __enter__(self) -> ProtocolClient:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def gui_uuid(handle: object) -> str:
    """The protocol id of a server-side GUI handle."""
    return handle._impl.uuid  # type: ignore[attr-defined]
