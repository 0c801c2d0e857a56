"""Who may operate: one client at a time holds the operator lock, everyone else watches.

Viser-free and thread-safe (GUI callbacks and connect/disconnect handlers run on viser's thread
pool). Clients are known by their integer ids. Without a password the first client to connect
operates while nobody does, and the lock passes to the longest-connected client when the
operator leaves. With a password only clients that gave it (:meth:`OperatorLock.authenticate`
or :meth:`OperatorLock.take` with the password) can hold the lock.

A reload is a new client: the page's connection closes and a new one opens. So that reloading the
operator's page keeps control, a client may be identified with its *browser* (a random token the page
keeps, :meth:`OperatorLock.identify`): when the operator leaves, another client of the same browser (a
reload that arrived first, a second tab) operates at once; otherwise the lock is kept for that browser
for RELOAD_GRACE_S and passes on (:meth:`OperatorLock.expire`) if no page of it comes back. A browser that
gave the password is known by it afterwards too.
"""

from __future__ import annotations

import hmac
import threading
import time
from collections.abc import Callable

RELOAD_GRACE_S = 10.0  # wall s: how long a departed operator's browser may take to come back (a reload)


class LockRefused(ValueError):
    """A request for the operator lock that is not granted (the message says why)."""


class OperatorLock:
    def __init__(
        self, password: str | None = None, clock: Callable[[], float] = time.monotonic, seat_on_connect: bool = True
    ) -> None:
        """``seat_on_connect=False`` (a server open to the network): nobody operates by connecting or by
        being left over; the seat goes to the first client that asks for it (:meth:`take`)."""
        self.password = password
        self.seat_on_connect = seat_on_connect
        self._clock = clock
        self._lock = threading.Lock()
        self._clients: list[int] = []  # in order of arrival
        self._authed: set[int] = set()
        self._browser: dict[int, str] = {}  # client -> the token of its browser
        self._authed_browsers: set[str] = set()
        self._kept: tuple[str, float] | None = None  # (browser, until when): the lock kept for a reloading page
        self.operator: int | None = None
        self.version = 0  # bumps whenever the operator or the set of clients changes

    def _eligible(self, client: int) -> bool:
        """May ``client`` get the seat without asking (on connect, or as the heir of a leaving operator)?"""
        if not self.seat_on_connect:
            return False
        return self._may_hold(client)

    def _may_hold(self, client: int) -> bool:
        return self.password is None or client in self._authed or self._browser.get(client) in self._authed_browsers

    def _keeping(self) -> bool:
        """The lock is kept for a reloading operator's browser (and the grace has not run out)."""
        return self._kept is not None and self._clock() <= self._kept[1]

    def _set(self, operator: int | None) -> None:
        self.operator = operator
        self.version += 1

    def connect(self, client: int) -> bool:
        """Register ``client``; True if it became the operator (nobody was, and no password is needed)."""
        with self._lock:
            if client not in self._clients:
                self._clients.append(client)
            self.version += 1
            if self.operator is None and not self._keeping() and self._eligible(client):
                self._set(client)
                return True
            return False

    def identify(self, client: int, browser: str) -> bool:
        """``client`` runs in the browser of token ``browser``; True if it became the operator (its browser's
        page operated and left within the grace: a reload)."""
        with self._lock:
            if client not in self._clients:
                return False
            self._browser[client] = browser
            if client in self._authed:
                self._authed_browsers.add(browser)
            self.version += 1
            if self._keeping() and self._kept is not None and self._kept[0] == browser:
                self._kept = None
                self._set(client)
                return True
            return False

    def expire(self) -> int | None:
        """Pass a kept lock on once its grace ran out; returns the new operator (None if nothing changed)."""
        with self._lock:
            if self._kept is None or self._keeping():
                return None
            self._kept = None
            heir = next((c for c in self._clients if self._eligible(c)), None)
            self._set(heir)
            return heir

    def disconnect(self, client: int) -> int | None:
        """Forget ``client``; if it operated, the lock passes to the longest-connected eligible client.

        Returns the new operator if the lock changed hands (None otherwise, or if nobody can take it)."""
        with self._lock:
            if client in self._clients:
                self._clients.remove(client)
            self._authed.discard(client)
            browser = self._browser.pop(client, None)
            self.version += 1
            if self.operator != client:
                return None
            same = [c for c in self._clients if browser is not None and self._browser.get(c) == browser]
            if same:  # its browser is still here (the reloaded page came first, or another tab): it goes on
                self._set(same[-1])
                return same[-1]
            if browser is not None:  # perhaps a reload: kept for the browser a while (expire passes it on)
                self._kept = (browser, self._clock() + RELOAD_GRACE_S)
                self._set(None)
                return None
            heir = next((c for c in self._clients if self._eligible(c)), None)
            self._set(heir)
            return heir

    def authenticate(self, client: int, password: str) -> bool:
        """Check ``password``; a correct one lets ``client`` operate (and gives it the lock if it is free)."""
        with self._lock:
            if self.password is not None and not hmac.compare_digest(str(password), self.password):
                return False
            self._authed.add(client)
            if client in self._browser:
                self._authed_browsers.add(self._browser[client])
            if self.operator is None and not self._keeping() and client in self._clients:
                self._set(client)
            return True

    def take(self, client: int, password: str | None = None) -> None:
        """Make ``client`` the operator; raises LockRefused without the password (when one is set)."""
        if password is not None and self.password is not None:
            self.authenticate(client, password)
        with self._lock:
            if client not in self._clients:
                raise LockRefused("that client is not connected")
            if not self._may_hold(client):
                raise LockRefused("enter the session password to take control")
            self._kept = None
            if self.operator != client:
                self._set(client)

    def release(self, client: int) -> None:
        """``client`` gives the lock up; nobody operates until someone takes it."""
        with self._lock:
            if self.operator == client:
                self._set(None)

    def may_operate(self, client: int) -> bool:
        """``client`` may hold the lock (no password is set, or it or its browser gave it)."""
        with self._lock:
            return self._may_hold(client)

    def browser(self, client: int) -> str | None:
        """The token of ``client``'s browser, once identified."""
        return self._browser.get(client)

    def is_operator(self, client: int) -> bool:
        return self.operator == client

    def clients(self) -> list[int]:
        with self._lock:
            return list(self._clients)

    def status(self, client: int) -> str:
        """The status line shown to ``client``."""
        operator = self.operator
        if operator == client:
            return "You are operating"
        if operator is None and self._keeping():
            return "Watching — the operator's page left; control is kept a few seconds in case it is reloading"
        if operator is None:
            return "Watching — nobody is operating"
        return f"Watching — client {operator} is operating"
