"""Pictures for slides: one button renders the scene in the clicking browser (viser's render API) at
1600 x 900 and hands it back as a PNG download. Rendering is slow with software WebGL, so it runs
in viser's callback pool with a timeout, never in the render or simulation thread.
"""

from __future__ import annotations

import io
import threading
import traceback
from collections.abc import Callable

import numpy as np
import viser
from PIL import Image

from rns_viz.viz.clients.connections import Connections

SIZE = (900, 1600)  # px, height x width of a slide picture
RENDER_TIMEOUT_S = 20.0


def png_bytes(image: np.ndarray) -> bytes:
    """An (H, W, 3|4) uint8 image as PNG file bytes."""
    with io.BytesIO() as buf:
        Image.fromarray(np.ascontiguousarray(image, dtype=np.uint8)).save(buf, format="PNG")
        return buf.getvalue()


class Pictures:
    """The *Save picture (PNG)* button; one picture at a time per server."""

    def __init__(self, server: viser.ViserServer, connections: Connections, model_name: Callable[[], str]) -> None:
        self.connections = connections
        self.model_name = model_name
        self.saved = 0  # pictures sent (tests read it)
        self._busy = threading.Lock()
        self.button = server.gui.add_button(
            "Save picture (PNG)",
            icon=viser.Icon.CAMERA,
            hint="Download what the scene shows now, 1600 × 900 pixels, for slides (transparent background).",
        )
        self.button.on_click(self._on_click)

    def _on_click(self, event: viser.GuiEvent) -> None:
        client = event.client
        if client is None or not self._busy.acquire(blocking=False):
            return
        try:
            h, w = SIZE
            image = client.get_render(h, w, transport_format="png", timeout=RENDER_TIMEOUT_S)
            client.send_file_download(f"rns_{self.model_name()}_scene.png", png_bytes(image), save_immediately=True)
            self.saved += 1
        except Exception as exc:  # a browser that cannot render must not take the server down
            traceback.print_exc()
            self.connections.notify(client, "Picture not saved", f"{type(exc).__name__}: {exc}", "warning")
        finally:
            self._busy.release()
