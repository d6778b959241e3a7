"""The batch itself: :func:`run` plans the meshes, skips those recorded, runs the others, writes the summary.

See :mod:`meshcurv.batch` for what is written where.
"""

from __future__ import annotations

import contextlib
import functools
import logging
import os
import pathlib
import tempfile
import uuid
import warnings
from collections.abc import Callable

import numpy as np

from .._validation import check_choice, check_int_option, check_positive_float
from ..errors import InvalidOptionError, MeshcurvWarning, MeshFileError
from ..estimators import DEFAULT_METHOD
from ._driver import MAX_WORKERS, _dashboard, _dependencies, _worker_count, cluster, run_tasks
from ._inputs import OUTPUT_FORMATS, RECORDS, _Job, _options, _plan, expand_inputs
from ._process import process_meshes
from ._records import _read_record, _record_failure, _remove_temporaries, _unchanged, _Unreadable, fingerprint
from ._summary import _ADDED_COLUMNS, _summary, _write_summary

logger = logging.getLogger(__name__)

#: The default time limit of one mesh, in seconds (``timeout`` of :func:`run`, ``--timeout``): far beyond
#: what a large mesh takes, so that only a mesh that never ends reaches it.
DEFAULT_TIMEOUT = 3600.0

#: The most bytes of input files sent to a worker as one task (a single larger mesh is a task of its
#: own), so that Dask's cost per task is shared by several meshes.
CHUNK_BYTES = 4 * 2**20

#: The fewest tasks per worker when there are enough meshes, so that no worker waits for another's long task.
CHUNKS_PER_WORKER = 8


def run(
    paths,
    out_dir,
    *,
    method: str = DEFAULT_METHOD,
    smoothing_steps: int | None = None,
    radius: float | None = None,
    orient: str | None = None,
    output_format: str = "ply",
    client=None,
    scheduler: str | None = None,
    workers: int | None = None,
    overwrite: bool = False,
    timeout: float | None = DEFAULT_TIMEOUT,
    retry_failed: bool = False,
    progress: Callable[[int, int, int], None] | None = None,
):
    """Compute the curvatures of many mesh files on a Dask cluster and summarise them.

    Parameters
    ----------
    paths : str, os.PathLike or sequence of them
        Mesh files, folders and glob patterns (see :func:`expand_inputs`).
        Files inside ``out_dir`` are never inputs: those of folders and
        patterns are left out, a file or folder named there is an error;
        ``out_dir`` is compared by real identity (a symbolic link to an input
        folder, ``IN/.``, a bind mount are the same folder).
    out_dir : str or os.PathLike
        The folder of the results and the summary; created if needed, and
        checked writable (a file created and removed) before any work.
    method : str, default: 'icc'
        Any of :data:`meshcurv.METHODS`.
    smoothing_steps, radius, orient : optional
        As in :func:`meshcurv.principal_curvatures` (checked before anything runs).
    output_format : {'ply', 'npz', 'vtp', 'vtu', 'vtk', 'csv'}, default: 'ply'
        The format of the result files (PLY, VTK and VTU need
        ``meshcurv[io]``, which the ``batch`` extra includes).
    client : distributed.Client, optional
        Run on the cluster of this client (left open).
    scheduler : str, optional
        The address of a running Dask scheduler (``'tcp://host:8786'``) to
        connect to, for the duration of the call.
    workers : int, optional
        The number of worker processes of the local cluster started when
        neither ``client`` nor ``scheduler`` is given (default: one per core),
        each with one thread (and ``OMP_NUM_THREADS``, ``NUMBA_NUM_THREADS``
        ... set to 1).
    overwrite : bool, default: False
        Compute every mesh again. By default a mesh whose result file exists
        (with its record) is skipped: its row is the one recorded then,
        unless the input has changed since (its size, mtime or content hash:
        :func:`fingerprint`). Whatever ``overwrite``, no result ever replaces
        an input file (checked by real identity: links, hard links, aliases).
    timeout : float or None, default: :data:`DEFAULT_TIMEOUT` (3600)
        The time limit of one mesh, in seconds (None: none). A mesh over it
        fails with the error ``timed out after N s``: its worker process is
        ended (nothing else can stop a reader or kernel that never returns)
        and started again by its nanny. Enforced on workers with a nanny (the
        local cluster's, ``dask worker``'s).
    retry_failed : bool, default: False
        Compute again the meshes that failed in an earlier run. By default a
        recorded failure is reported again (status ``'failed'``, its error)
        and not retried, so that a file that hangs or kills its workers costs
        one time limit, not one per run; a failed mesh whose input has
        changed since, or that timed out under a shorter ``timeout``, is
        always retried.
    progress : callable, optional
        Called as ``progress(done, total, failed)`` once before the first mesh
        (``done`` counts the skipped ones) and after each task: small meshes
        travel to the workers a few at a time (see :data:`CHUNK_BYTES`), so
        ``done`` may grow by more than one.

    Returns
    -------
    pandas.DataFrame
        One row per mesh, ordered by path, with the columns of
        :data:`COLUMNS`: ``path`` (as expanded from ``paths``), ``status``
        (``'computed'``, ``'skipped'`` or ``'failed'``), vertex and face
        counts, area, volume (closed meshes; NaN otherwise), Euler
        characteristic, components, boundary loops; for each of
        :data:`SUMMARY_FIELDS` the mean, median, 5th and 95th percentiles over
        the valid vertices, each vertex counting once (``mean_median`` is the
        per-vertex median of the mean curvature H), and the same weighted by
        the vertex areas (``mean_area_median``; each vertex counts by a third
        of its faces' area, independent of the sampling density); the integrals
        over the surface ``total_mean`` (int H dA), ``total_gaussian`` (int K
        dA, 2 pi chi on a closed mesh) and ``willmore`` (int H^2 dA over the
        valid vertices; see :meth:`meshcurv.CurvatureResult.integral`); the
        area-weighted columns and the integrals are NaN for point clouds;
        the number of invalid vertices; the seconds the mesh
        took; the error (its type and message) of a failed mesh, the warnings
        of the computation, the method and the result file. The same table is
        written to ``out_dir/summary.parquet`` and ``out_dir/summary.csv``
        (replaced at each run, written atomically).

    Raises
    ------
    MeshFileError
        An input that does not exist or matches nothing; an input inside
        ``out_dir``; a result or record that would be an input file; an
        ``out_dir`` that cannot be written; a result file that exists but was
        not written by a batch (no record) without ``overwrite``.
    InvalidOptionError
        Bad options; two inputs that would write the same result; results of
        another method or options in ``out_dir`` without ``overwrite``.
    NoWorkerError
        The cluster had no worker for :data:`NO_WORKER_SECONDS` (60 s on the
        local cluster, 600 s on another): the workers died and none could be
        started. What was computed is kept and recorded; the next run resumes.
    MissingDependencyError
        dask.distributed, pandas or pyarrow is not installed.

    Notes
    -----
    One bad file never stops the batch: its row has status ``'failed'`` and
    the error, and it is recorded (a later run reports it without trying
    again, see ``retry_failed``). When a worker process dies (killed, out of
    memory), Dask runs its task again on another worker; a mesh whose worker
    has died :data:`MAX_WORKER_DEATHS` (2) times while computing it fails
    with ``WorkerDied``, and the meshes that shared its task are computed. A
    task that has killed ``distributed.scheduler.allowed-failures`` + 1
    workers nonetheless (a lower setting) is split into one task per mesh,
    and a mesh whose own task kills that many workers is reported as failed
    (``KilledWorker``). A damaged record in ``out_dir/.meshcurv-batch`` (a
    run cut short, a full disk) is ignored with one warning, and its mesh
    computed again. When the summary files cannot be written at the end,
    the table is still returned (with a warning; its
    ``attrs["not_written"]`` says why). Files are written under temporary names and renamed
    when complete; temporaries left by a killed worker are removed when the
    batch ends. An interrupted call (KeyboardInterrupt) writes no summary; the
    next call resumes where it stopped.

    Examples
    --------
    Not run as a doctest (it starts a cluster)::

        import meshcurv, meshcurv.batch

        summary = meshcurv.batch.run("scans/*.ply", "results", workers=4)
        summary[["path", "area", "mean_median", "error"]]

        # the same meshes on a running cluster (dask scheduler / dask worker, SLURM, Kubernetes)
        summary = meshcurv.batch.run("scans/*.ply", "results", scheduler="tcp://head-node:8786")
    """
    distributed, pandas = _dependencies()
    check_choice(output_format, "output_format", OUTPUT_FORMATS)
    if client is not None and scheduler is not None:
        raise InvalidOptionError("give `client` or `scheduler`, not both")
    if scheduler is not None and not isinstance(scheduler, str) and not hasattr(scheduler, "scheduler_address"):
        raise InvalidOptionError(f"`scheduler` must be an address such as 'tcp://host:8786'; got {scheduler!r}")
    if progress is not None and not callable(progress):
        raise InvalidOptionError(f"`progress` must be a function of (done, total, failed); got {progress!r}")
    if workers is not None:
        if client is not None or scheduler is not None:
            raise InvalidOptionError(
                "`workers` sizes the local cluster; it cannot be used with `client` or `scheduler`"
            )
        workers = check_int_option(workers, "workers", minimum=1, maximum=MAX_WORKERS)
    if timeout is not None:
        timeout = check_positive_float(timeout, "timeout")
    options = _options(method, smoothing_steps, radius, orient)
    out_dir = pathlib.Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise MeshFileError(f"{out_dir}: is a file; the output must be a folder")
    jobs = _plan(expand_inputs(paths, exclude=out_dir), out_dir, "." + output_format)
    _check_writable(out_dir)

    rows: dict[int, dict] = {}
    todo: list[int] = []
    damaged: list[tuple[pathlib.Path, str]] = []
    for index, job in enumerate(jobs):
        stored = _completed(
            job, options, overwrite=overwrite, retry_failed=retry_failed, timeout=timeout, damaged=damaged
        )
        if stored is None:
            todo.append(index)
        else:
            rows[index] = stored
    if damaged:
        warnings.warn(
            f"{len(damaged)} records in {out_dir / RECORDS} cannot be read (cut short or corrupt: "
            f"{damaged[0][0].name}: {damaged[0][1]}); their meshes are computed again",
            MeshcurvWarning,
            stacklevel=2,
        )
    failed = sum(row["status"] == "failed" for row in rows.values())
    if progress is not None:
        progress(len(rows), len(jobs), failed)
    logger.info("%d meshes: %d to compute, %d already done", len(jobs), len(todo), len(rows))

    if todo:
        owned = False
        task_options = {**options, "timeout": timeout, "run_id": uuid.uuid4().hex}
        try:
            with cluster(client=client, scheduler=scheduler, workers=workers) as (active, owned):
                logger.info("Dask dashboard: %s", _dashboard(active) or "none (pip install bokeh to have one)")
                chunks = _chunks(jobs, todo, workers=_worker_count(active))
                logger.info("%d meshes in %d tasks", len(todo), len(chunks))
                # a task lost with its workers is split: a mesh that kills its workers then fails alone
                tasks = run_tasks(
                    active,
                    chunks,
                    functools.partial(_submit, active, jobs, options=task_options),
                    owned=owned,
                    split=lambda outcome: isinstance(outcome, distributed.KilledWorker),
                    items="meshes",
                )
                with contextlib.closing(tasks):
                    for chunk, outcome in tasks:
                        for index, row in zip(chunk, _rows(outcome, chunk, distributed), strict=True):
                            rows[index] = row
                            failed += row["status"] == "failed"
                            if isinstance(outcome, distributed.KilledWorker):
                                _record_lost(jobs[index], row, options, timeout)
                        if progress is not None:
                            progress(len(rows), len(jobs), failed)
                if not owned:  # every task has ended: what a dead worker left half-written can go
                    _remove_temporaries(jobs, todo)
        finally:
            if owned:  # the local workers are gone (also after an interruption)
                _remove_temporaries(jobs, todo)

    summary = _summary(pandas, jobs, rows)
    try:
        _write_summary(summary, out_dir)
    except OSError as exc:  # the rows are not lost with the files: the caller has them
        message = f"{out_dir}: the summary could not be written ({type(exc).__name__}: {exc})"
        summary.attrs["not_written"] = message
        warnings.warn(message, MeshcurvWarning, stacklevel=2)
    return summary


def _check_writable(out_dir: pathlib.Path) -> None:
    """Create ``out_dir`` and its records folder, and a file in each (removed): fail before any work."""
    for folder in (out_dir, out_dir / RECORDS):
        try:
            folder.mkdir(parents=True, exist_ok=True)
            handle, probe = tempfile.mkstemp(dir=folder, prefix=".meshcurv-probe.")
            os.close(handle)
            os.unlink(probe)
        except OSError as exc:
            raise MeshFileError(
                f"{folder}: cannot write the results there ({exc.strerror or exc}); nothing was computed"
            ) from None


def _record_lost(job: _Job, row: dict, options: dict, timeout) -> None:
    """Record a mesh whose task was lost (its workers killed), so that a later run does not retry it forever."""
    try:
        facts = fingerprint(job.source)
    except OSError:
        return
    _record_failure(pathlib.Path(job.record), row, options, facts, timeout)


def _completed(
    job: _Job,
    options: dict,
    *,
    overwrite: bool,
    retry_failed: bool,
    timeout: float | None,
    damaged: list[tuple[pathlib.Path, str]],
) -> dict | None:
    """The recorded row of a mesh that needs no work (status as recorded), or None when it is to be computed.

    A record that cannot be read is added to ``damaged`` (the mesh is computed
    again); a record whose input has changed since (:func:`fingerprint`) is
    ignored; a failure is reported again, not retried, unless ``retry_failed``
    or, for a mesh that timed out, a longer ``timeout``.
    """
    output, record = pathlib.Path(job.output), pathlib.Path(job.record)
    if overwrite:
        return None
    try:
        stored = _read_record(record)
    except _Unreadable as exc:
        damaged.append((record, str(exc)))
        return None
    if stored is None:
        if output.exists():
            raise MeshFileError(
                f"{output}: exists but was not written by meshcurv batch (no record in {record.parent}); "
                "pass overwrite=True (--overwrite) to replace it, or choose another output folder"
            )
        return None
    row = stored["row"]
    if row["status"] != "failed" and stored.get("options") != options and output.exists():
        raise InvalidOptionError(
            f"{output}: holds results computed with {_describe(stored.get('options'))}, not "
            f"{_describe(options)}; pass overwrite=True (--overwrite) to recompute, or choose another output folder"
        )
    if not _unchanged(job.source, stored.get("input")):
        logger.info("%s: changed since its result was recorded (or no fingerprint): computed again", job.path)
        return None
    missing = [column for column in _ADDED_COLUMNS if column not in row]
    if row["status"] != "failed" and missing:
        logger.info("%s: its record has no %s (an older meshcurv): computed again", job.path, ", ".join(missing))
        return None
    if row["status"] == "failed":
        if retry_failed or stored.get("options") != options:
            return None
        if row.get("error", "").startswith("TimeoutError") and _longer(timeout, stored.get("timeout")):
            return None
        return {**row, "output": ""}
    if not output.exists():
        return None
    return {**row, "status": "skipped", "output": job.output}


def _longer(timeout, before) -> bool:
    """Whether the time limit ``timeout`` (None: none) is longer than ``before``."""
    if timeout is None:
        return before is not None
    return before is not None and timeout > before


def _describe(options) -> str:
    return ", ".join(f"{name}={value!r}" for name, value in (options or {}).items()) or "unknown options"


def _chunks(jobs: list[_Job], indices: list[int], *, workers: int) -> list[list[int]]:
    """The meshes ``indices`` cut into tasks: runs of consecutive meshes, in path order.

    The meshes are first shared out evenly into :data:`CHUNKS_PER_WORKER`
    runs per worker (fewer when there are fewer meshes), so that the workers
    finish together; a run is then cut where its input files pass
    :data:`CHUNK_BYTES` (one mesh at least per task), so that large meshes go
    one by one.
    """
    runs = np.array_split(np.asarray(indices, dtype=np.int64), min(len(indices), CHUNKS_PER_WORKER * workers))
    chunks: list[list[int]] = []
    for run in runs:
        size = CHUNK_BYTES + 1
        for index in run.tolist():
            try:
                nbytes = os.path.getsize(jobs[index].source)
            except OSError:  # its task says what is wrong with it
                nbytes = 0
            if size + nbytes > CHUNK_BYTES:
                chunks.append([])
                size = 0
            chunks[-1].append(index)
            size += nbytes
    return chunks


def _submit(client, jobs: list[_Job], chunks: list[list[int]], *, options: dict) -> list:
    """Send each chunk to the cluster as one task (:func:`process_meshes`); their futures, in order."""
    return client.map(
        process_meshes,
        [[jobs[index].source for index in chunk] for chunk in chunks],
        [[jobs[index].output for index in chunk] for chunk in chunks],
        [[jobs[index].record for index in chunk] for chunk in chunks],
        pure=False,
        **options,
    )


def _rows(outcome, chunk: list[int], distributed) -> list[dict]:
    """The rows of a finished task: its own, or one failed row per mesh when the task itself was lost."""
    if not isinstance(outcome, BaseException):
        return outcome
    if isinstance(outcome, distributed.KilledWorker):
        error = f"KilledWorker: every worker that ran this mesh died (killed by the system: out of memory?) ({outcome})"
    else:
        error = f"{type(outcome).__name__}: {outcome}"
    return [{"status": "failed", "error": error, "warnings": "", "output": ""} for _ in chunk]
