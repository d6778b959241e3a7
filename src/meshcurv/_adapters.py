"""Mesh objects of other libraries in and out, by duck typing (none of them is imported unless asked).

In: :func:`mesh_arrays` takes the vertices and faces of


=======================  ==========================================  ===========================
library                  recognised by                               faces from
=======================  ==========================================  ===========================
trimesh ``Trimesh``      ``.vertices`` and ``.faces`` arrays         ``faces``
PyVista ``PolyData``     ``.points`` and ``.faces`` (flat, counted)  the flat VTK cell array
meshio ``Mesh``          ``.points`` and ``.cells`` (cell blocks)    "triangle" (and "quad") blocks
Open3D ``TriangleMesh``  ``.vertices`` and ``.triangles``            ``triangles``
=======================  ==========================================  ===========================

Out: :func:`to_pyvista`, :func:`to_trimesh` and :func:`to_dataframe` put the
per-vertex fields of a :class:`~meshcurv.CurvatureResult` onto a
``pyvista.PolyData`` (``point_data``), a ``trimesh.Trimesh``
(``vertex_attributes``) or a ``pandas.DataFrame``; they are also the
result's methods (``result.to_pyvista(mesh)``, ...).
"""

from __future__ import annotations

import numpy as np

from .errors import InvalidMeshError, MissingDependencyError

__all__ = ["mesh_arrays", "to_pyvista", "to_trimesh", "to_dataframe"]


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


# ------------------------------------------------------------------------------------------- out


def _require(module: str, purpose: str, install: str):
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError as exc:
        raise MissingDependencyError(f"{purpose} needs {module}: pip install {install}") from exc


def _result_fields(result, fields) -> dict[str, np.ndarray]:
    from .io.fields import curvature_fields

    return curvature_fields(result, fields=fields, quality=None)


def _mesh_of(result, mesh, purpose: str) -> tuple[np.ndarray, object]:
    """``(vertices, faces)`` of ``mesh`` (a mesh object or a ``(vertices, faces)`` pair), checked against ``result``."""
    if mesh is None:
        surface = result._surface
        if surface is None or surface.index is not None:
            why = ("it has no mesh (a point cloud's, or built directly)" if surface is None else
                   "its mesh was welded (rows of copies were merged)")
            raise InvalidMeshError(f"{purpose}: pass the mesh the result was computed on; {why}")
        return np.array(surface.vertices), np.array(surface.faces)
    if isinstance(mesh, tuple) and len(mesh) == 2:
        vertices, faces = mesh
    else:
        vertices, faces = mesh_arrays(mesh)
    vertices = np.asarray(vertices, dtype=np.float64)
    if vertices.ndim != 2 or vertices.shape[1] != 3:
        raise InvalidMeshError(f"{purpose}: the mesh's vertices must have shape (V, 3); got {vertices.shape}")
    if vertices.shape[0] != result.n_vertices:
        raise InvalidMeshError(
            f"{purpose}: the mesh has {vertices.shape[0]} vertices but the result {result.n_vertices} rows; "
            "pass the mesh the result was computed on")
    return vertices, faces


def _flat_cells(faces) -> np.ndarray:
    """The VTK flat cell array ``[n0, i.., n1, j.., ...]`` of (F, k) faces or a list of index lists."""
    if isinstance(faces, np.ndarray) and faces.ndim == 2:
        return np.column_stack([np.full(faces.shape[0], faces.shape[1]), faces]).astype(np.int64).ravel()
    return np.concatenate([np.r_[len(face), np.asarray(face)] for face in faces]).astype(np.int64)


def to_pyvista(result, mesh=None, *, fields=None):
    """A ``pyvista.PolyData`` of the mesh with the result's fields as ``point_data``.

    Parameters
    ----------
    result : CurvatureResult
    mesh : pyvista.PolyData, other mesh object, or (vertices, faces), optional
        The mesh the result was computed on. A ``PolyData`` is copied (never
        changed) with its own point and cell data; other meshes are built
        anew. Default: the mesh the result keeps (when nothing was welded).
    fields : sequence of str, optional
        Names of :data:`meshcurv.io.fields.FIELDS` (default all): (V,)
        scalars, (V, 3) vectors (``dir_min``, ``dir_max``, ``normals``),
        ``valid`` as uint8.

    Returns
    -------
    pyvista.PolyData

    Raises
    ------
    MissingDependencyError
        PyVista is not installed.
    InvalidMeshError
        The mesh has another number of vertices than the result has rows, or
        no mesh was given and the result keeps none.
    """
    pv = _require("pyvista", "to_pyvista", "pyvista")
    values = _result_fields(result, fields)
    if isinstance(mesh, pv.PolyData):
        _mesh_of(result, mesh, "to_pyvista")
        out = mesh.copy(deep=True)
    else:
        vertices, faces = _mesh_of(result, mesh, "to_pyvista")
        out = pv.PolyData(vertices, _flat_cells(faces))
    for name, array in values.items():
        out.point_data[name] = array
    return out


def to_trimesh(result, mesh=None, *, fields=None):
    """A ``trimesh.Trimesh`` of the mesh with the result's fields in ``vertex_attributes``.

    Parameters
    ----------
    result : CurvatureResult
    mesh : trimesh.Trimesh, other mesh object, or (vertices, faces), optional
        As for :func:`to_pyvista`; a ``Trimesh`` is copied, others are
        built with ``process=False`` (vertices kept in their order). Faces
        with more than three corners are fan-triangulated.
    fields : sequence of str, optional
        As for :func:`to_pyvista`.

    Returns
    -------
    trimesh.Trimesh

    Raises
    ------
    MissingDependencyError
        trimesh is not installed.
    InvalidMeshError
        As for :func:`to_pyvista`.
    """
    trimesh = _require("trimesh", "to_trimesh", "trimesh")
    values = _result_fields(result, fields)
    if isinstance(mesh, trimesh.Trimesh):
        _mesh_of(result, mesh, "to_trimesh")
        out = mesh.copy()
    else:
        from .topology import triangulate_faces

        vertices, faces = _mesh_of(result, mesh, "to_trimesh")
        out = trimesh.Trimesh(vertices, triangulate_faces(faces), process=False)
    for name, array in values.items():
        out.vertex_attributes[name] = array
    return out


def to_dataframe(result, *, fields=None):
    """A ``pandas.DataFrame`` of the per-vertex fields, one row per vertex.

    Columns: the scalar fields by name, the vectors as ``<name>_x``,
    ``<name>_y``, ``<name>_z``, ``valid`` as bool, and ``vertex_area``
    (:attr:`~meshcurv.CurvatureResult.vertex_areas`, NaN when the result has
    no mesh) when ``fields`` is not given.

    Raises
    ------
    MissingDependencyError
        pandas is not installed.
    """
    pd = _require("pandas", "to_dataframe", "pandas")
    columns = {}
    for name, array in _result_fields(result, fields).items():
        if array.ndim == 2:
            columns.update({f"{name}_{axis}": array[:, k] for k, axis in enumerate("xyz")})
        else:
            columns[name] = array.astype(bool) if name == "valid" else array
    if fields is None:
        columns["vertex_area"] = np.asarray(result.vertex_areas)
    return pd.DataFrame(columns)
