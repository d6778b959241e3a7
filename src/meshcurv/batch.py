"""Curvature of whole datasets: many mesh files at once, on a Dask cluster.

:func:`run` expands files, folders and glob patterns into a list of meshes,
computes the curvatures of each on a Dask cluster (a local one by default,
started and closed by the call, or an existing one given by its scheduler
address or a :class:`distributed.Client`), writes one result file per mesh
and returns a summary table, one row per mesh, that it also writes to
``OUT_DIR/summary.parquet`` and ``OUT_DIR/summary.csv``.

Paths travel to the workers, not arrays: each worker reads its own file and
writes its own result, so the inputs and ``OUT_DIR`` must be on storage that
the machine calling :func:`run` and every worker see under the same paths
(a local disk for a local cluster, a shared file system for a cluster).

Needs ``pip install 'meshcurv[batch]'`` (dask.distributed, pandas, pyarrow).

What is written (``OUT_DIR`` is created if needed):

- one result file per mesh, ``OUT_DIR/<name>.<output_format>``, holding the
  mesh and its curvature fields (:func:`meshcurv.io.write_curvatures`); inputs
  in several folders keep their folders below the deepest folder they share;
- a record per result in ``OUT_DIR/.meshcurv-batch/`` (its summary row, in
  JSON), so that a later run can skip the mesh and still report it;
- ``summary.parquet`` and ``summary.csv``, ordered by input path.

Every file is written under a temporary name and renamed when complete: a
result file that exists is complete, and a run that is interrupted or whose
worker dies leaves no partial file (see :func:`run`).
"""

from __future__ import annotations

import contextlib
import glob
import json
import logging
import os
import pathlib
import re
import time
import warnings
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ._validation import check_choice, check_int_option, check_positive_float
from .errors import InvalidOptionError, MeshFileError, MissingDependencyError
from .estimators import DEFAULT_METHOD

__all__ = ["run", "local_cluster", "process_mesh", "process_meshes", "expand_inputs", "COLUMNS", "SUMMARY_FIELDS", "OUTPUT_FORMATS", "RECORDS"]

logger = logging.getLogger(__name__)

#: The per-vertex fields summarised in each row (attributes of :class:`~meshcurv.CurvatureResult`).
SUMMARY_FIELDS = ("k_min", "k_max", "mean", "gaussian", "shape_index", "curvedness")

#: The statistics of each summarised field, over the valid vertices with a finite value.
STATISTICS = ("mean", "median", "p5", "p95")

#: The result file formats: those of :data:`meshcurv.io.FORMATS` that hold per-vertex fields.
OUTPUT_FORMATS = ("ply", "npz", "vtp", "vtu", "vtk", "csv")

#: The folder of ``OUT_DIR`` that holds one record (the summary row) per result file.
RECORDS = ".meshcurv-batch"

_SUMMARY_NAME = "summary"

#: The most bytes of input files sent to a worker as one task (a single larger mesh is a task of its
#: own). Dask costs a few milliseconds per task, and the process that schedules competes with the
#: workers for the cores: with a task per mesh of 10k vertices (30 ms of work), two workers on two
#: cores ran 1.1x as fast as one; in tasks of about 4 MiB (a few hundred milliseconds) the cost is shared.
CHUNK_BYTES = 4 * 2**20

#: The fewest tasks per worker when there are enough meshes, so that no worker waits for another's long task.
CHUNKS_PER_WORKER = 8

#: The columns of the summary, in order, with their pandas dtypes.
COLUMNS = {
    "path": "str",
    "status": "str",
    "n_vertices": "Int64",
    "n_faces": "Int64",
    "area": "float64",
    "volume": "float64",
    "euler_characteristic": "Int64",
    "n_components": "Int64",
    "n_boundary_loops": "Int64",
    **{f"{field}_{statistic}": "float64" for field in SUMMARY_FIELDS for statistic in STATISTICS},
    "n_invalid": "Int64",
    "seconds": "float64",
    "error": "str",
    "warnings": "str",
    "method": "str",
    "output": "str",
}

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

_GLOB_CHARACTERS = re.compile(r"[*?\[]")


def _readable_extensions() -> set[str]:
    from .io import FORMATS

    return {extension for extension, fmt in FORMATS.items() if fmt.read is not None}


def expand_inputs(inputs, *, exclude=None) -> list[pathlib.Path]:
    """The mesh files named by files, folders and glob patterns, sorted by path.

    Parameters
    ----------
    inputs : str, os.PathLike or sequence of them
        Files (kept whatever their extension: a file that cannot be read
        gets its error in the summary), folders (their mesh files, by the
        extensions of :data:`meshcurv.io.FORMATS` that can be read, not
        recursive, hidden files left out) and glob patterns (``*``, ``?``,
        ``[...]``; ``**`` crosses folders; mesh files only).
    exclude : str or os.PathLike, optional
        A folder whose files are never inputs (the output folder).

    Returns
    -------
    list of pathlib.Path
        Each file once, sorted by its path as a string.

    Raises
    ------
    MeshFileError
        An input that is neither a file, a folder nor a pattern that matches
        something; or nothing found at all.

    Examples
    --------
    >>> import meshcurv, pathlib, tempfile
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> for name in ("b.obj", "a.off", "notes.txt"):
    ...     _ = (folder / name).write_text("")
    >>> [path.name for path in expand_inputs([folder])]
    ['a.off', 'b.obj']
    """
    if isinstance(inputs, (str, os.PathLike)):
        inputs = [inputs]
    extensions = _readable_extensions()
    excluded = os.path.abspath(exclude) if exclude is not None else None
    found: dict[str, pathlib.Path] = {}

    def add(path: pathlib.Path) -> None:
        absolute = os.path.abspath(path)
        if excluded is not None and (absolute == excluded or absolute.startswith(excluded + os.sep)):
            return
        found.setdefault(absolute, path)

    for item in inputs:
        text = os.fspath(item)
        path = pathlib.Path(text)
        if path.is_dir():
            for child in sorted(path.iterdir()):
                if child.is_file() and not child.name.startswith(".") and child.suffix.lower() in extensions:
                    add(child)
        elif path.is_file():
            add(path)
        elif _GLOB_CHARACTERS.search(text):
            matches = [pathlib.Path(match) for match in glob.glob(text, recursive=True)]
            matches = [match for match in matches if match.is_file() and match.suffix.lower() in extensions]
            if not matches:
                raise MeshFileError(f"{text}: the pattern matches no mesh file")
            for match in matches:
                add(match)
        else:
            raise MeshFileError(f"{text}: no such file or folder")
    if not found:
        listed = ", ".join(os.fspath(item) for item in inputs) or "(none)"
        raise MeshFileError(f"no mesh file found in {listed} (mesh files end in {', '.join(sorted(extensions))})")
    return sorted(found.values(), key=os.fspath)


@dataclass(frozen=True)
class _Job:
    """One mesh of a batch: where it is read, written and recorded (absolute paths)."""

    path: pathlib.Path
    source: str
    output: str
    record: str


def _plan(paths: list[pathlib.Path], out_dir: pathlib.Path, suffix: str) -> list[_Job]:
    absolute = [pathlib.Path(os.path.abspath(path)) for path in paths]
    root = pathlib.Path(os.path.commonpath([path.parent for path in absolute]))
    out_dir = pathlib.Path(os.path.abspath(out_dir))
    jobs, claimed = [], {}
    reserved = {out_dir / f"{_SUMMARY_NAME}.csv": "the summary", out_dir / f"{_SUMMARY_NAME}.parquet": "the summary"}
    for path, source in zip(paths, absolute):
        relative = source.relative_to(root).with_suffix(suffix)
        output = out_dir / relative
        if output in reserved or output in claimed:
            other = reserved.get(output) or claimed[output]
            raise InvalidOptionError(
                f"{other} and {path} would both be written to {output}; "
                "give them different names or process them in separate runs"
            )
        claimed[output] = path
        record = out_dir / RECORDS / relative.with_name(relative.name + ".json")
        jobs.append(_Job(path, os.fspath(source), os.fspath(output), os.fspath(record)))
    return jobs


def _options(method, smoothing_steps, radius, orient) -> dict:
    """The options given, checked as :func:`meshcurv.principal_curvatures` checks them, defaults left out.

    The same computation is then recorded the same way however it was asked
    (``smoothing_steps=3`` or nothing), and a bad option fails before any work.
    """
    from .curvature import METHODS
    from .estimators import ESTIMATORS
    from .orient import ORIENT_CHOICES

    check_choice(method, "method", METHODS)
    defaults = ESTIMATORS[method].options
    options = {"method": method}
    for name, value in (("smoothing_steps", smoothing_steps), ("radius", radius)):
        if value is None:
            continue
        if name not in defaults:
            raise InvalidOptionError(f"method {method!r} does not take the option `{name}`")
        value = check_int_option(value, name) if name == "smoothing_steps" else check_positive_float(value, name)
        if value != defaults[name]:
            options[name] = value
    if orient is not None and check_choice(orient, "orient", ORIENT_CHOICES) != "keep":
        options["orient"] = orient
    return options


def _statistics(result) -> dict:
    row = {}
    for name in SUMMARY_FIELDS:
        values = np.asarray(getattr(result, name))[result.valid]
        values = values[np.isfinite(values)]
        if values.size:
            p5, median, p95 = np.percentile(values, [5, 50, 95])
            figures = {"mean": values.mean(), "median": median, "p5": p5, "p95": p95}
        else:
            figures = dict.fromkeys(STATISTICS, np.nan)
        row.update({f"{name}_{statistic}": float(figures[statistic]) for statistic in STATISTICS})
    return row


def _stale_temporaries(targets) -> list[pathlib.Path]:
    """Temporary files left beside ``targets`` by writes that never finished (a killed process).

    :func:`meshcurv.io._files.atomic_output` names them ``.<name>.<random><suffix>``
    in the folder of ``<name>``; a temporary of a temporary starts with
    ``..<name>.``. Each folder is listed once, however many targets it holds.
    """
    by_folder: dict[pathlib.Path, list[pathlib.Path]] = {}
    for target in targets:
        by_folder.setdefault(target.parent, []).append(target)
    found = []
    for folder, names in by_folder.items():
        try:
            hidden = [entry.name for entry in os.scandir(folder) if entry.name.startswith(".")]
        except (FileNotFoundError, NotADirectoryError):
            continue
        for target in names:
            prefixes = (f".{target.name}.", f"..{target.name}.")
            found.extend(folder / name for name in hidden
                         if name.startswith(prefixes) and name.endswith(target.suffix))
    return sorted(set(found))


def _write_record(path: pathlib.Path, record: dict) -> None:
    from .io._files import atomic_output

    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_output(path) as temporary:
        temporary.write_text(json.dumps(record, allow_nan=True))


def _read_record(path: pathlib.Path) -> dict | None:
    try:
        return json.loads(path.read_text())
    except (OSError, ValueError):
        return None


def process_mesh(source, output, record, *, method: str = DEFAULT_METHOD, smoothing_steps: int | None = None,
                 radius: float | None = None, orient: str | None = None) -> dict:
    """Compute the curvatures of one mesh file, write the result and its record, return its summary row.

    The task :func:`run` sends to the workers; it never raises for a bad mesh.
    The result file is written under a temporary name; the record is written
    before the result is renamed into place, so a result that exists always
    has its record. An older result at ``output`` is replaced.

    Parameters
    ----------
    source : str or os.PathLike
        The mesh file (any format :func:`meshcurv.read_mesh` reads).
    output : str or os.PathLike
        The result file; its extension picks the format (one of
        :data:`OUTPUT_FORMATS`). Its folder is created if needed.
    record : str or os.PathLike
        The JSON file that keeps the row, for later runs.
    method, smoothing_steps, radius, orient
        As in :func:`meshcurv.principal_curvatures`.

    Returns
    -------
    dict
        The summary row (the keys of :data:`COLUMNS` but ``path``), with
        ``status`` ``'computed'``, or ``'failed'`` and the ``error`` (its type
        and message) when the mesh could not be read, computed or written.
    """
    from .curvature import principal_curvatures
    from .io import read_mesh, write_curvatures
    from .io._files import atomic_output

    start = time.perf_counter()
    source, output, record = pathlib.Path(source), pathlib.Path(output), pathlib.Path(record)
    options = {"smoothing_steps": smoothing_steps, "radius": radius, "orient": orient}
    options = {name: value for name, value in options.items() if value is not None}
    row = {"status": "computed", "error": "", "warnings": "", "method": method, "output": os.fspath(output)}
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            vertices, faces = read_mesh(source)
            result = principal_curvatures(vertices, faces, method=method, **options)
        facts = result.diagnosis
        row.update(
            n_vertices=facts.n_vertices, n_faces=facts.n_faces, area=facts.area,
            volume=np.nan if facts.volume is None else facts.volume,
            euler_characteristic=facts.euler_characteristic, n_components=facts.n_components,
            n_boundary_loops=facts.n_boundary_loops, n_invalid=int((~result.valid).sum()),
            warnings="; ".join(dict.fromkeys(str(warning.message) for warning in caught)),
        )
        row.update(_statistics(result))
        output.parent.mkdir(parents=True, exist_ok=True)
        with atomic_output(output) as temporary:
            write_curvatures(temporary, vertices, faces, result, overwrite=True, source=source)
            output.unlink(missing_ok=True)  # an older result must not outlive a newer record
            row["seconds"] = time.perf_counter() - start
            _write_record(record, {"row": row, "options": {"method": method, **options}})
    except Exception as exc:  # one bad mesh never sinks the batch: its row says what went wrong
        row = {"status": "failed", "error": f"{type(exc).__name__}: {exc}", "warnings": "", "method": method,
               "output": "", "seconds": time.perf_counter() - start}
        logger.info("%s failed: %s", source, row["error"])
    return row


def process_meshes(sources, outputs, records, **options) -> list[dict]:
    """:func:`process_mesh` on several meshes in turn (one Dask task); their rows, in order."""
    return [process_mesh(source, output, record, **options)
            for source, output, record in zip(sources, outputs, records, strict=True)]


def _dependencies():
    try:
        import distributed
        import pandas
        import pyarrow  # noqa: F401 (the Parquet writer of pandas)
    except ImportError as exc:
        raise MissingDependencyError(
            f"meshcurv.batch needs {exc.name or 'dask.distributed, pandas and pyarrow'}: "
            "pip install 'meshcurv[batch]'"
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
    workers keep to N cores; they ignore Ctrl-C (the caller closes them). Dask
    normally starts its workers with ``MALLOC_TRIM_THRESHOLD_=65536``, which
    makes glibc hand every large array back to the system when freed: meshcurv
    allocates many, and each mesh then takes about twice as long; this cluster
    leaves the variable unset (glibc's own adaptive threshold), unless it is
    set in the environment. It sets ``MALLOC_ARENA_MAX=1``: the task runs in a
    thread of its worker, and glibc's per-thread arenas made each mesh about 7%
    slower there than in a main thread. It turns Dask's statistical profiler
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

    n_workers = CPU_COUNT if workers is None else check_int_option(workers, "workers", minimum=1)
    saved = dict(os.environ)
    try:
        with dask.config.set(WORKER_CONFIG), \
                distributed.LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=True,
                                         host="127.0.0.1", dashboard_address="127.0.0.1:0",
                                         scheduler_kwargs={"dashboard": dashboard},
                                         env=dict(WORKER_ENVIRONMENT), preload=["meshcurv._batch_worker"],
                                         silence_logs=logging.ERROR) as cluster, \
                distributed.Client(cluster) as client:
            yield client
    finally:
        for name in set(os.environ) - set(saved):
            del os.environ[name]
        os.environ.update({name: value for name, value in saved.items() if os.environ.get(name) != value})


@contextlib.contextmanager
def _cluster(distributed, *, client, scheduler, workers):
    """Yield ``(client, owned)``: the given client, one connected to ``scheduler``, or a new local cluster's."""
    if client is not None:
        yield client, False
    elif scheduler is not None:
        with distributed.Client(scheduler) as connected:
            yield connected, False
    else:
        with local_cluster(workers=workers) as local:
            yield local, True


def _dashboard(client) -> str | None:
    try:
        return client.dashboard_link if "dashboard" in client.scheduler_info().get("services", {}) else None
    except Exception:  # no dashboard is not a reason to stop
        return None


def run(paths, out_dir, *, method: str = DEFAULT_METHOD, smoothing_steps: int | None = None,
        radius: float | None = None, orient: str | None = None, output_format: str = "ply", client=None,
        scheduler: str | None = None, workers: int | None = None, overwrite: bool = False,
        progress: Callable[[int, int, int], None] | None = None):
    """Compute the curvatures of many mesh files on a Dask cluster and summarise them.

    Parameters
    ----------
    paths : str, os.PathLike or sequence of them
        Mesh files, folders and glob patterns (see :func:`expand_inputs`).
        Files inside ``out_dir`` are never inputs.
    out_dir : str or os.PathLike
        The folder of the results and the summary; created if needed.
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
        (with its record) is skipped: its row is the one recorded then.
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
        the valid vertices (``mean_median`` is the median of the mean
        curvature H); the number of invalid vertices; the seconds the mesh
        took; the error (its type and message) of a failed mesh, the warnings
        of the computation, the method and the result file. The same table is
        written to ``out_dir/summary.parquet`` and ``out_dir/summary.csv``
        (replaced at each run, written atomically).

    Raises
    ------
    MeshFileError
        An input that does not exist or matches nothing; a result file that
        exists but was not written by a batch (no record) without ``overwrite``.
    InvalidOptionError
        Bad options; two inputs that would write the same result; results of
        another method or options in ``out_dir`` without ``overwrite``.
    MissingDependencyError
        dask.distributed, pandas or pyarrow is not installed.

    Notes
    -----
    One bad file never stops the batch: its row has status ``'failed'`` and
    the error. When a worker process dies (killed, out of memory), Dask runs
    its task again on another worker. A task that has killed
    ``distributed.scheduler.allowed-failures`` + 1 workers (3 + 1 by default)
    is split into one task per mesh, and a mesh whose own task kills that many
    workers is reported as failed: the meshes that shared its task are not. Files are written under temporary names and renamed
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
    if workers is not None:
        if client is not None or scheduler is not None:
            raise InvalidOptionError("`workers` sizes the local cluster; it cannot be used with `client` or `scheduler`")
        workers = check_int_option(workers, "workers", minimum=1)
    options = _options(method, smoothing_steps, radius, orient)
    out_dir = pathlib.Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise MeshFileError(f"{out_dir}: is a file; the output must be a folder")
    jobs = _plan(expand_inputs(paths, exclude=out_dir), out_dir, "." + output_format)
    out_dir.mkdir(parents=True, exist_ok=True)

    rows: dict[int, dict] = {}
    todo = []
    for index, job in enumerate(jobs):
        stored = _completed(job, options, overwrite=overwrite)
        if stored is None:
            todo.append(index)
        else:
            rows[index] = {**stored, "status": "skipped", "output": job.output}
    failed = 0
    if progress is not None:
        progress(len(rows), len(jobs), failed)
    logger.info("%d meshes: %d to compute, %d already done", len(jobs), len(todo), len(rows))

    if todo:
        owned = False
        try:
            with _cluster(distributed, client=client, scheduler=scheduler, workers=workers) as (active, owned):
                logger.info("Dask dashboard: %s", _dashboard(active) or "none (pip install bokeh to have one)")
                chunks = _chunks(jobs, todo, workers=_worker_count(active))
                logger.info("%d meshes in %d tasks", len(todo), len(chunks))
                pending = _submit(active, jobs, chunks, options)
                try:
                    while pending:
                        outcomes = distributed.as_completed(list(pending), with_results=True, raise_errors=False)
                        retry = []
                        for future, outcome in outcomes:
                            chunk = pending.pop(future)
                            if future.status == "error":  # Dask gives (type, exception, traceback)
                                outcome = outcome[1]
                            future.release()
                            if isinstance(outcome, distributed.KilledWorker) and len(chunk) > 1:
                                # a mesh of the chunk kills its workers: run each alone, so that only it fails
                                logger.info("a task of %d meshes killed its workers; running them one by one",
                                            len(chunk))
                                retry.extend([index] for index in chunk)
                                continue
                            for index, row in zip(chunk, _rows(outcome, chunk, distributed)):
                                rows[index] = row
                                failed += row["status"] == "failed"
                            if progress is not None:
                                progress(len(rows), len(jobs), failed)
                        pending = _submit(active, jobs, retry, options)
                except BaseException:
                    active.cancel(list(pending))
                    raise
                if not owned:  # every task has ended: what a dead worker left half-written can go
                    _remove_temporaries(jobs, todo)
        finally:
            if owned:  # the local workers are gone (also after an interruption)
                _remove_temporaries(jobs, todo)

    summary = _summary(pandas, jobs, rows)
    _write_summary(summary, out_dir)
    return summary


def _completed(job: _Job, options: dict, *, overwrite: bool) -> dict | None:
    """The recorded row of a mesh whose result exists, or None when it is to be computed."""
    output, record = pathlib.Path(job.output), pathlib.Path(job.record)
    if overwrite or not output.exists():
        return None
    stored = _read_record(record)
    if stored is None:
        raise MeshFileError(
            f"{output}: exists but was not written by meshcurv batch (no record in {record.parent}); "
            "pass overwrite=True (--overwrite) to replace it, or choose another output folder"
        )
    if stored.get("options") != options:
        raise InvalidOptionError(
            f"{output}: holds results computed with {_describe(stored.get('options'))}, not "
            f"{_describe(options)}; pass overwrite=True (--overwrite) to recompute, or choose another output folder"
        )
    return stored["row"]


def _describe(options) -> str:
    return ", ".join(f"{name}={value!r}" for name, value in (options or {}).items()) or "unknown options"


def _worker_count(client) -> int:
    try:
        return max(1, len(client.scheduler_info().get("workers", {})))
    except Exception:  # an unusual scheduler: chunk as for one worker
        return 1


def _chunks(jobs: list[_Job], indices: list[int], *, workers: int) -> list[list[int]]:
    """The meshes ``indices`` cut into tasks: runs of consecutive meshes, in path order.

    The meshes are first shared out evenly into :data:`CHUNKS_PER_WORKER`
    runs per worker (fewer when there are fewer meshes), so that the workers
    finish together; a run is then cut where its input files pass
    :data:`CHUNK_BYTES` (one mesh at least per task), so that large meshes go
    one by one.
    """
    runs = np.array_split(np.asarray(indices, dtype=np.int64), min(len(indices), CHUNKS_PER_WORKER * workers))
    chunks = []
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


def _submit(client, jobs: list[_Job], chunks: list[list[int]], options: dict) -> dict:
    """Send each chunk to the cluster as one task; the futures, mapped to their chunks."""
    if not chunks:
        return {}
    futures = client.map(process_meshes, [[jobs[index].source for index in chunk] for chunk in chunks],
                         [[jobs[index].output for index in chunk] for chunk in chunks],
                         [[jobs[index].record for index in chunk] for chunk in chunks], pure=False, **options)
    return dict(zip(futures, chunks))


def _rows(outcome, chunk: list[int], distributed) -> list[dict]:
    """The rows of a finished task: its own, or one failed row per mesh when the task itself was lost."""
    if not isinstance(outcome, BaseException):
        return outcome
    if isinstance(outcome, distributed.KilledWorker):
        error = f"KilledWorker: every worker that ran this mesh died ({outcome})"
    else:
        error = f"{type(outcome).__name__}: {outcome}"
    return [{"status": "failed", "error": error, "warnings": "", "output": ""} for _ in chunk]


def _remove_temporaries(jobs: list[_Job], indices: list[int]) -> None:
    targets = [pathlib.Path(path) for index in indices for path in (jobs[index].output, jobs[index].record)]
    for temporary in _stale_temporaries(targets):
        logger.info("removing %s, left by an interrupted write", temporary)
        temporary.unlink(missing_ok=True)


def _summary(pandas, jobs: list[_Job], rows: dict[int, dict]):
    records = [{**rows[index], "path": os.fspath(job.path)} for index, job in enumerate(jobs)]
    frame = pandas.DataFrame.from_records(records, columns=list(COLUMNS))
    for name, dtype in COLUMNS.items():
        if dtype == "str":
            frame[name] = frame[name].fillna("").astype(str)
        else:
            frame[name] = frame[name].astype(dtype)
    return frame


def _write_summary(summary, out_dir: pathlib.Path) -> None:
    from .io._files import atomic_output

    for suffix in (".parquet", ".csv"):
        path = out_dir / f"{_SUMMARY_NAME}{suffix}"
        with atomic_output(path) as temporary:
            if suffix == ".parquet":
                summary.to_parquet(temporary, index=False)
            else:
                summary.to_csv(temporary, index=False)
        logger.info("wrote %s", path)
