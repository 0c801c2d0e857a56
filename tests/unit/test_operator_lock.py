"""The operator lock: one operator at a time, passed on when it leaves, password when set."""

from __future__ import annotations

import threading

import pytest

from rns_viz.live.operator.operator_lock import RELOAD_GRACE_S, LockRefused, OperatorLock


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


class Clock:
    """A wall clock the test moves by hand (s)."""

    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


def test_a_reloaded_operators_page_gets_control_back_within_the_grace() -> None:
    clock = Clock()
    lock = OperatorLock(clock=clock)
    lock.connect(1)
    lock.connect(2)
    lock.identify(1, "browser-a")
    lock.identify(2, "browser-b")
    assert lock.disconnect(1) is None and lock.operator is None  # kept for browser a, not passed to 2
    assert "reloading" in lock.status(2)
    assert not lock.connect(3) and lock.operator is None  # the reload's new connection, not identified yet
    clock.now = RELOAD_GRACE_S - 1.0
    assert lock.expire() is None
    assert lock.identify(3, "browser-a") and lock.is_operator(3)
    assert lock.expire() is None and lock.is_operator(3)


def test_a_kept_lock_passes_on_when_the_page_does_not_come_back() -> None:
    clock = Clock()
    lock = OperatorLock(clock=clock)
    lock.connect(1)
    lock.connect(2)
    lock.identify(1, "browser-a")
    lock.disconnect(1)
    clock.now = RELOAD_GRACE_S + 0.1
    assert lock.expire() == 2 and lock.is_operator(2)
    lock.connect(3)
    assert not lock.identify(3, "browser-a") and lock.is_operator(2)  # too late: 2 keeps control


def test_a_reload_that_arrives_before_the_old_page_leaves_operates_at_once() -> None:
    lock = OperatorLock()
    lock.connect(1)
    lock.connect(2)  # a watcher in another browser
    lock.identify(1, "browser-a")
    lock.connect(3)
    lock.identify(3, "browser-a")  # the reloaded page is here first
    assert lock.is_operator(1)
    assert lock.disconnect(1) == 3 and lock.is_operator(3)


def test_taking_control_ends_a_kept_lock_and_a_browser_keeps_its_password() -> None:
    lock = OperatorLock("s3cret")
    lock.connect(1)
    lock.identify(1, "browser-a")
    assert lock.authenticate(1, "s3cret") and lock.is_operator(1)
    lock.connect(2)
    lock.disconnect(1)
    lock.connect(3)
    assert lock.identify(3, "browser-a") and lock.is_operator(3)  # no password asked again after a reload
    lock.disconnect(3)
    with pytest.raises(LockRefused):
        lock.take(2)  # client 2 never gave the password
    lock.take(2, "s3cret")
    assert lock.is_operator(2) and "reloading" not in lock.status(2)
