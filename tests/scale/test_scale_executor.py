"""The executor (speclight.scale): serial and on a real LocalCluster (2 workers, loopback).

References: the results are plain functions of the items (squares), so the expected outcome
of every item is known exactly; a worker killed mid-task must cost only its tasks, which Dask
re-runs (each item is reported exactly once, none lost).
"""

import os
import re
import signal
import time

import pytest

from speclight.errors import InputError
from speclight.scale import open_executor, worker_cache, worker_cached


def _square(x: int) -> int:
    if x == 3:
        raise ValueError("three is refused")
    return x * x


def _slow_pid(x: int) -> tuple[int, int]:
    time.sleep(0.3)
    return x * x, os.getpid()


def _threads(_: int) -> str | None:
    return os.environ.get("SPECLIGHT_RENDER_THREADS")


def _check_squares(outcomes: list) -> None:
    assert sorted(o.item for o in outcomes) == list(range(8))
    for o in outcomes:
        if o.item == 3:
            assert o.result is None and o.error == "ValueError: three is refused"
        else:
            assert o.error is None and o.result == o.item**2


def test_serial_runs_in_process_and_records_errors():
    with open_executor("none") as ex:
        assert ex.serial and ex.dashboard_link is None
        _check_squares(list(ex.run(_square, range(8))))


@pytest.fixture(scope="module")
def local():
    with open_executor("local", n_workers=2) as ex:
        yield ex


def test_local_cluster_same_outcomes_as_serial(local):
    assert not local.serial
    assert local.dashboard_link.startswith("http://127.0.0.1:")
    _check_squares(list(local.run(_square, list(range(8)))))
    # each worker's Dr.Jit pool gets its share of the cores (2 workers share them)
    share = str(max(1, (os.cpu_count() or 1) // 2))
    assert set(o.result for o in local.run(_threads, [0, 1, 2, 3])) == {share}


def test_killed_worker_costs_only_its_tasks(local):
    items = list(range(12))
    pids = list(local.client.run(os.getpid).values())
    outcomes = []
    for k, outcome in enumerate(local.run(_slow_pid, items)):
        outcomes.append(outcome)
        if k == 1:  # mid-run: the tasks in flight on that worker are lost with it
            os.kill(outcome.result[1], signal.SIGKILL)
    assert sorted(o.item for o in outcomes) == items  # each exactly once, none lost
    assert all(o.error is None and o.result[0] == o.item**2 for o in outcomes)
    local.client.wait_for_workers(2, timeout=60)  # the restart takes seconds under load
    new_pids = set(local.client.run(os.getpid).values())
    assert len(new_pids) == 2 and new_pids != set(pids)  # the nanny restarted it


def test_unreachable_scheduler_is_an_input_error():
    with pytest.raises(InputError, match=re.escape("--scheduler = 'tcp://127.0.0.1:9'")):
        with open_executor("tcp://127.0.0.1:9", connect_timeout_s=1):
            pass


def test_worker_cache_builds_once_and_forgets_the_oldest():
    worker_cache.clear()
    built = []
    for key in ["a", "a", "b", "a", "c", "d", "e", "a", "b"]:
        worker_cached(key, lambda key=key: built.append(key) or key)
    # 4 entries: "e" pushes out "b" (least recently used), not "a" (used after "b")
    assert built == ["a", "b", "c", "d", "e", "b"]
    worker_cache.clear()
