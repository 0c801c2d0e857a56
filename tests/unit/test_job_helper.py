"""The helper process of rns_viz.live.jobs.helper: a helper that died is started again, its caller told
in a clear error rather than left waiting; stopping does not wait for a job in flight; and a script
without a ``__main__`` guard can use it (the spawned helper does not run the script's top level again)."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from rns_viz.live.jobs import helper as jobs
from rns_viz.live.jobs.worker import Worker
from rns_viz.model import FsmsModel


@pytest.fixture
def helper() -> Iterator[jobs._Helper]:
    """A helper of its own (the process-wide one stays up for the other tests)."""
    own = jobs._Helper()
    yield own
    own.kill()


def test_a_helper_that_died_while_idle_is_started_again_for_the_next_job(helper: jobs._Helper) -> None:
    assert len(helper.call("family_curves", "trep", 1)) == 1
    (process,) = helper.processes
    process.kill()
    process.join(10.0)
    # the pool's own thread may reap it first, and then this handle still says is_alive(): the helper asks the OS
    deadline = time.monotonic() + 60.0
    while jobs._running(process) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not jobs._running(process), "the helper outlived SIGKILL for 60 s"
    assert len(helper.call("family_curves", "trep", 2)) == 2  # a new helper, the job done there
    assert helper.processes and helper.processes[0] is not process


@pytest.mark.skipif(not hasattr(os, "getpriority"), reason="Unix scheduling priorities")
def test_the_helper_runs_below_the_apps_priority(helper: jobs._Helper) -> None:
    assert len(helper.call("family_curves", "trep", 1)) == 1
    (process,) = helper.processes
    ours = os.getpriority(os.PRIO_PROCESS, 0)
    assert os.getpriority(os.PRIO_PROCESS, process.pid) == min(19, ours + jobs.HELPER_NICENESS)


def test_a_helper_that_dies_during_a_job_fails_that_job_and_the_next_one_runs(
    helper: jobs._Helper, boom7: FsmsModel
) -> None:
    helper.call("family_curves", "trep", 1)  # the helper is up
    thetas = boom7.spec.default_configuration + np.outer(np.linspace(0.0, 0.4, 400), np.ones(boom7.n))
    failures: list[Exception] = []

    def sweep() -> None:
        try:
            helper.call("linear_loops", "boom7", "acceleration", thetas)  # seconds of work
        except jobs.JobError as exc:
            failures.append(exc)

    caller = threading.Thread(target=sweep)
    caller.start()
    deadline = time.monotonic() + 60.0
    while not helper.busy and time.monotonic() < deadline:
        time.sleep(0.01)
    assert helper.busy
    helper.processes[0].kill()
    caller.join(30.0)
    assert not caller.is_alive()  # the caller was answered, not left waiting
    (failure,) = failures
    assert "died while running linear_loops" in str(failure)
    assert len(helper.call("family_curves", "trep", 1)) == 1


def test_stopping_does_not_wait_for_the_job_in_flight(
    helper: jobs._Helper, boom7: FsmsModel, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(jobs, "_helper", helper)  # what jobs.call uses
    helper.call("family_curves", "trep", 1)  # the helper is up
    thetas = boom7.spec.default_configuration + np.outer(np.linspace(0.0, 0.4, 400), np.ones(boom7.n))
    worker = Worker()
    worker.submit("sweep", 0, lambda: jobs.call("linear_loops", "boom7", "acceleration", thetas))
    deadline = time.monotonic() + 60.0
    while not helper.busy and time.monotonic() < deadline:
        time.sleep(0.01)
    assert helper.busy
    worker.stop()
    assert helper.busy and not worker.collect()  # stop returned while the job was still in the helper


def test_a_script_without_a_main_guard_gets_its_jobs_done(tmp_path: Path) -> None:
    script = tmp_path / "unguarded.py"
    script.write_text(
        textwrap.dedent(
            """
            from rns_viz.live.jobs import helper as jobs

            print("top level", flush=True)
            print(len(jobs.call("family_curves", "trep", 3)), "curves", flush=True)
            """
        )
    )
    result = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stdout.split("\n") == ["top level", "3 curves", ""]  # the top level ran once
