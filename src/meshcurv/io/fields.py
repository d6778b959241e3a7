"""Per-vertex fields of a curvature result, named as they are written to files."""

from __future__ import annotations

import pathlib

import numpy as np

from ..errors import InvalidOptionError, MeshFileError
from ._files import check_input
from ._meshio import read_meshio_file
from ._ply import ply_vertex_columns
from ._tables import npz_arrays
from ._vtp import read_vtp_point_data

__all__ = ["FIELDS", "VIEWERS", "curvature_fields", "read_fields"]

#: The fields :func:`curvature_fields` can produce, in file order, with what they are.
FIELDS = {
    "k_min": "smaller principal curvature (1/length)",
    "k_max": "larger principal curvature (1/length)",
    "mean": "mean curvature (k_min + k_max) / 2 (1/length)",
    "gaussian": "Gaussian curvature k_min * k_max (1/length²)",
    "shape_index": "Koenderink's shape index in [-1, 1]: -1 cup, 0 saddle, +1 cap (no unit)",
    "curvedness": "Koenderink's curvedness sqrt((k_min² + k_max²) / 2) (1/length)",
    "dir_min": "unit direction of k_min (3-vector)",
    "dir_max": "unit direction of k_max (3-vector)",
    "normals": "unit vertex normal (3-vector)",
    "valid": "1 where the estimate is defined, 0 where it is not",
    "radius": "radius of the ball each vertex was measured over (length; NaN for methods without a ball)",
}


def curvature_fields(result, *, fields=None, quality: str | None = "mean") -> dict[str, np.ndarray]:
    """The per-vertex arrays of a curvature result, ready for :func:`meshcurv.write_mesh`.

    Parameters
    ----------
    result : CurvatureResult
    fields : sequence of str, optional
        Which of :data:`FIELDS` to include, in that order; all by default.
    quality : str or None, default: 'mean'
        A scalar field copied as ``quality``, the vertex property MeshLab
        colours by; None leaves it out.

    Returns
    -------
    dict of str to ndarray
        (V,) float64 scalars, (V, 3) float64 vectors and ``valid`` as (V,) uint8.

    Raises
    ------
    InvalidOptionError
        ``result`` not a curvature result, an unknown field name, ``fields`` a
        string rather than a list of names, or a ``quality`` that is not a
        scalar field.

    Examples
    --------
    >>> import meshcurv
    >>> from meshcurv.io.fields import curvature_fields
    >>> sphere = meshcurv.shapes.icosphere(subdivisions=4)
    >>> r = meshcurv.principal_curvatures(sphere.vertices, sphere.faces)
    >>> sorted(curvature_fields(r, fields=["mean", "normals"]))
    ['mean', 'normals', 'quality']
    """
    if not all(hasattr(result, name) for name in ("k_min", "k_max", "valid", "n_vertices")):
        raise InvalidOptionError(f"`result` must be a CurvatureResult; got {type(result).__name__}")
    if isinstance(fields, str):
        raise InvalidOptionError(f"`fields` must be a list of names; got the string {fields!r} (fields=[{fields!r}])")
    names = list(FIELDS) if fields is None else list(fields)
    unknown = [name for name in names if name not in FIELDS]
    if unknown:
        raise InvalidOptionError(f"unknown field {unknown[0]!r}; choose from {', '.join(FIELDS)}")
    if quality is not None and (quality not in FIELDS or quality in _NOT_FOR_QUALITY):
        scalars = [name for name in FIELDS if name not in _NOT_FOR_QUALITY]
        raise InvalidOptionError(f"`quality` must be a scalar field ({', '.join(scalars)}); got {quality!r}")
    wanted = names + ([quality] if quality is not None and quality not in names else [])
    values = {name: _field(result, name) for name in wanted}
    out = {name: values[name] for name in names}
    if quality is not None:
        out["quality"] = values[quality]
    return out


_NOT_FOR_QUALITY = ("dir_min", "dir_max", "normals", "valid")

#: Which file to write for each reader, and what it keeps of the fields, as measured with the readers
#: themselves (``tests/test_io_fields.py``: VTK 9.7 through PyVista 0.49, trimesh 5.2, meshio 5.3,
#: pymeshlab 2025): reader -> (extensions, what it keeps).
VIEWERS = {
    "ParaView / PyVista (VTK)": (
        (".vtp", ".vtu", ".vtk"),
        "every field by name, vectors as 3-component arrays; from .ply only the normals "
        "(VTK's PLY reader reads no other vertex property)",
    ),
    "MeshLab / pymeshlab": (
        (".ply",),
        "one field, as the vertex quality (--quality; default mean), and the normals; "
        "no other property of a PLY file (MeshLab reads no .vtk/.vtu/.vtp)",
    ),
    "meshio": (
        (".ply", ".vtu", ".vtk"),
        "every field by name (from .ply, vectors split into _x, _y, _z); meshio has no .vtp reader",
    ),
    "trimesh": (
        (".ply",),
        'every field in mesh.metadata["_ply_raw"]["vertex"]["data"] (load with process=False to keep the '
        "vertex order); vertex_attributes stay empty with every file: use CurvatureResult.to_trimesh",
    ),
    "pandas / spreadsheets": ((".csv",), "every field as columns, vectors split into _x, _y, _z"),
    "NumPy": ((".npz",), "every field as arrays, with the vertices and faces"),
    "meshcurv.io.fields.read_fields": (
        (".ply", ".vtp", ".npz", ".csv", ".vtu", ".vtk"),
        "every field by name (float32 from .ply, float64 from the others)",
    ),
}


def _field(result, name: str) -> np.ndarray:
    if name == "valid":
        return result.valid.astype(np.uint8)
    if name == "radius" and result.radius is None:
        return np.full(result.n_vertices, np.nan)
    return np.array(getattr(result, name), dtype=np.float64)


def read_fields(path) -> dict[str, np.ndarray]:
    """The per-vertex fields of a file written by meshcurv (or any file of these formats), by name.

    Parameters
    ----------
    path : str or os.PathLike
        A ``.ply`` (binary or ASCII: every vertex property but x, y, z),
        ``.vtp`` (read here), ``.npz``, ``.csv`` (numpy) or ``.vtk``/``.vtu``
        file (meshio, ``pip install 'meshcurv[io]'``).

    Returns
    -------
    dict of str to ndarray
        (V,) float64 scalars; vectors stored as ``<name>_x, _y, _z`` columns
        (PLY, CSV) are put back together as (V, 3) arrays, and ``nx, ny, nz``
        as ``normals``; ``valid`` is bool. The vertices and faces are
        :func:`meshcurv.read_mesh`'s.

    Raises
    ------
    MeshFileError
        An unknown extension, or a file that cannot be read.

    Examples
    --------
    >>> import pathlib, tempfile, meshcurv
    >>> from meshcurv.io.fields import read_fields
    >>> sphere = meshcurv.shapes.icosphere(subdivisions=4)
    >>> r = meshcurv.principal_curvatures(sphere.vertices, sphere.faces)
    >>> path = meshcurv.io.write_curvatures(pathlib.Path(tempfile.mkdtemp()) / "s.vtp", sphere.vertices,
    ...                                     sphere.faces, r)
    >>> fields = read_fields(path)
    >>> fields["dir_max"].shape, bool((fields["k_max"] == r.k_max).all())
    ((162, 3), True)
    """
    path = pathlib.Path(path)
    suffix = path.suffix.lower()
    readers = {".ply": _ply_fields, ".vtp": _vtp_fields, ".npz": _npz_fields, ".csv": _csv_fields}
    readers.update(dict.fromkeys((".vtk", ".vtu"), _meshio_fields))
    if suffix not in readers:
        raise MeshFileError(
            f"{path}: no per-vertex fields in a {suffix or 'file without extension'}; "
            f"read_fields knows {', '.join(readers)}"
        )
    check_input(path)
    columns = readers[suffix](path)
    return _regrouped(columns)


def _ply_fields(path):
    # the vertex element alone: a point cloud's file (no faces) as well as a surface's
    return {
        name: np.asarray(values, dtype=np.float64)
        for name, values in ply_vertex_columns(path).items()
        if name not in ("x", "y", "z")
    }


def _vtp_fields(path):
    return read_vtp_point_data(path)


def _npz_fields(path):
    return npz_arrays(path, lambda name: name not in ("vertices", "faces", "face_corners", "face_sizes"))[0]


def _csv_fields(path):
    with open(path, encoding="utf-8") as handle:
        names = handle.readline().strip().split(",")
    try:
        table = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    except ValueError as exc:
        raise MeshFileError(f"{path}: cannot be read as a table of numbers ({exc})") from exc
    if table.shape[1] != len(names):
        raise MeshFileError(f"{path}: {table.shape[1]} columns under a header of {len(names)} names")
    return {name: table[:, k] for k, name in enumerate(names) if name not in ("vertex", "x", "y", "z")}


def _meshio_fields(path):
    return dict(read_meshio_file(path, path.suffix.lower()[1:]).point_data)


def _regrouped(columns: dict) -> dict[str, np.ndarray]:
    """``<name>_x, _y, _z`` (and ``nx, ny, nz``) as (V, 3) vectors; scalars as float64, ``valid`` as bool."""
    out = {}
    groups = {name[:-2] for name in columns if name.endswith("_x")}
    groups = {base for base in groups if all(f"{base}_{axis}" in columns for axis in "yz")}
    for name, values in columns.items():
        values = np.asarray(values)
        if name.endswith(("_x", "_y", "_z")) and name[:-2] in groups:
            if name.endswith("_x"):
                base = name[:-2]
                out[base] = np.column_stack([np.asarray(columns[f"{base}_{a}"], dtype=np.float64) for a in "xyz"])
            continue
        if name in ("nx", "ny", "nz") and all(key in columns for key in ("nx", "ny", "nz")):
            if name == "nx":
                out["normals"] = np.column_stack(
                    [np.asarray(columns[key], dtype=np.float64) for key in ("nx", "ny", "nz")]
                )
            continue
        out[name] = values.astype(bool) if name == "valid" else values.astype(np.float64)
    return out
