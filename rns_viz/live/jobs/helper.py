"""Slow geometry for the live session, computed in a helper process.

A Python-heavy computation in a thread would take turns with the simulation thread for the GIL and
slow it down; a process runs beside it on another core. The helper is a
:class:`~concurrent.futures.ProcessPoolExecutor` of one process (spawned: it imports this module, not
the parent's main script), started on first use, shared by all sessions of the process, and started
again by the call after it died. :func:`call` runs one job there, blocking the calling thread (not the
GIL) until the result is back.

One job runs at a time. The gain explorer's linearisations (:data:`BACKGROUND_JOBS`) yield to every
other job: a caller of those waits while one of the others waits, so a reachable set asked for after a
change of S waits for at most the one explorer call in flight (the explorer cuts its sweep over a path
into calls of a few configurations, rns_viz.live.explorer.gain_explorer).

Jobs are the top-level functions below: plain arguments, picklable results. Each is a function of its
arguments (and the model file), so a request answered before is answered again from the
:class:`ReplyCache` of this process, without the helper.
"""

from __future__ import annotations

import os
import pickle
import sys
import threading
from collections import OrderedDict
from collections.abc import Iterator
from concurrent.futures import BrokenExecutor, Future, ProcessPoolExecutor
from contextlib import contextmanager, suppress
from multiprocessing import active_children, get_context
from multiprocessing.process import BaseProcess
from typing import Any

import numpy as np

from rns_viz.analysis import Authority, GainMap, LinearLoop, authority, linearise, loops_along, map_of
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


_loops_kept: OrderedDict[bytes, list[LinearLoop]] = OrderedDict()
LOOPS_KEPT = 32  # runs of configurations whose loops the helper keeps (a path's 80 points are 8 runs)


def linear_loops(name: str, law: LawKind, thetas: np.ndarray) -> list[LinearLoop]:
    """One linearised loop per configuration (kept: the authority at new gains reuses them)."""
    key = pickle.dumps((name, law, np.asarray(thetas, dtype=float)))
    if key in _loops_kept:
        _loops_kept.move_to_end(key)
        return _loops_kept[key]
    loops = _loops_kept[key] = loops_along(_model(name), law, thetas)
    while len(_loops_kept) > LOOPS_KEPT:
        _loops_kept.popitem(last=False)
    return loops


def authority_at(name: str, law: LawKind, thetas: np.ndarray, g_b: float, g_m: float) -> Authority:
    """The predicted decay rates at gains (g_b, g_m) (1/s) at configurations ``thetas`` (the gain explorer's
    authority along a path): each configuration's kick response costs tens of ms on boom7, here and not in a
    thread of the app's process, where it took turns with the simulation for the GIL."""
    return authority(linear_loops(name, law, thetas), g_b, g_m)


JOBS = {
    f.__name__: f
    for f in (family_curves, path_table, reach_region, linear_loop, loop_and_map, linear_loops, authority_at)
}
CACHE_BYTES = 64 * 2**20  # the helper's reply cache (ReplyCache); the largest reply, boom7's gain map, is 1.8 MB
# the gain explorer's jobs: they yield to the others
BACKGROUND_JOBS = frozenset({"linear_loop", "loop_and_map", "linear_loops", "authority_at"})


class JobError(RuntimeError):
    """A job failed, or the helper process died while running it (the message says which)."""


HELPER_NICENESS = 10  # the helper's scheduling priority below the app's (Unix nice increment)


def _below_the_loop() -> None:
    """In the helper, at its start: run at a lower priority than the app's process. Its geometry can wait;
    the simulation cannot (on two cores beside a browser that draws the scene in software, a helper at the
    same priority recomputing boom7's gain map after every kick took the cycles the simulation needed)."""
    if hasattr(os, "nice"):
        with suppress(OSError):
            os.nice(HELPER_NICENESS)


def _compute(request: bytes) -> bytes:
    """Run a pickled request (job name, arguments) in the helper process; the result comes back pickled,
    as the cache keeps it."""
    name, args = pickle.loads(request)
    return pickle.dumps(JOBS[name](*args), protocol=pickle.HIGHEST_PROTOCOL)


@contextmanager
def _main_script_hidden() -> Iterator[None]:
    """While the helper is spawned: multiprocessing would have it import the parent's main script again
    (the top level of a script without a ``__main__`` guard would run twice; the app's would import viser
    for nothing). The helper needs this module only."""
    main = sys.modules["__main__"]
    spec, file = getattr(main, "__spec__", None), main.__dict__.pop("__file__", None)
    main.__spec__ = None
    try:
        yield
    finally:
        main.__spec__ = spec
        if file is not None:
            main.__file__ = file


class ReplyCache:
    """The last replies by request bytes, at most ``budget`` bytes of them (least recently used leave first).

    Every job is a function of its arguments and the model file, so a request seen before is answered
    from here: a reset, a lesson restarted or a model switched back gets its path table, reachable set
    and gain map at once instead of in seconds (a planar 3R's reachable set: ~1 s). Each caller unpickles
    its own copy of the reply.
    """

    def __init__(self, budget: int = CACHE_BYTES) -> None:
        self.budget = budget
        self._replies: OrderedDict[bytes, bytes] = OrderedDict()
        self._size = 0
        self._lock = threading.Lock()

    def get(self, request: bytes) -> bytes | None:
        with self._lock:
            reply = self._replies.get(request)
            if reply is not None:
                self._replies.move_to_end(request)
            return reply

    def put(self, request: bytes, reply: bytes) -> None:
        with self._lock:
            if request in self._replies or len(request) + len(reply) > self.budget:
                return
            self._replies[request] = reply
            self._size += len(request) + len(reply)
            while self._size > self.budget:
                old, old_reply = self._replies.popitem(last=False)
                self._size -= len(old) + len(old_reply)


class _Helper:
    def __init__(self) -> None:
        self.cv = threading.Condition()
        self.busy = False  # a job is in the helper
        self.urgent_waiting = 0  # callers of jobs outside BACKGROUND_JOBS waiting for the helper
        self.pool: ProcessPoolExecutor | None = None
        self.processes: list[BaseProcess] = []  # the pool's process
        self.cache = ReplyCache()

    def call(self, name: str, *args: Any) -> Any:
        if name not in JOBS:
            raise JobError(f"no job named {name!r}")
        request = pickle.dumps((name, args), protocol=pickle.HIGHEST_PROTOCOL)
        reply = self.cache.get(request)
        if reply is None:
            reply = self._gated(name, request)
        return pickle.loads(reply)

    def _gated(self, name: str, request: bytes) -> bytes:
        """The reply computed in the helper once it is this caller's turn (or found in the cache by then)."""
        urgent = name not in BACKGROUND_JOBS
        with self.cv:
            self.urgent_waiting += urgent
            try:
                self.cv.wait_for(lambda: not self.busy and (urgent or not self.urgent_waiting))
            finally:
                self.urgent_waiting -= urgent
            self.busy = True
        try:
            reply = self.cache.get(request)  # the same request, answered while this caller waited
            if reply is None:
                reply = self._run(name, request)
                self.cache.put(request, reply)
            return reply
        finally:
            with self.cv:
                self.busy = False
                self.cv.notify_all()

    def _run(self, name: str, request: bytes) -> bytes:
        """Run one job in the helper and wait for it; the caller holds the helper."""
        try:
            return self._submit(request).result()
        except BrokenExecutor:
            self.close()
            raise JobError(f"the job helper died while running {name}; it starts again on the next call") from None
        except Exception as exc:
            raise JobError(f"{name}: {type(exc).__name__}: {exc}") from exc

    def _submit(self, request: bytes) -> Future[bytes]:
        """The future of ``request`` in the helper, which is started first if there is none or it died
        while idle (not this job's doing, so the job gets a new one)."""
        if self.pool is not None and not all(_running(p) for p in self.processes):
            self.close()
        if self.pool is not None:
            return self.pool.submit(_compute, request)
        self.pool = ProcessPoolExecutor(max_workers=1, mp_context=get_context("spawn"), initializer=_below_the_loop)
        before = set(active_children())
        with _main_script_hidden():  # the helper is spawned by its first submit
            future = self.pool.submit(_compute, request)
        self.processes = [p for p in active_children() if p not in before]
        return future

    def close(self) -> None:
        """Let the helper go: it ends once a job in flight is done (that job's result is dropped)."""
        pool, self.pool = self.pool, None
        if pool is not None:
            pool.shutdown(wait=False, cancel_futures=True)

    def kill(self) -> None:
        """End the helper now, a job in flight with it (its caller gets a JobError)."""
        for process in self.processes:
            process.kill()
        self.close()


_helper = _Helper()
# At exit the executor's own hook waits for a job in flight (seconds for boom7's geometry); this hook,
# registered after it, runs before it and ends the helper instead.
threading._register_atexit(_helper.kill)  # type: ignore[attr-defined]


def call(name: str, *args: Any) -> Any:
    """Run job ``name`` with ``args`` in the helper process and return its result (JobError if it failed)."""
    return _helper.call(name, *args)


def _running(process: BaseProcess) -> bool:
    """Whether the helper process still runs. ``is_alive()`` alone is not enough: when the pool's own thread
    reaped a dead helper first, this handle can no longer read its exit and still says alive."""
    if not process.is_alive() or process.pid is None:
        return False
    try:
        os.kill(process.pid, 0)  # signal 0: only asks whether the process exists
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True
