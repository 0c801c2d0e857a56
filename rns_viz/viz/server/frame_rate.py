"""How often the render thread sends the scene, the plots and the text to the pages."""

from __future__ import annotations

FRAME_S = 1.0 / 60.0  # scene updates at 60 Hz ...
CROWD = 3  # ... and at 33 Hz from this many clients on (the server encodes every update once per client)
CROWDED_FRAME_S = 1.0 / 33.0
PLOT_S = 1.0 / 15.0  # live plots at 15 Hz (13 Hz when crowded)
TEXT_S = 0.2  # status line and readouts at 5 Hz


def frame_interval(clients: int) -> float:
    """Wall s to the next scene update: 60 Hz, or 33 Hz for a crowd of pages."""
    return CROWDED_FRAME_S if clients >= CROWD else FRAME_S
