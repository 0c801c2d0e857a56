"""The live reaction null-space app: operate a simulated arm on a flexible base in the browser.

Kick the base, switch vibration suppression, drag the end-effector target, scrub along the
reactionless path, load the paper's experiments as presets and watch base deflection with
suppression on and off side by side (the shadow run).

    python apps/rns_app.py                      # TREP on http://127.0.0.1:8080
    python apps/rns_app.py --model planar3r --port 8081
"""

from __future__ import annotations

import tyro

from rns_viz.viz.server.app import serve


def main(model: str = "trep", host: str = "127.0.0.1", port: int = 8080) -> None:
    """Serve the live app for ``model`` ("trep" or "planar3r") at http://host:port until Ctrl+C."""
    serve(model=model, host=host, port=port)


if __name__ == "__main__":
    tyro.cli(main)
