"""OFF, read and written with numpy.

meshio's OFF reader accepts triangles only and its writer keeps 12
significant digits; OFF is a plain list of numbers, so it is done here.
"""

from __future__ import annotations

import re

import numpy as np

from ..errors import MeshFileError
from ._text import not_a_number, numbers_per_line, row_error, without_bom

__all__ = ["read_off", "write_off"]

_COMMENT = re.compile(rb"#[^\n]*")


def read_off(path):
    """Read an OFF file: ``OFF``, ``V F E``, V lines of x y z, F lines of ``k i j ...`` (0-based).

    Read line by line (in numpy): what follows the coordinates of a vertex or
    the ``k`` indices of a face on its line (a colour, as the format allows)
    is ignored. The declared counts are checked against the lines the file
    holds before anything is allocated for them. A line with fewer values
    than its vertex or face needs, a word that is not a number, or a line
    after the declared faces is an error naming its line number.
    """
    with open(path, "rb") as handle:
        data = _COMMENT.sub(b"", without_bom(handle.read()))
    lines = [line for line in data.split(b"\n") if line.strip()]
    words = lines[0].split() if lines else []
    if not words or words[0] != b"OFF":
        found = words[0][:20].decode("ascii", "replace") if words else ""
        raise MeshFileError(f"{path}: not an OFF file (it should start with 'OFF'; starts with {found!r})")
    counts_line = words[1:] if len(words) > 1 else (lines[1].split() if len(lines) > 1 else [])
    body = lines[1:] if len(words) > 1 else lines[2:]
    try:
        n_vertices, n_faces = int(counts_line[0]), int(counts_line[1])
    except (IndexError, ValueError) as exc:
        raise MeshFileError(f"{path}: the OFF counts, vertices or faces cannot be read ({exc})") from None
    if n_vertices < 0 or n_faces < 0:
        raise MeshFileError(f"{path}: the OFF counts must not be negative; got {n_vertices} and {n_faces}")
    start = len(lines) - len(body)  # body[j] is the (start + j)-th non-blank line

    def line(j: int) -> int:  # the file's line number of body[j], for messages
        return _line_number(data, start + j)

    parsed = numbers_per_line(body[:n_vertices])
    if parsed is None:
        raise not_a_number(path, b"\n".join(body[:n_vertices]), line, "a vertex coordinate")
    values, counts = parsed
    if (counts < 3).any():
        row = int(np.flatnonzero(counts < 3)[0])
        raise row_error(path, line(row), int(counts[row]), "3 or more", "x, y, z, then maybe a colour")
    usual = int(np.bincount(counts).argmax()) if counts.size else 3
    if (counts != usual).any():  # a colour on every vertex or on none: one row apart has a value too many or few
        row = int(np.argmax(counts != usual))
        meaning = "as most vertex rows: x, y, z" + (", then a colour" if usual > 3 else "")
        raise row_error(path, line(row), int(counts[row]), usual, meaning)
    if n_vertices > len(body):  # the rows there are were checked first: a damaged row is named
        raise MeshFileError(f"{path}: the header announces {n_vertices} vertices; the file has {len(body)}")
    vertices = values[(np.cumsum(counts) - counts)[:, None] + np.arange(3)]
    parsed = numbers_per_line(body[n_vertices : n_vertices + n_faces])
    if parsed is None:
        raise not_a_number(
            path, b"\n".join(body[n_vertices : n_vertices + n_faces]), lambda j: line(n_vertices + j), "a face"
        )
    values, counts = parsed
    first = np.cumsum(counts) - counts
    sizes = np.where(counts > 0, values[np.minimum(first, max(values.size - 1, 0))] if values.size else 0, 0)
    malformed = (counts == 0) | (sizes != np.floor(sizes)) | (sizes < 3)
    if malformed.any():
        face = int(np.flatnonzero(malformed)[0])
        raise MeshFileError(
            f"{path}: line {line(n_vertices + face)}: a face of {sizes[face]:g} corners (its first "
            "value counts its corners: a whole number, 3 or more)"
        )
    bad = sizes > counts - 1
    if bad.any():
        face = int(np.flatnonzero(bad)[0])
        meaning = f"a count of {int(sizes[face])} and as many vertex indices, then maybe a colour"
        raise row_error(path, line(n_vertices + face), int(counts[face]), f"{int(sizes[face]) + 1} or more", meaning)
    if n_vertices + n_faces > len(body):
        raise MeshFileError(
            f"{path}: the header declares {n_vertices} vertices and {n_faces} faces but the file holds only "
            f"{len(body)} lines for them, up to line {_line_number(data, len(lines) - 1)}; face "
            f"{len(body) - n_vertices} is missing (the file is cut short, or two rows were written as one)"
        )
    if len(body) > n_vertices + n_faces:
        raise MeshFileError(
            f"{path}: line {line(n_vertices + n_faces)}: a row after the {n_vertices} vertices and "
            f"{n_faces} faces the header declares"
        )
    sizes = sizes.astype(np.int64)
    corners = values[np.repeat(first + 1 - (np.cumsum(sizes) - sizes), sizes) + np.arange(sizes.sum())]
    bad = (corners != np.floor(corners)) | ~(np.abs(corners) <= 2.0**53)
    if bad.any():
        face = int(np.searchsorted(np.cumsum(sizes), np.argmax(bad), side="right"))
        raise MeshFileError(
            f"{path}: line {line(n_vertices + face)}: a face index is not an integer ({float(corners[bad][0])!r})"
        )
    corners = corners.astype(np.int64)
    bad = (corners < 0) | (corners >= n_vertices)
    if bad.any():
        face = int(np.searchsorted(np.cumsum(sizes), np.argmax(bad), side="right"))
        raise MeshFileError(
            f"{path}: line {line(n_vertices + face)}: a face uses vertex {int(corners[bad][0])}; "
            f"the file has {n_vertices} vertices, numbered from 0"
        )
    if sizes.size and (sizes == sizes[0]).all():
        return vertices, corners.reshape(sizes.size, int(sizes[0]))
    return vertices, np.split(corners, np.cumsum(sizes)[:-1])


def _line_number(data: bytes, index: int) -> int:
    """The 1-based line number of the ``index``-th non-blank line of ``data`` (for messages)."""
    seen = -1
    for number, text in enumerate(data.split(b"\n"), start=1):
        seen += bool(text.strip())
        if seen == index:
            return number
    return number


def write_off(path, vertices: np.ndarray, faces, point_data: dict) -> None:
    """Write ``OFF``, the counts, the vertices (17 significant digits) and the faces (0-based)."""
    with open(path, "w", encoding="ascii") as handle:
        handle.write(f"OFF\n{vertices.shape[0]} {len(faces)} 0\n")
        np.savetxt(handle, vertices, fmt="%.17g %.17g %.17g")
        if isinstance(faces, np.ndarray):
            k = faces.shape[1]
            np.savetxt(handle, np.column_stack([np.full(len(faces), k), faces]), fmt="%d" + " %d" * k)
        else:
            handle.writelines(f"{len(face)} " + " ".join(map(str, face)) + "\n" for face in faces)
