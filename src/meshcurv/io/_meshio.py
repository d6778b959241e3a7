"""PLY, STL and VTK (legacy .vtk, XML .vtu) through meshio, an optional extra.

OFF is done in :mod:`._off` (meshio's OFF reader takes triangles only and its
writer keeps 12 significant digits).
"""

from __future__ import annotations

import contextlib
import io
import logging
import re

import numpy as np

from ..errors import MeshFileError, optional_module
from ._text import line_of, line_of_match, not_a_number, numbers_per_line, row_error, without_bom

__all__ = ["read_with_meshio", "write_with_meshio"]

logger = logging.getLogger(__name__)

_SURFACE_CELLS = ("triangle", "quad", "polygon")
#: the numbers of the rows of an ASCII STL that meshio reads as the last three numbers of the line
_STL_VERTEX = re.compile(rb"^[ \t]*vertex[ \t]+([^\n]*)", re.M)
_STL_NORMAL = re.compile(rb"^[ \t]*facet[ \t]+normal[ \t]+([^\n]*)", re.M)


def _meshio():
    return optional_module(
        "meshio", "reading and writing PLY, STL, VTK and VTU files needs meshio: pip install 'meshcurv[io]'"
    )


@contextlib.contextmanager
def _to_log():
    """Send what meshio prints on stderr (its warnings) to this module's logger instead."""
    captured = io.StringIO()
    try:
        with contextlib.redirect_stderr(captured):
            yield
    finally:
        for line in captured.getvalue().splitlines():
            if line.strip():
                logger.info("meshio: %s", line.strip())


def check_stl(path):
    """Refuse what is neither a binary STL (its size matches its triangle count) nor starts with ``solid``.

    Returns None for a binary STL (meshio reads it) and ``(vertices, faces)``
    for an ASCII one, read here: meshio's ASCII STL reader takes the last
    three numbers of any line and cuts the rows into facets by fours, so an
    OBJ file named .stl, a ``vertex`` row of four numbers or a loop of four
    vertices beside one of two would be read as shifted triangles, and a
    blank line makes it fail.
    """
    with open(path, "rb") as handle:
        head = handle.read(84)
    size = path.stat().st_size
    if len(head) == 84 and 84 + 50 * int.from_bytes(head[80:84], "little") == size:
        return None
    if not without_bom(head).lstrip().startswith(b"solid"):
        raise MeshFileError(
            f"{path}: not an STL file (not a binary STL: its size does not match its triangle count; "
            "not an ASCII STL: it does not start with 'solid')"
        )
    with open(path, "rb") as handle:
        return read_ascii_stl(path, without_bom(handle.read()))


def read_ascii_stl(path, data: bytes):
    """The triangles of an ASCII STL: ``facet normal`` rows, each followed by 3 ``vertex x y z`` rows.

    Every ``vertex`` and ``facet normal`` row must hold 3 numbers and every
    facet 3 vertices (an error names the line otherwise). Repeated corners
    are merged into one vertex, in the order they first appear (as meshio).
    """
    found = {}
    for pattern, what in ((_STL_VERTEX, "vertex x y z"), (_STL_NORMAL, "facet normal nx ny nz")):
        rows = pattern.findall(data)
        parsed = numbers_per_line(rows)
        if parsed is None:
            raise not_a_number(path, b"\n".join(rows), lambda i: line_of_match(data, pattern, i), what)
        wrong = parsed[1] != 3
        if wrong.any():
            index = int(np.argmax(wrong))
            raise row_error(path, line_of_match(data, pattern, index), int(parsed[1][index]), 3, what)
        found[what] = parsed[0].reshape(-1, 3)
    corners = found["vertex x y z"]
    facets = np.array([m.start() for m in _STL_NORMAL.finditer(data)], dtype=np.int64)
    starts = np.array([m.start() for m in _STL_VERTEX.finditer(data)], dtype=np.int64)
    owner = np.searchsorted(facets, starts, side="right") - 1  # the facet each vertex row follows
    if facets.size == 0 or (owner < 0).any():
        where = f"line {line_of(data, int(starts[0]))}: a vertex before any facet" if starts.size else "no facets"
        raise MeshFileError(f"{path}: {where} (an ASCII STL lists 'facet normal' rows, each with 3 vertices)")
    per_facet = np.bincount(owner, minlength=facets.size)
    if (per_facet != 3).any():
        facet = int(np.argmax(per_facet != 3))
        raise MeshFileError(
            f"{path}: line {line_of(data, int(facets[facet]))}: a facet of {per_facet[facet]} "
            "vertices; an STL facet is a triangle of 3"
        )
    _, first, inverse = np.unique(corners, axis=0, return_index=True, return_inverse=True)
    order = np.argsort(first)  # the merged vertices in the order they first appear
    rank = np.zeros_like(order)
    rank[order] = np.arange(order.size)
    return corners[first[order]], rank[inverse.ravel()].reshape(-1, 3)


def read_meshio_file(path, file_format: str):
    """The ``meshio.Mesh`` of a file, read by the format's own reader (``meshio.vtu.read``, ...).

    Not ``meshio.read``, which prints and calls ``sys.exit(1)`` when a reader
    fails: any failure is one :class:`MeshFileError` naming the file.
    """
    reader = getattr(_meshio(), file_format).read
    try:
        # errstate: meshio's STL reader tests for binary by multiplying a uint32 header count
        with _to_log(), np.errstate(over="ignore"):
            return reader(str(path))
    except Exception as exc:  # any parser failure becomes one readable error naming the file
        reason = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise MeshFileError(f"{path}: cannot be read as {file_format.upper()} ({reason})") from exc


def read_with_meshio(path, file_format: str):
    """Read the vertices and the surface faces (triangles, quads, polygons) of a mesh file.

    Calls the format's own reader (``meshio.ply.read``, ...): ``meshio.read``
    prints and calls ``sys.exit(1)`` when a reader fails.
    """
    mesh = read_meshio_file(path, file_format)
    blocks = [np.asarray(block.data, dtype=np.int64) for block in mesh.cells if block.type in _SURFACE_CELLS]
    points = np.asarray(mesh.points, dtype=np.float64)
    if not blocks or sum(len(b) for b in blocks) == 0:
        found = sorted({block.type for block in mesh.cells}) or ["none"]
        raise MeshFileError(
            f"{path}: the file has no surface faces (triangles or polygons); cells found: {', '.join(found)}"
        )
    if points.ndim != 2 or points.shape[1] not in (2, 3):
        raise MeshFileError(f"{path}: vertices must have 3 coordinates; got shape {points.shape}")
    if points.shape[1] == 2:
        points = np.column_stack([points, np.zeros(points.shape[0])])
    if len({b.shape[1] for b in blocks}) == 1:
        return points, np.concatenate(blocks)
    return points, [face for block in blocks for face in block]


def _cells(faces):
    """meshio cell blocks for an (F, k) array or a list of index arrays, grouped by size."""
    if isinstance(faces, np.ndarray):
        groups = {faces.shape[1]: faces}
    else:
        sizes = np.array([len(face) for face in faces])
        groups = {int(k): np.array([faces[i] for i in np.flatnonzero(sizes == k)]) for k in np.unique(sizes)}
    names = {3: "triangle", 4: "quad"}
    return [(names.get(k, "polygon"), block.astype(np.int32)) for k, block in groups.items()]


def write_with_meshio(path, vertices, faces, point_data: dict, *, file_format: str, binary: bool) -> None:
    """Write a mesh and its per-vertex fields (already flattened for PLY by the caller)."""
    meshio = _meshio()
    options: dict[str, bool | str] = {"binary": binary}
    if file_format == "vtk":
        options["fmt_version"] = "4.2"  # the legacy layout every VTK and ParaView version reads
    mesh = meshio.Mesh(vertices, _cells(faces), point_data=point_data)
    try:
        with _to_log():
            getattr(meshio, file_format).write(str(path), mesh, **options)
    except Exception as exc:
        raise MeshFileError(f"{path}: cannot be written as {file_format.upper()} ({exc})") from exc
