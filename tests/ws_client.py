"""A protocol-level viser client: acts like a browser tab without rendering (DESIGN.md section 8).

Connects with subprotocol ``viser-v<version>``, sends msgpack messages as the web client does
(GUI value changes, button clicks, transform-control drags) and decodes what the server sends
(zstd-compressed msgpack windows), counting scene pose updates and GUI updates per element.
"""

from __future__ import annotations

import threading
import time
from collections import Counter
from typing import Any

import msgspec
import viser
import websockets.sync.client
import zstandard

_SCENE_POSE = ("SetPositionMessage", "SetOrientationMessage")


class WsClient:
    """One connection; a background thread receives and counts messages."""

    def __init__(self, port: int, watch_node: str = "/base", decode: bool = True) -> None:
        self.ws = websockets.sync.client.connect(
            f"ws://127.0.0.1:{port}",
            subprotocols=[websockets.Subprotocol(f"viser-v{viser.__version__}")],
            max_size=None,
            open_timeout=20,
        )
        self.watch_node = watch_node
        self.decode = decode
        self.types: Counter[str] = Counter()
        self.nodes: Counter[str] = Counter()  # scene node name -> messages that touched it
        self.gui_updates: Counter[str] = Counter()  # uuid -> count of GuiUpdateMessage
        self.pose_times: list[float] = []  # receive times of windows that moved ``watch_node``
        self.gui_times: dict[str, list[float]] = {}
        self.bytes = 0
        self._stop = False
        self._zstd = zstandard.ZstdDecompressor()
        self._thread = threading.Thread(target=self._receive, daemon=True)
        self._thread.start()
        self.send_camera()  # viser counts a client as connected from its first camera message

    def send_camera(self) -> None:
        self.send(
            {
                "type": "ViewerCameraMessage",
                "wxyz": (1.0, 0.0, 0.0, 0.0),
                "position": (0.0, 0.0, 1.0),
                "fov": 1.0,
                "near": 0.01,
                "far": 100.0,
                "image_height": 800,
                "image_width": 1280,
                "look_at": (0.0, 0.0, 0.0),
                "up_direction": (0.0, 0.0, 1.0),
            }
        )

    # -- sending ---------------------------------------------------------------------------------
    def send(self, message: dict[str, Any]) -> None:
        self.ws.send(msgspec.msgpack.encode(message))

    def set_value(self, uuid: str, value: Any) -> None:
        """What the browser sends when a slider, checkbox or dropdown changes."""
        self.send({"type": "GuiUpdateMessage", "uuid": uuid, "updates": {"value": value}})

    def click(self, uuid: str, value: Any = True) -> None:
        """A button click (a button group sends the clicked option as the value)."""
        self.set_value(uuid, value)

    def drag(self, name: str, position: tuple[float, float, float], phase: str = "update") -> None:
        """A transform-control drag: phase "start", "update" or "end"."""
        if phase == "start":
            self.send({"type": "TransformControlsDragStartMessage", "name": name, "owner": ""})
        self.send(
            {
                "type": "TransformControlsUpdateMessage",
                "name": name,
                "wxyz": (1.0, 0.0, 0.0, 0.0),
                "position": tuple(float(x) for x in position),
                "owner": "",
            }
        )
        if phase == "end":
            self.send({"type": "TransformControlsDragEndMessage", "name": name, "owner": ""})

    # -- receiving -------------------------------------------------------------------------------
    def _receive(self) -> None:
        while not self._stop:
            try:
                raw = self.ws.recv(timeout=0.5)
            except TimeoutError:
                continue
            except Exception:
                return
            now = time.perf_counter()
            assert isinstance(raw, bytes)
            self.bytes += len(raw)
            if not self.decode:
                continue
            size = int.from_bytes(raw[0:8], "little")
            compressed = int.from_bytes(raw[8:16], "little")
            window = msgspec.msgpack.decode(self._zstd.decompress(raw[16 : 16 + compressed], max_output_size=size))
            moved = False
            for msg in window["messages"]:
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

    def rate(self, times: list[float], since: float) -> float:
        """Events per second in ``times`` after ``since`` (perf_counter seconds)."""
        recent = [t for t in times if t >= since]
        if len(recent) < 2:
            return 0.0
        return (len(recent) - 1) / (recent[-1] - recent[0])

    def close(self) -> None:
        self._stop = True
        try:
            self.ws.close()
        finally:
            self._thread.join(timeout=2.0)
