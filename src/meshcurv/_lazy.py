"""Label images read block by block (Zarr, OME-Zarr, Dask arrays): :mod:`meshcurv.volume` without the whole image.

:class:`LazyImage` wraps an array-like that is read by slicing (a
``zarr.Array``, a ``dask.array.Array``, a ``numpy.memmap``): it has the
shape, dtype and chunk grid of a 3D image, and ``image[box]`` reads that box
into memory as a numpy array. :func:`lazy_objects` finds the bounding box of
every label one chunk at a time (:func:`scipy.ndimage.find_objects` on each
chunk, the boxes of a label merged over the chunks it spans), so that the
largest array in memory is one chunk; :mod:`meshcurv.volume` then reads each
object's crop (its box padded by a voxel) from the store. Memory is bounded by
a chunk, a crop and, on Dask, the crops in flight, whatever the image's size.
"""

from __future__ import annotations

import itertools
import logging

import numpy as np

from .errors import InvalidMeshError

__all__ = ["LazyImage", "is_lazy", "as_lazy", "lazy_objects", "check_lazy_labels"]

logger = logging.getLogger(__name__)


def _edges(shape, chunks) -> list[np.ndarray]:
    """The chunk boundaries along each axis: ``[0, c, 2c, ..., n]`` (or the given sizes' sums, as Dask's)."""
    edges = []
    for n, chunk in zip(shape, chunks):
        if isinstance(chunk, (tuple, list)):  # dask: the size of each chunk
            edges.append(np.concatenate([[0], np.cumsum(chunk)]).astype(np.int64))
        else:
            step = max(int(chunk), 1)
            edges.append(np.unique(np.concatenate([np.arange(0, n, step), [n]])).astype(np.int64))
    return edges


class LazyImage:
    """A 3D image read box by box: ``image[box]`` is a numpy array, nothing else is held.

    Parameters
    ----------
    array : array-like
        Sliceable (``array[key]`` returns a numpy array or something
        ``numpy.asarray`` reads), with ``shape``, ``dtype`` and optionally
        ``chunks`` (Zarr's chunk shape, or Dask's chunk sizes).
    axes : tuple of int or None, optional
        For an array of more than 3 axes: the index taken on each axis that
        is not an image axis (an int), or None for the image axes, in
        order (z, y, x). Default: the array's own 3 axes.
    chunks : tuple of 3 ints, optional
        The blocks :func:`lazy_objects` reads; default the array's chunks,
        else about 64 MiB slabs along axis 0.
    """

    def __init__(self, array, *, axes=None, chunks=None) -> None:
        self.array = array
        full = tuple(int(n) for n in array.shape)
        self._axes = tuple([None] * len(full)) if axes is None else tuple(axes)
        keep = [k for k, a in enumerate(self._axes) if a is None]
        if len(keep) != 3 or len(self._axes) != len(full):
            raise InvalidMeshError(f"`labels` must be a 3D image (axes 0, 1, 2 = z, y, x); got shape {full}")
        self.shape = tuple(full[k] for k in keep)
        self.dtype = np.dtype(array.dtype)
        own = getattr(array, "chunks", None)
        if chunks is None and own is not None:
            chunks = tuple(own[k] for k in keep)
        if chunks is None:
            plane = max(1, int(np.prod(self.shape[1:])) * self.dtype.itemsize)
            chunks = (max(1, 2**26 // plane), self.shape[1], self.shape[2])
        self.chunk_edges = _edges(self.shape, chunks)

    ndim = 3

    @property
    def size(self) -> int:
        return int(np.prod(self.shape, dtype=np.int64))

    @property
    def nbytes(self) -> int:
        return self.size * self.dtype.itemsize

    def __getitem__(self, box) -> np.ndarray:
        box = tuple(box) if isinstance(box, tuple) else (box,)
        if len(box) != 3 or not all(isinstance(part, slice) for part in box):
            raise TypeError("a LazyImage is read by a box of 3 slices")
        parts = iter(box)
        key = tuple(next(parts) if a is None else a for a in self._axes)
        return np.asarray(self.array[key])

    def __repr__(self) -> str:
        return f"LazyImage(shape={self.shape}, dtype={self.dtype}, {type(self.array).__module__}.{type(self.array).__name__})"

    def blocks(self):
        """Yield ``(starts, block)``: each chunk of the image as a numpy array, and its first voxel's index."""
        ranges = [list(zip(edge[:-1].tolist(), edge[1:].tolist())) for edge in self.chunk_edges]
        for parts in itertools.product(*ranges):
            box = tuple(slice(a, b) for a, b in parts)
            yield np.array([a for a, _ in parts], dtype=np.int64), self[box]


def is_lazy(labels) -> bool:
    """Whether ``labels`` is read box by box: a :class:`LazyImage` (or a Zarr or Dask array, wrapped by :func:`as_lazy`)."""
    return isinstance(labels, LazyImage) or (
        not isinstance(labels, np.ndarray)
        and hasattr(labels, "chunks")
        and hasattr(labels, "shape")
        and hasattr(labels, "dtype")
    )


def as_lazy(labels) -> LazyImage:
    """``labels`` as a :class:`LazyImage` (itself when it is one)."""
    return labels if isinstance(labels, LazyImage) else LazyImage(labels)


def check_lazy_labels(image: LazyImage) -> LazyImage:
    """The checks of :mod:`meshcurv.volume` on a lazy image that need no voxel: dtype, 3 axes, not empty."""
    if image.dtype.kind not in "iub":
        raise InvalidMeshError(
            f"`labels` must be an integer label image or a boolean mask; got dtype {image.dtype} (a probability map "
            "read lazily cannot be thresholded: its components would span chunks; threshold it into a label image "
            "first)"
        )
    if image.size == 0:
        raise InvalidMeshError(f"`labels` is empty; got shape {image.shape}")
    return image


def lazy_objects(image: LazyImage, wanted, find_objects) -> dict:
    """``{label: box or None}`` of a lazy image, one chunk in memory at a time.

    ``find_objects(block, None)`` is :func:`meshcurv.volume._objects` (every
    label of a numpy block and its box); the boxes of each label over the
    chunks are merged into one. Negative labels are refused at the chunk
    where they are found.
    """
    low: dict[int, np.ndarray] = {}
    high: dict[int, np.ndarray] = {}
    n_blocks = 0
    for starts, block in image.blocks():
        n_blocks += 1
        if block.dtype == bool:
            block = block.view(np.uint8)
        if block.dtype.kind == "i" and block.size and block.min() < 0:
            raise InvalidMeshError(
                f"`labels` must be >= 0 (0 is the background); got the value {int(block.min())} "
                f"in the chunk at {tuple(starts.tolist())}"
            )
        for label, box in find_objects(block, None).items():
            a = np.array([part.start for part in box], dtype=np.int64) + starts
            b = np.array([part.stop for part in box], dtype=np.int64) + starts
            if label in low:
                np.minimum(low[label], a, out=low[label])
                np.maximum(high[label], b, out=high[label])
            else:
                low[label], high[label] = a, b
    logger.info("%d labels found in %d chunks", len(low), n_blocks)
    present = {label: tuple(slice(int(x), int(y)) for x, y in zip(low[label], high[label])) for label in sorted(low)}
    if wanted is None:
        return present
    return {label: present.get(label) for label in wanted}
