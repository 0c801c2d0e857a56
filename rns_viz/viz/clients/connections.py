"""Who is connected and who may operate: the operator lock, the password modal and notifications.

Every browser sees the same simulation; the :class:`~rns_viz.live.operator.operator_lock.OperatorLock`
decides whose inputs count. The server itself (client ``None``) may always operate.
"""

from __future__ import annotations

import secrets
from contextlib import suppress

import viser

from rns_viz.live.operator.operator_lock import OperatorLock
from rns_viz.viz.clients.operator_panel import OperatorPanels

NOTICE_COLOURS = {"info": "blue", "warning": "yellow", "error": "red"}
NOTICE_SECONDS = 8.0  # a notification closes itself after this long
BROWSER_KEY = "rns_viz_browser"  # localStorage key of the page's browser token (a reload keeps it)
BROWSER_ASK_S = 30.0  # s: how long a page may take to answer (it answers after the scene it is sent first)


class Connections:
    """The clients of one server: notifications, operator rights and the per-client panels."""

    def __init__(
        self, server: viser.ViserServer, password: str | None, seat_on_connect: bool = True, shared: bool = True
    ) -> None:
        """``seat_on_connect=False``: a visitor operates only after pressing Take control (OperatorLock);
        ``shared=False``: one page's own simulation, which it operates (no Operator panel)."""
        self.server = server
        self.shared = shared
        self.password = password
        self.lock = OperatorLock(password, seat_on_connect=seat_on_connect)
        self.panels = OperatorPanels(self.lock, self.notify)

    def recipients(self, client: viser.ClientHandle | None) -> list[viser.ClientHandle]:
        """``client`` itself, or every connected client for the server's own input (None)."""
        return [client] if client is not None else list(self.server.get_clients().values())

    def notify(self, client: viser.ClientHandle | None, title: str, body: str, level: str) -> None:
        """Show a notification to ``client``, or to every client when it is None."""
        for c in self.recipients(client):
            with suppress(Exception):  # the client may have gone
                c.add_notification(title, body, color=NOTICE_COLOURS.get(level), auto_close_seconds=NOTICE_SECONDS)

    def notify_by_id(self, client_id: int | None, title: str, body: str, level: str) -> None:
        """Like :meth:`notify`, by client id; nothing if that client has left."""
        client = None
        if client_id is not None:
            client = self.server.get_clients().get(client_id)
            if client is None:
                return
        self.notify(client, title, body, level)

    def allowed(self, client: viser.ClientHandle | None) -> bool:
        """The server itself (client None) and the operator may operate; everyone else watches."""
        return client is None or self.lock.is_operator(client.client_id)

    def refuse_watcher(self, client: viser.ClientHandle | None) -> None:
        """Tell a watcher why their input was not applied."""
        if client is None:
            return
        body = f"{self.lock.status(client.client_id)}. Press 'Take control' to operate."
        if self.password is not None:
            body += " Taking control needs the session password."
        self.notify(client, "View only", body, "warning")

    def client_count(self) -> int:
        return len(self.server.get_clients())

    def client_joined(self, client: viser.ClientHandle) -> None:
        """Give the newcomer its operator panel (a page with a simulation of its own: only the seat)."""
        if self.shared:
            self.panels.add(client)
        else:
            self.lock.connect(client.client_id)

    def _ask_password(self, client: viser.ClientHandle) -> None:
        """The password modal, for a page whose browser has not given the password yet."""
        with client.gui.add_modal("rns_viz: password") as modal:
            client.gui.add_markdown("Enter the password to operate this session; without it you can only watch.")
            text = client.gui.add_text("Password", "")
            enter = client.gui.add_button("Enter")
            watch = client.gui.add_button("Watch only")

        @enter.on_click
        def _(_: viser.GuiEvent) -> None:
            if self.lock.authenticate(client.client_id, text.value):
                modal.close()
            else:
                client.add_notification("Wrong password", "Try again, or watch only.", color="red")

        @watch.on_click
        def _(_: viser.GuiEvent) -> None:
            modal.close()

    def identify_browser(self, client: viser.ClientHandle) -> None:
        """Ask the page for its browser's token (made and stored on its first visit) and tell the operator
        lock: a reloaded operator's page gets control back, a browser that gave the password is not asked
        again. Blocks this callback thread for one round trip; a page that does not answer (or has no
        storage) stays unidentified."""
        try:
            token = client.local_storage.get_item(BROWSER_KEY, timeout=BROWSER_ASK_S)
            if not (isinstance(token, str) and 16 <= len(token) <= 64 and token.isascii()):
                token = secrets.token_urlsafe(24)  # 32 characters
                client.local_storage.set_item(BROWSER_KEY, token)
        except (RuntimeError, TimeoutError):
            token = None
        if token is not None:
            self.panels.identified(client.client_id, token)
        if self.password is not None and not self.lock.may_operate(client.client_id):
            with suppress(Exception):  # the page may have gone meanwhile
                self._ask_password(client)

    def client_left(self, client_id: int) -> None:
        """Forget a client; the lock passes control on if it was operating."""
        self.panels.remove(client_id)
