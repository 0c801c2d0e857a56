"""Slow geometry for the live session, computed in a helper process.

A Python-heavy computation in a thread would take turns with the simulation thread for the GIL
and slow it down; a separate process runs beside it on another core. The helper is
``python -m rns_viz.live.jobs.helper`` (a plain subprocess, so no caller needs a ``__main__`` guard),
speaking length-prefixed pickles over its stdin and stdout. :func:`call` runs one job there,
blocking the calling thread (not the GIL) until the result is back; the helper is started on
first use, restarted if it died, and shared by all sessions of the process.

One helper runs one job at a time. The gain explorer's linearisations (:data:`BACKGROUND_JOBS`) yield
to every other job: a caller of those waits while one of the others waits, so a reachable set asked
for after a change of S waits for at most the one explorer call in flight (the explorer cuts its
sweep over a path into calls of a few configurations, rns_viz.live.explorer.gain_explorer).

Jobs are the top-level functions below: plain arguments, picklable results. Each is a function of its
arguments (and the model file), so the helper answers a request it has already answered from its
:class:`ReplyCache`.
"""

from __future__ import annotations

import atexit
import pickle
import struct
import subprocess
import sys
import threading
from collections import OrderedDict
from typing import IO, Any

import numpy as np

from rns_viz.analysis import GainMap, LinearLoop, linearise, loops_along, map_of
from rns_viz.control import LawKind
from rns_viz.live.reach.region import ReachRegion, build_reach_region
from rns_viz.model import FsmsModel
from rns_viz.paths import PathTable, build_path_table, path_family

_models: dict[str, FsmsModel] = {}


def _model(name: str) -> FsmsModel:
    if name not in _models:
        _models[name] = FsmsModel.from_key(name)
    return _models[name]


def family_curves(name: str, count: int) -> list[np.ndarray]:
    """End-effector curves (base frame, m) of the Fig. 8 path family."""
    return [p.ee for p in path_family(_model(name), count)]


def path_table(name: str, seed: np.ndarray) -> PathTable:
    return build_path_table(_model(name), seed)


def reach_region(name: str, seed: np.ndarray) -> ReachRegion:
    return build_reach_region(_model(name), seed)


def linear_loop(name: str, law: LawKind, theta: np.ndarray) -> LinearLoop:
    """The closed loop linearised in the gains about ``theta`` at rest (the gain explorer's map)."""
    return linearise(_model(name), law, theta)


def loop_and_map(name: str, law: LawKind, theta: np.ndarray) -> tuple[LinearLoop, GainMap]:
    """The linearised loop and its gain map (60 x 60 eigenproblems: seconds for boom7's 13 DOF, so here,
    not in a thread of the app's process where it would take turns with the simulation for the GIL)."""
    loop = linear_loop(name, law, theta)
    return loop, map_of(loop)


def linear_loops(name: str, law: LawKind, thetas: np.ndarray) -> list[LinearLoop]:
    """One linearised loop per configuration (the gain explorer's authority along a path)."""
    return loops_along(_model(name), law, thetas)


JOBS = {f.__name__: f for f in (family_curves, path_table, reach_region, linear_loop, loop_and_map, linear_loops)}
CACHE_BYTES = 64 * 2**20  # the helper's reply cache (ReplyCache); the largest reply, boom7's gain map, is 1.8 MB
BACKGROUND_JOBS = frozenset({"linear_loop", "loop_and_map", "linear_loops"})  # the gain explorer's: they yield


class JobError(RuntimeError):
    """A job failed in the helper process (the message carries its error)."""


def _write(stream: IO[bytes], obj: Any) -> None:
    _write_bytes(stream, pickle.dumps(obj, protocol=pickle.HIGHEST_PROTOCOL))


def _write_bytes(stream: IO[bytes], data: bytes) -> None:
    stream.write(struct.pack("<Q", len(data)) + data)
    stream.flush()


def _read(stream: IO[bytes]) -> Any:
    return pickle.loads(_read_bytes(stream))


def _read_bytes(stream: IO[bytes]) -> bytes:
    header = stream.read(8)
    if len(header) < 8:
        raise EOFError("the job helper closed its pipe")
    (size,) = struct.unpack("<Q", header)
    return stream.read(size)


class _Helper:
    def __init__(self) -> None:
        self.cv = threading.Condition()
        self.busy = False  # a job is in the helper
        self.urgent_waiting = 0  # callers of jobs outside BACKGROUND_JOBS waiting for the helper
        self.proc: subprocess.Popen[bytes] | None = None

    def call(self, name: str, *args: Any) -> Any:
        urgent = name not in BACKGROUND_JOBS
        with self.cv:
            self.urgent_waiting += urgent
            try:
                self.cv.wait_for(lambda: not self.busy and (urgent or not self.urgent_waiting))
            finally:
                self.urgent_waiting -= urgent
            self.busy = True
        try:
            ok, value = self._exchange(name, args)
        finally:
            with self.cv:
                self.busy = False
                self.cv.notify_all()
        if not ok:
            raise JobError(value)
        return value

    def _exchange(self, name: str, args: tuple[Any, ...]) -> tuple[bool, Any]:
        """Send one job and read its reply (restarting a dead helper once); the caller holds the helper."""
        for attempt in range(2):
            proc = self._running()
            try:
                assert proc.stdin is not None and proc.stdout is not None
                _write(proc.stdin, (name, args))
                return _read(proc.stdout)
            except (EOFError, BrokenPipeError, OSError):
                self.close()
                if attempt:
                    raise JobError(f"the job helper died while running {name}") from None
        raise AssertionError("unreachable")

    def _running(self) -> subprocess.Popen[bytes]:
        if self.proc is None or self.proc.poll() is not None:
            self.proc = subprocess.Popen(
                [sys.executable, "-m", "rns_viz.live.jobs.helper"], stdin=subprocess.PIPE, stdout=subprocess.PIPE
            )
        return self.proc

    def close(self) -> None:
        proc, self.proc = self.proc, None
        if proc is not None and proc.poll() is None:
            try:
                proc.stdin.close()  # type: ignore[union-attr]
                proc.wait(timeout=2.0)
            except Exception:
                proc.kill()


_helper = _Helper()
atexit.register(_helper.close)


def call(name: str, *args: Any) -> Any:
    """Run job ``name`` with ``args`` in the helper process and return its result (JobError if it failed)."""
    return _helper.call(name, *args)


class ReplyCache:
    """The last replies by request bytes, at most ``budget`` bytes of them (least recently used leave first).

    Every job is a function of its arguments and the model file, so a request seen before is answered
    from here: a reset, a lesson restarted or a model switched back gets its path table, reachable set
    and gain map at once instead of in seconds (a planar 3R's reachable set: ~1 s).
    """

    def __init__(self, budget: int = CACHE_BYTES) -> None:
        self.budget = budget
        self._replies: OrderedDict[bytes, bytes] = OrderedDict()
        self._size = 0

    def get(self, request: bytes) -> bytes | None:
        reply = self._replies.get(request)
        if reply is not None:
            self._replies.move_to_end(request)
        return reply

    def put(self, request: bytes, reply: bytes) -> None:
        if request in self._replies or len(request) + len(reply) > self.budget:
            return
        self._replies[request] = reply
        self._size += len(request) + len(reply)
        while self._size > self.budget:
            old, old_reply = self._replies.popitem(last=False)
            self._size -= len(old) + len(old_reply)


def _answer(request: bytes) -> tuple[bytes, bool]:
    """The pickled reply to one pickled request, and whether it may be cached (failures are not)."""
    name, args = pickle.loads(request)
    try:
        reply: tuple[bool, Any] = (True, JOBS[name](*args))
    except Exception as exc:
        reply = (False, f"{name}: {type(exc).__name__}: {exc}")
    return pickle.dumps(reply, protocol=pickle.HIGHEST_PROTOCOL), reply[0]


def serve(stdin: IO[bytes], stdout: IO[bytes]) -> None:
    """The helper's loop: read a job, run it (or find its reply in the cache), write (ok, result or error
    text); stop at end of input."""
    cache = ReplyCache()
    while True:
        try:
            request = _read_bytes(stdin)
        except EOFError:
            return
        reply = cache.get(request)
        if reply is None:
            reply, ok = _answer(request)
            if ok:
                cache.put(request, reply)
        try:
            _write_bytes(stdout, reply)
        except BrokenPipeError:  # the caller's process ended while this job ran: nobody wants the result
            return


if __name__ == "__main__":
    out = sys.stdout.buffer
    sys.stdout = sys.stderr  # a stray print must not corrupt the pipe
    serve(sys.stdin.buffer, out)
