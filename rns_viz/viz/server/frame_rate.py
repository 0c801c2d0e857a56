"""How often the render thread sends the scene, the plots and the text to the pages."""

from __future__ import annotations

FRAME_S = 1.0 / 60.0  # scene updates at 60 Hz ...
CROWD = 3  # ... and at 33 Hz from this many clients on (the server encodes every update once per client) ...
CROWDED_FRAME_S = 1.0 / 33.0
# ... and while the simulation falls behind real time, and this long after (wall s): a page draws on every
# update, and where it shares the cores with the simulation (a browser on the server's machine drawing in
# software) its frames take the cycles the simulation needs
BEHIND_HOLD_S = 10.0
PLOT_S = 1.0 / 15.0  # live plots at 15 Hz (13 Hz when crowded)
TEXT_S = 0.2  # status line and readouts at 5 Hz


def frame_interval(clients: int, behind: bool) -> float:
    """Wall s to the next scene update: 60 Hz, or 33 Hz for a crowd of pages or a simulation that has fallen
    behind real time (recently: BEHIND_HOLD_S)."""
    return CROWDED_FRAME_S if clients >= CROWD or behind else FRAME_S
