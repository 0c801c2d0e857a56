"""A protocol-level viser client: speaks the websocket protocol like a browser tab, without one.

It connects with the subprotocol ``viser-v<version>``, sends client->server messages exactly as
the browser does (msgpack dicts built by viser's own message classes: camera reports, GUI updates,
transform drags) and drains what the server sends on a background thread, counting messages and
bytes. With ``decode=True`` it also unpacks the server's zstd-compressed msgpack windows and
counts message types, scene nodes touched, pose updates of ``watch_node`` and GUI updates per
element (update rates for benchmarks). Like a browser it answers the server's localStorage
questions (the app times them to pace slow pages, rns_viz.viz.server.page_pacing) from its ``storage`` (a
dict: give two clients the same one and they are tabs of one browser, or a page and its reload);
``answer_delay_s`` answers late, as a page that draws slowly does, and ``frozen`` (an Event) holds the
answers back until ``thaw()``, as a frozen tab does. Only connects to loopback addresses
(docs/testing-notes.md says why).
"""

from __future__ import annotations

import contextlib
import threading
import time
from collections import Counter
from dataclasses import dataclass
from typing import Any

import msgspec.msgpack
import viser
import zstandard
from viser import _messages
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import ClientConnection, connect

_SCENE_POSE = ("SetPositionMessage", "SetOrientationMessage")
_IDENTITY = (1.0, 0.0, 0.0, 0.0)
_MESSAGE_CLASSES = {c.__name__: c for c in _messages.Message.get_subclasses()}


@dataclass
class MirroredNode:
    """A scene node as viser's page holds it: its pose (parent frame) and visibility."""

    position: tuple[float, ...] = (0.0, 0.0, 0.0)
    wxyz: tuple[float, ...] = _IDENTITY
    visible: bool = True


class SceneMirror:
    """The scene as viser's page (1.1.1, SceneTreeState.ts) keeps it from the messages it receives: a create
    for a name it has updates that node and keeps its pose and visibility; a remove takes the name and what
    hangs below it; pose and visibility messages set them. Compare it with the server's handles to see what a
    browser shows."""

    def __init__(self) -> None:
        self.nodes: dict[str, MirroredNode] = {}
        self.lock = threading.Lock()

    def apply(self, msg: dict[str, Any]) -> None:
        cls = _MESSAGE_CLASSES.get(msg.get("type", ""))
        if cls is None or cls.entity_type != "scene" or msg.get("owner", ""):
            return  # not a node of the shared scene
        name, kind = msg["name"], msg["type"]
        with self.lock:
            if cls.lifecycle_phase == "create":
                self.nodes.setdefault(name, MirroredNode())
            elif cls.lifecycle_phase == "remove":
                for gone in [n for n in self.nodes if n == name or n.startswith(name + "/")]:
                    del self.nodes[gone]
            elif name in self.nodes:
                node = self.nodes[name]
                if kind == "SetPositionMessage":
                    node.position = tuple(msg["position"])
                elif kind == "SetOrientationMessage":
                    node.wxyz = tuple(msg["wxyz"])
                elif kind == "SetSceneNodeVisibilityMessage":
                    node.visible = bool(msg["visible"])

    def snapshot(self) -> dict[str, MirroredNode]:
        with self.lock:
            return {name: MirroredNode(n.position, n.wxyz, n.visible) for name, n in self.nodes.items()}


class ProtocolClient:
    """One simulated browser tab connected to a local viser server."""

    def __init__(
        self,
        port: int,
        host: str = "127.0.0.1",
        timeout: float = 20.0,
        decode: bool = False,
        watch_node: str = "/base",
        answer_delay_s: float = 0.0,
        storage: dict[str, str] | None = None,
        mirror: bool = False,
    ) -> None:
        if not (host.startswith("127.") or host in ("localhost", "::1")):
            raise ValueError("protocol clients only connect to this machine")
        self._ws: ClientConnection = connect(
            f"ws://{host}:{port}",
            subprotocols=[f"viser-v{viser.__version__}"],  # type: ignore[list-item]
            open_timeout=timeout,
            max_size=None,
        )
        self.decode = decode
        self.watch_node = watch_node
        self.messages = 0  # frames received
        self.bytes = 0
        self.last_message_time = 0.0
        self.types: Counter[str] = Counter()  # decoded message type -> count
        self.nodes: Counter[str] = Counter()  # scene node name -> messages that touched it
        self.gui_updates: Counter[str] = Counter()  # GUI element uuid -> GuiUpdateMessages
        self.pose_times: list[float] = []  # perf_counter times of windows that moved ``watch_node``
        self.gui_times: dict[str, list[float]] = {}  # uuid -> perf_counter times of its updates
        self.answer_delay_s = answer_delay_s  # s: how late the page answers the server's questions
        self.storage = {} if storage is None else storage  # the browser's localStorage (viser's keys)
        self.frozen = threading.Event()  # set: questions wait for thaw()
        self._deferred: list[tuple[str, str]] = []
        self.answers = 0
        self.answers_to: Counter[str] = Counter()  # localStorage key -> questions answered about it
        self.notifications: list[tuple[str, str]] = []  # (title, body) of every notification shown to this tab
        self.scene = SceneMirror() if mirror else None  # the scene as a browser would hold it
        self.closed = threading.Event()
        self._zstd = zstandard.ZstdDecompressor()
        self._lock = threading.Lock()
        self._reader = threading.Thread(target=self._drain, daemon=True)
        self._reader.start()
        # viser registers a client (get_clients, on_client_connect) at its first camera message.
        self.camera(_IDENTITY, (0.5, 0.5, 0.5))

    # -- sending -------------------------------------------------------------------------------
    def _send(self, message: _messages.Message) -> None:
        payload = msgspec.msgpack.encode(message.as_serializable_dict())
        with self._lock:
            self._ws.send(payload)

    def camera(
        self,
        wxyz: tuple[float, ...],
        position: tuple[float, float, float],
        size: tuple[int, int] = (1280, 720),
        look_at: tuple[float, float, float] = (0.0, 0.0, 0.0),
    ) -> None:
        """A viewer camera report, as the browser sends when it starts, when the view moves and when its
        canvas changes ``size`` (width, height px)."""
        self._send(
            _messages.ViewerCameraMessage(
                wxyz=tuple(wxyz),  # type: ignore[arg-type]
                position=position,
                fov=1.0,
                near=0.01,
                far=100.0,
                image_height=size[1],
                image_width=size[0],
                look_at=look_at,
                up_direction=(0.0, 0.0, 1.0),
            )
        )

    def gui_update(self, uuid: str, **updates: Any) -> None:
        """What the browser sends when a control changes (value=..., or value=True for a click)."""
        self._send(_messages.GuiUpdateMessage(uuid, updates))

    def set_value(self, uuid: str, value: Any) -> None:
        """A slider, checkbox, text field or dropdown changed."""
        self.gui_update(uuid, value=value)

    def command(self, uuid: str) -> None:
        """A keyboard command (its hotkey pressed, or picked in the command palette)."""
        self._send(_messages.CommandTriggerMessage(uuid))

    def click(self, uuid: str, value: Any = True) -> None:
        """A button click (a button group sends the clicked option as the value)."""
        self.gui_update(uuid, value=value)

    def drag(
        self,
        name: str,
        position: tuple[float, float, float],
        phase: str = "update",
        wxyz: tuple[float, ...] = _IDENTITY,
        owner: str = "",
    ) -> None:
        """A transform-controls drag event on scene node ``name`` (position in the parent frame);
        phase "start" and "end" also send the drag start/end markers around it. ``owner``: the scope of the
        node dragged, as the page echoes it ("" the shared scene, a client id's string that client's own)."""
        if phase == "start":
            self.drag_phase(name, "start", owner)
        position_ = tuple(float(x) for x in position)
        self._send(_messages.TransformControlsUpdateMessage(name, tuple(wxyz), position_, owner=owner))  # type: ignore[arg-type]
        if phase == "end":
            self.drag_phase(name, "end", owner)

    def drag_phase(self, name: str, phase: str, owner: str = "") -> None:
        """Drag start/end markers (viser's TransformControlsDragStart/EndMessage) if this viser has them."""
        cls = {"start": "TransformControlsDragStartMessage", "end": "TransformControlsDragEndMessage"}[phase]
        message_type = getattr(_messages, cls, None)
        if message_type is not None:
            self._send(message_type(name, owner=owner))

    def scene_click(
        self,
        name: str,
        ray_origin: tuple[float, ...],
        ray_direction: tuple[float, ...],
        screen_pos: tuple[float, float] = (0.5, 0.5),
    ) -> None:
        """A click on scene node ``name`` (viser's SceneNodeClickMessage): the ray in world coordinates."""
        self._send(
            _messages.SceneNodeClickMessage(
                name=name,
                instance_index=None,
                ray_origin=tuple(ray_origin),  # type: ignore[arg-type]
                ray_direction=tuple(ray_direction),  # type: ignore[arg-type]
                screen_pos=screen_pos,
                modifier=None,
            )
        )

    # -- receiving -----------------------------------------------------------------------------
    def _drain(self) -> None:
        try:
            for frame in self._ws:
                now = time.perf_counter()
                self.messages += 1
                self.bytes += len(frame)
                self.last_message_time = time.monotonic()
                if isinstance(frame, bytes):
                    self._read(frame, now)
        except (ConnectionClosed, OSError):
            pass
        finally:
            self.closed.set()

    def _read(self, frame: bytes, now: float) -> None:
        """Answer the questions in one server window (8-byte size, 8-byte compressed size, zstd
        msgpack) and, with ``decode``, count its messages."""
        size = int.from_bytes(frame[0:8], "little")
        compressed = int.from_bytes(frame[8:16], "little")
        window = msgspec.msgpack.decode(self._zstd.decompress(frame[16 : 16 + compressed], max_output_size=size))
        for msg in window["messages"]:
            if self.scene is not None:
                self.scene.apply(msg)
            if msg.get("type") == "NotificationShowMessage":
                self.notifications.append((msg["props"]["title"], msg["props"]["body"]))
            elif msg.get("type") == "LocalStorageSetItemMessage":
                self.storage[msg["key"]] = msg["value"]
            elif msg.get("type") == "LocalStorageGetItemRequestMessage":
                self._answer(msg["request_uuid"], msg["key"])
        if self.decode:
            self._count(window["messages"], now)

    def _answer(self, request_uuid: str, key: str) -> None:
        """Answer a localStorage question now, later (``answer_delay_s``) or, while ``frozen``, on
        :meth:`thaw`."""
        if self.frozen.is_set():
            self._deferred.append((request_uuid, key))
            return
        value = self.storage.get(key)
        reply = _messages.LocalStorageGetItemResponseMessage(value=value, error=None, request_uuid=request_uuid)
        if self.answer_delay_s > 0.0:
            timer = threading.Timer(self.answer_delay_s, self._send_quietly, (reply,))
            timer.daemon = True
            timer.start()
        else:
            self._send_quietly(reply)
        self.answers += 1
        self.answers_to[key] += 1

    def thaw(self) -> None:
        """Answer the questions that came while frozen (in order, as a thawed tab does), then go on."""
        self.frozen.clear()
        deferred, self._deferred = self._deferred, []
        for request_uuid, key in deferred:
            self._answer(request_uuid, key)

    def _send_quietly(self, message: _messages.Message) -> None:
        with contextlib.suppress(ConnectionClosed, OSError):
            self._send(message)

    def _count(self, messages: list[dict[str, Any]], now: float) -> None:
        """Count the messages of one server window."""
        moved = False
        for msg in messages:
            kind = msg.get("type", "?")
            self.types[kind] += 1
            if "name" in msg:
                self.nodes[msg["name"]] += 1
            if kind in _SCENE_POSE and msg.get("name") == self.watch_node:
                moved = True
            elif kind == "GuiUpdateMessage":
                uuid = msg.get("uuid", "")
                self.gui_updates[uuid] += 1
                self.gui_times.setdefault(uuid, []).append(now)
        if moved:
            self.pose_times.append(now)

    @staticmethod
    def rate(times: list[float], since: float) -> float:
        """Events per second in ``times`` after ``since`` (perf_counter seconds)."""
        recent = [t for t in times if t >= since]
        if len(recent) < 2:
            return 0.0
        return (len(recent) - 1) / (recent[-1] - recent[0])

    # -- ending --------------------------------------------------------------------------------
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
