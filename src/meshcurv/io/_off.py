"""OFF, read and written with numpy.

meshio's OFF reader accepts triangles only and its writer keeps 12
significant digits; OFF is a plain list of numbers, so it is done here.
"""

from __future__ import annotations

import re

import numpy as np

from ..errors import MeshFileError

__all__ = ["read_off", "write_off"]

_COMMENT = re.compile(rb"#[^\n]*")


def read_off(path):
    """Read an OFF file: ``OFF``, ``V F E``, V lines of x y z, F lines of ``k i j ...`` (0-based)."""
    with open(path, "rb") as handle:
        data = _COMMENT.sub(b"", handle.read())
    tokens = data.split()
    if not tokens or tokens[0] != b"OFF":
        found = tokens[0][:20].decode("ascii", "replace") if tokens else ""
        raise MeshFileError(f"{path}: not an OFF file (it should start with 'OFF'; starts with {found!r})")
    try:
        n_vertices, n_faces = int(tokens[1]), int(tokens[2])
        end = 4 + 3 * n_vertices
        vertices = np.array(tokens[4:end], dtype=np.float64).reshape(-1, 3)
        corners = np.array(tokens[end:], dtype=np.int64)
    except (IndexError, ValueError) as exc:
        raise MeshFileError(f"{path}: the OFF counts, vertices or faces cannot be read ({exc})") from None
    if vertices.shape[0] != n_vertices:
        raise MeshFileError(f"{path}: the header announces {n_vertices} vertices; the file has {vertices.shape[0]}")
    if corners.size == 4 * n_faces and (corners[::4] == 3).all():
        return vertices, corners.reshape(-1, 4)[:, 1:]
    faces, position = [], 0
    for _ in range(n_faces):  # polygons (or face colours): the sizes decide where each face starts
        size = int(corners[position]) if position < corners.size else 0
        if size < 3 or position + 1 + size > corners.size:
            raise MeshFileError(f"{path}: face {len(faces)} is truncated or has fewer than 3 corners")
        faces.append(corners[position + 1:position + 1 + size])
        position += 1 + size
    return vertices, faces


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
