"""A request answered before is answered from the reply cache of the app's process
(rns_viz.live.jobs.helper), without the helper process: one computation for two requests, each caller
its own copy of the same result, failures computed each time, and the least recently used replies leave
first once the byte budget is spent."""

from __future__ import annotations

import pickle
import threading
from collections.abc import Iterator

import numpy as np
import pytest

from rns_viz.live.jobs import helper as jobs
from rns_viz.model import FsmsModel


@pytest.fixture
def computed(monkeypatch: pytest.MonkeyPatch) -> Iterator[list[str]]:
    """The names of the jobs this test's thread sent to the helper process, an empty cache to start with.
    (Only this thread's: in the suite's worker, a session an earlier test stopped may still have a request
    waiting for the helper, which it sends during this test.)"""
    sent: list[str] = []
    run = jobs._Helper._run
    ours = threading.current_thread()

    def counting(helper: jobs._Helper, name: str, request: bytes) -> bytes:
        if threading.current_thread() is ours:
            sent.append(name)
        return run(helper, name, request)

    monkeypatch.setattr(jobs._Helper, "_run", counting)
    monkeypatch.setattr(jobs._helper, "cache", jobs.ReplyCache())
    yield sent


def test_a_repeated_request_is_computed_once_and_each_caller_gets_its_own_copy(
    computed: list[str], trep: FsmsModel
) -> None:
    seed = trep.spec.default_configuration
    first = jobs.call("path_table", "trep", seed)
    second = jobs.call("path_table", "trep", seed)
    assert computed == ["path_table"]
    assert pickle.dumps(first) == pickle.dumps(second)  # the same reply ...
    assert second is not first and second.theta is not first.theta  # ... unpickled for each caller
    fresh = jobs.path_table("trep", seed)
    assert np.array_equal(second.theta, fresh.theta) and np.array_equal(second.sigma, fresh.sigma)

    # Another seed is another request: computed, not served from the first.
    jobs.call("path_table", "trep", seed + 0.01)
    assert computed == ["path_table"] * 2


def test_a_failed_request_is_computed_again(computed: list[str]) -> None:
    for _ in range(2):
        with pytest.raises(jobs.JobError, match="no-such-model"):
            jobs.call("path_table", "no-such-model", np.zeros(3))
    assert computed == ["path_table"] * 2


def test_an_unknown_job_is_refused_in_this_process(computed: list[str]) -> None:
    with pytest.raises(jobs.JobError, match="no job named 'path_tabel'"):
        jobs.call("path_tabel", "trep", np.zeros(2))
    assert computed == []


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
