"""The app inside a real Jupyter server, through jupyter-server-proxy (``pip install 'rns-viz[jupyter]'``).

A ``jupyter server`` (loopback, a token, a free port, no browser) runs in a subprocess with the entry point
registered as pip registers it (the ``jupyter_serverproxy_servers`` table of pyproject.toml, written as the
entry points of a distribution on its path, so the shared environment is not reinstalled). Chromium opens
``<base>/rns-viz/?token=...``: the proxy starts ``rns-viz serve``, the page, its script and its websocket
come through the proxy, the panel shows, and a press of *Kick the base* moves the base's plot.
"""

from __future__ import annotations

import os
import secrets
import signal
import socket
import subprocess
import sys
import time
import tomllib
import urllib.error
import urllib.request
from collections.abc import Iterator
from pathlib import Path

import pytest

from tests.support.browser import url_page, wait_until
from tests.support.repo import REPO

pytest.importorskip("jupyter_server_proxy", reason="needs the extra: pip install 'rns-viz[jupyter]'")

START_S = 120.0  # s: Jupyter up, then the app started by the proxy on the first visit (a loaded machine)
# The largest finite value of every chart on the page (viser's uPlot test points), by chart.
CHART_PEAKS_JS = """() => {
  const out = {};
  for (const [uuid, tp] of Object.entries(window.__viserTestpoints?.uplots ?? {})) {
    const d = tp.chart.data; let peak = 0;
    for (let s = 1; s < d.length; s++)
      for (const v of d[s] ?? []) if (Number.isFinite(v)) peak = Math.max(peak, Math.abs(v));
    out[uuid] = peak;
  }
  return out;
}"""


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def entry_points_text() -> str:
    """pyproject's jupyter-server-proxy entry points as a distribution's entry_points.txt."""
    table = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]["entry-points"]
    lines = [f"{name} = {target}" for name, target in table["jupyter_serverproxy_servers"].items()]
    return "[jupyter_serverproxy_servers]\n" + "\n".join(lines) + "\n"


@pytest.fixture
def jupyter(tmp_path: Path) -> Iterator[tuple[str, str]]:
    """A Jupyter server with the entry point; yields (base URL, token); stopped with everything it started."""
    site = tmp_path / "site"
    dist = site / "rns_viz_entry_points-0.dist-info"
    dist.mkdir(parents=True)
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: rns-viz-entry-points\nVersion: 0\n")
    (dist / "entry_points.txt").write_text(entry_points_text())
    home = tmp_path / "home"
    home.mkdir()
    token, port = secrets.token_hex(16), free_port()
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join(filter(None, [str(REPO), str(site), os.environ.get("PYTHONPATH")])),
        "HOME": str(home),
        "JUPYTER_CONFIG_DIR": str(tmp_path / "config"),
        "JUPYTER_DATA_DIR": str(tmp_path / "data"),
        "JUPYTER_RUNTIME_DIR": str(tmp_path / "runtime"),
    }
    command = [sys.executable, "-m", "jupyter_server", "--no-browser", "--ip=127.0.0.1", f"--port={port}"]
    command += [f"--IdentityProvider.token={token}", f"--ServerApp.root_dir={home}", "--ServerApp.port_retries=0"]
    if os.geteuid() == 0:
        command.append("--allow-root")
    log = (tmp_path / "jupyter.log").open("w")
    process = subprocess.Popen(command, env=env, stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
    base = f"http://127.0.0.1:{port}"
    try:
        status = f"{base}/api/status?token={token}"
        wait_until(lambda: _answers(status) or process.poll() is not None, START_S, "Jupyter")
        assert process.poll() is None, (tmp_path / "jupyter.log").read_text()
        yield base, token
    finally:
        os.killpg(process.pid, signal.SIGTERM)  # the server and the app it started (one session)
        try:
            process.wait(timeout=20.0)
        except subprocess.TimeoutExpired:
            os.killpg(process.pid, signal.SIGKILL)
        log.close()


def _answers(url: str) -> bool:
    try:
        with urllib.request.urlopen(url, timeout=5.0) as response:
            return response.status == 200
    except (urllib.error.URLError, OSError):
        return False


def test_the_app_runs_through_jupyter_server_proxy_and_a_kick_moves_its_plot(jupyter: tuple[str, str]) -> None:
    base, token = jupyter
    # the shared Chromium of this test process (a second Playwright driver would clash with its loop)
    with url_page(f"{base}/rns-viz/?token={token}", timeout=START_S) as page:
        assert "/rns-viz/" in page.url  # served under the proxy's prefix
        kick = page.get_by_role("button", name="Kick the base")
        kick.wait_for(timeout=START_S * 1000)  # the panel came over the websocket, through the proxy
        wait_until(lambda: len(page.evaluate(CHART_PEAKS_JS)) >= 2, 30.0, "the live plots")
        time.sleep(1.0)
        before = page.evaluate(CHART_PEAKS_JS)
        at_rest = [uuid for uuid, peak in before.items() if peak < 1e-6]
        assert at_rest, before  # TREP at rest: its live signals (base deflection, ...) are zero
        kick.click()  # the input goes back through the proxy to the app

        def moved() -> bool:
            after = page.evaluate(CHART_PEAKS_JS)
            return any(after.get(uuid, 0.0) > 1e-3 for uuid in at_rest)

        wait_until(moved, 30.0, "a plot at rest to show the kick")
