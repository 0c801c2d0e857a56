"""Who may operate: one client at a time holds the operator lock, everyone else watches.

Viser-free and thread-safe (GUI callbacks and connect/disconnect handlers run on viser's thread
pool). Clients are known by their integer ids. Without a password the first client to connect
operates while nobody does, and the lock passes to the longest-connected client when the
operator leaves. With a password only clients that gave it (:meth:`OperatorLock.authenticate`
or :meth:`OperatorLock.take` with the password) can hold the lock.
"""

from __future__ import annotations

import hmac
import threading


class LockRefused(ValueError):
    """A request for the operator lock that is not granted (the message says why)."""


class OperatorLock:
    def __init__(self, password: str | None = None) -> None:
        self.password = password
        self._lock = threading.Lock()
        self._clients: list[int] = []  # in order of arrival
        self._authed: set[int] = set()
        self.operator: int | None = None
        self.version = 0  # bumps whenever the operator or the set of clients changes

    def _eligible(self, client: int) -> bool:
        return self.password is None or client in self._authed

    def _set(self, operator: int | None) -> None:
        self.operator = operator
        self.version += 1

    def connect(self, client: int) -> bool:
        """Register ``client``; True if it became the operator (nobody was, and no password is needed)."""
        with self._lock:
            if client not in self._clients:
                self._clients.append(client)
            self.version += 1
            if self.operator is None and self._eligible(client):
                self._set(client)
                return True
            return False

    def disconnect(self, client: int) -> int | None:
        """Forget ``client``; if it operated, the lock passes to the longest-connected eligible client.

        Returns the new operator if the lock changed hands (None otherwise, or if nobody can take it)."""
        with self._lock:
            if client in self._clients:
                self._clients.remove(client)
            self._authed.discard(client)
            self.version += 1
            if self.operator != client:
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
            if self.operator is None and client in self._clients:
                self._set(client)
            return True

    def take(self, client: int, password: str | None = None) -> None:
        """Make ``client`` the operator; raises LockRefused without the password (when one is set)."""
        if password is not None and self.password is not None:
            self.authenticate(client, password)
        with self._lock:
            if client not in self._clients:
                raise LockRefused("that client is not connected")
            if not self._eligible(client):
                raise LockRefused("enter the session password to take control")
            if self.operator != client:
                self._set(client)

    def release(self, client: int) -> None:
        """``client`` gives the lock up; nobody operates until someone takes it."""
        with self._lock:
            if self.operator == client:
                self._set(None)

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
        if operator is None:
            return "Watching — nobody is operating"
        return f"Watching — client {operator} is operating"
