"""Per-vertex tables: CSV (for pandas, spreadsheets) and NPZ (numpy), no optional dependency."""

from __future__ import annotations

import zipfile

import numpy as np

from ..errors import MeshFileError
from ._files import read_as

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
    columns = {"vertex": np.arange(vertices.shape[0]), "x": vertices[:, 0], "y": vertices[:, 1], "z": vertices[:, 2]}
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
    np.savez_compressed(path, vertices=vertices, **arrays, **point_data)  # type: ignore[arg-type]  # mypy matches **arrays with allow_pickle


#: deflate expands at most about 1032 times; a member declaring more is corrupt (or a zip bomb)
_DEFLATE_RATIO = 1100


def _check_members(path, archive: zipfile.ZipFile) -> None:
    """Refuse mesh arrays whose declared shape needs more bytes than their zip member holds.

    numpy allocates the declared shape before it reads a member, so a header
    claiming a huge shape would be a MemoryError (or take all memory): the
    header is read first and checked against the member's size, and that
    size against what its compressed bytes can expand to.
    """
    readers = {(1, 0): np.lib.format.read_array_header_1_0, (2, 0): np.lib.format.read_array_header_2_0}
    for info in archive.infolist():
        key = info.filename[:-4] if info.filename.endswith(".npy") else info.filename
        if not key.startswith(("vertices", "face")):
            continue
        if info.file_size > _DEFLATE_RATIO * info.compress_size + 4096:
            raise MeshFileError(
                f"{path}: the NPZ member {key!r} claims {info.file_size} bytes from "
                f"{info.compress_size} compressed ones; the archive is corrupt"
            )
        with archive.open(info) as member:
            version = np.lib.format.read_magic(member)
            if version not in readers:
                raise MeshFileError(f"{path}: the NPZ member {key!r} has an unsupported .npy version {version}")
            shape, _, dtype = readers[version](member)
        need = int(np.prod(shape, dtype=object)) * dtype.itemsize
        if dtype.hasobject or need > info.file_size:
            raise MeshFileError(
                f"{path}: the NPZ array {key!r} declares shape {shape} of {dtype} ({need} bytes) but the "
                f"archive holds only {info.file_size} bytes for it"
            )


def npz_arrays(path, keep) -> tuple[dict, list[str]]:
    """``({name: array}, names)``: the arrays of an NPZ file whose name ``keep(name)`` accepts, and all names.

    Members are checked before numpy allocates them (:func:`_check_members`);
    any zip, zlib or npy failure is one :class:`MeshFileError` naming the file.
    """
    # zip, zlib, npy header, tokenizer errors: all one kind for the caller
    with read_as(path, "NPZ", passes=(MeshFileError, MemoryError)), open(path, "rb") as handle:
        with zipfile.ZipFile(handle) as archive:
            _check_members(path, archive)
        handle.seek(0)
        with np.load(handle, allow_pickle=False) as archive:
            names = sorted(archive.files)
            return {name: archive[name] for name in names if keep(name)}, names


def read_npz(path):
    """Read ``vertices`` and ``faces`` back from an NPZ file written by :func:`write_npz`."""
    arrays, names = npz_arrays(path, lambda name: name.startswith(("vertices", "face")))
    if "vertices" not in arrays or not ({"faces"} <= set(arrays) or {"face_corners", "face_sizes"} <= set(arrays)):
        raise MeshFileError(f"{path}: an NPZ mesh needs arrays named 'vertices' and 'faces'; found {names}")
    if "faces" in arrays:
        return arrays["vertices"], arrays["faces"]
    corners, sizes = arrays["face_corners"], arrays["face_sizes"]
    if (
        corners.ndim != 1
        or sizes.ndim != 1
        or sizes.dtype.kind not in "iu"
        or (sizes < 0).any()
        or int(sizes.sum(dtype=np.int64)) != corners.size
    ):
        raise MeshFileError(f"{path}: the NPZ 'face_sizes' do not add up to the {corners.size} 'face_corners'")
    return arrays["vertices"], np.split(corners, np.cumsum(sizes)[:-1])
