"""The presenter's simulation shown on every visitor's page (``rns-viz serve --each-visitor``).

The presenter is the page opened on the server's own machine (a loopback address): in a lab room the
teacher runs the server and projects that page. Their panel gets a checkbox *Show my simulation to every
visitor*. While it is ticked, every other page shows an app on a :class:`WatchedSession` of the
presenter's session: the same scene, plots and readouts, drawn to that page alone, and any input there
is refused with a message (the presenter's simulation is the presenter's to drive). The visitor's own
simulation is paused meanwhile and comes back, as it was, when the presenter unticks the box or leaves.
"""

from __future__ import annotations

from collections.abc import Callable
from contextlib import suppress
from typing import Any

import viser

from rns_viz.live.loop.session import Session

SHOW_LABEL = "Show my simulation to every visitor"
SHOW_HINT = "Every other page shows your simulation, view only; theirs pause and come back when you untick this."
WATCHING_TEXT = (
    "**You are watching the presenter's simulation.** Your own is paused and comes back when the presenter "
    "stops showing theirs."
)
REFUSED_TITLE = "Watching the presenter"
REFUSED_BODY = "This page shows the presenter's simulation; inputs return with yours when the presenter is done."
# What an app reads from its session; everything else it calls is an input.
READS = frozenset(
    {"snapshot", "overlays", "gain_view", "plots", "plot_arrays", "recording", "log_csv", "latencies", "dt"}
    | {"pending_commands", "realtime", "pacer", "state", "stopped", "wait_background"}
)


class WatchedSession:
    """A session seen, not driven: reads pass through, inputs are refused with ``refuse()``, notices stay
    with the session's own app (they are addressed to its pages), and stopping leaves it running."""

    def __init__(self, session: Session, refuse: Callable[[], None]) -> None:
        self._session = session
        self._refuse = refuse

    def __getattr__(self, name: str) -> Any:
        if name in READS:
            return getattr(self._session, name)
        if name.startswith("_"):
            raise AttributeError(name)
        return self._refused

    def _refused(self, *_args: object, **_kwargs: object) -> None:
        self._refuse()

    def pop_notices(self) -> list[Any]:
        return []

    def stop(self) -> None:
        """Nothing: the presenter's session is not this app's to stop."""


def is_loopback(server: viser.ViserServer, client_id: int) -> bool:
    """Whether the page of ``client_id`` connected from this machine (False if viser does not say)."""
    with suppress(AttributeError, KeyError, TypeError, IndexError):
        address = server._websock_server._live_connections[client_id].remote_address[0]  # type: ignore[attr-defined]
        return str(address).startswith("127.") or address in ("::1", "localhost")
    return False


def refuser(client: viser.ClientHandle) -> Callable[[], None]:
    """Tell ``client`` that its input went to no simulation."""

    def refuse() -> None:
        with suppress(Exception):  # the page may have gone
            client.add_notification(REFUSED_TITLE, REFUSED_BODY, color="yellow", auto_close_seconds=6.0)

    return refuse


def add_show_switch(client: viser.ClientHandle, on: bool, toggled: Callable[[bool], None]) -> Any:
    """The presenter's checkbox, at the top of their panel."""
    box = client.gui.add_checkbox(SHOW_LABEL, initial_value=on, hint=SHOW_HINT, order=-2000.0)
    box.on_update(lambda _: toggled(bool(box.value)))
    return box


def add_watching_line(client: viser.ClientHandle) -> Any:
    return client.gui.add_markdown(WATCHING_TEXT, order=-2000.0)
