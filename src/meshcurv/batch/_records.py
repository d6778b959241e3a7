"""What a batch keeps between runs: input fingerprints, one record per mesh, attempt notes, time limits.

A record (JSON, in ``OUT_DIR/.meshcurv-batch``) holds a mesh's summary row,
its options and its input's :func:`fingerprint`, so that a later run skips
it; a worker notes the mesh it computes beside its record (an attempt
note), so that the next attempt after the worker died knows it.
"""

from __future__ import annotations

import contextlib
import faulthandler
import hashlib
import json
import logging
import os
import pathlib
import threading
import time

import numpy as np

from ..io._files import atomic_output
from ._driver import _seconds
from ._inputs import _Job

logger = logging.getLogger(__name__)

#: Files up to this size are hashed whole for their fingerprint; of larger ones, the first and last
#: :data:`HASH_PART_BYTES` (with the size and mtime): see :func:`fingerprint`.
HASH_WHOLE_BYTES = 256 * 2**20
HASH_PART_BYTES = 16 * 2**20


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
            found.extend(folder / name for name in hidden if name.startswith(prefixes) and name.endswith(target.suffix))
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
        The input file.

    Returns
    -------
    dict
        ``{"size": int, "mtime_ns": int, "blake2b": str}``. Files up to
        :data:`HASH_WHOLE_BYTES` (256 MiB) are hashed whole; of a larger file,
        the first and the last :data:`HASH_PART_BYTES` (16 MiB) are hashed:
        every format keeps its header (and so the counts) at the start and
        ends with the last faces, so a mesh of another size or shape changes
        them, and a resume does not read every large scan whole.

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
    if not (
        isinstance(record, dict)
        and isinstance(record.get("row"), dict)
        and isinstance(record["row"].get("status"), str)
    ):
        raise _Unreadable("not a meshcurv batch record")
    return record


def _attempt_path(record: pathlib.Path) -> pathlib.Path:
    """Where a worker notes the mesh it is computing (beside its record), until its record is written."""
    return record.with_name(record.name.removesuffix(".json") + ".attempt")


#: The most times the worker computing a mesh may die (killed: out of memory, a flaky node) before
#: the mesh is reported as failed; below Dask's ``allowed-failures`` (3), so that the meshes that
#: share its task are not lost with it.
MAX_WORKER_DEATHS = 2

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
        return deaths, (
            f"WorkerDied: the worker computing this mesh died {deaths} times (killed by the system: out of memory?)"
        )
    return deaths, None


def _record_failure(record: pathlib.Path, row: dict, options: dict, facts: dict | None, timeout) -> None:
    """Record a failed mesh, so that a later run reports it without trying again (unless its input changes)."""
    if facts is None:  # the input cannot be read: nothing identifies it; a later run tries again
        return
    try:
        _write_record(record, {"row": row, "options": options, "input": facts, "timeout": timeout})
    except OSError as exc:  # the row still reaches the summary
        logger.info("%s: cannot record the failure: %s", record, exc)


def _remove_temporaries(jobs: list[_Job], indices: list[int]) -> None:
    records = [pathlib.Path(jobs[index].record) for index in indices]
    targets = [pathlib.Path(jobs[index].output) for index in indices] + records
    for attempt in map(_attempt_path, records):  # notes of meshes whose task ended without them
        attempt.unlink(missing_ok=True)
        targets.append(attempt)
    for temporary in _stale_temporaries(targets):
        logger.info("removing %s, left by an interrupted write", temporary)
        temporary.unlink(missing_ok=True)
