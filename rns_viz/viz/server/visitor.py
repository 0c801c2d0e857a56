"""One page of a per-visitor server (:mod:`rns_viz.viz.server.classroom`): what the room knows of it, and
what its panel says while it has no simulation."""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

from rns_viz.live.loop.session import Session
from rns_viz.viz.clients.client_view import ClientView
from rns_viz.viz.server.app import RnsApp

FULL_TEXT = (
    "**This class is full.** All {cap} simulations are in use. This page waits and starts yours as soon as "
    "one is free; there is no need to reload. You are number {place} in the queue."
)
CLOSED_TEXT = (
    "**Your simulation was closed** after {minutes:g} minutes without input, to make room for others. "
    "Press the button to start a new one."
)


@dataclass
class Visitor:
    """One page: its view of the server and, while it holds a place, its session and the app it shows (on
    its own session, or on the presenter's while the presenter shows theirs)."""

    view: ClientView
    presenter: bool = False  # may show its simulation on every other page
    session: Session | None = None
    app: RnsApp | None = None
    watching: bool = False  # the app shows the presenter's session
    resume_after_watch: bool = False  # the own session ran when watching began
    extra: Any = None  # the presenter's switch, or the watcher's line, in the page's panel
    last_input: float = field(default_factory=time.monotonic)
    opening: bool = False  # its app is being built (it holds a place already)
    idle_paused: bool = False  # paused by the idle rule (the next input resumes it)
    notice: Any = None  # the waiting / closed message in the page's panel
    start_again: Any = None  # the button under a "closed" message
