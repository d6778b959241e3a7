"""The Dask driver of :mod:`meshcurv.batch` (and of the label images' parallel path).

One way to run groups of items as tasks on a Dask cluster, whatever the
items are (mesh files, label crops):

- :func:`cluster` yields a client: the caller's, one connected to a
  scheduler's address, or that of a new :func:`local_cluster` (closed at
  the end of the block);
- :func:`run_tasks` submits the groups (all at once, or a few ahead of the
  results), waits for them while watching that the cluster still has
  workers (:class:`NoWorkerError` after :data:`NO_WORKER_SECONDS`), runs
  each item of a failed group again as a task of its own, and yields
  ``(group, outcome)`` as each task ends; tasks still pending are cancelled
  when the caller stops.

What a task computes, how its items are grouped and what a failure means
for an item are the caller's.
"""

from __future__ import annotations

import collections
import contextlib
import logging
import os
import time
from collections.abc import Callable, Generator, Iterable
from typing import Any

from .._validation import check_int_option
from ..errors import MissingDependencyError

logger = logging.getLogger(__name__)

#: The most worker processes of a local cluster.
MAX_WORKERS = 1024

#: Seconds without any worker after which :func:`run_tasks` gives up (:class:`NoWorkerError`): on the local
#: cluster, whose nannies restart a dead worker within seconds, and on a cluster of one's own (whose
#: workers may wait in a queue of the batch system).
NO_WORKER_SECONDS = {"local": 60.0, "remote": 600.0}

#: How often :func:`run_tasks` looks at the cluster while it waits for results, in seconds.
_POLL_SECONDS = 1.0


class NoWorkerError(TimeoutError):
    """The cluster has had no worker for too long (they died and none could be started)."""


#: Environment of the worker processes of the local cluster: one thread each for
#: BLAS, OpenMP and numba, so that N workers use N cores and not N x N threads.
WORKER_ENVIRONMENT = {
    "OMP_NUM_THREADS": "1",
    "MKL_NUM_THREADS": "1",
    "OPENBLAS_NUM_THREADS": "1",
    "NUMBA_NUM_THREADS": "1",
}

#: Dask settings of the local cluster (see :func:`local_cluster`); on a cluster of one's own, a Dask
#: configuration file on the workers can hold the same.
WORKER_CONFIG = {
    # glibc variables, read when a process starts: Dask's MALLOC_TRIM_THRESHOLD_=65536 unset (glibc's
    # adaptive threshold), and one malloc arena, so that the task thread allocates as a main thread does
    "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None,
    "distributed.nanny.pre-spawn-environ.MALLOC_ARENA_MAX": 1,
    # the statistical profiler samples the task thread's stack every 10 ms: not needed for meshes
    "distributed.worker.profile.enabled": False,
}


def _dependencies():
    try:
        import distributed
        import pandas
        import pyarrow  # noqa: F401 (the Parquet writer of pandas)
    except ImportError as exc:
        raise MissingDependencyError(
            f"meshcurv.batch needs {exc.name or 'dask.distributed, pandas and pyarrow'}: pip install 'meshcurv[batch]'"
        ) from None
    return distributed, pandas


@contextlib.contextmanager
def local_cluster(*, workers: int | None = None, dashboard: bool = True):
    """Start the local Dask cluster :func:`run` starts, and close it at the end of the block.

    Pass its client to several :func:`run` calls to start the workers once
    (in a notebook, say).

    Parameters
    ----------
    workers : int, optional
        The number of worker processes (default: one per core), each with one
        thread.
    dashboard : bool, default: True
        Serve the Dask dashboard on 127.0.0.1 and a free port
        (``client.dashboard_link``). The scheduler's HTTP server (health
        checks) listens there in any case; without ``dashboard`` it does not
        serve the dashboard's pages.

    Yields
    ------
    distributed.Client
        A client of the cluster, listening on 127.0.0.1 only.

    Raises
    ------
    InvalidOptionError
        ``workers`` is not a positive integer.
    MissingDependencyError
        dask.distributed, pandas or pyarrow is not installed.

    Notes
    -----
    The worker processes get ``OMP_NUM_THREADS``, ``MKL_NUM_THREADS``,
    ``OPENBLAS_NUM_THREADS`` and ``NUMBA_NUM_THREADS`` set to 1, so that N
    workers keep to N cores; they ignore Ctrl-C (the caller closes them). Dask's
    ``MALLOC_TRIM_THRESHOLD_=65536`` is left unset (glibc's own adaptive
    threshold) unless set in the environment, ``MALLOC_ARENA_MAX=1`` is set,
    and Dask's statistical profiler is turned
    off (:data:`WORKER_CONFIG`). The variables Dask writes into ``os.environ`` of
    this process to start the workers are put back as they were on closing.

    Examples
    --------
    Not run as a doctest (it starts a cluster)::

        with meshcurv.batch.local_cluster(workers=2) as client:
            first = meshcurv.batch.run("scans/a/*.ply", "results/a", client=client)
            second = meshcurv.batch.run("scans/b/*.ply", "results/b", client=client)
    """
    distributed, _ = _dependencies()
    import dask
    from dask.system import CPU_COUNT

    n_workers = CPU_COUNT if workers is None else check_int_option(workers, "workers", minimum=1, maximum=MAX_WORKERS)
    saved = dict(os.environ)
    try:
        with (
            dask.config.set(WORKER_CONFIG),
            distributed.LocalCluster(
                n_workers=n_workers,
                threads_per_worker=1,
                processes=True,
                host="127.0.0.1",
                dashboard_address="127.0.0.1:0",
                scheduler_kwargs={"dashboard": dashboard},
                env=dict(WORKER_ENVIRONMENT),
                preload=["meshcurv._batch_worker"],
                silence_logs=logging.ERROR,
            ) as cluster,
            distributed.Client(cluster) as client,
        ):
            yield client
    finally:
        for name in set(os.environ) - set(saved):
            del os.environ[name]
        os.environ.update({name: value for name, value in saved.items() if os.environ.get(name) != value})


@contextlib.contextmanager
def cluster(
    *,
    client=None,
    scheduler: str | None = None,
    workers: int | None = None,
    dashboard: bool = True,
    config: dict | None = None,
):
    """The cluster to run on, for the duration of the block.

    Parameters
    ----------
    client : distributed.Client, optional
        Run on the cluster of this client (left open).
    scheduler : str, optional
        The address of a running scheduler, connected to for the block.
    workers : int, optional
        The worker processes of the local cluster started when neither
        ``client`` nor ``scheduler`` is given (:func:`local_cluster`).
    dashboard : bool, default: True
        Whether that local cluster serves the Dask dashboard.
    config : dict, optional
        Dask settings (``dask.config.set``) while that local cluster starts
        and runs.

    Yields
    ------
    client : distributed.Client
        The client to submit to.
    owned : bool
        True when the cluster is the local one started here (its workers
        end with the block); :func:`run_tasks` waits less for its workers.
    """
    if client is not None:
        yield client, False
        return
    distributed, _ = _dependencies()
    if scheduler is not None:
        with distributed.Client(scheduler) as connected:
            yield connected, False
        return
    import dask

    with dask.config.set(config or {}), local_cluster(workers=workers, dashboard=dashboard) as local:
        yield local, True


def _split_any(outcome: BaseException) -> bool:
    return True


def run_tasks(
    client,
    groups: Iterable[list],
    submit: Callable[[list[list]], list],
    *,
    owned: bool,
    limit: int | None = None,
    split: Callable[[BaseException], bool] = _split_any,
    items: str = "items",
) -> Generator[tuple[list, Any], None, None]:
    """Run each group of items as one task on the cluster of ``client``; yield each group as its task ends.

    Parameters
    ----------
    client : distributed.Client
        The client of the cluster (see :func:`cluster`).
    groups : iterable of list
        The items of each task, submitted in this order.
    submit : callable
        ``submit(some_groups)`` sends each group of the list ``some_groups``
        to the cluster as one task (``client.map`` or ``client.submit``,
        ``pure=False``) and returns their futures, in the same order.
    owned : bool
        Whether the cluster is the local one started for the caller (as
        :func:`cluster` yields): how long to wait without any worker
        (:data:`NO_WORKER_SECONDS`).
    limit : int, optional
        The most tasks in flight at once (None: every group submitted at
        once): the groups beyond it are submitted as tasks end, so that data
        sent with the tasks (crops of an image) is made and held only for
        the tasks in flight.
    split : callable, optional
        ``split(exception)`` for a task of several items that ended with an
        exception (raised by the task, :class:`distributed.KilledWorker`
        when its workers died): true to run each of its items again as a task
        of its own, at the head of the queue (that group is then not
        yielded). By default every failed task of several items is split.
    items : str, default: 'items'
        What the items are, for the log (``'meshes'``, ``'labels'``).

    Yields
    ------
    group : list
        The items of a task that has ended.
    outcome : object
        The task's result, or the exception it ended with (never raised
        here: what it means for the items is the caller's).

    Raises
    ------
    NoWorkerError
        The cluster had no worker for :data:`NO_WORKER_SECONDS`.

    Notes
    -----
    Tasks still pending are cancelled when the generator is closed
    (``contextlib.closing``: when the caller stops early or raises) and when
    waiting is interrupted (``KeyboardInterrupt``, :class:`NoWorkerError`).
    """
    import distributed

    queue = collections.deque(groups)
    watch = _WorkerWatch(client, NO_WORKER_SECONDS["local" if owned else "remote"])
    pending: dict = {}
    try:
        while queue or pending:
            room = len(queue) if limit is None else min(len(queue), limit - len(pending))
            if room > 0:
                chosen = [queue.popleft() for _ in range(room)]
                pending.update(zip(submit(chosen), chosen, strict=True))
            for future in _finished(distributed, list(pending), watch):
                group = pending.pop(future)
                outcome = _outcome(future)
                future.release()
                if isinstance(outcome, BaseException) and len(group) > 1 and split(outcome):
                    logger.info(
                        "a task of %d %s ended with %s; running them one by one",
                        len(group),
                        items,
                        type(outcome).__name__,
                    )
                    queue.extendleft([item] for item in reversed(group))
                    continue
                yield group, outcome
    finally:
        if pending:
            client.cancel(list(pending))


def _dashboard(client) -> str | None:
    try:
        return client.dashboard_link if "dashboard" in client.scheduler_info().get("services", {}) else None
    except Exception:  # no dashboard is not a reason to stop
        return None


class _WorkerWatch:
    """Notices a cluster left without workers, and says so after ``patience`` seconds of it."""

    def __init__(self, client, patience: float):
        self.client = client
        self.patience = patience
        self.since: float | None = None

    def check(self) -> None:
        try:
            count = len(self.client.nthreads())
        except Exception:  # the scheduler does not answer: as bad as no worker
            count = 0
        if count:
            self.since = None
            return
        now = time.monotonic()
        if self.since is None:
            self.since = now
            logger.warning("the cluster has no worker (they died?); waiting up to %s for one", _seconds(self.patience))
        elif now - self.since >= self.patience:
            raise NoWorkerError(
                f"the cluster has had no worker for {_seconds(self.patience)}: the workers died and none could be "
                "started (out of memory? see the worker logs); the meshes computed so far are kept, run again "
                "to resume"
            )


def _finished(distributed, futures: list, watch: _WorkerWatch) -> list:
    """The futures that have ended, waiting for at least one while watching the cluster's workers."""
    while True:
        done, _ = _wait_some(distributed, futures)
        if done:
            return list(done)
        watch.check()


def _wait_some(distributed, futures: list):
    try:
        return distributed.wait(futures, timeout=_POLL_SECONDS, return_when="FIRST_COMPLETED")
    except TimeoutError:
        return set(), set(futures)


def _outcome(future):
    """The result of a finished future, or the exception it ended with (errors and cancellations alike)."""
    try:
        return future.result()
    except Exception as exc:  # noqa: BLE001 (a task's error is its row, not ours)
        return exc


def _worker_count(client) -> int:
    try:
        return max(1, len(client.scheduler_info().get("workers", {})))
    except Exception:  # an unusual scheduler: chunk as for one worker
        return 1


def _seconds(value: float) -> str:
    return f"{value:g} s"
