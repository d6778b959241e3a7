"""Mesh objects of other libraries as ``(vertices, faces)``, by duck typing (none of them is imported).

=======================  ==========================================  ===========================
library                  recognised by                               faces from
=======================  ==========================================  ===========================
trimesh ``Trimesh``      ``.vertices`` and ``.faces`` arrays         ``faces``
PyVista ``PolyData``     ``.points`` and ``.faces`` (flat, counted)  the flat VTK cell array
meshio ``Mesh``          ``.points`` and ``.cells`` (cell blocks)    "triangle" (and "quad") blocks
Open3D ``TriangleMesh``  ``.vertices`` and ``.triangles``            ``triangles``
=======================  ==========================================  ===========================
"""

from __future__ import annotations

import numpy as np

from .errors import InvalidMeshError

__all__ = ["mesh_arrays"]


def _vtk_cells(flat: np.ndarray):
    """The faces of a VTK flat cell array ``[n0, i.., n1, j.., ...]``: (F, k) when all equal, else a list."""
    flat = np.asarray(flat, dtype=np.int64).ravel()
    if flat.size == 0:
        return np.zeros((0, 3), dtype=np.int64)
    size = int(flat[0])
    if size > 0 and flat.size % (size + 1) == 0:
        table = flat.reshape(-1, size + 1)
        if (table[:, 0] == size).all():
            return table[:, 1:]
    faces, position = [], 0
    while position < flat.size:  # ragged polygons: a loop over faces only for mixed polygon sizes
        count = int(flat[position])
        if count < 1 or position + 1 + count > flat.size:
            raise InvalidMeshError("the PyVista mesh's face array is malformed (a count runs past its end)")
        faces.append(flat[position + 1:position + 1 + count])
        position += 1 + count
    return faces


def mesh_arrays(mesh) -> tuple[np.ndarray, object]:
    """``(vertices, faces)`` of a mesh object of trimesh, PyVista, meshio or Open3D.

    Raises
    ------
    InvalidMeshError
        The object is none of these, or has no faces.
    """
    kind = type(mesh).__name__
    if hasattr(mesh, "triangles") and hasattr(mesh, "vertices") and not hasattr(mesh, "faces"):
        return np.asarray(mesh.vertices), np.asarray(mesh.triangles)  # Open3D
    if hasattr(mesh, "points") and hasattr(mesh, "cells") and not hasattr(mesh, "faces"):  # meshio
        blocks = [(block.type, np.asarray(block.data)) for block in mesh.cells]
        faces = [data for cell_type, data in blocks if cell_type in ("triangle", "quad", "polygon")]
        if not faces:
            raise InvalidMeshError(
                f"the meshio mesh has no surface cells (triangle, quad or polygon); it has "
                f"{', '.join(t for t, _ in blocks) or 'no cells'}")
        polygons = faces[0] if len(faces) == 1 else [face for block in faces for face in block]
        return np.asarray(mesh.points), polygons
    if hasattr(mesh, "points") and hasattr(mesh, "faces"):  # PyVista PolyData
        if np.asarray(mesh.faces).size == 0:
            raise InvalidMeshError(f"the {kind} has no polygon faces (lines, vertices or strips only?)")
        return np.asarray(mesh.points), _vtk_cells(mesh.faces)
    if hasattr(mesh, "vertices") and hasattr(mesh, "faces"):  # trimesh (and alike)
        return np.asarray(mesh.vertices), np.asarray(mesh.faces)
    raise InvalidMeshError(
        f"`vertices` is a {kind}, not an array, and not a mesh object meshcurv knows (trimesh.Trimesh, "
        "pyvista.PolyData, meshio.Mesh, open3d.geometry.TriangleMesh); pass `vertices, faces` arrays")
