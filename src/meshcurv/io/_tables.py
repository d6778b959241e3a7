"""Per-vertex tables: CSV (for pandas, spreadsheets) and NPZ (numpy), no optional dependency."""

from __future__ import annotations

import zipfile
import zlib

import numpy as np

from ..errors import MeshFileError

__all__ = ["flat_columns", "write_csv", "write_npz", "read_npz"]


def flat_columns(point_data: dict, *, normals_as_nxyz: bool = True) -> dict[str, np.ndarray]:
    """Split (V, k) fields into (V,) columns: ``normals`` -> nx, ny, nz; ``d`` -> d_x, d_y, d_z."""
    columns = {}
    for name, value in point_data.items():
        if value.ndim == 1:
            columns[name] = value
            continue
        if name == "normals" and normals_as_nxyz and value.shape[1] == 3:
            labels = ["nx", "ny", "nz"]
        elif value.shape[1] == 3:
            labels = [f"{name}_{axis}" for axis in "xyz"]
        else:
            labels = [f"{name}_{i}" for i in range(value.shape[1])]
        columns.update({label: value[:, i] for i, label in enumerate(labels)})
    return columns


def write_csv(path, vertices: np.ndarray, faces, point_data: dict) -> None:
    """One row per vertex: ``vertex, x, y, z`` then the fields (vectors split into columns)."""
    columns = {"vertex": np.arange(vertices.shape[0]), "x": vertices[:, 0], "y": vertices[:, 1],
               "z": vertices[:, 2]}
    columns.update(flat_columns(point_data, normals_as_nxyz=False))
    table = np.column_stack([np.asarray(value, dtype=np.float64) for value in columns.values()])
    formats = ["%d" if np.issubdtype(np.asarray(v).dtype, np.integer) else "%.17g" for v in columns.values()]
    np.savetxt(path, table, fmt=formats, delimiter=",", header=",".join(columns), comments="")


def write_npz(path, vertices: np.ndarray, faces, point_data: dict) -> None:
    """``vertices``, ``faces`` (or ``face_corners`` + ``face_sizes`` for mixed polygons) and the fields."""
    reserved = {"vertices", "faces", "face_corners", "face_sizes"} & set(point_data)
    if reserved:
        raise MeshFileError(f"{path}: a field may not be called {sorted(reserved)[0]!r} in an NPZ file")
    if isinstance(faces, np.ndarray):
        arrays = {"faces": faces}
    else:
        arrays = {"face_corners": np.concatenate(faces), "face_sizes": np.array([len(f) for f in faces])}
    np.savez_compressed(path, vertices=vertices, **arrays, **point_data)


def read_npz(path):
    """Read ``vertices`` and ``faces`` back from an NPZ file written by :func:`write_npz`."""
    try:
        with open(path, "rb") as handle, np.load(handle, allow_pickle=False) as archive:
            names = sorted(archive.files)
            arrays = {name: archive[name] for name in names if name.startswith(("vertices", "face"))}
    except (OSError, ValueError, KeyError, zipfile.BadZipFile, zlib.error, EOFError) as exc:
        raise MeshFileError(f"{path}: cannot be read as NPZ ({exc})") from exc
    if "vertices" not in arrays or not ({"faces"} <= set(arrays) or {"face_corners", "face_sizes"} <= set(arrays)):
        raise MeshFileError(f"{path}: an NPZ mesh needs arrays named 'vertices' and 'faces'; found {names}")
    if "faces" in arrays:
        return arrays["vertices"], arrays["faces"]
    return arrays["vertices"], np.split(arrays["face_corners"], np.cumsum(arrays["face_sizes"])[:-1])
