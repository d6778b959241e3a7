"""Paths: the checks before a write, and the atomic write itself."""

from __future__ import annotations

import contextlib
import os
import pathlib
import tempfile

from ..errors import MeshFileError

__all__ = ["check_output", "atomic_output", "check_input"]


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
    try:
        return a.samefile(b)
    except OSError:
        return a.resolve() == b.resolve()


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
def atomic_output(path: pathlib.Path):
    """Yield a temporary path beside ``path``; move it onto ``path`` only if the block succeeds.

    The temporary file lives in the same folder (so :func:`os.replace` is an
    atomic rename) and keeps the suffix of ``path``; it is removed on failure.
    """
    handle, temporary = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=path.suffix)
    os.close(handle)
    temporary = pathlib.Path(temporary)
    try:
        yield temporary
        os.chmod(temporary, 0o666 & ~_umask())
        os.replace(temporary, path)
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask
