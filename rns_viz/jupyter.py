"""The app inside Jupyter: a ``jupyter_serverproxy_servers`` entry point for jupyter-server-proxy.

With ``pip install 'rns-viz[jupyter]'`` a Jupyter server (a student's single-user server on JupyterHub,
or ``jupyter lab`` on a laptop) starts ``rns-viz serve`` on first visit of ``<base URL>/rns-viz/`` and
proxies page, assets and websocket to it; JupyterLab's launcher shows an *rns_viz* tile. One simulation
per Jupyter server, so one per student on a hub.

The app binds loopback only (the proxy is its only door, behind Jupyter's login) on the port the proxy
chose, and the proxy strips the prefix (``absolute_url=False``): viser's page loads with relative URLs.
It opens its websocket at its own address less a trailing slash, and ``<base>/rns-viz`` is Jupyter's
redirect to ``<base>/rns-viz/``, which a websocket does not follow; so a visit of ``<base>/rns-viz/``
is sent on to ``<base>/rns-viz/index.html`` (:func:`page_address`), whose websocket the proxy passes on.

Model files: every ``*.toml`` in ``~/rns-viz-models`` (or the folder named by ``RNS_VIZ_MODEL_DIR``)
joins the model dropdown when the app starts.
"""

from __future__ import annotations

import os
import sys
from importlib.resources import files
from pathlib import Path
from typing import Any

NAME = "rns-viz"  # the proxy's path: <base URL>/rns-viz/
START_TIMEOUT_S = 120.0  # s the proxy waits for the app to answer (tens of students starting at once share cores)
MODEL_DIR_VARIABLE = "RNS_VIZ_MODEL_DIR"
DEFAULT_MODEL_DIR = "~/rns-viz-models"


def model_dir() -> Path:
    """The folder whose parameter files join the model dropdown."""
    return Path(os.environ.get(MODEL_DIR_VARIABLE) or DEFAULT_MODEL_DIR).expanduser()


def serve_command(port: int) -> list[str]:
    """``rns-viz serve`` on loopback at ``port``, with the student's model folder, paused while no page is
    open (a closed tab costs little), by this interpreter (the Jupyter server's environment, whatever is on
    PATH)."""
    cmd = [sys.executable, "-m", "rns_viz.cli", "serve", "--host", "127.0.0.1", "--port", str(port)]
    return [*cmd, "--model-dir", str(model_dir()), "--pause-unwatched"]


def page_address(response: Any, path: str, request: Any) -> None:
    """jupyter-server-proxy's ``rewrite_response``: the app's root answers with a redirect to its page,
    ``index.html``, keeping the query (Jupyter's ``?token=`` on a first visit)."""
    from tornado.httputil import HTTPHeaders  # the Jupyter server's web framework (only imported in it)

    if path in ("", "/") and response.code == 200:
        query = f"?{request.query}" if request.query else ""
        response.code = 302
        response.headers = HTTPHeaders({"Location": f"index.html{query}", "Content-Length": "0"})
        response.body = b""


def setup_rns_viz() -> dict[str, Any]:
    """jupyter-server-proxy's description of the app (the entry point ``rns-viz``)."""
    return {
        "command": serve_command,  # called with the port the proxy picked
        "timeout": START_TIMEOUT_S,
        "absolute_url": False,
        "rewrite_response": page_address,
        "new_browser_tab": True,  # a full tab: the app's panel and 3-D view want the room
        "launcher_entry": {
            "title": "rns_viz",
            "icon_path": str(files("rns_viz") / "jupyter_icon.svg"),
            "category": "Other",
        },
    }
