"""Mesh files in and out: one registry of formats keyed by file extension.

============  =====================  =========================  ==================
extension     format                 per-vertex fields          needs
============  =====================  =========================  ==================
.obj          Wavefront OBJ          no                         (numpy)
.ply          PLY, binary or ASCII   float properties           (numpy) [1]_
.stl          STL, binary or ASCII   no                         meshcurv[io]
.off          OFF                    no                         (numpy)
.vtk          legacy VTK             point data, vectors        meshcurv[io] [2]_
.vtu          VTK XML unstructured   point data, vectors        meshcurv[io]
.vtp          VTK XML PolyData       point data, vectors        (numpy)
.csv          table, one row/vertex  columns (write only)       (numpy)
.npz          numpy archive          arrays                     (numpy)
============  =====================  =========================  ==================

.. [1] Writing PLY needs meshcurv[io]; reading needs only numpy.
.. [2] Reading a legacy POLYDATA file (what VTK and ParaView write for
   surfaces) needs only numpy; UNSTRUCTURED_GRID files and writing need meshio.

PLY (:mod:`._ply`), legacy VTK POLYDATA (:mod:`._vtk`), OBJ, OFF and VTP are
read here with numpy, every count a header declares checked against the size
of the file before anything is allocated; STL, UNSTRUCTURED_GRID .vtk and
.vtu go through meshio, and so does writing PLY, STL, VTK and VTU. Outputs
are written to a temporary file and published atomically, without replacing
a file that appeared meanwhile unless ``overwrite=True``. Every failure to
read or write is a :class:`~meshcurv.errors.MeshFileError` naming the file.
"""

from __future__ import annotations

import logging
import pathlib
from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from .._validation import _check_range, as_polygons, as_vertices
from ..errors import InvalidMeshError, InvalidOptionError, MeshFileError, MissingDependencyError
from . import _meshio, _obj, _off, _ply, _tables, _vtk, _vtp
from ._files import atomic_output, check_input, check_output, format_key, named_fields
from ._points import POINT_EXTENSIONS, is_point_cloud, read_points, write_point_curvatures, write_points
from .fields import FIELDS, curvature_fields, read_fields

__all__ = [
    "Mesh",
    "FileFormat",
    "FORMATS",
    "read_mesh",
    "write_mesh",
    "write_curvatures",
    "read_fields",
    "curvature_fields",
    "FIELDS",
    "read_points",
    "write_points",
    "write_point_curvatures",
    "is_point_cloud",
    "POINT_EXTENSIONS",
]

logger = logging.getLogger(__name__)


class Mesh(NamedTuple):
    """What :func:`read_mesh` returns; unpacks as ``vertices, faces``.

    Attributes
    ----------
    vertices : ndarray of shape (V, 3), float64
        Finite coordinates.
    faces : ndarray of shape (F, 3) or (F, k), int64, or list of ndarray
        0-based indices in ``[0, V)``: triangles, polygons of k corners, or
        one array per face when their sizes differ.
    """

    vertices: np.ndarray
    """(V, 3) float64 coordinates."""
    faces: np.ndarray | list
    """(F, 3) int64 0-based triangles; (F, k) for polygons, a list of arrays when mixed."""


@dataclass(frozen=True)
class FileFormat:
    """A file format of the registry.

    Attributes
    ----------
    name : str
    extensions : tuple of str
    fields : {'vectors', 'scalars', 'none'}
        What per-vertex data it holds: arrays of any width, scalar properties
        only (vectors are split into ``_x, _y, _z``), or nothing.
    read : callable or None
        ``read(path) -> (vertices, faces)``; None for write-only formats.
    write : callable
        ``write(path, vertices, faces, point_data, binary)``.
    """

    name: str
    extensions: tuple
    fields: str
    read: Callable | None
    write: Callable


def _meshio_format(file_format: str):
    def read(path):
        if file_format == "stl":
            ascii_mesh = _meshio.check_stl(path)  # ASCII read here: meshio shifts rows of the wrong length
            if ascii_mesh is not None:
                return ascii_mesh
        if file_format == "ply":
            return _ply.read_ply(path)  # our own bounded reader: meshio's loops on a header cut short
        if file_format == "vtk" and _vtk.is_polydata(path):
            return _vtk.read_vtk_polydata(path)  # meshio reads only UNSTRUCTURED_GRID legacy files
        return _meshio.read_with_meshio(path, file_format)

    def write(path, vertices, faces, point_data, binary):
        if file_format == "ply":
            point_data = {
                name: value.astype(np.float32) if value.dtype.kind == "f" else value
                for name, value in _tables.flat_columns(point_data).items()
            }
        _meshio.write_with_meshio(
            path, vertices, faces, point_data, file_format=file_format, binary=binary or file_format == "vtu"
        )

    return read, write


def _plain(function):
    def write(path, vertices, faces, point_data, binary):
        function(path, vertices, faces, point_data)

    return write


def _registry() -> dict[str, FileFormat]:
    formats = [
        FileFormat("Wavefront OBJ", (".obj",), "none", _obj.read_obj, _plain(_obj.write_obj)),
        FileFormat("PLY", (".ply",), "scalars", *_meshio_format("ply")),
        FileFormat("STL", (".stl",), "none", *_meshio_format("stl")),
        FileFormat("OFF", (".off",), "none", _off.read_off, _plain(_off.write_off)),
        FileFormat("legacy VTK", (".vtk",), "vectors", *_meshio_format("vtk")),
        FileFormat("VTK XML UnstructuredGrid", (".vtu",), "vectors", *_meshio_format("vtu")),
        FileFormat("VTK XML PolyData", (".vtp",), "vectors", _vtp.read_vtp, _plain(_vtp.write_vtp)),
        FileFormat("CSV table", (".csv",), "scalars", None, _plain(_tables.write_csv)),
        FileFormat("NumPy NPZ", (".npz",), "vectors", _tables.read_npz, _plain(_tables.write_npz)),
    ]
    return {extension: fmt for fmt in formats for extension in fmt.extensions}


#: The known formats, keyed by lower-case file extension (with its dot).
FORMATS: dict[str, FileFormat] = _registry()


def _format_of(path: pathlib.Path, file_format: str | None) -> FileFormat:
    return FORMATS[format_key(path, file_format, FORMATS, "mesh file")]


def read_mesh(path, *, file_format: str | None = None) -> Mesh:
    """Read a triangle (or polygon) mesh from a file.

    Parameters
    ----------
    path : str or os.PathLike
    file_format : str, optional
        An extension of :data:`FORMATS` (``'ply'`` or ``'.ply'``); by default
        the file's own extension.

    Returns
    -------
    Mesh
        A named tuple ``(vertices, faces)``: (V, 3) float64 coordinates and
        0-based int64 faces, (F, 3) for triangles ((F, k) for polygons, a list
        of index arrays when the sizes differ).

    Raises
    ------
    MeshFileError
        Missing file, directory, empty file, unknown extension, a file the
        parser cannot read (truncated, another format under this extension),
        no vertices or faces, NaN coordinates or out-of-range indices.
    MissingDependencyError
        STL, VTU and legacy VTK other than POLYDATA need ``pip install 'meshcurv[io]'``.

    Examples
    --------
    >>> import meshcurv, pathlib, tempfile
    >>> torus = meshcurv.shapes.torus()
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "torus.obj"
    >>> _ = meshcurv.write_mesh(path, torus.vertices, torus.faces)
    >>> vertices, faces = meshcurv.read_mesh(path)
    >>> vertices.shape, faces.shape
    ((3600, 3), (7200, 3))
    """
    path = pathlib.Path(path)
    fmt = _format_of(path, file_format)
    if fmt.read is None:
        raise MeshFileError(f"{path}: {fmt.name} files hold per-vertex values, not a mesh; they cannot be read back")
    path = check_input(path)
    try:
        vertices, faces = fmt.read(path)
    except (MeshFileError, MissingDependencyError, MemoryError):
        raise  # ours already name the file; a MemoryError is a real lack of memory (sizes are bounded)
    except OSError as exc:
        raise MeshFileError(f"{path}: {exc.strerror or exc}") from exc
    except Exception as exc:  # any other parser failure: one readable error naming the file
        reason = str(exc).strip().splitlines()[0][:200] if str(exc).strip() else ""
        raise MeshFileError(
            f"{path}: cannot be read as {fmt.name} ({type(exc).__name__}" + (f": {reason})" if reason else ")")
        ) from exc
    try:
        vertices = as_vertices(vertices)
        polygons = as_polygons(faces)
        _check_range(np.concatenate(polygons) if isinstance(polygons, list) else polygons, vertices.shape[0], "faces")
    except InvalidMeshError as exc:
        raise MeshFileError(f"{path}: {exc}") from exc
    logger.info("read %s: %d vertices, %d faces", path, vertices.shape[0], len(polygons))
    return Mesh(vertices, polygons)


def _point_data(point_data, n_vertices: int) -> dict[str, np.ndarray]:
    arrays = {}
    for name, array in named_fields(point_data).items():
        if array.dtype.kind not in "biuf" or array.ndim not in (1, 2) or array.shape[0] != n_vertices:
            raise InvalidOptionError(
                f"`point_data[{name!r}]` must be a numeric array of shape ({n_vertices},) or ({n_vertices}, k); "
                f"got dtype {array.dtype}, shape {array.shape}"
            )
        arrays[name] = array.astype(np.uint8) if array.dtype == bool else array
    return arrays


def write_mesh(
    path,
    vertices,
    faces,
    *,
    point_data=None,
    overwrite: bool = False,
    source=None,
    binary: bool = True,
    file_format: str | None = None,
) -> pathlib.Path:
    """Write a mesh, and optionally per-vertex fields, to a file chosen by its extension.

    The file is written to a temporary name in the same folder and renamed
    onto ``path`` when complete, so a failed write leaves nothing behind.

    Parameters
    ----------
    path : str or os.PathLike
    vertices : array_like of shape (V, 3)
    faces : array_like of shape (F, 3) or (F, k), or list of index lists
        0-based.
    point_data : dict of str to array_like, optional
        Per-vertex fields, (V,) or (V, k). PLY stores them as float
        properties (``normals`` as ``nx, ny, nz``, other vectors as
        ``name_x, name_y, name_z``); VTK, VTU and VTP as point data (vectors
        kept); CSV as columns; NPZ as arrays. OBJ, STL and OFF hold none.
    overwrite : bool, default: False
        Replace an existing file.
    source : str or os.PathLike, optional
        The file the mesh was read from: writing onto it is refused.
    binary : bool, default: True
        Binary rather than ASCII PLY, STL and legacy VTK (VTU and VTP are
        always written binary: meshio's ASCII VTU keeps 11 digits).
    file_format : str, optional
        An extension of :data:`FORMATS`, to override the one of ``path``.

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    MeshFileError
        Unknown extension, existing file without ``overwrite`` (also one
        created by another writer while this one wrote), ``path`` the same
        file as ``source`` (through any link), a missing folder or one that
        cannot take the temporary file, fields for a format that holds none.
    InvalidMeshError
        Vertices or faces unusable (see :func:`meshcurv.principal_curvatures`).
    InvalidOptionError
        A ``point_data`` array without one row per vertex.
    """
    path = pathlib.Path(path)
    fmt = _format_of(path, file_format)
    points = as_vertices(vertices)
    polygons = as_polygons(faces)
    _check_range(np.concatenate(polygons) if isinstance(polygons, list) else polygons, points.shape[0], "faces")
    data = _point_data(point_data, points.shape[0])
    if data and fmt.fields == "none":
        raise MeshFileError(
            f"{path}: {fmt.name} files cannot hold per-vertex fields; write .ply, .vtk, .vtu, .vtp, .csv or .npz"
        )
    path = check_output(path, overwrite=overwrite, source=source)
    with atomic_output(path, overwrite=overwrite) as temporary:
        try:
            fmt.write(temporary, points, polygons, data, binary)
        except OSError as exc:
            raise MeshFileError(f"{path}: cannot be written ({exc.strerror or exc})") from exc
        except MeshFileError as exc:  # name the file asked for, not the temporary
            raise MeshFileError(str(exc).replace(str(temporary), str(path))) from exc
    logger.info("wrote %s (%s, %d fields)", path, fmt.name, len(data))
    return path


def write_curvatures(
    path,
    vertices,
    faces,
    result,
    *,
    fields=None,
    quality: str | None = "mean",
    overwrite: bool = False,
    source=None,
    binary: bool = True,
) -> pathlib.Path:
    """Write a mesh with the fields of a curvature result as per-vertex data.

    ``write_mesh(path, vertices, faces, point_data=curvature_fields(result, ...))``.

    Parameters
    ----------
    path, vertices, faces
        As for :func:`write_mesh`; ``vertices`` has one row per row of ``result``.
    result, fields, quality
        As for :func:`~meshcurv.io.fields.curvature_fields`: the
        :class:`~meshcurv.CurvatureResult`, which of its fields (default all),
        and the scalar field copied as ``quality`` (default ``'mean'``; None
        for none).
    overwrite, source, binary
        As for :func:`write_mesh` (defaults False, None, True).

    Returns
    -------
    pathlib.Path
        The mesh written, ``path``.

    Raises
    ------
    MeshFileError
        As :func:`write_mesh`, and for OBJ, STL and OFF, which hold no fields.
    InvalidMeshError
        As :func:`write_mesh`.
    InvalidOptionError
        As :func:`~meshcurv.io.fields.curvature_fields`, or a result with
        another number of rows than ``vertices``.

    Examples
    --------
    >>> import meshcurv, pathlib, tempfile
    >>> torus = meshcurv.shapes.torus()
    >>> r = meshcurv.principal_curvatures(torus.vertices, torus.faces)
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "torus.npz"
    >>> _ = meshcurv.io.write_curvatures(path, torus.vertices, torus.faces, r, fields=["mean"])
    >>> import numpy as np
    >>> sorted(np.load(path).files)
    ['faces', 'mean', 'quality', 'vertices']
    """
    point_data = curvature_fields(result, fields=fields, quality=quality)
    return write_mesh(path, vertices, faces, point_data=point_data, overwrite=overwrite, source=source, binary=binary)
