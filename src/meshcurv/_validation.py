"""The one place where user input is checked and coerced.

Every public entry point passes its arrays through :func:`as_vertices` and
:func:`as_faces` (a mesh: :func:`as_mesh`, both at once); the core then trusts
them (float64 (V, 3) finite vertices, int64 (F, 3) triangles with indices in
range).
"""

from __future__ import annotations

import numbers
import operator
import warnings
from collections.abc import Sequence
from itertools import chain
from typing import NamedTuple

import numpy as np

from .errors import InvalidMeshError, InvalidOptionError, TriangulationWarning

__all__ = [
    "as_vertices",
    "as_faces",
    "as_mesh",
    "as_polygons",
    "polygon_arrays",
    "fan_triangles",
    "checked_triangles",
    "Ragged",
    "check_int_option",
    "check_vertex_count",
    "check_positive_float",
    "check_choice",
    "checked_mesh",
    "checked_points",
    "checked_indices",
    "checked_mask",
    "MAX_VERTICES",
]


def _short_repr(value, limit: int = 40) -> str:
    """``repr(value)``, cut to ``limit`` characters (an option of 400 digits stays readable)."""
    text = repr(value)
    return text if len(text) <= limit else f"{text[: limit - 12]}... ({len(text)} chars)"


def _shape_text(array) -> str:
    return str(tuple(np.shape(array)))


def as_vertices(vertices, *, name: str = "vertices") -> np.ndarray:
    """Return ``vertices`` as a new C-contiguous float64 array of shape (V, 3).

    Raises
    ------
    InvalidMeshError
        Wrong shape or dtype, no vertices, NaN or infinite coordinates.
    """
    _refuse_masked(vertices, name)
    try:
        array = np.asarray(vertices)
    except (ValueError, TypeError, OverflowError) as exc:  # ragged nested lists, ints beyond float
        raise InvalidMeshError(
            f"`{name}` must be an array of shape (V, 3); it could not be converted to an array ({exc})"
        ) from None
    if array.dtype == object or not (np.issubdtype(array.dtype, np.floating) or np.issubdtype(array.dtype, np.integer)):
        raise InvalidMeshError(f"`{name}` must hold real numbers (float or int); got dtype {array.dtype}")
    if array.ndim != 2 or array.shape[1] != 3:
        raise InvalidMeshError(f"`{name}` must have shape (V, 3); got {_shape_text(array)}")
    if array.shape[0] == 0:
        raise InvalidMeshError(f"`{name}` is empty: the mesh has no vertices")
    with np.errstate(over="ignore"):  # float128 beyond float64: caught as infinite below
        try:
            out = np.array(array, dtype=np.float64, order="C", copy=True)
        except OverflowError:  # Python ints beyond float64 in an object-free int array cannot occur; be safe
            raise InvalidMeshError(f"`{name}` has coordinates beyond the float64 range") from None
    with np.errstate(over="ignore", invalid="ignore"):
        total = out.sum()  # finite unless a coordinate is NaN or infinite (or the sum overflows)
    finite = np.isfinite(out).all(axis=1) if not np.isfinite(total) else None
    if finite is not None and not finite.all():
        bad = np.flatnonzero(~finite)
        raise InvalidMeshError(
            f"`{name}` has NaN or infinite coordinates at {bad.size} vertices (first at index {bad[0]})"
        )
    largest = max(float(out.max()), -float(out.min()))
    if largest > MAX_COORDINATE:
        raise InvalidMeshError(
            f"`{name}` has coordinates as large as {largest:.3g}; products of four lengths (squared "
            f"areas) would overflow float64 beyond {MAX_COORDINATE:.0e}: rescale the mesh"
        )
    if 0.0 < largest < MIN_COORDINATE:
        raise InvalidMeshError(
            f"`{name}` has no coordinate larger than {largest:.3g}; products of four lengths (squared "
            f"areas) would underflow float64 below {MIN_COORDINATE:.0e}: rescale the mesh"
        )
    return out


#: Largest coordinate magnitude accepted. The estimators form products of up to four
#: lengths (squared face areas, ``b^2 - 4ac`` of a segment-ball intersection, the
#: squared norms of cross products); a length is at most ``2 sqrt(3)`` times the largest
#: coordinate, so with 1e75 such a product stays below ``(3.5e75)^4 = 1.5e302``, inside
#: float64's 1.8e308, with a margin for sums of a few dozen terms.
MAX_COORDINATE = 1e75

#: Smallest largest-coordinate magnitude accepted (a mesh of coordinates all below this
#: is refused): products of four lengths of 1e-75 are 1e-300, above float64's smallest
#: normal number 2.2e-308; below, squared areas underflow to 0 and every face would be
#: read as zero-area. A mesh whose coordinates are all exactly 0 passes (its faces are
#: all degenerate, which the estimators report).
MIN_COORDINATE = 1e-75


def _refuse_masked(value, name: str) -> None:
    """Refuse a :class:`numpy.ma.MaskedArray` with masked entries (its mask would be ignored)."""
    if isinstance(value, np.ma.MaskedArray):
        n_masked = int(np.ma.count_masked(value))
        if n_masked:
            raise InvalidMeshError(
                f"`{name}` is a masked array with {n_masked} masked values; meshcurv does not guess "
                "them: remove the masked rows (or fill them) first"
            )


def _integer_faces(array: np.ndarray, name: str) -> np.ndarray:
    """Coerce a numeric face array to int64, refusing non-integral values."""
    if array.dtype == bool or not (np.issubdtype(array.dtype, np.integer) or np.issubdtype(array.dtype, np.floating)):
        if array.dtype == object and array.size and all(isinstance(x, numbers.Integral) for x in array.flat):
            raise InvalidMeshError(f"`{name}` has indices too large for int64")  # Python ints beyond uint64
        raise InvalidMeshError(f"`{name}` must hold integer vertex indices; got dtype {array.dtype}")
    if np.issubdtype(array.dtype, np.floating):
        if not np.isfinite(array).all():
            raise InvalidMeshError(f"`{name}` has NaN or infinite values; indices must be integers")
        if not np.array_equal(array, np.round(array)):
            swapped = (
                f" (a {array.dtype} array of shape {_shape_text(array)}: coordinates? were `vertices` "
                f"and `{name}` swapped? pass the vertices first)"
                if array.ndim == 2
                else ""
            )
            raise InvalidMeshError(f"`{name}` has non-integer values; vertex indices must be whole numbers{swapped}")
        if array.size and np.abs(array).max() >= 2.0**62:
            raise InvalidMeshError(f"`{name}` has indices too large for int64")
    if np.issubdtype(array.dtype, np.unsignedinteger) and array.size and array.max() > np.iinfo(np.int64).max:
        raise InvalidMeshError(f"`{name}` has indices too large for int64")
    return array.astype(np.int64, copy=True)


def _as_array(value, name: str) -> np.ndarray:
    """``np.asarray`` with numpy's conversion errors (ragged, mixed types) as InvalidMeshError."""
    try:
        return np.asarray(value)
    except (ValueError, TypeError, OverflowError) as exc:
        raise InvalidMeshError(
            f"`{name}` must be an array of shape (F, 3) or (F, k), or a list of index lists; "
            f"it could not be converted to an array ({exc})"
        ) from None


class Ragged(NamedTuple):
    """Faces of varying lengths, flat: face ``f`` is ``flat[starts[f]:starts[f] + lengths[f]]``."""

    flat: np.ndarray
    lengths: np.ndarray

    @property
    def starts(self) -> np.ndarray:
        return np.cumsum(self.lengths) - self.lengths

    def split(self) -> list[np.ndarray]:
        """One int64 index array per face."""
        return np.split(self.flat, np.cumsum(self.lengths)[:-1])


def _sequence_type(kind: type) -> bool:
    return (issubclass(kind, (Sequence, np.ndarray))) and not issubclass(kind, (str, bytes))


def polygon_arrays(faces, *, name: str = "faces") -> np.ndarray | Ragged:
    """``faces`` as an int64 (F, k) array (k >= 3), or as :class:`Ragged` when the faces differ in length.

    Vectorised: a list of 100,000 mixed triangles and quads is checked in one
    conversion of its concatenated indices (no array per face).

    Raises
    ------
    InvalidMeshError
        Not an array or a list of index lists, empty, a face of fewer than 3
        corners, nested or non-integer values, indices beyond int64.
    """
    if isinstance(faces, (str, bytes)):
        raise InvalidMeshError(f"`{name}` must be an array of vertex indices; got a {type(faces).__name__}")
    _refuse_masked(faces, name)
    if isinstance(faces, np.ndarray) or not isinstance(faces, Sequence):
        array = _as_array(faces, name)
    else:
        if not all(_sequence_type(kind) for kind in set(map(type, faces))):
            raise InvalidMeshError(
                f"`{name}` must be an array of shape (F, 3) or (F, k), or a list of index lists; "
                "got a list whose items are not sequences"
            )
        lengths = np.fromiter(map(len, faces), dtype=np.int64, count=len(faces))
        ragged = lengths.size and lengths.min() != lengths.max()
        if ragged and lengths.min() < 3:
            raise InvalidMeshError(f"`{name}` has a face with fewer than 3 vertices; every face needs at least 3")
        # one conversion of the concatenated indices (twice as fast as numpy's nested-list path)
        flat = _as_array(list(chain.from_iterable(faces)), name)
        if flat.ndim != 1:
            raise InvalidMeshError(f"`{name}` must be a list of flat index lists; a face holds nested lists")
        if ragged:
            return Ragged(_integer_faces(flat, name), lengths)
        array = flat.reshape(lengths.size, -1) if lengths.size else flat
    if array.ndim != 2:
        raise InvalidMeshError(f"`{name}` must have shape (F, 3) or (F, k) with k >= 3; got {_shape_text(array)}")
    if array.shape[0] == 0:
        raise InvalidMeshError(f"`{name}` is empty: the mesh has no faces")
    if array.shape[1] < 3:
        raise InvalidMeshError(
            f"`{name}` must have at least 3 columns (one vertex index per corner); got {_shape_text(array)}"
        )
    _refuse_transposed(array, name)
    return _integer_faces(array, name)


def _refuse_transposed(array: np.ndarray, name: str) -> None:
    """Refuse (3, F) faces, F > 3, whose rows repeat an index: triangles given column-wise, not F-gons.

    Three polygons of F corners would be read from such an array, but a
    polygon visits each of its vertices once, while the rows of transposed
    triangles (each row one corner of every face) repeat the vertices that
    several faces share (always on a closed mesh, which has more faces than
    vertices).
    """
    if array.shape[0] != 3 or array.shape[1] <= 3:
        return
    rows = np.sort(array, axis=1)
    if (rows[:, 1:] == rows[:, :-1]).any():
        raise InvalidMeshError(
            f"`{name}` has shape {_shape_text(array)} and looks transposed: 3 rows of {array.shape[1]} vertex "
            f"indices that repeat (a polygon repeats no vertex); faces go one per row, shape (F, 3): "
            f"pass `{name}.T`"
        )


def as_polygons(faces, *, name: str = "faces") -> list[np.ndarray] | np.ndarray:
    """Return ``faces`` as an int64 (F, k) array, or a list of int64 index arrays when ragged."""
    shaped = polygon_arrays(faces, name=name)
    return shaped.split() if isinstance(shaped, Ragged) else shaped


def fan_triangles(shaped: np.ndarray | Ragged) -> np.ndarray:
    """(T, 3) int64 fan triangles of checked polygons (:func:`polygon_arrays`), as matGeom's ``triangulateFaces``.

    Face ``(f0, f1, ..., f(k-1))`` gives ``(f0, f(j-1), f(j))`` for ``j = 2 .. k-1``,
    the triangles of each face next to each other in the order of the faces.
    One gather for all faces, whatever their lengths.
    """
    if not isinstance(shaped, Ragged):
        if shaped.shape[1] == 3:
            return np.ascontiguousarray(shaped)
        shaped = Ragged(shaped.ravel(), np.full(shaped.shape[0], shaped.shape[1], dtype=np.int64))
    counts = shaped.lengths - 2  # triangles per face
    first = np.repeat(shaped.starts, counts)  # position of each triangle's f0 in `flat`
    # j - 1 for every triangle: 1 .. k-2 within each face
    offset = np.arange(first.size) - np.repeat(np.cumsum(counts) - counts, counts) + 1
    flat = shaped.flat
    return np.stack([flat[first], flat[first + offset], flat[first + offset + 1]], axis=1)


def _check_range(triangles: np.ndarray, n_vertices: int, name: str) -> None:
    low = int(triangles.min())
    high = int(triangles.max())
    if low < 0:
        raise InvalidMeshError(f"`{name}` has negative vertex indices (smallest {low}); indices are 0-based and >= 0")
    if high >= n_vertices:
        if high == n_vertices and low >= 1:
            raise InvalidMeshError(
                f"`{name}` look 1-based: indices run from {low} to {high} with {n_vertices} vertices; "
                "meshcurv uses 0-based indices, pass `faces - 1`"
            )
        raise InvalidMeshError(
            f"`{name}` has vertex index {high} out of range for {n_vertices} vertices (valid: 0 to {n_vertices - 1})"
        )


def as_faces(faces, n_vertices: int, *, name: str = "faces", stacklevel: int = 3) -> np.ndarray:
    """Return ``faces`` as a new int64 (F, 3) triangle array with indices checked.

    Polygons ((F, k) arrays with k > 3, or lists of index lists of varying length)
    are fan-triangulated as matGeom's ``triangulateFaces`` does
    (:func:`fan_triangles`, :func:`meshcurv.topology.triangulate_faces`), with a
    :class:`TriangulationWarning`, as matGeom's meshCurvatures does.

    Raises
    ------
    InvalidMeshError
        Wrong shape or dtype, non-integer values, empty, fewer than 3 corners,
        negative or out-of-range indices (with a hint when they look 1-based).
    """
    return checked_triangles(polygon_arrays(faces, name=name), n_vertices, name=name, stacklevel=stacklevel + 1)


def as_mesh(vertices, faces, *, stacklevel: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """Return ``(as_vertices(vertices), as_faces(faces, V))``: a mesh checked and coerced, once.

    The door of :func:`meshcurv.principal_curvatures` (:func:`meshcurv._prepared.prepare_mesh`):
    the arrays it returns are new, float64 (V, 3) finite vertices and int64 (F, 3) triangles
    with indices in ``[0, V)``, and nothing after it checks them again. Polygons are
    fan-triangulated with a :class:`TriangulationWarning` attributed ``stacklevel`` frames up.

    Raises
    ------
    InvalidMeshError
        As :func:`as_vertices` (checked first), then as :func:`as_faces`.
    """
    points = as_vertices(vertices)
    return points, as_faces(faces, points.shape[0], stacklevel=stacklevel + 1)


def checked_triangles(
    shaped: np.ndarray | Ragged, n_vertices: int, *, name: str = "faces", stacklevel: int = 3
) -> np.ndarray:
    """:func:`as_faces` of faces already shaped by :func:`polygon_arrays`."""
    _check_range(shaped.flat if isinstance(shaped, Ragged) else shaped, n_vertices, name)
    if isinstance(shaped, Ragged) or shaped.shape[1] != 3:
        warnings.warn(
            "requires triangle mesh, forces triangulation: polygonal faces were fan-triangulated",
            TriangulationWarning,
            stacklevel=stacklevel,
        )
    return fan_triangles(shaped)


#: Most vertices a mesh may have: the edges are keyed ``p * V + q`` (times 2, plus a direction
#: bit) in int64, which holds for ``V < 2**31`` (2.1 billion vertices, 51 GB of coordinates).
MAX_VERTICES = 2**31 - 1


def check_vertex_count(n_vertices, *, name: str = "n_vertices") -> int:
    """``n_vertices`` as an int in ``[1, MAX_VERTICES]`` or :class:`InvalidOptionError`."""
    return check_int_option(n_vertices, name, minimum=1, maximum=MAX_VERTICES)


def check_int_option(value, name: str, *, minimum: int = 0, maximum: int | None = None) -> int:
    """Return ``value`` as an int in ``[minimum, maximum]`` or raise :class:`InvalidOptionError`.

    ``maximum`` defaults to the largest int64 (the compiled kernels take int64):
    ``2**63`` is refused here, not by an OverflowError deep inside.
    """
    top = INT64_MAX if maximum is None else min(maximum, INT64_MAX)
    expected = f"an integer >= {minimum}" if maximum is None else f"an integer between {minimum} and {top}"
    if isinstance(value, (bool, np.bool_)):
        raise InvalidOptionError(f"`{name}` must be {expected}; got {_short_repr(value)}")
    try:
        number = operator.index(value)
    except TypeError:
        raise InvalidOptionError(f"`{name}` must be {expected}; got {_short_repr(value)}") from None
    if number < minimum:
        raise InvalidOptionError(f"`{name}` must be {expected}; got {_short_repr(number)}")
    if number > top:
        raise InvalidOptionError(f"`{name}` must be {expected}; got {_short_repr(number)}")
    return int(number)


#: Largest value of an integer option (the compiled kernels take int64).
INT64_MAX = int(np.iinfo(np.int64).max)


def check_positive_float(value, name: str) -> float:
    """Return ``value`` as a finite float > 0 or raise :class:`InvalidOptionError`.

    Only real numbers are accepted (int, float and their NumPy scalars, 0-d
    arrays): a string such as ``"0.5"`` is refused rather than parsed, and an
    integer beyond the float64 range (``10**400``) is refused, not overflowed.
    """
    if isinstance(value, (bool, np.bool_, str, bytes)) or not isinstance(value, (numbers.Real, np.ndarray)):
        raise InvalidOptionError(f"`{name}` must be a positive number; got {_short_repr(value)}")
    if isinstance(value, np.ndarray) and (
        value.ndim != 0 or not np.issubdtype(value.dtype, np.number) or np.issubdtype(value.dtype, np.complexfloating)
    ):
        raise InvalidOptionError(f"`{name}` must be a positive number; got {_short_repr(value)}")
    if isinstance(value, np.ma.MaskedArray) and np.ma.getmaskarray(value).any():  # numpy.ma.masked
        raise InvalidOptionError(f"`{name}` must be a positive finite number; got a masked value")
    try:
        number = float(value)
    except (TypeError, ValueError, OverflowError):
        raise InvalidOptionError(f"`{name}` must be a positive finite number; got {_short_repr(value)}") from None
    if not np.isfinite(number) or number <= 0:
        raise InvalidOptionError(f"`{name}` must be a positive finite number; got {_short_repr(value)}")
    if number < np.finfo(float).tiny:  # subnormal: its inverse is inf
        raise InvalidOptionError(
            f"`{name}` must be at least {np.finfo(float).tiny:.3g} (the smallest normal "
            f"float64: its inverse is finite); got {number!r}"
        )
    return number


def checked_spacing(spacing) -> np.ndarray:
    """``spacing`` as a (3,) float array: the voxel size along image axes 0, 1, 2 (z, y, x), each finite and > 0.

    Real numbers only (a string or a boolean is refused rather than parsed); raises
    :class:`InvalidOptionError` naming what was given.
    """
    try:
        raw = np.asarray(spacing)
    except (TypeError, ValueError):  # ragged sequences
        raw = None
    if raw is None or raw.dtype.kind not in "iuf" or raw.shape != (3,):
        raise InvalidOptionError(
            f"`spacing` must be 3 numbers, the voxel size along image axes 0, 1, 2 (z, y, x); got {_short_repr(spacing)}"
        )
    with np.errstate(over="ignore"):
        values = raw.astype(float)
    if not (np.isfinite(values).all() and (values > 0).all()):
        raise InvalidOptionError(
            f"`spacing` must be positive and finite along every axis (z, y, x); got {tuple(values.tolist())}"
        )
    return values


def check_choice(value, name: str, choices) -> str:
    """Return ``value`` if it is one of ``choices`` or raise :class:`InvalidOptionError`."""
    if not isinstance(value, str) or value not in choices:
        listed = ", ".join(repr(c) for c in choices)
        raise InvalidOptionError(f"unknown {name} {value!r}; choose one of {listed}")
    return value


# -- cheap checks at the public helpers (geometry, neighborhoods, smoothing, diagnose) --------------
def checked_points(vertices, *, name: str = "vertices") -> np.ndarray:
    """``vertices`` as a C-contiguous float64 (V, 3) array, checked finite.

    The public helpers of the core call this on every input: an array that is
    already float64 (V, 3) is not copied and costs a ``min`` and a ``max`` (NaN
    or infinite coordinates would send the compiled grid searches out of
    bounds; coordinates beyond :data:`MAX_COORDINATE` overflow squared areas,
    so they are refused here as by :func:`as_vertices`); anything else goes
    through :func:`as_vertices`.
    """
    if not (
        isinstance(vertices, np.ndarray)
        and type(vertices) is np.ndarray
        and vertices.dtype == np.float64
        and vertices.ndim == 2
        and vertices.shape[1] == 3
        and vertices.shape[0] > 0
    ):
        return as_vertices(vertices, name=name)
    largest = max(float(vertices.max()), -float(vertices.min()))  # NaN if any coordinate is NaN
    if not largest <= MAX_COORDINATE or 0.0 < largest < MIN_COORDINATE:
        return as_vertices(vertices, name=name)  # raises, naming the vertices and the problem
    return np.ascontiguousarray(vertices)


def checked_mask(mask, length: int, *, name: str) -> np.ndarray:
    """``mask`` as a bool array of shape ``(length,)``; InvalidMeshError naming it otherwise."""
    try:
        array = np.asarray(mask)
    except (ValueError, TypeError):  # ragged lists
        array = np.empty(0, dtype=object)
    if array.dtype != bool or array.shape != (length,):
        raise InvalidMeshError(
            f"`{name}` must be a bool array of shape ({length},); got {array.dtype} {_shape_text(array)}"
        )
    return array


def checked_indices(indices, n_vertices: int, *, columns: int = 3, name: str = "faces") -> np.ndarray:
    """``indices`` as a C-contiguous int64 (N, columns) array of 0-based vertex indices, checked in range.

    Unlike :func:`as_faces`, no polygon is triangulated and an empty array is
    accepted: this is the check of the helpers that take faces (or edges) the
    caller has built. An int64 array is not copied; the check is one pass of
    ``min`` and ``max``.

    Raises
    ------
    InvalidMeshError
        Wrong shape or dtype, non-integer values, indices out of range (with the
        1-based hint of :func:`as_faces`).
    """
    _refuse_masked(indices, name)
    array = indices if isinstance(indices, np.ndarray) else _as_array(indices, name)
    if array.ndim != 2 or array.shape[1] != columns:
        raise InvalidMeshError(f"`{name}` must have shape (N, {columns}); got {_shape_text(array)}")
    if array.dtype != np.int64:
        array = _integer_faces(array, name)
    if array.size:
        _check_range(array, n_vertices, name)
    return np.ascontiguousarray(array)


def checked_mesh(vertices, faces, *, columns: int = 3, name: str = "faces") -> tuple[np.ndarray, np.ndarray]:
    """``(checked_points(vertices), checked_indices(faces, V))``."""
    points = checked_points(vertices)
    return points, checked_indices(faces, points.shape[0], columns=columns, name=name)
