"""Paths: the checks before a write, and the atomic write itself."""

from __future__ import annotations

import contextlib
import os
import pathlib
import secrets
from collections.abc import Mapping

import numpy as np

from ..errors import InvalidOptionError, MeshFileError

__all__ = ["check_output", "atomic_output", "check_input", "format_key", "read_as", "named_fields"]


@contextlib.contextmanager
def read_as(path, kind: str, *, passes: tuple = (MeshFileError,)):
    """A block that reads ``path``: what it raises becomes one :class:`MeshFileError` naming the file.

    "``path``: cannot be read as ``kind`` (the first line of the error, at
    most 200 characters, or its type)"; the exceptions of ``passes`` (a
    :class:`MeshFileError` already naming the file) go through as they are.
    """
    try:
        yield
    except passes:
        raise
    except Exception as exc:
        text = str(exc).strip()
        reason = text.splitlines()[0][:200] if text else type(exc).__name__
        raise MeshFileError(f"{path}: cannot be read as {kind} ({reason})") from exc


def check_input(path) -> pathlib.Path:
    """Return ``path`` as a Path to an existing regular file, or raise MeshFileError."""
    path = pathlib.Path(path)
    if path.is_dir():
        raise MeshFileError(f"{path}: is a directory, not a mesh file")
    if not path.exists():
        raise MeshFileError(f"{path}: no such file")
    if not os.access(path, os.R_OK):
        raise MeshFileError(f"{path}: permission denied")
    if path.stat().st_size == 0:
        raise MeshFileError(f"{path}: the file is empty")
    return path


def _same_file(a: pathlib.Path, b: pathlib.Path) -> bool:
    """Whether ``a`` and ``b`` are one file: same device and inode, or the same real path.

    Symbolic links, ``..``, hard links and bind mounts of one file are all
    the same file; when ``a`` does not exist yet, its real path (symbolic
    links of its folders resolved) is compared.
    """
    try:
        return os.path.samefile(a, b)
    except (OSError, ValueError):
        try:
            return os.path.normcase(os.path.realpath(a)) == os.path.normcase(os.path.realpath(b))
        except (OSError, ValueError):
            return False


def check_output(path, *, overwrite: bool = False, source=None) -> pathlib.Path:
    """Refuse to write over ``source`` (the input) or over an existing file unless asked.

    Raises
    ------
    MeshFileError
        ``path`` is the input file, a directory, an existing file without
        ``overwrite=True``, or lies in a folder that does not exist.
    """
    path = pathlib.Path(path)
    if source is not None and _same_file(path, pathlib.Path(source)):
        raise MeshFileError(f"{path}: the output would replace the input file; choose another name")
    if path.is_dir():
        raise MeshFileError(f"{path}: is a directory; give a file name")
    if path.exists() and not overwrite:
        raise MeshFileError(f"{path}: already exists; pass overwrite=True (--overwrite) to replace it")
    if not path.parent.is_dir():
        raise MeshFileError(f"{path}: the folder {path.parent} does not exist")
    return path


@contextlib.contextmanager
def atomic_output(path: pathlib.Path, *, overwrite: bool = True):
    """Yield a temporary path beside ``path``; publish it as ``path`` only if the block succeeds.

    The temporary file lives in the same folder and keeps the suffix of
    ``path``; it is removed on failure. With ``overwrite=True`` it is moved
    with :func:`os.replace` (an atomic rename onto any existing file). With
    ``overwrite=False`` it is published without replacement: a hard link to
    ``path`` (which fails if ``path`` exists, atomically), or where the file
    system has no hard links, an exclusive creation (``O_EXCL``) of ``path``
    before the rename. Of two writers started together, the second gets a
    MeshFileError instead of silently replacing the first one's file.

    Raises
    ------
    MeshFileError
        The folder cannot take the temporary file (read-only, missing, full),
        or ``path`` appeared meanwhile and ``overwrite`` is False. The message
        names ``path``, never the temporary.
    """
    path = pathlib.Path(path)
    temporary = _temporary_beside(path)
    try:
        yield temporary
        try:
            if overwrite:
                os.replace(temporary, path)
            else:
                _publish_exclusive(temporary, path)
        except FileExistsError as exc:
            raise MeshFileError(
                f"{path}: already exists (another writer created it meanwhile); "
                "pass overwrite=True (--overwrite) to replace it"
            ) from exc
        except OSError as exc:
            raise MeshFileError(f"{path}: cannot be written ({exc.strerror or exc})") from exc
    finally:
        temporary.unlink(missing_ok=True)


def _publish_exclusive(temporary: pathlib.Path, path: pathlib.Path) -> None:
    """Give the finished ``temporary`` the name ``path``, failing with FileExistsError if it is taken."""
    try:
        os.link(temporary, path)
        return
    except FileExistsError:
        raise
    except OSError:  # no hard links here (FAT, some network and FUSE file systems)
        pass
    descriptor = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    os.close(descriptor)
    os.replace(temporary, path)


def _temporary_beside(path: pathlib.Path) -> pathlib.Path:
    """Create an empty, new file ``.<name>.<random><suffix>`` beside ``path`` and return its path.

    It is created with mode 0o666, so the operating system applies the
    process's umask to it, as to any file the process creates: the published
    output gets the same permissions as a plain ``open(path, "w")`` would give
    it. The umask itself is never read or changed (changing it, even for a
    moment, would change the mode of the files other threads create then).
    """
    for _ in range(100):
        candidate = path.parent / f".{path.name}.{secrets.token_hex(6)}{path.suffix}"
        try:
            descriptor = os.open(candidate, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
        except FileExistsError:
            continue
        except OSError as exc:
            raise MeshFileError(f"{path}: cannot be written ({exc.strerror or exc})") from exc
        os.close(descriptor)
        return candidate
    raise MeshFileError(f"{path}: cannot be written (no free temporary name in {path.parent})")


def format_key(path: pathlib.Path, file_format: str | None, known, what: str) -> str:
    """The lower-case extension of the format: ``file_format`` (``'ply'`` or ``'.ply'``), else ``path``'s.

    A :class:`~meshcurv.errors.MeshFileError` naming the file, the ``what``
    and the ``known`` extensions when it is not one of them.
    """
    if file_format is not None and not isinstance(file_format, str):
        raise InvalidOptionError(f"`file_format` must be an extension such as 'ply'; got {file_format!r}")
    key = file_format if file_format is None or file_format.startswith(".") else "." + file_format
    key = (key or path.suffix).lower()
    if key not in known and file_format is None and path.is_dir():
        raise MeshFileError(f"{path}: is a directory, not a {what}")
    if key not in known:
        given = f"extension {path.suffix!r}" if path.suffix else "extension (none)"
        given = f"format {file_format!r}" if file_format else given
        raise MeshFileError(f"{path}: unknown {what} {given}; known formats: {', '.join(known)}")
    return key


def named_fields(point_data) -> dict[str, np.ndarray]:
    """``point_data`` (None, or a mapping of identifiers to arrays) as a dict of ndarrays, checked before a write.

    The names become PLY properties, table headers and PCD fields, where a
    space or a symbol would break the file: an InvalidOptionError names the
    first that is not an identifier, or what was given instead of a mapping.
    """
    if point_data is None:
        return {}
    if not isinstance(point_data, Mapping):
        raise InvalidOptionError(f"`point_data` must be a dict of name -> array; got {type(point_data).__name__}")
    for name in point_data:
        if not isinstance(name, str) or not name.isidentifier():
            raise InvalidOptionError(f"`point_data` names must be identifiers (letters, digits, _); got {name!r}")
    return {name: np.asarray(value) for name, value in point_data.items()}
