"""What a batch reads and where it writes: inputs expanded, one job per mesh, options checked.

Nothing here touches a cluster or computes a curvature: a bad input, option
or output folder fails here, before any work.
"""

from __future__ import annotations

import glob
import os
import pathlib
import re
from dataclasses import dataclass

from .._validation import check_choice
from ..curvature import _checked_options
from ..errors import InvalidOptionError, MeshFileError
from ..io import FORMATS, POINT_EXTENSIONS
from ..orient import ORIENT_CHOICES

#: The result file formats: those of :data:`meshcurv.io.FORMATS` that hold per-vertex fields.
OUTPUT_FORMATS = ("ply", "npz", "vtp", "vtu", "vtk", "csv")

#: The folder of ``OUT_DIR`` that holds one record (the summary row) per result file.
RECORDS = ".meshcurv-batch"

_SUMMARY_NAME = "summary"

_GLOB_CHARACTERS = re.compile(r"[*?\[]")


def _readable_extensions() -> set[str]:
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
            raise MeshFileError(
                f"no mesh file found in {listed} but in the output folder {os.fspath(exclude)} "
                f"({len(left_out)} files: results are never inputs)"
            )
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
    _, _, options = _checked_options(method, smoothing_steps=smoothing_steps, radius=radius)
    if orient is not None and check_choice(orient, "orient", ORIENT_CHOICES) != "auto":
        options["orient"] = orient  # 'auto' is the default: recorded the same as nothing
    return options
