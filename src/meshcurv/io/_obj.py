"""Wavefront OBJ, read and written with numpy (no optional dependency).

Only ``v`` and ``f`` records are kept, each corner's part before its first
slash (texture coordinates may outnumber the vertices, as in ``spot.obj``;
vertices are not split along UV seams), polygons and negative (relative)
indices accepted.
"""

from __future__ import annotations

import re
import warnings

import numpy as np

from ..errors import MeshFileError
from ._text import first_bad_line, line_of, line_of_match, numbers_per_line, without_bom

__all__ = ["read_obj", "write_obj"]

_VERTEX = re.compile(rb"^v[ \t]+([^\r\n#]*)", re.M)
_FACE = re.compile(rb"^f[ \t]+(\S+[ \t]+\S+[ \t]+\S+[^\r\n#]*)", re.M)
_CORNER_TAIL = re.compile(rb"/\S*")
_LEADING_BLANKS = re.compile(rb"^[ \t]+", re.M)
_FACE_START = re.compile(rb"^f[ \t][^\n]*", re.M)
_INTEGERS = re.compile(rb"[ \t]*[-+]?\d+(?:[ \t]+[-+]?\d+)*[ \t\r]*")


def read_obj(path):
    """Read the vertices and faces of an OBJ file.

    Returns
    -------
    vertices : ndarray of shape (V, 3), float64
    faces : ndarray of shape (F, k), int64, or list of int64 arrays when the
        faces have different numbers of corners. 0-based.
    """
    with open(path, "rb") as handle:
        data = without_bom(handle.read())
    if data[:1] in (b" ", b"\t") or b"\n " in data or b"\n\t" in data:
        data = _LEADING_BLANKS.sub(b"", data)
    vertex_lines = _VERTEX.findall(data)
    if not vertex_lines:
        raise MeshFileError(f"{path}: no vertices (`v` lines) found; is it an OBJ file?")
    parsed = numbers_per_line(vertex_lines)
    if parsed is None:
        index, word = first_bad_line(b"\n".join(vertex_lines))
        raise MeshFileError(
            f"{path}: line {line_of_match(data, _VERTEX, index)}: a vertex coordinate is not a "
            f"number ({word[:30].decode('utf-8', 'replace')!r})"
        )
    values, counts = parsed
    if (counts == 3).all():
        vertices = values.reshape(-1, 3)
    else:  # per line: `v x y z w` and `v x y z r g b` keep x y z; the next lines do not shift
        short = int(np.flatnonzero(counts < 3)[0]) if (counts < 3).any() else None
        if short is not None:
            raise MeshFileError(
                f"{path}: line {line_of_match(data, _VERTEX, short)}: a `v` line has fewer than "
                f"3 coordinates ({int(counts[short])})"
            )
        first = np.cumsum(counts) - counts
        vertices = values[first[:, None] + np.arange(3)]

    face_lines = _FACE.findall(data)
    n_face_lines = sum(data.count(b"\nf" + blank) + data.startswith(b"f" + blank) for blank in (b" ", b"\t"))
    if len(face_lines) != n_face_lines:
        line = next(line_of(data, m.start()) for m in _FACE_START.finditer(data) if not _FACE.match(m.group()))
        raise MeshFileError(f"{path}: line {line}: a face has fewer than 3 corners")
    if not face_lines:
        raise MeshFileError(f"{path}: no faces (`f` lines) found")
    joined = b"\n".join(face_lines)
    if b"/" in joined:
        joined = _CORNER_TAIL.sub(b"", joined)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            corners = np.fromstring(joined, dtype=np.int64, sep=" ")
    except (ValueError, DeprecationWarning):
        corners = np.zeros(0, dtype=np.int64)
    if corners.size == 3 * len(face_lines):  # every face has at least 3 corners: all triangles
        sizes = None
    else:
        lines = joined.split(b"\n")
        sizes = np.char.count(np.array([b" ".join(line.split()) for line in lines]), b" ") + 1
    if corners.size != (3 * len(face_lines) if sizes is None else sizes.sum()):  # a word is not an integer
        index = next((i for i, line in enumerate(joined.split(b"\n")) if not _INTEGERS.fullmatch(line)), 0)
        raise MeshFileError(f"{path}: line {line_of_match(data, _FACE, index)}: a face index is not an integer")
    if (corners < 0).any():
        corners = _resolve_relative(data, corners, sizes)
    if (corners == 0).any():
        line = _line_of_corner(data, sizes, int(np.argmax(corners == 0)))
        raise MeshFileError(f"{path}: line {line}: a face uses vertex index 0; OBJ indices start at 1")
    if corners.max() > vertices.shape[0]:
        line = _line_of_corner(data, sizes, int(np.argmax(corners)))
        raise MeshFileError(
            f"{path}: line {line}: a face uses vertex {int(corners.max())} but the file has {vertices.shape[0]} "
            "vertices"
        )
    corners -= 1
    if sizes is None:
        return vertices, corners.reshape(-1, 3)
    if (sizes == sizes[0]).all():
        return vertices, corners.reshape(-1, int(sizes[0]))
    return vertices, np.split(corners, np.cumsum(sizes)[:-1])


def _line_of_corner(data: bytes, sizes, corner: int) -> int:
    """The line number of the face holding the ``corner``-th corner (``sizes`` None: all triangles)."""
    face = corner // 3 if sizes is None else int(np.searchsorted(np.cumsum(sizes), corner, side="right"))
    return line_of_match(data, _FACE, face)


def _resolve_relative(data: bytes, corners: np.ndarray, sizes) -> np.ndarray:
    """Turn negative OBJ indices (-1 = the last vertex so far) into absolute 1-based ones."""
    text = np.frombuffer(data, dtype=np.uint8)
    starts = np.concatenate([[0], np.flatnonzero(text == ord("\n")) + 1])
    starts = starts[starts < text.size - 1]
    first, second = text[starts], text[starts + 1]
    blank = (second == ord(" ")) | (second == ord("\t"))
    is_vertex = (first == ord("v")) & blank
    is_face = (first == ord("f")) & blank
    seen = np.cumsum(is_vertex)[is_face]  # vertices defined before each face line
    per_corner = np.repeat(seen, 3 if sizes is None else sizes)
    return np.where(corners < 0, per_corner + 1 + corners, corners)


def write_obj(path, vertices: np.ndarray, faces, point_data: dict) -> None:
    """Write ``v`` and ``f`` records (1-based); OBJ has no place for per-vertex fields."""
    if point_data:
        raise MeshFileError(
            f"{path}: OBJ files cannot hold per-vertex fields; write .ply, .vtk, .vtu, .vtp, .csv or .npz"
        )
    with open(path, "w", encoding="ascii") as handle:
        handle.write(f"# written by meshcurv: {vertices.shape[0]} vertices, {len(faces)} faces\n")
        np.savetxt(handle, vertices, fmt="v %.17g %.17g %.17g")
        if isinstance(faces, np.ndarray):
            np.savetxt(handle, faces + 1, fmt="f" + " %d" * faces.shape[1])
        else:
            handle.writelines("f " + " ".join(map(str, face + 1)) + "\n" for face in faces)
