"""The Dask driver of meshcurv.batch (``meshcurv.batch._driver``), on an in-process cluster of threads."""

import contextlib
import time

import pytest

distributed = pytest.importorskip("distributed")
pytest.importorskip("pandas")
pytest.importorskip("pyarrow")

from meshcurv.batch import _driver  # noqa: E402


@pytest.fixture(scope="module")
def client():
    with (
        distributed.LocalCluster(
            n_workers=1, threads_per_worker=2, processes=False, dashboard_address=":0", silence_logs=50
        ) as cluster,
        distributed.Client(cluster) as connected,
    ):
        yield connected


def total(items):
    """A task: the sum of its items; an item 13 raises, as a bad mesh or label would."""
    if 13 in items:
        raise ValueError("13 is bad")
    return sum(items)


def submitter(client, log):
    def submit(groups):
        log.append(len(groups))
        return client.map(total, groups, pure=False)

    return submit


def test_every_group_is_run_once_and_a_failed_group_is_split(client):
    log = []
    groups = [[1, 2], [3, 13, 4], [5]]
    tasks = _driver.run_tasks(client, groups, submitter(client, log), owned=True)
    with contextlib.closing(tasks):
        ended = list(tasks)
    results = {tuple(group): outcome for group, outcome in ended}
    # the failed group of three is run again item by item: only the bad item fails
    assert set(results) == {(1, 2), (5,), (3,), (13,), (4,)}
    assert results[(1, 2)] == 3 and results[(5,)] == 5 and results[(3,)] == 3 and results[(4,)] == 4
    assert isinstance(results[(13,)], ValueError) and "13 is bad" in str(results[(13,)])
    assert log[0] == 3  # without a limit, every group at once


def test_a_failure_the_caller_does_not_split_is_yielded_whole(client):
    tasks = _driver.run_tasks(client, [[3, 13]], submitter(client, []), owned=True, split=lambda outcome: False)
    with contextlib.closing(tasks):
        [(group, outcome)] = list(tasks)
    assert group == [3, 13] and isinstance(outcome, ValueError)


def test_a_limit_keeps_that_many_tasks_in_flight(client):
    log = []
    groups = [[value] for value in range(7)]
    tasks = _driver.run_tasks(client, groups, submitter(client, log), owned=True, limit=2)
    with contextlib.closing(tasks):
        ended = sorted(group[0] for group, _ in tasks)
    assert ended == list(range(7))
    assert log[0] == 2 and max(log) <= 2 and sum(log) == 7


def slow(items):
    """A task: the sum of its items, after a second per item above 1."""
    time.sleep(sum(item > 1 for item in items))
    return sum(items)


def test_closing_early_cancels_the_tasks_still_pending(client):
    seen = []

    def submit(groups):
        futures = client.map(slow, groups, pure=False)
        seen.extend(futures)
        return futures

    tasks = _driver.run_tasks(client, [[1], [2], [3]], submit, owned=True)
    with contextlib.closing(tasks):
        group, outcome = next(tasks)  # the quick one ends; the caller stops there
    assert group == [1] and outcome == 1
    # the two still running were cancelled: the scheduler forgets them though this test holds their futures
    pending = {seen[1].key, seen[2].key}
    deadline = time.monotonic() + 5
    while time.monotonic() < deadline and pending & set(client.run_on_scheduler(scheduler_keys)):
        time.sleep(0.05)
    assert not pending & set(client.run_on_scheduler(scheduler_keys))
    assert seen[1].status == seen[2].status == "cancelled"


def scheduler_keys(dask_scheduler):
    return list(dask_scheduler.tasks)


def test_cluster_passes_a_given_client_through_unowned(client):
    with _driver.cluster(client=client) as (active, owned):
        assert active is client and owned is False
