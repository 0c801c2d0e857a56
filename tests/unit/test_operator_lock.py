"""The operator lock: one operator at a time, passed on when it leaves, password when set."""

from __future__ import annotations

import threading

import pytest

from rns_viz.live.operator.operator_lock import LockRefused, OperatorLock


def test_first_client_operates_and_control_passes_on_in_order_of_arrival() -> None:
    lock = OperatorLock()
    assert lock.connect(1) and not lock.connect(2) and not lock.connect(3)
    assert lock.is_operator(1) and lock.status(1) == "You are operating"
    assert lock.status(2) == "Watching — client 1 is operating"
    assert lock.disconnect(1) == 2 and lock.is_operator(2)
    assert lock.disconnect(3) is None and lock.is_operator(2)  # a watcher leaving changes nothing
    assert lock.disconnect(2) is None and lock.operator is None
    assert lock.connect(4)  # nobody operates: the newcomer does


def test_take_and_release() -> None:
    lock = OperatorLock()
    lock.connect(1)
    lock.connect(2)
    lock.take(2)
    assert lock.is_operator(2) and not lock.is_operator(1)
    lock.release(1)  # not the operator: nothing happens
    assert lock.is_operator(2)
    lock.release(2)
    assert lock.operator is None and lock.status(1) == "Watching — nobody is operating"
    with pytest.raises(LockRefused):
        lock.take(99)  # not connected


def test_password_is_needed_to_operate() -> None:
    lock = OperatorLock("s3cret")
    assert not lock.connect(1) and lock.operator is None
    with pytest.raises(LockRefused, match="password"):
        lock.take(1)
    with pytest.raises(LockRefused):
        lock.take(1, "wrong")
    assert not lock.authenticate(1, "wrong") and lock.operator is None
    lock.take(1, "s3cret")
    assert lock.is_operator(1)
    lock.connect(2)
    assert lock.disconnect(1) is None and lock.operator is None  # client 2 never gave the password
    assert lock.authenticate(2, "s3cret") and lock.is_operator(2)


def test_concurrent_requests_leave_exactly_one_operator() -> None:
    lock = OperatorLock()
    for c in range(16):
        lock.connect(c)
    version = lock.version

    def grab(c: int) -> None:
        for _ in range(200):
            lock.take(c)
            lock.release(c)
            lock.take(c)

    threads = [threading.Thread(target=grab, args=(c,)) for c in range(16)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert lock.operator in range(16) and lock.version > version
    assert sum(lock.is_operator(c) for c in range(16)) == 1
