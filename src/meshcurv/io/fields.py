"""Per-vertex fields of a curvature result, named as they are written to files."""

from __future__ import annotations

import numpy as np

from ..errors import InvalidOptionError

__all__ = ["FIELDS", "VIEWERS", "curvature_fields"]

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
        An unknown field name, or a ``quality`` that is not a scalar field.

    Examples
    --------
    >>> import meshcurv
    >>> from meshcurv.io.fields import curvature_fields
    >>> sphere = meshcurv.shapes.icosphere(subdivisions=4)
    >>> r = meshcurv.principal_curvatures(sphere.vertices, sphere.faces)
    >>> sorted(curvature_fields(r, fields=["mean", "normals"]))
    ['mean', 'normals', 'quality']
    """
    names = list(FIELDS) if fields is None else list(fields)
    unknown = [name for name in names if name not in FIELDS]
    if unknown:
        raise InvalidOptionError(
            f"unknown field {unknown[0]!r}; choose from {', '.join(FIELDS)}"
        )
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
#: themselves (``tests/test_field_roundtrip.py``: VTK 9.7 through PyVista 0.49, trimesh 5.2, meshio 5.3,
#: pymeshlab 2025): reader -> (extensions, what it keeps).
VIEWERS = {
    "ParaView / PyVista (VTK)": (
        (".vtp", ".vtu", ".vtk"),
        "every field by name, vectors as 3-component arrays; from .ply only the normals "
        "(VTK's PLY reader reads no other vertex property)"),
    "MeshLab / pymeshlab": (
        (".ply",),
        "one field, as the vertex quality (--quality; default mean), and the normals; "
        "no other property of a PLY file (MeshLab reads no .vtk/.vtu/.vtp)"),
    "meshio": (
        (".ply", ".vtu", ".vtk"),
        "every field by name (from .ply, vectors split into _x, _y, _z); meshio has no .vtp reader"),
    "trimesh": (
        (".ply",),
        'every field in mesh.metadata["_ply_raw"]["vertex"]["data"] (load with process=False to keep the '
        "vertex order); vertex_attributes stay empty with every file: use CurvatureResult.to_trimesh"),
    "pandas / spreadsheets": ((".csv",), "every field as columns, vectors split into _x, _y, _z"),
    "NumPy": ((".npz",), "every field as arrays, with the vertices and faces"),
}


def _field(result, name: str) -> np.ndarray:
    if name == "valid":
        return result.valid.astype(np.uint8)
    return np.array(getattr(result, name), dtype=np.float64)
