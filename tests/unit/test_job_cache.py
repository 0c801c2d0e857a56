"""The helper process answers a request it has seen from its reply cache (rns_viz.live.jobs.helper): the same
bytes as computing it again, one computation for two requests, failures computed each time, and the
least recently used replies leave first once the byte budget is spent."""

from __future__ import annotations

import io
import pickle
from typing import Any

import numpy as np
import pytest

from rns_viz.live.jobs import helper as jobs
from rns_viz.model import FsmsModel


def framed(*requests: tuple[str, tuple[Any, ...]]) -> io.BytesIO:
    out = io.BytesIO()
    for request in requests:
        jobs._write(out, request)
    out.seek(0)
    return out


def replies(stream: io.BytesIO) -> list[bytes]:
    stream.seek(0)
    found = []
    while True:
        try:
            found.append(jobs._read_bytes(stream))
        except EOFError:
            return found


def test_a_repeated_request_is_computed_once_and_answered_with_the_same_bytes(
    monkeypatch: pytest.MonkeyPatch, trep: FsmsModel
) -> None:
    seed = trep.spec.default_configuration
    computed: list[str] = []

    def counting(name: str, real: Any) -> Any:
        def job(*args: Any) -> Any:
            computed.append(name)
            return real(*args)

        return job

    monkeypatch.setattr(jobs, "JOBS", {name: counting(name, f) for name, f in jobs.JOBS.items()})
    out = io.BytesIO()
    jobs.serve(framed(("path_table", ("trep", seed)), ("path_table", ("trep", seed))), out)
    first, second = replies(out)
    assert computed == ["path_table"]
    assert first == second
    ok, table = pickle.loads(second)
    fresh = jobs.path_table("trep", seed)
    assert ok and np.array_equal(table.theta, fresh.theta) and np.array_equal(table.sigma, fresh.sigma)

    # Another seed is another request: computed, not served from the first.
    out = io.BytesIO()
    jobs.serve(framed(("path_table", ("trep", seed)), ("path_table", ("trep", seed + 0.01))), out)
    assert computed == ["path_table"] * 3


def test_a_failed_request_is_computed_again() -> None:
    out = io.BytesIO()
    jobs.serve(framed(*[("path_table", ("no-such-model", np.zeros(3)))] * 2), out)
    answers = [pickle.loads(r) for r in replies(out)]
    assert [ok for ok, _ in answers] == [False, False]
    assert all("no-such-model" in text for _, text in answers)


def test_the_least_recently_used_reply_leaves_first_within_the_byte_budget() -> None:
    cache = jobs.ReplyCache(budget=300)
    cache.put(b"a", b"x" * 99)  # 100 bytes each, request and reply counted
    cache.put(b"b", b"x" * 99)
    cache.put(b"c", b"x" * 99)
    assert cache.get(b"a") is not None  # a is now the most recent
    cache.put(b"d", b"x" * 99)  # 400 > 300: b, the least recent, leaves
    assert cache.get(b"b") is None
    assert all(cache.get(k) is not None for k in (b"a", b"c", b"d"))
    cache.put(b"e", b"x" * 400)  # larger than the whole budget: not kept, nothing evicted for it
    assert cache.get(b"e") is None and cache.get(b"a") is not None
