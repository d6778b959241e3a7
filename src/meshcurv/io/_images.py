"""3D images for :mod:`meshcurv.volume`: TIFF stacks, NumPy ``.npy`` / ``.npz``, NIfTI, MRC.

:func:`read_image` returns the array with its axes as image axes 0, 1, 2
(z, y, x: planes, rows, columns) and the voxel size along them when the file
records it. Every failure is a :class:`~meshcurv.errors.MeshFileError` naming
the file; sizes declared by a header are checked against :data:`MAX_IMAGE_BYTES`
before anything is allocated.
"""

from __future__ import annotations

import pathlib
import zipfile
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from ..errors import MeshFileError, optional_module
from ._files import check_input, read_as
from ._mrc import MRC_UNIT, read_mrc
from ._zarr import read_zarr

if TYPE_CHECKING:
    from .._lazy import LazyImage

__all__ = ["read_image", "Image", "IMAGE_FORMATS", "MAX_IMAGE_BYTES"]

#: The largest image accepted, in bytes of its array (the 512 x 1024 x 1024 uint16 image of issue 17 is 1 GiB).
MAX_IMAGE_BYTES = 32 * 2**30

#: Extensions read, and what they are.
IMAGE_FORMATS = {
    ".tif": "TIFF stack (tifffile)",
    ".tiff": "TIFF stack (tifffile)",
    ".npy": "NumPy array",
    ".npz": "NumPy archive (the array 'labels', or its only array)",
    ".nii": "NIfTI (nibabel)",
    ".nii.gz": "NIfTI, gzipped (nibabel)",
    ".mrc": "MRC map (cryo-EM, tomography)",
    ".rec": "MRC map (IMOD reconstruction)",
    ".map": "MRC / CCP4 map",
    ".zarr": "Zarr or OME-Zarr folder, read lazily (zarr)",
}

#: deflate expands at most about 1032 times; a member declaring more is corrupt
_DEFLATE_RATIO = 1100


class Image(NamedTuple):
    """An image read by :func:`read_image`.

    Attributes
    ----------
    array : ndarray of shape (Z, Y, X), or LazyImage
        A :class:`meshcurv._lazy.LazyImage` for a Zarr store: read box by
        box, never whole.
    spacing : tuple of 3 floats or None
        Voxel size along image axes 0, 1, 2 when the file records it (NIfTI
        header; ImageJ TIFF; MRC header), else None.
    unit : str or None
        The unit of ``spacing`` when the format fixes it (``"angstrom"`` for
        MRC), else None.
    """

    array: np.ndarray | LazyImage
    spacing: tuple[float, float, float] | None
    unit: str | None = None


def _suffix(path: pathlib.Path) -> str:
    name = path.name.lower()
    return ".nii.gz" if name.endswith(".nii.gz") else path.suffix.lower()


def _check_size(path, shape, dtype) -> None:
    need = int(np.prod([int(n) for n in shape], dtype=object)) * np.dtype(dtype).itemsize
    if need > MAX_IMAGE_BYTES:
        raise MeshFileError(
            f"{path}: the image declares shape {tuple(int(n) for n in shape)} of {np.dtype(dtype)} "
            f"({need} bytes), more than the {MAX_IMAGE_BYTES} bytes meshcurv reads"
        )


def _check_3d(path, array: np.ndarray) -> np.ndarray:
    if array.ndim > 3:
        array = array.reshape([n for n in array.shape if n != 1] or [1])
    if array.ndim != 3:
        raise MeshFileError(f"{path}: a 3D image (z, y, x) is needed; the file holds shape {array.shape}")
    return array


def _npy_header(handle, path, where: str = ""):
    """``(shape, dtype)`` of the .npy header at ``handle``, checked against :data:`MAX_IMAGE_BYTES`."""
    version = np.lib.format.read_magic(handle)
    reader = {(1, 0): np.lib.format.read_array_header_1_0, (2, 0): np.lib.format.read_array_header_2_0}.get(version)
    if reader is None:
        raise MeshFileError(f"{path}: unsupported .npy version {version}{where}")
    shape, _, dtype = reader(handle)
    if dtype.hasobject:
        raise MeshFileError(f"{path}: the array{where} holds Python objects; an image of numbers is needed")
    _check_size(path, shape, dtype)
    return shape, dtype


def _npy(path):
    with read_as(path, ".npy"), open(path, "rb") as handle:
        _npy_header(handle, path)
    with read_as(path, ".npy", passes=()):
        return np.load(path, mmap_mode="r", allow_pickle=False), None  # a file shorter than its header says fails


def _npz(path):
    with read_as(path, ".npz"):
        with zipfile.ZipFile(path) as archive:
            members = {
                info.filename[:-4] if info.filename.endswith(".npy") else info.filename: info
                for info in archive.infolist()
            }
            if "labels" in members:
                name = "labels"
            elif len(members) == 1:
                name = next(iter(members))
            else:
                raise MeshFileError(
                    f"{path}: an archive of several arrays needs one named 'labels'; found {sorted(members)}"
                )
            info = members[name]
            if info.file_size > _DEFLATE_RATIO * info.compress_size + 4096:
                raise MeshFileError(
                    f"{path}: the member {name!r} claims {info.file_size} bytes from "
                    f"{info.compress_size} compressed ones; the archive is corrupt"
                )
            with archive.open(info) as member:
                shape, dtype = _npy_header(member, path, f" {name!r}")
            if int(np.prod(shape, dtype=object)) * dtype.itemsize > info.file_size:
                raise MeshFileError(
                    f"{path}: the array {name!r} declares shape {shape} but the archive holds "
                    f"only {info.file_size} bytes for it"
                )
        with np.load(path, allow_pickle=False) as archive:
            return archive[name], None


def _tiff(path):
    tifffile = optional_module("tifffile", "reading TIFF images needs tifffile: pip install 'meshcurv[volume]'")
    with read_as(path, "TIFF"), tifffile.TiffFile(path) as tif:
        if not tif.series:
            raise MeshFileError(f"{path}: the TIFF file holds no image")
        series = tif.series[0]
        _check_size(path, series.shape, series.dtype)
        return series.asarray(), _tiff_spacing(tif, series)


def _tiff_spacing(tif, series):
    """(z, y, x) from ImageJ's metadata (``spacing``) and the resolution tags, or None."""
    metadata = tif.imagej_metadata or {}
    if "spacing" not in metadata:
        return None
    try:
        page = series.pages[0] if hasattr(series, "pages") else tif.pages[0]
        tags = page.tags
        x = tags["XResolution"].value
        y = tags["YResolution"].value
        spacing = (float(metadata["spacing"]), y[1] / y[0], x[1] / x[0])
    except (KeyError, TypeError, ZeroDivisionError, IndexError, ValueError):
        return None
    return spacing if all(np.isfinite(s) and s > 0 for s in spacing) else None


def _nifti(path):
    nibabel = optional_module("nibabel", "reading NIfTI images needs nibabel: pip install 'meshcurv[volume]'")
    with read_as(path, "NIfTI"):
        image = nibabel.load(str(path))  # .nii, .nii.gz: a Nifti1Image or Nifti2Image
        _check_size(path, image.shape, image.get_data_dtype())
        array = np.asanyarray(image.dataobj)
        zooms = [float(z) for z in image.header.get_zooms()[:3]]
    array = _check_3d(path, np.asarray(array))
    # NIfTI's array axes are (i, j, k), x fastest on disk: turned to (k, j, i) = (z, y, x), a view
    spacing = tuple(zooms[::-1]) if len(zooms) == 3 and all(np.isfinite(z) and z > 0 for z in zooms) else None
    return array.transpose(2, 1, 0), spacing


def _mrc(path):
    with read_as(path, "MRC"):
        return read_mrc(path, _check_size)


_FILES = ((".tif .tiff", _tiff), (".npy", _npy), (".npz", _npz), (".nii .nii.gz", _nifti), (".mrc .rec .map", _mrc))
_READERS = {extension: reader for extensions, reader in _FILES for extension in extensions.split()}


def read_image(path) -> Image:
    """Read a 3D image (a label image or a mask) and the voxel size its file records.

    Parameters
    ----------
    path : str or os.PathLike
        ``.tif``/``.tiff`` (tifffile: the first series; the spacing of an
        ImageJ hyperstack), ``.npy``, ``.npz`` (the array ``labels``, or the
        only array), ``.nii``/``.nii.gz`` (nibabel; the spacing from the
        header's ``pixdim``), ``.mrc``/``.rec``/``.map`` (MRC2014, modes 0,
        1, 2, 6; the spacing ``cella / (mx, my, mz)`` of the header, in
        Angstrom, :mod:`meshcurv.io._mrc`), a ``.zarr`` folder (Zarr or
        OME-Zarr, read lazily: :mod:`meshcurv.io._zarr`). Axes of length 1
        are dropped.

    Returns
    -------
    Image
        ``array`` with image axes 0, 1, 2 = z, y, x (NIfTI's (i, j, k) array
        is transposed to (k, j, i), and its spacing with it; an MRC map's
        axes are put in the order Z, Y, X whatever its ``mapc, mapr, maps``),
        ``spacing`` or None, and ``unit`` (``"angstrom"`` for MRC, else None).

    Raises
    ------
    MeshFileError
        Missing, empty or unreadable file, unknown extension, not 3D, larger
        than :data:`MAX_IMAGE_BYTES`; the message names the file.
    MissingDependencyError
        tifffile or nibabel missing (``pip install 'meshcurv[volume]'``);
        zarr missing (``pip install zarr``).
    """
    if _suffix(pathlib.Path(path)) == ".zarr":
        return Image(*read_zarr(path))
    path = check_input(path)
    suffix = _suffix(path)
    reader = _READERS.get(suffix)
    if reader is None:
        known = ", ".join(IMAGE_FORMATS)
        raise MeshFileError(f"{path}: unknown image extension {suffix or '(none)'!r}; known: {known}")
    array, spacing = reader(path)
    array = _check_3d(path, np.asarray(array) if not isinstance(array, np.ndarray) else array)
    return Image(array, spacing, MRC_UNIT if reader is _mrc else None)
