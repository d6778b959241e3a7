"""Mesh objects of other libraries in and out, by duck typing (none of them is imported unless asked).

In: :func:`mesh_arrays` takes the vertices and faces of

=============================  ==========================================  ==================================
library                        recognised by                               faces from
=============================  ==========================================  ==================================
trimesh ``Trimesh``            ``.vertices`` and ``.faces`` arrays         ``faces``
PyVista ``PolyData``           ``.points``, ``.faces`` and ``.strips``     the flat VTK cell arrays
PyVista ``UnstructuredGrid``   ``.points`` and ``.celltypes``              triangle, quad, pixel, polygon cells
meshio ``Mesh``                ``.points`` and ``.cells`` (cell blocks)    "triangle" (and "quad") blocks
Open3D ``TriangleMesh``        ``.vertices`` and ``.triangles``            ``triangles``
=============================  ==========================================  ==================================

An ``UnstructuredGrid`` is what ``pyvista.read`` returns for ``.vtu`` and
legacy ``.vtk`` files (meshcurv's own outputs included). Its vertex and line
cells are left out, as a ``PolyData``'s are; a grid with volume cells
(tetrahedra, hexahedra, ...), triangle strips or higher-order cells is
refused with an error that names them and suggests ``grid.extract_surface()``:
its surface is not a guess meshcurv makes (inner faces of a volume mesh, a
boundary the user may want open or closed), and the one call says which.

:func:`point_array` takes the points of the same objects and of point
clouds (PyVista ``PointSet``, trimesh ``PointCloud``, Open3D ``PointCloud``):
anything with a ``.points`` or ``.vertices`` array. :func:`drawn_arrays` takes
either, checked as the computations check them, for the pictures and the viewer.

Out: :func:`to_pyvista`, :func:`to_trimesh` and :func:`to_dataframe` put the
per-vertex fields of a :class:`~meshcurv.CurvatureResult` onto a
``pyvista.PolyData`` (``point_data``), a ``trimesh.Trimesh``
(``vertex_attributes``) or a ``pandas.DataFrame``; they are also the
result's methods (``result.to_pyvista(mesh)``, ...).
"""

from __future__ import annotations

import numpy as np

from ._validation import as_mesh, as_vertices
from .errors import InvalidMeshError, optional_module
from .io.fields import curvature_fields
from .topology import MeshTopology, strip_triangles, triangulate_faces

__all__ = ["mesh_arrays", "point_array", "drawn_arrays", "to_pyvista", "to_trimesh", "to_dataframe"]


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
    ids, sizes = _counted(flat, "face", least=1)  # ragged polygons: mixed polygon sizes
    return np.split(ids, np.cumsum(sizes)[:-1])


def _counted(flat: np.ndarray, what: str, *, least: int) -> tuple[np.ndarray, np.ndarray]:
    """``(ids, sizes)``: a VTK flat counted array ``[n0, i.., n1, j.., ...]`` without its counts, and the counts
    (each at least ``least``); a walk over the counts only."""
    counts, position = [], 0
    while position < flat.size:
        count = int(flat[position])
        if count < least or position + 1 + count > flat.size:
            raise InvalidMeshError(f"the PyVista mesh's {what} array is malformed (a count runs past its end)")
        counts.append(count)
        position += 1 + count
    sizes = np.asarray(counts, dtype=np.int64)
    keep = np.ones(flat.size, dtype=bool)
    keep[np.cumsum(sizes + 1) - sizes - 1] = False  # the place of each count in ``flat``
    return flat[keep], sizes


def _strip_triangles(flat: np.ndarray) -> np.ndarray:
    """(T, 3) the triangles of a VTK flat array of triangle strips ``[n0, i.., n1, j.., ...]``
    (:func:`meshcurv.topology.strip_triangles`)."""
    ids, sizes = _counted(np.asarray(flat, dtype=np.int64).ravel(), "strip", least=0)
    return strip_triangles(ids, np.cumsum(sizes))


#: VTK cell types (``vtkCellType.h``) taken as faces; a pixel's corners run 0, 1, 3, 2 around it.
_VTK_SURFACE_CELLS = {5: "triangle", 7: "polygon", 8: "pixel", 9: "quad"}

#: VTK cell types left out as a ``PolyData``'s vertices and lines are: they bound no surface.
_VTK_POINT_AND_LINE_CELLS = {1: "vertex", 2: "poly_vertex", 3: "line", 4: "poly_line"}

#: Names of the other VTK cell types an error may name (others by number).
_OTHER_NAMES = "triangle_strip tetra voxel hexahedron wedge pyramid pentagonal_prism hexagonal_prism quadratic_edge"
_OTHER_NAMES += " quadratic_triangle quadratic_quad quadratic_tetra quadratic_hexahedron polyhedron"
_VTK_OTHER_CELLS = dict(zip((6, 10, 11, 12, 13, 14, 15, 16, 21, 22, 23, 24, 25, 42), _OTHER_NAMES.split()))

_KNOWN_MESHES = "trimesh.Trimesh, pyvista.PolyData, pyvista.UnstructuredGrid, meshio.Mesh, open3d.geometry.TriangleMesh"


def _cell_name(cell_type: int) -> str:
    known = {**_VTK_SURFACE_CELLS, **_VTK_POINT_AND_LINE_CELLS, **_VTK_OTHER_CELLS}
    return known.get(cell_type, f"VTK cell type {cell_type}")


def _grid_faces(grid):
    """The surface cells of a PyVista ``UnstructuredGrid`` as faces: (F, k) when all have k corners, else a list."""
    kind = type(grid).__name__
    types = np.asarray(grid.celltypes, dtype=np.int64).ravel()
    surface = np.isin(types, list(_VTK_SURFACE_CELLS))
    other = ~surface & ~np.isin(types, list(_VTK_POINT_AND_LINE_CELLS))
    if other.any():
        found, counts = np.unique(types[other], return_counts=True)
        listed = ", ".join(f"{n} {_cell_name(int(t))}" for t, n in zip(found, counts))
        raise InvalidMeshError(
            f"the {kind} has cells that are not surface polygons ({listed}); meshcurv computes the curvature "
            "of surfaces: pass its boundary surface, `grid.extract_surface().triangulate()` (PyVista)"
        )
    if not surface.any():
        raise InvalidMeshError(
            f"the {kind} has no surface cells (triangle, quad, pixel or polygon); it has "
            + (
                ", ".join(f"{n} {_cell_name(int(t))}" for t, n in zip(*np.unique(types, return_counts=True)))
                or "no cells"
            )
        )
    # cell_offsets in PyVista >= 0.45 (offset before, deprecated since): n_cells + 1 starts in the connectivity
    offsets = grid.cell_offsets if hasattr(type(grid), "cell_offsets") else grid.offset
    offsets = np.asarray(offsets, dtype=np.int64).ravel()
    connectivity = np.asarray(grid.cell_connectivity, dtype=np.int64).ravel()
    starts = offsets[:-1][surface]
    lengths = np.diff(offsets)[surface]
    pixels = types[surface] == 8
    if lengths.min() == lengths.max():
        faces = connectivity[starts[:, None] + np.arange(lengths[0])]
        if pixels.any():
            faces[pixels] = faces[pixels][:, [0, 1, 3, 2]]
        return faces
    # faces of several lengths: one gather of all their corners, then one array per face
    corner = np.arange(lengths.sum()) - np.repeat(np.cumsum(lengths) - lengths, lengths)
    if pixels.any():  # a pixel's corners 2 and 3 swap places
        corner = np.where(np.repeat(pixels, lengths), np.array([0, 1, 3, 2])[np.minimum(corner, 3)], corner)
    flat = connectivity[np.repeat(starts, lengths) + corner]
    return np.split(flat, np.cumsum(lengths)[:-1])


def _array_summary(value) -> str | None:
    """``"an int64 array of shape (12, 3)"`` for an array or a list that converts to numbers, else None."""
    try:
        array = np.asarray(value)
    except (ValueError, TypeError, OverflowError):
        return None
    if array.dtype == object or not (np.issubdtype(array.dtype, np.number) or array.dtype == bool):
        return None
    return f"{'an' if array.dtype.name[0] in 'aeiou' else 'a'} {array.dtype} array of shape {array.shape}"


def mesh_arrays(mesh) -> tuple[np.ndarray, object]:
    """``(vertices, faces)`` of a mesh object of trimesh, PyVista (``PolyData``, ``UnstructuredGrid``), meshio or Open3D.

    Raises
    ------
    InvalidMeshError
        The object is none of these, has no faces, or has cells that are not
        surface polygons (a volume mesh: tetrahedra, hexahedra, ...); an array
        (the vertices alone, or faces given as vertices) is told to come with
        its faces.
    """
    kind = type(mesh).__name__
    if isinstance(mesh, (np.ndarray, list, tuple)):
        summary = _array_summary(mesh)
        if summary is not None:
            array = np.asarray(mesh)
            looks_like_faces = np.issubdtype(array.dtype, np.integer) and array.ndim == 2 and array.shape[1] >= 3
            hint = (
                " (integer indices: it looks like the faces; pass the vertices first)"
                if looks_like_faces
                else "; for points without faces use meshcurv.point_cloud_curvatures"
            )
            raise InvalidMeshError(
                f"`faces` is missing: `vertices` is {summary}, not a mesh object; pass "
                f"`principal_curvatures(vertices, faces)`{hint}"
            )
    if hasattr(mesh, "triangles") and hasattr(mesh, "vertices") and not hasattr(mesh, "faces"):
        return np.asarray(mesh.vertices), np.asarray(mesh.triangles)  # Open3D
    if hasattr(mesh, "points") and hasattr(mesh, "celltypes") and hasattr(mesh, "cell_connectivity"):
        return np.asarray(mesh.points), _grid_faces(mesh)  # PyVista UnstructuredGrid (before meshio: both have .cells)
    if hasattr(mesh, "points") and hasattr(mesh, "cells") and not hasattr(mesh, "faces"):  # meshio
        blocks = [(block.type, np.asarray(block.data)) for block in mesh.cells]
        faces = [data for cell_type, data in blocks if cell_type in ("triangle", "quad", "polygon")]
        if not faces:
            raise InvalidMeshError(
                f"the meshio mesh has no surface cells (triangle, quad or polygon); it has "
                f"{', '.join(t for t, _ in blocks) or 'no cells'}"
            )
        polygons = faces[0] if len(faces) == 1 else [face for block in faces for face in block]
        return np.asarray(mesh.points), polygons
    if hasattr(mesh, "points") and hasattr(mesh, "faces"):  # PyVista PolyData
        polygons, strips = np.asarray(mesh.faces), np.asarray(getattr(mesh, "strips", np.zeros(0)))
        if polygons.size == 0 and strips.size == 0:
            raise InvalidMeshError(f"the {kind} has no polygon faces and no triangle strips (lines or vertices only?)")
        if strips.size == 0:
            return np.asarray(mesh.points), _vtk_cells(polygons)
        triangles = _strip_triangles(strips)  # triangle strips (``PolyData.strip()``, some VTK files): their triangles
        faces = _vtk_cells(polygons)
        if isinstance(faces, np.ndarray) and faces.shape[1] == 3:
            return np.asarray(mesh.points), np.concatenate([faces, triangles])
        return np.asarray(mesh.points), [*faces, *triangles]
    if hasattr(mesh, "vertices") and hasattr(mesh, "faces"):  # trimesh (and alike)
        return np.asarray(mesh.vertices), np.asarray(mesh.faces)
    if hasattr(mesh, "points") or hasattr(mesh, "vertices"):  # PyVista PointSet, trimesh or Open3D PointCloud
        raise InvalidMeshError(
            f"`vertices` is a {kind}, which has points but no faces; for a point cloud use "
            "meshcurv.point_cloud_curvatures, or pass `vertices, faces` arrays"
        )
    raise InvalidMeshError(
        f"`vertices` is a {kind}, not an array, and not a mesh object meshcurv knows ({_KNOWN_MESHES}); "
        "pass `vertices, faces` arrays"
    )


def point_array(points, *, name: str = "points"):
    """The points of a point cloud or mesh object, or ``points`` itself when it is an array or a list.

    Parameters
    ----------
    points : array_like of shape (N, 3), or an object with a ``.points`` or ``.vertices`` array
        PyVista ``PolyData``, ``PointSet`` and ``UnstructuredGrid``, trimesh
        ``Trimesh`` and ``PointCloud``, Open3D ``PointCloud`` and
        ``TriangleMesh``, meshio ``Mesh``, ... (none of them imported).
        Arrays, lists and objects that convert to arrays (``__array__``:
        pandas ``DataFrame``, ...) are returned as they are, for the caller's
        check of their shape and values.
    name : str, default: 'points'
        The argument's name, for the error.

    Returns
    -------
    array_like

    Raises
    ------
    InvalidMeshError
        An object that is none of these (it would otherwise be read as an
        array of one Python object).
    """
    if isinstance(points, (np.ndarray, list, tuple)) or hasattr(points, "__array__"):
        return points
    for attribute in ("points", "vertices"):
        value = getattr(points, attribute, None)
        if value is not None and not callable(value):
            return np.asarray(value)
    raise InvalidMeshError(
        f"`{name}` is a {type(points).__name__}, not an array of shape (N, 3), nor an object with a `.points` "
        "or `.vertices` array (pyvista.PolyData, PointSet or UnstructuredGrid, trimesh.Trimesh or PointCloud, "
        "open3d.geometry.PointCloud, meshio.Mesh)"
    )


def _no_faces(faces) -> bool:
    """True for None and for an empty face array or list (the points are drawn alone)."""
    return faces is None or (not isinstance(faces, MeshTopology) and hasattr(faces, "__len__") and len(faces) == 0)


def _is_point_cloud(thing) -> bool:
    """True for points alone: an array or list, or an object of points without faces (PyVista ``PointSet``, ...)."""
    if isinstance(thing, (np.ndarray, list, tuple)) or hasattr(thing, "__array__"):
        return True
    if hasattr(thing, "points") and hasattr(thing, "faces"):  # PyVista PolyData: of points when it has no faces
        return np.asarray(thing.faces).size == 0
    has_points = hasattr(thing, "points") or hasattr(thing, "vertices")  # else neither: the error of a mesh
    return has_points and not any(hasattr(thing, name) for name in ("faces", "triangles", "cells", "celltypes"))


def drawn_arrays(vertices, faces=None, *, stacklevel: int = 3) -> tuple[np.ndarray, np.ndarray | None]:
    """``(points, triangles)`` of a mesh or a point cloud to draw, checked once at the door of the computations.

    Parameters
    ----------
    vertices : array_like of shape (V, 3), or a mesh or point cloud object
        What :func:`meshcurv.principal_curvatures` takes as ``vertices``
        (with ``faces`` left out: a mesh object, :func:`mesh_arrays`), or
        what :func:`meshcurv.point_cloud_curvatures` takes (an array, or an
        object of points alone, :func:`point_array`).
    faces : array_like of shape (F, 3) or (F, k), list of index lists, or MeshTopology, optional
        As for :func:`meshcurv.principal_curvatures`; None or empty: the
        points alone (or the mesh object's faces).
    stacklevel : int, default: 3
        The frame a :class:`~meshcurv.errors.TriangulationWarning` is attributed
        to (1: this function).

    Returns
    -------
    points : (V, 3) float64 array
        New, finite (:func:`meshcurv._validation.as_mesh`).
    triangles : (F, 3) int64 array or None
        Fan-triangulated, indices checked; None for points alone.

    Raises
    ------
    InvalidMeshError
        As :func:`meshcurv.principal_curvatures` (or
        :func:`meshcurv.point_cloud_curvatures` for points alone).
    """
    if _no_faces(faces):
        if _is_point_cloud(vertices):
            return as_vertices(point_array(vertices, name="vertices")), None
        vertices, faces = mesh_arrays(vertices)
    if isinstance(faces, MeshTopology):  # its faces, checked against these vertices
        faces = faces.faces
    return as_mesh(vertices, faces, stacklevel=stacklevel + 1)


# ------------------------------------------------------------------------------------------- out


def _require(module: str, purpose: str, install: str):
    return optional_module(module, f"{purpose} needs {module}: pip install {install}")


def _result_fields(result, fields) -> dict[str, np.ndarray]:
    return curvature_fields(result, fields=fields, quality=None)


def _mesh_of(result, mesh, purpose: str) -> tuple[np.ndarray, object]:
    """``(vertices, faces)`` of ``mesh`` (a mesh object or a ``(vertices, faces)`` pair), checked against ``result``."""
    if mesh is None:
        surface = result._surface
        if surface is None or surface.index is not None:
            why = (
                "it has no mesh (a point cloud's, or built directly)"
                if surface is None
                else "its mesh was welded (rows of copies were merged)"
            )
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
            "pass the mesh the result was computed on"
        )
    return vertices, faces


def _flat_cells(faces) -> np.ndarray:
    """The VTK flat cell array ``[n0, i.., n1, j.., ...]`` of (F, k) faces or a list of index lists."""
    if isinstance(faces, np.ndarray) and faces.ndim == 2:
        return np.column_stack([np.full(faces.shape[0], faces.shape[1]), faces]).astype(np.int64).ravel()
    return np.concatenate([np.r_[len(face), np.asarray(face)] for face in faces]).astype(np.int64)


def to_pyvista(result, mesh=None, *, fields=None):
    """:meth:`meshcurv.CurvatureResult.to_pyvista` (parameters, result and errors there): a ``pyvista.PolyData``."""
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
    """:meth:`meshcurv.CurvatureResult.to_trimesh` (parameters, result and errors there): a ``trimesh.Trimesh``."""
    trimesh = _require("trimesh", "to_trimesh", "trimesh")
    values = _result_fields(result, fields)
    if isinstance(mesh, trimesh.Trimesh):
        _mesh_of(result, mesh, "to_trimesh")
        out = mesh.copy()
    else:
        vertices, faces = _mesh_of(result, mesh, "to_trimesh")
        out = trimesh.Trimesh(vertices, triangulate_faces(faces), process=False)
    for name, array in values.items():
        out.vertex_attributes[name] = array
    return out


def to_dataframe(result, *, fields=None):
    """:meth:`meshcurv.CurvatureResult.to_dataframe` (parameters, result and errors there): a ``pandas.DataFrame``."""
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
