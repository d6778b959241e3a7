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
- a record per mesh in ``OUT_DIR/.meshcurv-batch/`` (its summary row, the
  options and the input's :func:`fingerprint`, in JSON), so that a later run
  can skip the mesh and still report it, and notice an input changed since;
  failures are recorded too (a later run reports them without trying again,
  unless asked); a damaged record is ignored (its mesh computed again);
- ``summary.parquet`` and ``summary.csv``, ordered by input path.

``OUT_DIR`` is kept apart from the inputs: an input in it (under any name:
links, ``..``, bind mounts) is refused or, matched by a folder or pattern,
left out, and no result or record is ever written over an input file. Each
mesh has a time limit (``timeout``, one hour by default), and a mesh whose
workers keep dying fails alone (see :func:`run`).

Every file is written under a temporary name and renamed when complete: a
result file that exists is complete, and a run that is interrupted or whose
worker dies leaves no partial file (see :func:`run`).
"""

from __future__ import annotations

import contextlib
import faulthandler
import glob
import hashlib
import json
import logging
import os
import pathlib
import re
import tempfile
import threading
import time
import uuid
import warnings
from dataclasses import dataclass
from collections.abc import Callable
from typing import Any

import numpy as np

from ._validation import check_choice, check_int_option, check_positive_float
from .errors import InvalidOptionError, MeshcurvWarning, MeshFileError, MissingDependencyError
from .estimators import DEFAULT_METHOD

__all__ = ["run", "local_cluster", "process_mesh", "process_meshes", "expand_inputs", "fingerprint", "COLUMNS",
           "SUMMARY_FIELDS", "OUTPUT_FORMATS", "RECORDS", "DEFAULT_TIMEOUT", "NoWorkerError"]

logger = logging.getLogger(__name__)

#: The per-vertex fields summarised in each row (attributes of :class:`~meshcurv.CurvatureResult`).
SUMMARY_FIELDS = ("k_min", "k_max", "mean", "gaussian", "shape_index", "curvedness")

#: The per-vertex statistics of each summarised field, over the valid vertices with a finite value
#: (each vertex counts once: they depend on the sampling density), as ``<field>_<statistic>``.
STATISTICS = ("mean", "median", "p5", "p95")

#: The area-weighted statistics of each summarised field (each vertex counts by its vertex area,
#: :attr:`meshcurv.CurvatureResult.vertex_areas`), as ``<field>_area_<statistic>``; NaN for point clouds.
AREA_STATISTICS = ("mean", "median", "p5", "p95")

#: The integrals over the surface (:meth:`meshcurv.CurvatureResult.integral`): column -> field.
#: ``willmore`` is over the valid vertices. NaN for point clouds.
INTEGRAL_COLUMNS = {"total_mean": "mean", "total_gaussian": "gaussian", "willmore": "willmore"}

#: The result file formats: those of :data:`meshcurv.io.FORMATS` that hold per-vertex fields.
OUTPUT_FORMATS = ("ply", "npz", "vtp", "vtu", "vtk", "csv")

#: The folder of ``OUT_DIR`` that holds one record (the summary row) per result file.
RECORDS = ".meshcurv-batch"

_SUMMARY_NAME = "summary"

#: The most worker processes of a local cluster (each a Python process of about 100 MB, before any mesh).
MAX_WORKERS = 1024

#: The default time limit of one mesh, in seconds (``timeout`` of :func:`run`, ``--timeout``): a hundred
#: times what icc takes on a mesh of ten million vertices, so only a mesh that never ends reaches it.
DEFAULT_TIMEOUT = 3600.0

#: The most times the worker computing a mesh may die (killed: out of memory, a flaky node) before
#: the mesh is reported as failed; below Dask's ``allowed-failures`` (3), so that the meshes that
#: share its task are not lost with it.
MAX_WORKER_DEATHS = 2

#: Seconds without any worker after which :func:`run` gives up (:class:`NoWorkerError`): on the local
#: cluster, whose nannies restart a dead worker within seconds, and on a cluster of one's own (whose
#: workers may wait in a queue of the batch system).
NO_WORKER_SECONDS = {"local": 60.0, "remote": 600.0}

#: Files up to this size are hashed whole for their fingerprint; of larger ones, the first and last
#: :data:`HASH_PART_BYTES` (with the size and mtime): see :func:`fingerprint`.
HASH_WHOLE_BYTES = 256 * 2**20
HASH_PART_BYTES = 16 * 2**20

#: How often :func:`run` looks at the cluster while it waits for results, in seconds.
_POLL_SECONDS = 1.0


class NoWorkerError(TimeoutError):
    """The cluster has had no worker for too long (they died and none could be started)."""

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
    **{f"{field}_area_{statistic}": "float64" for field in SUMMARY_FIELDS for statistic in AREA_STATISTICS},
    **dict.fromkeys(INTEGRAL_COLUMNS, "float64"),
    "n_invalid": "Int64",
    "seconds": "float64",
    "error": "str",
    "warnings": "str",
    "method": "str",
    "output": "str",
}

#: Columns added since the first records: a record without them is computed again.
_ADDED_COLUMNS = (*(f"{field}_area_{statistic}" for field in SUMMARY_FIELDS for statistic in AREA_STATISTICS),
                  *INTEGRAL_COLUMNS)

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
    from .io import FORMATS, POINT_EXTENSIONS

    # point clouds too, but for .txt and .csv, which a folder holds for other reasons (notes, tables)
    points = set(POINT_EXTENSIONS) - {".txt", ".csv"}
    return {extension for extension, fmt in FORMATS.items() if fmt.read is not None} | points


def _identity(path) -> tuple[int, int] | None:
    """The real identity of a file or folder, ``(st_dev, st_ino)`` (links followed), or None if it is not there."""
    try:
        stat = os.stat(path)
    except (OSError, ValueError):
        return None
    return stat.st_dev, stat.st_ino


class _Folder:
    """A folder known by its real identity: whether a path lies in it, whatever the path's spelling.

    Symbolic links, ``.`` and ``..``, bind mounts and other aliases of the
    folder (or of the folders above a path) all compare equal: each folder
    above the path's real location is compared by ``(st_dev, st_ino)``.
    """

    def __init__(self, path):
        self.path = path
        self.identity = _identity(path)
        self._seen: dict[str, bool] = {}

    def holds(self, path) -> bool:
        """True when ``path`` is this folder or lies below it."""
        if self.identity is None:
            return False
        return self._below(os.path.realpath(path))

    def _below(self, real: str) -> bool:
        if real not in self._seen:
            parent = os.path.dirname(real)
            self._seen[real] = _identity(real) == self.identity or (parent != real and self._below(parent))
        return self._seen[real]


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
        A folder whose files are never inputs (the output folder), compared
        by real identity (symbolic links, ``..``, bind mounts resolved): the
        files of folders and patterns that lie in it are left out; a file or
        folder named explicitly that lies in it is an error.

    Returns
    -------
    list of pathlib.Path
        Each file once, sorted by its path as a string.

    Raises
    ------
    MeshFileError
        An input that is neither a file, a folder nor a pattern that matches
        something; a file or folder named explicitly inside ``exclude``; or
        nothing found at all.

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
    excluded = _Folder(exclude) if exclude is not None else None
    found: dict[str, pathlib.Path] = {}
    left_out = []

    def add(path: pathlib.Path) -> None:
        if excluded is not None and excluded.holds(path):
            left_out.append(path)
            return
        found.setdefault(os.path.abspath(path), path)

    def refuse_inside(text: str, path: pathlib.Path) -> None:
        if excluded is not None and excluded.holds(path):
            raise MeshFileError(
                f"{text}: is in the output folder {os.fspath(exclude)} (the same folder, under another name "
                "or not); the results would replace or mix with the inputs: choose an output folder "
                "apart from the inputs"
            )

    for item in inputs:
        text = os.fspath(item)
        path = pathlib.Path(text)
        if path.is_dir():
            refuse_inside(text, path)
            for child in sorted(path.iterdir()):
                if child.is_file() and not child.name.startswith(".") and child.suffix.lower() in extensions:
                    add(child)
        elif path.is_file():
            refuse_inside(text, path)
            add(path)
        elif _GLOB_CHARACTERS.search(text):
            matches = [pathlib.Path(match) for match in glob.glob(text, recursive=True)]
            matches = [match for match in matches if match.is_file() and match.suffix.lower() in extensions]
            if not matches:
                raise MeshFileError(f"{text}: the pattern matches no mesh file")
            for match in matches:
                add(match)
        elif path.exists() or os.path.lexists(path):
            raise MeshFileError(f"{text}: neither a file nor a folder (a broken link, a device?)")
        else:
            raise MeshFileError(f"{text}: no such file or folder")
    if not found:
        listed = ", ".join(os.fspath(item) for item in inputs) or "(none)"
        if left_out:
            raise MeshFileError(f"no mesh file found in {listed} but in the output folder {os.fspath(exclude)} "
                                f"({len(left_out)} files: results are never inputs)")
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
    jobs: list[_Job] = []
    claimed: dict[pathlib.Path, pathlib.Path] = {}
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
    inputs = {_identity(job.source): job.path for job in jobs}
    inputs.pop(None, None)
    for target in [*reserved, *(pathlib.Path(path) for job in jobs for path in (job.output, job.record))]:
        _refuse_input(target, inputs)
    return jobs


def _refuse_input(target, inputs: dict) -> None:
    """Raise MeshFileError when the file ``target`` is one of ``inputs`` (keyed by real identity)."""
    identity = _identity(target)
    if identity is not None and identity in inputs:
        raise MeshFileError(
            f"{os.fspath(target)}: is the input file {os.fspath(inputs[identity])} under another name (a link, "
            "an alias of its folder); writing it would replace the input: choose an output folder apart "
            "from the inputs"
        )


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
    if orient is not None and check_choice(orient, "orient", ORIENT_CHOICES) != "auto":
        options["orient"] = orient  # 'auto' is the default: recorded the same as nothing
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
    if result._surface is None:  # a point cloud: no areas
        row.update({f"{name}_area_{statistic}": np.nan for name in SUMMARY_FIELDS for statistic in AREA_STATISTICS})
        row.update(dict.fromkeys(INTEGRAL_COLUMNS, np.nan))
        return row
    from .integrals import weighted_statistics

    areas = np.where(result.valid, result.vertex_areas, 0.0)
    for name in SUMMARY_FIELDS:
        figures = weighted_statistics(getattr(result, name), areas)
        row.update({f"{name}_area_{statistic}": figures[statistic] for statistic in AREA_STATISTICS})
    for column, field in INTEGRAL_COLUMNS.items():
        row[column] = result.integral(field, where=result.valid if field == "willmore" else None)
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
    found: list[pathlib.Path] = []
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


def fingerprint(path) -> dict:
    """What identifies the content of an input file: its size, mtime (ns) and a BLAKE2b hash.

    A batch records it with each result; a later run computes the mesh again
    when the size or mtime differ, or else when the hash differs (a file
    replaced by another of the same size with its mtime kept: ``cp -p``,
    ``rsync -t``, an archive unpacked).

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    dict
        ``{"size": int, "mtime_ns": int, "blake2b": str}``. Files up to
        :data:`HASH_WHOLE_BYTES` (256 MiB) are hashed whole; of a larger file,
        the first and the last :data:`HASH_PART_BYTES` (16 MiB) are hashed:
        every format keeps its header (and so the counts) at the start and
        ends with the last faces, so a mesh of another size or shape changes
        them, while hashing a 10 GB scan whole would cost a resume tens of
        seconds for each file.

    Raises
    ------
    OSError
        The file cannot be read.
    """
    with open(path, "rb") as stream:
        stat = os.fstat(stream.fileno())
        digest = hashlib.blake2b(digest_size=16)
        if stat.st_size <= HASH_WHOLE_BYTES:
            for block in iter(lambda: stream.read(2**20), b""):
                digest.update(block)
        else:
            digest.update(stream.read(HASH_PART_BYTES))
            stream.seek(-HASH_PART_BYTES, os.SEEK_END)
            digest.update(stream.read(HASH_PART_BYTES))
    return {"size": stat.st_size, "mtime_ns": stat.st_mtime_ns, "blake2b": digest.hexdigest()}


def _unchanged(path, stored) -> bool:
    """Whether ``path`` still has the fingerprint ``stored`` (the hash is read only when size and mtime agree)."""
    if not isinstance(stored, dict):
        return False
    try:
        stat = os.stat(path)
        if (stat.st_size, stat.st_mtime_ns) != (stored.get("size"), stored.get("mtime_ns")):
            return False
        return fingerprint(path) == stored
    except OSError:
        return False


def _write_record(path: pathlib.Path, record: dict) -> None:
    from .io._files import atomic_output

    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_output(path) as temporary:
        temporary.write_text(json.dumps(record, allow_nan=True))


class _Unreadable(Exception):
    """A record that exists but cannot be used (cut short, corrupt, not a record)."""


def _read_record(path: pathlib.Path) -> dict | None:
    """The record at ``path``; None when there is none; :class:`_Unreadable` when it is damaged."""
    try:
        record = json.loads(pathlib.Path(path).read_text())
    except FileNotFoundError:
        return None
    except (OSError, ValueError) as exc:  # UnicodeDecodeError and JSONDecodeError are ValueErrors
        raise _Unreadable(f"{type(exc).__name__}: {exc}") from None
    if not (isinstance(record, dict) and isinstance(record.get("row"), dict)
            and isinstance(record["row"].get("status"), str)):
        raise _Unreadable("not a meshcurv batch record")
    return record


def _attempt_path(record: pathlib.Path) -> pathlib.Path:
    """Where a worker notes the mesh it is computing (beside its record), until its record is written."""
    return record.with_name(record.name.removesuffix(".json") + ".attempt")


# ------------------------------------------------------------------------------------- time limits
# A mesh over its time limit is stopped by ending its worker process: a reader looping in Python, a
# compiled kernel holding the GIL or a C library cannot be interrupted from another thread. The
# timer is faulthandler's, a C thread that needs no GIL; the nanny starts a new worker, Dask runs the
# task again, and that attempt finds the mesh's attempt note with its deadline passed: the mesh is
# failed ("timed out") and recorded, the meshes after it in the task are computed.

_DEADLINES: dict[object, float] = {}
_DEADLINES_LOCK = threading.Lock()
_DEVNULL = None


def _can_be_ended() -> bool:
    """True in a Dask worker process that a nanny restarts (the local cluster's, ``dask worker``'s)."""
    try:
        from distributed import get_worker

        return get_worker().nanny is not None
    except (ImportError, ValueError, AttributeError):
        return False


def _arm_locked() -> None:
    global _DEVNULL
    if not _DEADLINES:
        faulthandler.cancel_dump_traceback_later()
        return
    if _DEVNULL is None:
        _DEVNULL = open(os.devnull, "w")  # noqa: SIM115 (kept open: faulthandler writes to it on expiry)
    remaining = max(min(_DEADLINES.values()) - time.monotonic(), 0.001)
    faulthandler.dump_traceback_later(remaining, exit=True, file=_DEVNULL)


@contextlib.contextmanager
def _time_limit(seconds: float | None):
    """End this worker process if the block runs longer than ``seconds`` (no limit: None, or not in a worker)."""
    if seconds is None or not _can_be_ended():
        yield
        return
    token = object()
    with _DEADLINES_LOCK:
        _DEADLINES[token] = time.monotonic() + seconds
        _arm_locked()
    try:
        yield
    finally:
        with _DEADLINES_LOCK:
            del _DEADLINES[token]
            _arm_locked()


def _seconds(value: float) -> str:
    return f"{value:g} s"


def _previous_attempt(attempt: pathlib.Path, run_id: str | None, timeout: float | None) -> tuple[int, str | None]:
    """The worker deaths of this run while computing the mesh, and the error to report instead of trying again."""
    if run_id is None:
        return 0, None
    try:
        noted = json.loads(attempt.read_text())
    except (OSError, ValueError):
        return 0, None
    if not isinstance(noted, dict) or noted.get("run") != run_id:
        return 0, None  # a note of an earlier run, interrupted: try again
    deaths = int(noted.get("deaths", 0)) + 1
    if timeout is not None and time.time() >= float(noted.get("deadline", np.inf)):
        return deaths, f"TimeoutError: timed out after {_seconds(timeout)} (the time limit of a mesh: --timeout)"
    if deaths >= MAX_WORKER_DEATHS:
        return deaths, (f"WorkerDied: the worker computing this mesh died {deaths} times (killed by the system: "
                        "out of memory?)")
    return deaths, None


def process_mesh(source, output, record, *, method: str = DEFAULT_METHOD, smoothing_steps: int | None = None,
                 radius: float | None = None, orient: str | None = None, timeout: float | None = None,
                 run_id: str | None = None) -> dict:
    """Compute the curvatures of one mesh file, write the result and its record, return its summary row.

    The task :func:`run` sends to the workers; it never raises for a bad mesh.
    The result file is written under a temporary name; the record is written
    before the result is renamed into place, so a result that exists always
    has its record. An older result at ``output`` is replaced; ``output``
    is never the input file itself (checked before the rename).

    Parameters
    ----------
    source : str or os.PathLike
        The mesh file (any format :func:`meshcurv.read_mesh` reads).
    output : str or os.PathLike
        The result file; its extension picks the format (one of
        :data:`OUTPUT_FORMATS`). Its folder is created if needed.
    record : str or os.PathLike
        The JSON file that keeps the row and the input's :func:`fingerprint`,
        for later runs; a failure is recorded too.
    method, smoothing_steps, radius, orient
        As in :func:`meshcurv.principal_curvatures`.
    timeout : float, optional
        The time limit in seconds. Enforced only in a Dask worker that has a
        nanny (the local cluster's, ``dask worker``'s): past it, the worker
        process is ended, and the next attempt of the task (``run_id`` given)
        reports the mesh as timed out.
    run_id : str, optional
        The batch run: with it, the mesh being computed is noted beside its
        record, so that an attempt after its worker died knows it (see
        :data:`MAX_WORKER_DEATHS`).

    Returns
    -------
    dict
        The summary row (the keys of :data:`COLUMNS` but ``path``), with
        ``status`` ``'computed'``, or ``'failed'`` and the ``error`` (its type
        and message) when the mesh could not be read, computed or written,
        took longer than ``timeout`` or killed its workers.
    """
    from .curvature import principal_curvatures
    from .io import is_point_cloud, read_mesh, read_points, write_curvatures, write_point_curvatures
    from .io._files import atomic_output
    from .pointcloud import POINT_CLOUD_METHODS, point_cloud_curvatures

    start = time.perf_counter()
    source, output, record = pathlib.Path(source), pathlib.Path(output), pathlib.Path(record)
    given = {"smoothing_steps": smoothing_steps, "radius": radius, "orient": orient}
    options: dict[str, Any] = {name: value for name, value in given.items() if value is not None}
    stored_options = {"method": method, **options}
    row = {"status": "computed", "error": "", "warnings": "", "method": method, "output": os.fspath(output)}
    attempt = _attempt_path(record)
    deaths, error = _previous_attempt(attempt, run_id, timeout)
    facts = None
    try:
        facts = fingerprint(source)
    except OSError:
        pass  # read_mesh says what is wrong with it
    if error is not None:
        row = {"status": "failed", "error": error, "warnings": "", "method": method, "output": "",
               "seconds": timeout if error.startswith("TimeoutError") else np.nan}
        logger.info("%s failed: %s", source, error)
        _record_failure(record, row, stored_options, facts, timeout)
        attempt.unlink(missing_ok=True)
        return row
    try:
        if run_id is not None:
            deadline = time.time() + timeout if timeout is not None else None
            # a plain write (no temporary, no sync: 0.1 ms, not 5): a note cut short reads as no note
            attempt.parent.mkdir(parents=True, exist_ok=True)
            attempt.write_text(json.dumps({"run": run_id, "deaths": deaths, "deadline": deadline}))
        with _time_limit(timeout), warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            if is_point_cloud(source):  # a file without faces: the point-cloud estimators, their default
                vertices, normals = read_points(source)
                faces = None
                result = point_cloud_curvatures(vertices, normals=normals, radius=options.get("radius"),
                                                method=method if method in POINT_CLOUD_METHODS else None)
                row["method"] = result.method
            else:
                vertices, faces = read_mesh(source)
                result = principal_curvatures(vertices, faces, method=method, **options)
        facts_of = result.diagnosis
        if facts_of is None:  # a point cloud
            row.update(n_vertices=vertices.shape[0], n_faces=0, area=np.nan, volume=np.nan)
        else:
            row.update(
                n_vertices=facts_of.n_vertices, n_faces=facts_of.n_faces, area=facts_of.area,
                volume=np.nan if facts_of.volume is None else facts_of.volume,
                euler_characteristic=facts_of.euler_characteristic, n_components=facts_of.n_components,
                n_boundary_loops=facts_of.n_boundary_loops)
        row.update(n_invalid=int((~result.valid).sum()),
                   warnings="; ".join(dict.fromkeys(str(warning.message) for warning in caught)))
        row.update(_statistics(result))
        output.parent.mkdir(parents=True, exist_ok=True)
        with atomic_output(output) as temporary:
            if faces is None:
                write_point_curvatures(temporary, vertices, result, overwrite=True, source=source)
            else:
                write_curvatures(temporary, vertices, faces, result, overwrite=True, source=source)
            inputs = {_identity(source): source}
            _refuse_input(output, inputs)  # the output folder may have become an alias of the input's
            _refuse_input(record, inputs)
            output.unlink(missing_ok=True)  # an older result must not outlive a newer record
            row["seconds"] = time.perf_counter() - start
            _write_record(record, {"row": row, "options": stored_options, "input": facts})
    except Exception as exc:  # one bad mesh never sinks the batch: its row says what went wrong
        row = {"status": "failed", "error": f"{type(exc).__name__}: {exc}", "warnings": "", "method": method,
               "output": "", "seconds": time.perf_counter() - start}
        logger.info("%s failed: %s", source, row["error"])
        _record_failure(record, row, stored_options, facts, timeout)
    attempt.unlink(missing_ok=True)
    return row


def _record_failure(record: pathlib.Path, row: dict, options: dict, facts: dict | None, timeout) -> None:
    """Record a failed mesh, so that a later run reports it without trying again (unless its input changes)."""
    if facts is None:  # the input cannot be read: nothing identifies it; a later run tries again
        return
    try:
        _write_record(record, {"row": row, "options": options, "input": facts, "timeout": timeout})
    except OSError as exc:  # the row still reaches the summary
        logger.info("%s: cannot record the failure: %s", record, exc)


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

    n_workers = CPU_COUNT if workers is None else check_int_option(workers, "workers", minimum=1, maximum=MAX_WORKERS)
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
        timeout: float | None = DEFAULT_TIMEOUT, retry_failed: bool = False,
        progress: Callable[[int, int, int], None] | None = None):
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
    if workers is not None:
        if client is not None or scheduler is not None:
            raise InvalidOptionError(
                "`workers` sizes the local cluster; it cannot be used with `client` or `scheduler`")
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
        stored = _completed(job, options, overwrite=overwrite, retry_failed=retry_failed, timeout=timeout,
                            damaged=damaged)
        if stored is None:
            todo.append(index)
        else:
            rows[index] = stored
    if damaged:
        warnings.warn(f"{len(damaged)} records in {out_dir / RECORDS} cannot be read (cut short or corrupt: "
                      f"{damaged[0][0].name}: {damaged[0][1]}); their meshes are computed again",
                      MeshcurvWarning, stacklevel=2)
    failed = sum(row["status"] == "failed" for row in rows.values())
    if progress is not None:
        progress(len(rows), len(jobs), failed)
    logger.info("%d meshes: %d to compute, %d already done", len(jobs), len(todo), len(rows))

    if todo:
        owned = False
        task_options = {**options, "timeout": timeout, "run_id": uuid.uuid4().hex}
        try:
            with _cluster(distributed, client=client, scheduler=scheduler, workers=workers) as (active, owned):
                logger.info("Dask dashboard: %s", _dashboard(active) or "none (pip install bokeh to have one)")
                chunks = _chunks(jobs, todo, workers=_worker_count(active))
                logger.info("%d meshes in %d tasks", len(todo), len(chunks))
                pending = _submit(active, jobs, chunks, task_options)
                watch = _WorkerWatch(active, NO_WORKER_SECONDS["local" if owned else "remote"])
                try:
                    while pending:
                        retry: list[list[int]] = []
                        for future in _finished(distributed, list(pending), watch):
                            chunk = pending.pop(future)
                            outcome = _outcome(future)
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
                                if isinstance(outcome, distributed.KilledWorker):
                                    _record_lost(jobs[index], row, options, timeout)
                            if progress is not None:
                                progress(len(rows), len(jobs), failed)
                        pending.update(_submit(active, jobs, retry, task_options))
                except BaseException:
                    active.cancel(list(pending))
                    raise
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
            raise MeshFileError(f"{folder}: cannot write the results there ({exc.strerror or exc}); "
                                "nothing was computed") from None


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
            logger.warning("the cluster has no worker (they died?); waiting up to %s for one",
                           _seconds(self.patience))
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


def _record_lost(job: _Job, row: dict, options: dict, timeout) -> None:
    """Record a mesh whose task was lost (its workers killed), so that a later run does not retry it forever."""
    try:
        facts = fingerprint(job.source)
    except OSError:
        return
    _record_failure(pathlib.Path(job.record), row, options, facts, timeout)


def _completed(job: _Job, options: dict, *, overwrite: bool, retry_failed: bool, timeout: float | None,
               damaged: list[tuple[pathlib.Path, str]]) -> dict | None:
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
        error = (f"KilledWorker: every worker that ran this mesh died (killed by the system: out of memory?) "
                 f"({outcome})")
    else:
        error = f"{type(outcome).__name__}: {outcome}"
    return [{"status": "failed", "error": error, "warnings": "", "output": ""} for _ in chunk]


def _remove_temporaries(jobs: list[_Job], indices: list[int]) -> None:
    records = [pathlib.Path(jobs[index].record) for index in indices]
    targets = [pathlib.Path(jobs[index].output) for index in indices] + records
    for attempt in map(_attempt_path, records):  # notes of meshes whose task ended without them
        attempt.unlink(missing_ok=True)
        targets.append(attempt)
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
