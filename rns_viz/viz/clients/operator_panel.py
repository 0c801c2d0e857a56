"""Per-client "Operator" panel: who operates, and Take control / Release control buttons.

Every connected browser sees the same simulation; the :class:`~rns_viz.live.operator.operator_lock.OperatorLock`
decides whose inputs count. Each client gets its own small panel (``client.gui``) with its status
line ("You are operating" / "Watching — client 3 is operating"), a password field when the
session has one, and the two buttons. The render thread calls :meth:`OperatorPanels.refresh`. Whoever
loses control is told why (another client took it); whoever gets it is told too.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from contextlib import suppress
from dataclasses import dataclass

import viser

from rns_viz.live.operator.operator_lock import LockRefused, OperatorLock

Notify = Callable[[viser.ClientHandle | None, str, str, str], None]


@dataclass
class ClientPanel:
    client: viser.ClientHandle
    status: viser.GuiHtmlHandle
    take: viser.GuiButtonHandle
    release: viser.GuiButtonHandle
    password: viser.GuiTextHandle | None
    shown: str = ""


def status_html(text: str, operating: bool) -> str:
    colour = "#2a9d4b" if operating else "#7a7a7a"
    return f'<div style="font-weight:600;color:{colour};padding:2px 0">{text}</div>'


class OperatorPanels:
    def __init__(self, lock: OperatorLock, notify: Notify) -> None:
        self.lock = lock
        self.notify = notify
        self._panels: dict[int, ClientPanel] = {}
        self._guard = threading.Lock()
        self._shown_version = -1

    def add(self, client: viser.ClientHandle) -> None:
        """Build ``client``'s panel (on connect) and register it with the lock."""
        self.lock.connect(client.client_id)
        gui = client.gui
        with gui.add_folder("Operator", order=-1000.0):
            status = gui.add_html(status_html(self.lock.status(client.client_id), False))
            password = gui.add_text("Password", "") if self.lock.password is not None else None
            take = gui.add_button("Take control", icon=viser.Icon.HAND_GRAB)
            release = gui.add_button("Release control", icon=viser.Icon.HAND_STOP)
        panel = ClientPanel(client, status, take, release, password)
        take.on_click(lambda _: self._take(panel))
        release.on_click(lambda _: self._release(panel))
        with self._guard:
            self._panels[client.client_id] = panel
        self._shown_version = -1

    def panel(self, client_id: int) -> ClientPanel | None:
        """The panel of a connected client (its handles)."""
        with self._guard:
            return self._panels.get(client_id)

    def remove(self, client_id: int) -> int | None:
        """Forget a client that left; returns the new operator if the lock passed on."""
        with self._guard:
            self._panels.pop(client_id, None)
        was = self.lock.operator
        heir = self.lock.disconnect(client_id)
        if was == client_id and heir is not None:
            self._tell(heir, "You are operating", f"Client {client_id} left; you have control.")
        self._shown_version = -1
        return heir

    def _take(self, panel: ClientPanel) -> None:
        cid = panel.client.client_id
        was = self.lock.operator
        try:
            self.lock.take(cid, None if panel.password is None else panel.password.value)
        except LockRefused as exc:
            self.notify(panel.client, "Control not taken", str(exc), "warning")
        if was is not None and was != cid and self.lock.is_operator(cid):
            self._tell(was, "Control taken", f"Client {cid} took control. Press 'Take control' to operate again.")
        self.refresh()

    def identified(self, client_id: int, browser: str) -> None:
        """The client's browser is known (its page's token): a reloaded operator's page operates again."""
        if self.lock.identify(client_id, browser):
            self._tell(client_id, "You are operating", "Your page reloaded; you still have control.")
        self._shown_version = -1

    def _tell(self, client_id: int, title: str, body: str) -> None:
        panel = self.panel(client_id)
        if panel is not None:
            self.notify(panel.client, title, body, "info")

    def _release(self, panel: ClientPanel) -> None:
        self.lock.release(panel.client.client_id)
        self.refresh()

    def refresh(self) -> None:
        """Pass on a lock kept for a reloading page that did not come back; show every client its status
        (cheap when nothing changed)."""
        heir = self.lock.expire()
        if heir is not None:
            self._tell(heir, "You are operating", "The operator's page did not come back; you have control.")
        version = self.lock.version
        if version == self._shown_version:
            return
        self._shown_version = version
        with self._guard:
            panels = list(self._panels.values())
        for panel in panels:
            cid = panel.client.client_id
            operating = self.lock.is_operator(cid)
            html = status_html(self.lock.status(cid), operating)
            if html == panel.shown:
                continue
            with suppress(Exception):  # the client may be going
                panel.status.content = html
                panel.take.visible = not operating
                panel.release.visible = operating
                panel.shown = html
