"""MRC / CCP4 maps (``.mrc``, ``.map``, ``.rec``): cryo-electron tomograms and their segmentations, with numpy.

The MRC2014 format (Cheng et al. 2015) is a 1024-byte header of 4-byte words,
an extended header of ``nsymbt`` bytes, then the data, columns fastest. This
reader takes what a segmentation needs and checks every size the header
declares against the file before anything is read:

- the data type from ``mode``: 0 (int8; uint8 when IMOD's stamp says the
  bytes are unsigned), 1 (int16), 2 (float32), 6 (uint16); any other mode is
  refused with the list;
- the byte order from the machine stamp (``0x44 0x44`` little-endian,
  ``0x11 0x11`` big-endian; without a stamp, the order in which ``mode`` and
  the sizes make sense);
- the axes: the file's sections, rows and columns are the map axes
  ``maps``, ``mapr``, ``mapc`` (1 = X, 2 = Y, 3 = Z); the array is returned
  with its axes as Z, Y, X (image axes 0, 1, 2, as the other readers of
  :mod:`meshcurv.io._images`), a transposed view when the file's order is
  another;
- the voxel size along Z, Y, X: ``cella / (mz, my, mx)``, in Angstrom as
  the format stores it (kept so: areas are then in A^2, curvatures in 1/A);
  None when the header gives no cell (``cella`` or a sampling 0).

References
----------
A. Cheng, R. Henderson, D. Mastronarde, S. J. Ludtke, R. H. M. Schoenmakers,
J. Short, R. Marabini, S. Dallakyan, D. Agard, M. Winn (2015). MRC2014:
Extensions to the MRC format header for electron cryo-microscopy and
tomography. Journal of Structural Biology 192(2), 146-150.
https://doi.org/10.1016/j.jsb.2015.04.002
"""

from __future__ import annotations

import os

import numpy as np

from ..errors import MeshFileError

__all__ = ["read_mrc", "MRC_MODES", "MRC_UNIT", "HEADER_BYTES"]

#: The data types read, by MRC ``mode``.
MRC_MODES = {0: "i1", 1: "i2", 2: "f4", 6: "u2"}

#: The unit of the voxel size an MRC header records.
MRC_UNIT = "angstrom"

HEADER_BYTES = 1024

#: IMOD's stamp (word 39): with it, bit 0 of ``imodFlags`` (word 40) clear means mode 0 holds unsigned bytes.
_IMOD_STAMP = 1146047817

_NAMES = {0: "int8", 1: "int16", 2: "float32", 6: "uint16"}


def _header(raw: bytes, order: str) -> dict:
    words = np.frombuffer(raw, dtype=order + "i4", count=56)
    floats = np.frombuffer(raw, dtype=order + "f4", count=56)
    return {
        "shape_crs": words[0:3].astype(np.int64),
        "mode": int(words[3]),
        "sampling": words[7:10].astype(np.int64),
        "cell": floats[10:13].astype(np.float64),
        "axes": words[16:19].astype(np.int64),
        "ispg": int(words[22]),
        "nsymbt": int(words[23]),
        "imod_stamp": int(words[38]),
        "imod_flags": int(words[39]),
    }


def _byte_order(raw: bytes) -> str:
    stamp = raw[212:214]
    if stamp == b"\x44\x44" or stamp == b"\x44\x41":
        return "<"
    if stamp == b"\x11\x11":
        return ">"
    # no stamp (old files): the order in which the mode and the sizes make sense
    for order in ("<", ">"):
        header = _header(raw, order)
        if header["mode"] in range(0, 17) and (header["shape_crs"] > 0).all() and (header["shape_crs"] < 2**24).all():
            return order
    return "<"


def read_mrc(path, check_size) -> tuple[np.ndarray, tuple[float, float, float] | None]:
    """``(array (Z, Y, X), spacing (z, y, x) in Angstrom or None)`` of an MRC file.

    ``check_size(path, shape, dtype)`` refuses an image too large to read
    (:func:`meshcurv.io._images._check_size`). The array is a read-only memory
    map of the file (a copy when its byte order is not the machine's).

    Raises
    ------
    MeshFileError
        Header shorter than 1024 bytes; sizes, axes or extended header that
        make no sense; a mode other than 0, 1, 2, 6; a stack of several
        volumes; a header that declares more data than the file holds. The
        message names the file.
    """
    size = os.path.getsize(path)
    with open(path, "rb") as handle:
        raw = handle.read(HEADER_BYTES)
    if len(raw) < HEADER_BYTES:
        raise MeshFileError(
            f"{path}: an MRC file starts with a {HEADER_BYTES}-byte header; the file holds {len(raw)} bytes"
        )
    order = _byte_order(raw)
    header = _header(raw, order)
    shape_crs, mode = header["shape_crs"], header["mode"]
    if not (shape_crs > 0).all():
        raise MeshFileError(
            f"{path}: the MRC header declares {tuple(shape_crs.tolist())} columns, rows and "
            "sections; each must be at least 1"
        )
    if mode not in MRC_MODES:
        known = ", ".join(f"{key} ({name})" for key, name in _NAMES.items())
        raise MeshFileError(f"{path}: MRC mode {mode} is not read; known modes: {known}")
    code = MRC_MODES[mode]
    if mode == 0 and header["imod_stamp"] == _IMOD_STAMP and not header["imod_flags"] & 1:
        code = "u1"
    axes = header["axes"]
    if sorted(axes.tolist()) != [1, 2, 3]:
        raise MeshFileError(
            f"{path}: the MRC header's axes (mapc, mapr, maps) = {tuple(axes.tolist())} are not "
            "an order of 1, 2, 3 (X, Y, Z)"
        )
    nsymbt = header["nsymbt"]
    if nsymbt < 0:
        raise MeshFileError(f"{path}: the MRC header declares an extended header of {nsymbt} bytes")
    n_columns, n_rows, n_sections = (int(n) for n in shape_crs)
    sampling = header["sampling"]
    if 401 <= header["ispg"] <= 630 and sampling[2] > 0 and n_sections > sampling[2]:
        raise MeshFileError(
            f"{path}: the MRC file is a stack of {n_sections // int(sampling[2])} volumes "
            f"(space group {header['ispg']}, {n_sections} sections of {int(sampling[2])}); "
            "meshcurv reads one volume"
        )
    dtype = np.dtype(order + code)
    disk_shape = (n_sections, n_rows, n_columns)
    check_size(path, disk_shape, dtype)
    need = HEADER_BYTES + nsymbt + n_sections * n_rows * n_columns * dtype.itemsize
    if need > size:
        raise MeshFileError(
            f"{path}: the MRC header declares {n_columns} x {n_rows} x {n_sections} values of "
            f"{_NAMES[mode]} after {HEADER_BYTES + nsymbt} header bytes ({need} bytes in all), "
            f"but the file holds only {size}"
        )
    data: np.ndarray = np.memmap(path, dtype=dtype, mode="r", offset=HEADER_BYTES + nsymbt, shape=disk_shape)
    if not dtype.isnative:
        data = data.astype(dtype.newbyteorder("="))
    # the file's axes (sections, rows, columns) are the map axes (maps, mapr, mapc); wanted: (Z, Y, X) = (3, 2, 1)
    on_disk = [int(axes[2]), int(axes[1]), int(axes[0])]
    array = data.transpose([on_disk.index(axis) for axis in (3, 2, 1)])
    return array, _spacing(header)


def _spacing(header: dict) -> tuple[float, float, float] | None:
    """``cella / sampling`` along Z, Y, X (Angstrom), or None when the header has no cell."""
    cell, sampling = header["cell"], header["sampling"]
    if not (sampling > 0).all() or not (np.isfinite(cell).all() and (cell > 0).all()):
        return None
    x, y, z = (cell / sampling).tolist()
    return (z, y, x)
