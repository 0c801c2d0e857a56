"""One background thread for slow computations (paths, reachable sets, preset builds).

The simulation loop submits jobs and later collects finished results between steps, so a
recomputation never stalls the simulation. A newer job of the same kind replaces a pending one.
Each result carries the tag it was submitted with; the loop drops results whose tag is stale.
"""

from __future__ import annotations

import threading
import traceback
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class Result:
    kind: str
    tag: Any
    value: Any = None
    error: str | None = None


class Worker:
    def __init__(self) -> None:
        self._pending: dict[str, tuple[Any, Callable[[], Any]]] = {}
        self._done: list[Result] = []
        self._cv = threading.Condition()
        self._busy = False
        self._stop = False
        self._thread = threading.Thread(target=self._run, name="rns-worker", daemon=True)
        self._thread.start()

    def submit(self, kind: str, tag: Any, job: Callable[[], Any]) -> None:
        with self._cv:
            self._pending[kind] = (tag, job)
            self._cv.notify_all()

    def has_results(self) -> bool:
        """Finished results wait to be collected (a cheap check for the simulation loop)."""
        return bool(self._done)

    def collect(self) -> list[Result]:
        if not self._done:
            return []
        with self._cv:
            out, self._done = self._done, []
        return out

    def idle(self) -> bool:
        with self._cv:
            return not self._pending and not self._busy

    def wait_idle(self, timeout: float = 30.0) -> bool:
        with self._cv:
            return self._cv.wait_for(lambda: not self._pending and not self._busy, timeout)

    def stop(self) -> None:
        """Take no more jobs. A job in flight (a call into the helper process, up to a second or two for
        boom7's geometry) is not waited for: the thread is a daemon that ends when the call returns, and
        its result is dropped. (Waiting cost every stopped session that long.)"""
        with self._cv:
            self._stop = True
            self._cv.notify_all()
        self._thread.join(timeout=0.05)

    def _run(self) -> None:
        while True:
            with self._cv:
                self._cv.wait_for(lambda: self._pending or self._stop)
                if self._stop:
                    return
                kind = next(iter(self._pending))
                tag, job = self._pending.pop(kind)
                self._busy = True
            try:
                result = Result(kind, tag, job())
            except Exception as exc:  # a failed computation is reported, never fatal
                if not self._stop:  # after stop (a helper ended at exit, say) nobody reads it
                    traceback.print_exc()
                result = Result(kind, tag, error=f"{type(exc).__name__}: {exc}")
            with self._cv:
                self._done.append(result)
                self._busy = False
                self._cv.notify_all()
