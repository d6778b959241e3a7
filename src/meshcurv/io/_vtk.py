"""Legacy VTK POLYDATA (.vtk), read with numpy: what VTK and ParaView write for surfaces.

meshio reads legacy files of the UNSTRUCTURED_GRID dataset only; a surface
saved from ParaView or VTK (``vtkPolyDataWriter``) is a POLYDATA: POINTS
followed by POLYGONS (and maybe VERTICES, LINES, TRIANGLE_STRIPS), then
attributes (POINT_DATA, CELL_DATA) that are not read. Both layouts of the
cell arrays are read: ``k i j ...`` records (versions up to 4.2) and
OFFSETS + CONNECTIVITY (version 5.1, VTK 9's default), ASCII or BINARY
(big-endian). Every declared count is checked against what is left of the
file before anything is allocated for it; triangle strips become triangles.
"""

from __future__ import annotations

import re

import numpy as np

from ..errors import MeshFileError
from ..topology import strip_triangles
from ._text import numbers, without_bom

__all__ = ["is_polydata", "read_vtk_polydata"]

_NAMES = "bit unsigned_char char unsigned_short short unsigned_int int unsigned_long long float double"
_TYPES = dict(zip(_NAMES.split(), (None, "u1", "i1", "u2", "i2", "u4", "i4", "u8", "i8", "f4", "f8")))
_TYPES.update(vtktypeint64="i8", vtktypeuint64="u8", vtkidtype="i8", vtktypeint32="i4", vtktypeuint32="u4")
_DATASET = re.compile(rb"^\s*DATASET\s+(\w+)", re.M | re.I)
_WHITE = np.zeros(256, dtype=bool)
_WHITE[[9, 10, 11, 12, 13, 32]] = True
_CELL_SECTIONS = ("VERTICES", "LINES", "POLYGONS", "TRIANGLE_STRIPS")
_LARGEST_INDEX = 2.0**53


def is_polydata(path) -> bool:
    """Whether a legacy VTK file declares ``DATASET POLYDATA`` (in its first kilobyte)."""
    with open(path, "rb") as handle:
        head = handle.read(1024)
    match = _DATASET.search(head)
    return match is not None and match.group(1).upper() == b"POLYDATA"


class _Cursor:
    """A position in the file and the two ways to read on: a line of words, or n numbers."""

    def __init__(self, data: bytes, position: int, binary: bool, path):
        self.data, self.position, self.binary, self.path = data, position, binary, path

    def line(self, *, skip_blank: bool = True):
        """The next line (the next non-blank one by default) as words; None at the end of the file."""
        data = self.data
        while self.position < len(data):
            end = data.find(b"\n", self.position)
            end = len(data) if end < 0 else end
            text = data[self.position : end]
            self.position = end + 1
            if text.strip() or not skip_blank:
                return text.decode("ascii", "replace").split()
        return None

    def numbers(self, n: int, kind: str, what: str) -> np.ndarray:
        code = _TYPES.get(kind.lower())
        if code is None:
            raise MeshFileError(f"{self.path}: VTK data type {kind!r} is not supported for {what}")
        left = len(self.data) - self.position
        if self.binary:
            need = n * np.dtype(code).itemsize
            if need > left:
                raise self.short(n, what, need, left)
            values = np.frombuffer(self.data, ">" + code, count=n, offset=self.position)
            self.position += need
            return values
        if 2 * n - 1 > left:  # n numbers need n digits and n - 1 separators at least
            raise self.short(n, what, 2 * n - 1, left)
        return self._ascii(n, what)

    def _ascii(self, n: int, what: str) -> np.ndarray:
        if n == 0:
            return np.zeros(0)
        window = 16 * n + 64
        while True:
            chunk = self.data[self.position : self.position + window]
            white = _WHITE[np.frombuffer(chunk, np.uint8)]
            starts = np.flatnonzero(~white[1:] & white[:-1]) + 1
            if chunk and not white[0]:
                starts = np.concatenate([[0], starts])
            at_end = self.position + window >= len(self.data)
            if starts.size > n or at_end:
                break
            window *= 2
        if starts.size < n:
            raise MeshFileError(f"{self.path}: the file ends inside its {what} ({starts.size} of {n} numbers)")
        cut = starts[n] if starts.size > n else len(chunk)
        values = numbers(chunk[:cut])
        if values is None or values.size != n:
            raise MeshFileError(f"{self.path}: the {what} hold something that is not a number")
        self.position += cut
        return values

    def short(self, n, what, need, left) -> MeshFileError:
        unit = "bytes" if self.binary else "bytes of text"
        return MeshFileError(
            f"{self.path}: the file declares {n} values of {what} but holds only {left} {unit} after them "
            f"({need} needed at least); the file is cut short or its counts are wrong"
        )


def _integers(values: np.ndarray, path, what: str) -> np.ndarray:
    if values.dtype.kind == "f":
        bad = ~(np.abs(values) <= _LARGEST_INDEX) | (values != np.floor(values))
        if bad.any():
            raise MeshFileError(f"{path}: the {what} hold a value that is not an integer ({values[bad][0]!r})")
    elif values.dtype.kind == "u" and values.size and values.max() > np.iinfo(np.int64).max:
        raise MeshFileError(f"{path}: the {what} hold an index beyond any mesh size")
    return values.astype(np.int64)


def read_vtk_polydata(path):
    """Read the points and the polygons (and triangle strips) of a legacy VTK POLYDATA file.

    Returns
    -------
    vertices : ndarray of shape (V, 3), float64
    faces : ndarray of shape (F, k), int64, or a list of int64 arrays
    """
    with open(path, "rb") as handle:
        data = without_bom(handle.read())
    cursor = _Cursor(data, 0, False, path)
    first = cursor.line(skip_blank=False)
    if not first or first[:3] != ["#", "vtk", "DataFile"]:
        raise MeshFileError(f"{path}: not a legacy VTK file (no '# vtk DataFile Version' line)")
    try:
        version = float(first[-1])
    except ValueError:
        version = 4.2
    cursor.line(skip_blank=False)  # the title
    encoding = cursor.line()
    if not encoding or encoding[0].upper() not in ("ASCII", "BINARY"):
        raise MeshFileError(f"{path}: the third line of a legacy VTK file must be ASCII or BINARY")
    cursor.binary = encoding[0].upper() == "BINARY"
    dataset = cursor.line()
    if not dataset or [word.upper() for word in dataset[:2]] != ["DATASET", "POLYDATA"]:
        raise MeshFileError(f"{path}: not a POLYDATA legacy VTK file")
    points, polygons = None, []
    while (words := cursor.line()) is not None:
        key = words[0].upper()
        if key in ("POINT_DATA", "CELL_DATA"):
            break  # attributes follow the geometry: not read
        if key == "METADATA":
            while (line := cursor.line(skip_blank=False)) is not None and line:
                pass
        elif key == "FIELD" and len(words) == 3 and words[2].isdigit():
            for _ in range(int(words[2])):
                array = cursor.line()
                if not array or len(array) != 4 or not (array[1].isdigit() and array[2].isdigit()):
                    raise MeshFileError(f"{path}: a FIELD array of the legacy VTK file is malformed")
                cursor.numbers(int(array[1]) * int(array[2]), array[3], "field data")
        elif key == "POINTS" and len(words) == 3 and words[1].isdigit():
            n = int(words[1])
            points = cursor.numbers(3 * n, words[2], "POINTS").astype(np.float64).reshape(n, 3)
        elif key in _CELL_SECTIONS and len(words) == 3 and words[1].isdigit() and words[2].isdigit():
            cells = _cells(cursor, key, int(words[1]), int(words[2]), version, path)
            if key == "POLYGONS":
                polygons.extend(cells)
            elif key == "TRIANGLE_STRIPS":
                polygons.extend(_strip_triangles(cells))
        else:
            raise MeshFileError(f"{path}: unexpected line in a legacy VTK POLYDATA file: {' '.join(words)[:60]!r}")
    if points is None:
        raise MeshFileError(f"{path}: the legacy VTK file has no POINTS")
    blocks = [block for block in polygons if len(block)]
    if not blocks:
        raise MeshFileError(f"{path}: the legacy VTK file has no POLYGONS (or TRIANGLE_STRIPS)")
    return points, _merge(blocks)


def _merge(blocks):
    """Faces from blocks (F, k) arrays and single faces: one (F, k) array when they all have k corners."""
    if (
        all(isinstance(block, np.ndarray) and block.ndim == 2 for block in blocks)
        and len({block.shape[1] for block in blocks}) == 1
    ):
        return np.concatenate(blocks)
    return [
        face for block in blocks for face in (block if isinstance(block, np.ndarray) and block.ndim == 2 else [block])
    ]


def _cells(cursor, key, n_cells, size, version, path):
    """The cells of one section as a list holding one (n, k) array or single index arrays."""
    what = f"{key} cells"
    if version >= 5:
        words = cursor.line()
        if not words or words[0].upper() != "OFFSETS" or len(words) != 2:
            raise MeshFileError(f"{path}: a version 5 {key} section must start with OFFSETS")
        offsets = _integers(cursor.numbers(n_cells, words[1], f"{key} offsets"), path, f"{key} offsets")
        words = cursor.line()
        if not words or words[0].upper() != "CONNECTIVITY" or len(words) != 2:
            raise MeshFileError(f"{path}: a version 5 {key} section lacks its CONNECTIVITY")
        connectivity = _integers(cursor.numbers(size, words[1], f"{key} connectivity"), path, what)
        if n_cells == 0:
            return []
        counts = np.diff(offsets)
        if offsets[0] != 0 or offsets[-1] != size or (counts < 0).any():
            raise MeshFileError(f"{path}: the {key} offsets do not match the connectivity")
        if counts.size == 0:
            return []
        if (counts == counts[0]).all():
            return [connectivity.reshape(counts.size, int(counts[0]))] if counts[0] else []
        return np.split(connectivity, offsets[1:-1])
    values = _integers(cursor.numbers(size, "int", what), path, what)
    if n_cells == 0:
        return []
    k = int(values[0]) if values.size else -1
    if k >= 0 and size == n_cells * (k + 1) and (values[:: k + 1] == k).all():
        return [values.reshape(n_cells, k + 1)[:, 1:]] if k else []
    starts: list[int] = []
    lengths: list[int] = []
    position = 0
    for _ in range(n_cells):  # cells of different sizes: each count says where the next cell starts
        if position >= size or values[position] < 0 or position + 1 + values[position] > size:
            raise MeshFileError(f"{path}: the {key} counts do not match the declared size {size}")
        starts.append(position + 1)
        lengths.append(int(values[position]))
        position += 1 + lengths[-1]
    if position != size:
        raise MeshFileError(f"{path}: the {key} counts do not match the declared size {size}")
    return [values[start : start + length] for start, length in zip(starts, lengths)]


def _strip_triangles(cells):
    """The triangles of a section of triangle strips (:func:`strip_triangles`), as a list of one (T, 3) array."""
    if not cells:
        return []
    sizes = [np.full(block.shape[0], block.shape[1]) if block.ndim == 2 else [block.size] for block in cells]
    return [strip_triangles(np.concatenate([block.ravel() for block in cells]), np.cumsum(np.concatenate(sizes)))]
