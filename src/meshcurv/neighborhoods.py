"""Euclidean balls around vertices: which faces, edges and vertices they hold, and how much.

Every estimator that takes ``radius=`` uses it through this module, so the
option has one meaning: the closed Euclidean ball ``B(x_v, radius)`` around
each vertex position, in the units of the coordinates. The rules that choose
it, and the checks of a given one, are in :mod:`meshcurv.radius`.

Bounds: before any ball search, the
number of (centre, point) pairs is estimated from a sample
(:func:`estimate_ball_pairs`); beyond :data:`MAX_BALL_PAIRS` the radius is
refused, and the work is split so that memory stays bounded (NumPy path:
chunks of at most about :data:`PAIRS_PER_CHUNK` pairs) and Ctrl-C gets
through (compiled path: calls of about :data:`PAIRS_PER_CALL` pairs).

Queries run on :class:`scipy.spatial.cKDTree` pair searches, in chunks of
centres so that memory stays bounded on large meshes; all per-pair work is
vectorized (no Python loop over vertices, edges or faces). With numba, the
face and edge sums (and the jet fits of :mod:`meshcurv.estimators.quadric`)
run on a grid of cells at least as wide as the ball instead, in compiled
kernels that find the same points (tests/test_backends.py compares the two).
A mesh's balls can also be walked breadth-first from their centre over the
mesh itself (``connected=True`` here, ``adjacency=`` of the jet fits; what
``icc`` does): no search structure over the whole mesh, and the same ball
wherever the surface inside it is connected, another sheet of the surface
within the ball left out (tests/test_speed_design.py). The same walk over a
k-nearest-neighbour graph would serve point clouds.

Both backends compute the same balls (issue 29: a user's numbers must not
depend on whether numba is installed). The NumPy path finds the
surface-connected pieces for a whole chunk of centres at once: the cells that
may meet each ball (k-d tree pairs of centres and cell centroids), the exact
tests of the kernels on each pair (the same operations, in the same order),
then the connected components of the graph whose nodes are the ``(centre,
vertex)`` pairs and whose links are the cells meeting the ball
(:func:`scipy.sparse.csgraph.connected_components`); the nodes in their
centre's component are the vertices the walk reaches (tests/test_backend_parity.py,
tests/test_kernel_twins.py).
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from ._backend import kernel_threads, numba_kernels
from ._validation import check_positive_float, checked_indices, checked_points
from .errors import InvalidMeshError, InvalidOptionError

__all__ = [
    "MAX_BALL_PAIRS",
    "estimate_ball_pairs",
    "check_ball_work",
    "vertex_pairs_in_ball",
    "ball_face_sums",
    "ball_edge_sums",
    "face_in_ball_ratios",
    "segment_in_ball_lengths",
    "ring_sums",
    "ring_max",
]

#: Centres per chunk of a ball query (bounds the memory of the pair lists).
CHUNK = 32768

#: Most (centre, point) pairs a ball computation may take: about a minute of jet fits on two
#: cores (a million vertices with 2000 points per ball). More is refused (a radius far too
#: large for the mesh's resolution) instead of running for hours.
MAX_BALL_PAIRS = 2_000_000_000

#: (Centre, point) pairs per chunk of the NumPy path's ball searches (bounds their memory).
PAIRS_PER_CHUNK = 1 << 20

#: (Centre, point) pairs per call of a compiled ball kernel: between calls Python gets control
#: back (Ctrl-C); a default radius on a million vertices is one call.
PAIRS_PER_CALL = 100_000_000

#: Centres and points of the sample that estimates the pairs of a ball computation.
SAMPLE_CENTRES = 32
SAMPLE_POINTS = 8192
#: ... whose distances are computed for this many centres at a time (a block of 1 MB).
PROBE_ROWS = 16

#: Cells of different sizes share one search while its radius (radius + largest reach) grows
#: by at most this factor over that of their smallest size class.
GROUP_GROWTH = 1.5

#: Surface-connected balls of more faces than this (on average) are summed over clusters of faces
#: (:func:`_face_clusters`), each cluster inside a ball added as one precomputed sum ...
CLUSTER_MIN_FACES = 800
#: ... of about this many faces each.
CLUSTER_FACES = 16
#: The clusters of :func:`coarse_face_sums` (an approximation at the rim, :func:`coarse_share`): about this many
#: faces each. Against 16 (``benchmarks/dense_voxel.md``): the sums of the R 6 sphere take 0.10 s instead of
#: 0.18 and its median H error is 4% lower (R 4 at 0.1: 0.229 -> 0.221%), a torus (3, 1) at 0.1 x 0.04 x 0.04
#: moves by +1.4% (H) and +6% (K); 64 moved that torus's K by +18% (3.87 -> 4.57%): the wider rim of larger
#: clusters blurs a curvature that varies.
COARSE_CLUSTER_FACES = 32


def _sample(n: int, size: int) -> np.ndarray:
    """``size`` indices evenly spread over ``range(n)`` (all of them when n <= size): deterministic."""
    if n <= size:
        return np.arange(n)
    return np.linspace(0, n - 1, size).round().astype(np.int64)


def estimate_ball_pairs(points: np.ndarray, radius, centres: np.ndarray | None = None) -> tuple[float, float]:
    """Estimated points of ``points`` within ``radius`` of each centre: ``(mean, largest)`` per centre.

    From :data:`SAMPLE_CENTRES` centres (default: the points themselves) against
    :data:`SAMPLE_POINTS` points, both evenly spaced in index order and scaled to
    the whole cloud: some 0.3 million distances, about a millisecond, whatever
    the radius (the balls themselves are never searched). Exact when the cloud
    and the centres are no larger than the sample. ``radius``: one for all
    centres, or an array of one per centre; then the mean is that of the
    evenly spaced centres, each with its own radius, and the largest ball is
    looked for among them and the :data:`SAMPLE_CENTRES` centres of the largest radii.
    """
    points = checked_points(points, name="points")
    return _estimate_ball_pairs(points, radius, points if centres is None else centres)


def _estimate_ball_pairs(points: np.ndarray, radius, centres: np.ndarray) -> tuple[float, float]:
    """:func:`estimate_ball_pairs` of checked ``points`` (the library's own arrays: :func:`check_ball_work`)."""
    if centres.shape[0] == 0:
        return 0.0, 0.0
    sub = points[_sample(points.shape[0], SAMPLE_POINTS)]
    picked = _sample(centres.shape[0], SAMPLE_CENTRES)
    if np.ndim(radius):  # one radius per centre: the sample and the widest balls, each with its own radius
        widest = np.argpartition(radius, -min(SAMPLE_CENTRES, radius.size))[-SAMPLE_CENTRES:]
        probe_radius = radius[np.concatenate([picked, widest])][:, None]
        return _pairs_within(points, sub, centres[np.concatenate([picked, widest])], probe_radius, picked.size)
    return _pairs_within(points, sub, centres[picked], radius, picked.size)


def _pairs_within(points: np.ndarray, sub: np.ndarray, probe: np.ndarray, radius, n_mean: int) -> tuple[float, float]:
    """:func:`estimate_ball_pairs` from the sample ``sub`` of ``points`` and the centres ``probe``: the mean
    over the first ``n_mean`` centres, the largest over all (``radius``: a number, or a column per centre)."""
    origin = probe.mean(axis=0)  # |p - c|^2 = |p|^2 + |c|^2 - 2 p.c about a nearby origin
    sub, probe = sub - origin, probe - origin
    probe2, sub2 = np.einsum("ij,ij->i", probe, probe), np.einsum("ij,ij->i", sub, sub)
    columns = _columns(sub)
    limit = radius * radius
    inside = np.empty(probe.shape[0])
    kernels = numba_kernels("neighborhoods")
    if kernels is not None:  # the same operations, compiled: no (16, 8192) blocks written and read back
        limits = np.ascontiguousarray(np.asarray(limit, dtype=np.float64).reshape(-1))
        kernels._pair_counts(np.ascontiguousarray(probe), probe2, *columns, sub2, limits, inside)
        inside *= points.shape[0] / sub.shape[0]
        return float(inside[:n_mean].mean()), float(inside.max())
    # PROBE_ROWS centres at a time: the distances stay in the caches (a whole (64, 8192) array: 2.5 times the CPU)
    d2 = np.empty((min(PROBE_ROWS, probe.shape[0]), sub.shape[0]))
    term = np.empty_like(d2)
    for start in range(0, probe.shape[0], PROBE_ROWS):
        rows = slice(start, min(start + PROBE_ROWS, probe.shape[0]))
        d, t = d2[: rows.stop - start], term[: rows.stop - start]
        np.add(probe2[rows, None], sub2[None, :], out=d)
        for axis in range(3):  # p.c axis by axis: a BLAS product of inner size 3 cost 5 times more CPU
            np.multiply.outer(probe[rows, axis], columns[axis], out=t)
            np.multiply(2.0, t, out=t)
            np.subtract(d, t, out=d)
        inside[rows] = np.count_nonzero(d <= (limit if np.ndim(limit) == 0 else limit[rows]), axis=1)
    inside *= points.shape[0] / sub.shape[0]
    return float(inside[:n_mean].mean()), float(inside.max())


def check_ball_work(
    points: np.ndarray, radius, n_centres: int, *, centres: np.ndarray | None = None
) -> tuple[float, float]:
    """Refuse a ball computation beyond :data:`MAX_BALL_PAIRS`; return :func:`estimate_ball_pairs`.

    ``radius``: one for all centres, or an array of one per centre. ``points`` and ``centres`` are
    the library's own float64 (N, 3) arrays, checked already: they are not checked again.

    Raises
    ------
    InvalidOptionError
        The balls of ``radius`` around ``n_centres`` centres would hold more than
        :data:`MAX_BALL_PAIRS` (centre, point) pairs in all.
    """
    mean, largest = _estimate_ball_pairs(points, radius, points if centres is None else centres)
    if mean * n_centres > MAX_BALL_PAIRS:
        named = f"{radius:g}" if np.ndim(radius) == 0 else f"up to {np.max(radius):g}"
        raise InvalidOptionError(
            f"`radius` {named} is far too large for the mesh's resolution: each ball would hold about "
            f"{mean:.3g} of its {points.shape[0]} points ({mean * n_centres:.3g} pairs in all, more than "
            f"{MAX_BALL_PAIRS:.1g}: hours of work); pass a radius of a few edge lengths"
        )
    return mean, largest


def _checked_radius_value(radius) -> float:
    """A radius passed to the helpers: a finite real number >= 0 (0: a mesh of coincident points)."""
    if radius == 0 and not isinstance(radius, (str, bytes, bool)):
        return 0.0
    return check_positive_float(radius, "radius")


def centre_radii(radius, n: int, name: str = "radius"):
    """``radius`` checked: a float (one for all, >= 0), or a (n,) float64 array of one per centre (> 0, finite).

    Raises
    ------
    InvalidOptionError
        ``radius`` is not a finite real number >= 0, or an array of ``n``
        positive finite numbers.
    """
    if np.ndim(radius) == 0:
        return _checked_radius_value(radius)
    try:
        radii = np.asarray(radius, dtype=np.float64)
    except (TypeError, ValueError):
        raise InvalidOptionError(f"`{name}` must be a number or an array of {n} positive numbers") from None
    if radii.shape != (n,):
        raise InvalidOptionError(
            f"`{name}` must be a number or an array of shape ({n},): one radius per centre; got shape {radii.shape}"
        )
    if radii.size and not (np.isfinite(radii).all() and radii.min() > 0):
        bad = int(np.count_nonzero(~(np.isfinite(radii) & (radii > 0))))
        raise InvalidOptionError(f"`{name}` must hold positive finite radii; {bad} of {n} are not")
    return np.ascontiguousarray(radii)


def _chunks(n: int, size: int = CHUNK) -> Iterator[slice]:
    for start in range(0, n, size):
        yield slice(start, min(n, start + size))


def _pairs(tree, centers: np.ndarray, cutoff: float) -> tuple[np.ndarray, np.ndarray]:
    """(i, j): centre ``i`` and point ``j`` of ``tree`` (a ``cKDTree``) no farther apart than ``cutoff``."""
    from scipy.spatial import cKDTree  # imported on use: scipy.spatial costs import time

    found = cKDTree(centers).sparse_distance_matrix(tree, cutoff, output_type="ndarray")
    return found["i"].astype(np.int64), found["j"].astype(np.int64)


def vertex_pairs_in_ball(
    points: np.ndarray, radius: float, *, centres: np.ndarray | None = None, chunk_size: int = CHUNK
) -> Iterator[tuple[slice, np.ndarray, np.ndarray]]:
    """Yield ``(chunk, centre, neighbour)``: every point within ``radius`` of each centre.

    The centres are the points ``centres`` (default: all), taken by chunk of
    at most ``chunk_size`` (fewer when the balls are large, so that a chunk holds
    about :data:`PAIRS_PER_CHUNK` pairs); ``centre`` indexes them (absolute:
    ``chunk.start`` and up), ``neighbour`` indexes ``points``: the point within
    the ball (the centre itself included).

    Raises
    ------
    InvalidOptionError
        More than :data:`MAX_BALL_PAIRS` pairs in all (:func:`check_ball_work`).
    """
    points = checked_points(points, name="points")
    radius = _checked_radius_value(radius)
    centres = np.arange(points.shape[0]) if centres is None else _checked_ids(centres, points.shape[0])
    yield from _ball_pairs(points, points[centres], radius, chunk_size)


def _ball_pairs(
    points: np.ndarray, centre_points: np.ndarray, radius, chunk_size: int = CHUNK
) -> Iterator[tuple[slice, np.ndarray, np.ndarray]]:
    """:func:`vertex_pairs_in_ball` around arbitrary ``centre_points`` (trusted arrays).

    ``radius``: one for all, or a (C,) array of one per centre (checked): the
    pairs of the chunk's largest ball, then those within each centre's own
    radius (squared distances summed x, y, z, as the compiled ``_ball_members``).
    """
    from scipy.spatial import cKDTree

    _, largest = check_ball_work(points, radius, centre_points.shape[0], centres=centre_points)
    chunk_size = max(1, min(int(chunk_size), int(PAIRS_PER_CHUNK // max(4.0 * largest, 1.0))))
    tree = cKDTree(points)
    for chunk in _chunks(centre_points.shape[0], chunk_size):
        if np.ndim(radius) == 0:
            i, j = _pairs(tree, centre_points[chunk], radius)
        else:
            i, j = _pairs(tree, centre_points[chunk], float(radius[chunk].max()) * (1 + _SEARCH_SLACK))
            inside = _squared(*(points[j] - centre_points[chunk][i]).T) <= radius[chunk][i] ** 2
            i, j = i[inside], j[inside]
        yield chunk, i + chunk.start, j


def _checked_ids(ids, n: int, name: str = "centres") -> np.ndarray:
    """(N,) int64 vertex ids in ``range(n)``."""
    array = np.asarray(ids)
    if array.ndim != 1:
        raise InvalidMeshError(f"`{name}` must be a 1-d array of vertex indices; got shape {array.shape}")
    return checked_indices(array[:, None], n, columns=1, name=name)[:, 0]


def face_in_ball_ratios(corners: np.ndarray, centers: np.ndarray, radius: float) -> np.ndarray:
    """Approximate share of each triangle inside the ball around each centre.

    ``corners`` (P, 3, 3) and ``centers`` (P, 3). With ``d_min, d_max`` the
    smallest and largest distance from the centre to the corners and the
    centroid, the share is 1 if ``d_max <= r``, 0 if ``d_min >= r``, and
    ``(r - d_min) / (d_max - d_min)`` otherwise: the linear approximation of
    Lachaud et al. (2020) and CGAL's ``interpolated_corrected_curvatures``.
    """
    points = np.concatenate([corners, corners.mean(axis=1, keepdims=True)], axis=1)
    distances = np.linalg.norm(points - centers[:, None, :], axis=2)
    low, high = distances.min(axis=1), distances.max(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        partial = (radius - low) / (high - low)
    return np.where(high <= radius, 1.0, np.where(low >= radius, 0.0, partial))


def segment_in_ball_lengths(starts: np.ndarray, ends: np.ndarray, centers: np.ndarray, radius: float) -> np.ndarray:
    """(P,) exact length of each segment ``[start, end]`` inside the ball around its centre.

    From the end nearer the centre: the distance ``t`` along the segment to the
    point closest to the centre, that point's squared distance ``h2`` to the
    centre (the point itself, not ``|f|^2 - t^2``), then the chord
    ``[t - s, t + s]`` with ``s = sqrt(r^2 - h2)`` clipped to the segment. The
    quadratic formula ``b^2 - 4ac`` cancels on a segment far longer than the
    ball (a spike's edge through a ball of one edge length: every digit lost,
    so that each backend's rounding gave its own chord; issue 29). The
    operations of the compiled ``_segment_length``, in the same order.
    """
    first = _columns(np.asarray(starts, dtype=np.float64) - centers)
    second = _columns(np.asarray(ends, dtype=np.float64) - centers)
    swap = _squared(*second) < _squared(*first)
    near = tuple(np.where(swap, b, a) for a, b in zip(first, second))
    d = tuple(np.where(swap, a, b) - p for a, b, p in zip(first, second, near))
    length2 = _squared(*d)
    with np.errstate(invalid="ignore", divide="ignore"):
        length = np.sqrt(length2)
        along = -((near[0] * d[0] + near[1] * d[1]) + near[2] * d[2]) / length
        share = along / length
        h2 = _squared(*(p + share * q for p, q in zip(near, d)))
        half = np.sqrt(np.maximum(radius * radius - h2, 0.0))
        inside = np.minimum(along + half, length) - np.maximum(along - half, 0.0)
    return np.where((length2 > 0) & (h2 < radius * radius) & (inside > 0), inside, 0.0)


def _size_groups(reach: np.ndarray, radius: float) -> list[np.ndarray | slice]:
    """The cells by group of similar ``reach``, smallest first (see :func:`_ball_sums`).

    A group is an index array, or ``slice(None)`` when all cells form one.
    """
    _, exponent = np.frexp(np.maximum(reach, np.finfo(float).tiny))
    level = exponent - exponent.min()
    largest = np.zeros(level.max() + 1)
    for k in np.flatnonzero(np.bincount(level)):  # a few size classes: one pass each
        largest[k] = reach[level == k].max()
    label = np.zeros(largest.size, dtype=np.int64)
    first = 0
    for k in np.flatnonzero(largest):
        if radius + largest[k] > GROUP_GROWTH * (radius + largest[first]):
            first = int(k)
        label[k] = first
    firsts = np.unique(label[largest > 0])
    if firsts.size == 1:
        return [slice(None)]
    return [np.flatnonzero(label[level] == first) for first in firsts]


def _ball_sums(
    vertices: np.ndarray,
    cells: np.ndarray,
    radius,
    values: np.ndarray,
    usable: np.ndarray | None,
    weight,
    connected: bool = False,
) -> np.ndarray:
    """(V, k) ``sum_c weight(c, B(x_v, r)) * values[c]`` over cells (faces or edges) given by corner indices.

    ``vertices`` and ``cells`` checked (:func:`_checked_cells`), ``radius`` too (:func:`_trusted_radius`).
    ``connected`` (faces only): with the compiled kernels, the faces of the
    surface-connected piece of each ball (see :func:`ball_face_sums`).
    """
    values, usable = _checked_values(cells, values, usable)
    kernels = numba_kernels("neighborhoods")
    if connected and cells.shape[1] == 3 and cells.shape[0]:
        if kernels is not None:
            radii = np.array([[radius]]) if np.ndim(radius) == 0 else radius[None, :]
            return _connected_face_sums(kernels, vertices, cells, radii, values[None], usable)[0]
        return _connected_face_sums_numpy(vertices, cells, radius, values, usable)
    if np.ndim(radius):
        raise InvalidOptionError(
            "a `radius` per vertex takes the surface-connected balls (`connected=True`); "
            "the Euclidean ball sums take one radius"
        )
    if usable is not None:
        keep = np.flatnonzero(usable)
        cells, values = cells[keep], values[keep]
    n = vertices.shape[0]
    out = np.zeros((n, values.shape[1]))
    if cells.shape[0] == 0:
        return out
    if kernels is not None:
        centres, reach = kernels.cell_centres(vertices, cells)
    else:
        centres, reach = cell_centres(vertices, cells)
    # Cells are searched by their centres within radius + their own reach. One
    # search radius for all would be set by the largest cell: on a mesh with a
    # few long edges (a scan with a coarse patch) every ball would then gather
    # thousands of small cells. So cells are grouped by size: each group is
    # searched with its own largest reach, and a group takes the next power of
    # two of reach as long as its search radius grows by at most GROUP_GROWTH.
    if kernels is None:
        for chunk, i, c in _candidate_pairs(vertices, centres, reach, radius):
            weights = weight(vertices[cells[c]], vertices[chunk][i], radius)
            out[chunk] += _gathered(i, c, weights, chunk, values)
        return out
    for group in _size_groups(reach, radius):
        cutoff = radius + reach[group].max()
        mean, _ = check_ball_work(centres[group], cutoff, n, centres=vertices)
        ranges = call_ranges(n, mean)
        for start, stop in ranges:
            sums = kernels.ball_cell_sums(
                vertices,
                cells[group],
                centres[group],
                np.ascontiguousarray(values[group]),
                radius,
                cutoff,
                64 * kernel_threads(),
                start,
                stop,
            )
            if isinstance(group, slice) and len(ranges) == 1:  # one group, one call: its sums are the result
                return sums
            out += sums
    return out


def _checked_values(cells: np.ndarray, values, usable) -> tuple[np.ndarray, np.ndarray | None]:
    """``values`` (C, k) float64 and ``usable`` (C,) bool or None, one row per cell, checked."""
    values = np.asarray(values, dtype=np.float64)
    if values.ndim != 2 or values.shape[0] != cells.shape[0]:
        raise InvalidMeshError(f"`values` must have shape ({cells.shape[0]}, k): one row per cell; got {values.shape}")
    if usable is not None:
        usable = np.asarray(usable, dtype=bool)
        if usable.shape != (cells.shape[0],):
            raise InvalidMeshError(f"`usable` must have shape ({cells.shape[0]},); got {usable.shape}")
    return values, usable


def _gathered(rows: np.ndarray, cells: np.ndarray, weights: np.ndarray, chunk: slice, values: np.ndarray) -> np.ndarray:
    """(chunk length, k) ``sum weights * values[cells]`` by row: one sparse product."""
    import scipy.sparse as sp  # the NumPy path only

    gather = sp.csr_matrix((weights, (rows, cells)), shape=(chunk.stop - chunk.start, values.shape[0]))
    return np.asarray(gather @ values)


def cell_centres(vertices: np.ndarray, cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(C, 3) centroids of cells (faces or edges, corner indices) and (C,) their reach.

    The reach is the largest distance from the centroid to a corner: every point
    of the cell is within it. The operations of the compiled ``cell_centres``
    (corner by corner, in order), so that both backends test the same numbers.
    """
    corners = cells.shape[1]
    centres = vertices[cells[:, 0]]
    for k in range(1, corners):
        centres += vertices[cells[:, k]]
    centres /= corners
    reach = np.zeros(cells.shape[0])
    for k in range(corners):
        reach = np.maximum(reach, np.sqrt(_squared(*(vertices[cells[:, k]] - centres).T)))
    return centres, reach


def _squared(x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Squared lengths of offsets given by coordinate, summed x, y, z in that order (the kernels' rounding)."""
    return (x * x + y * y) + z * z


def _columns(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The x, y and z coordinates of (N, 3) points as three contiguous arrays (gathers by index from
    a column are several times faster than of rows)."""
    x, y, z = (np.ascontiguousarray(column) for column in points.T)
    return x, y, z


def _offsets(columns: tuple, index: np.ndarray, centre: tuple) -> tuple[np.ndarray, ...]:
    """The coordinates of the points ``index`` of ``columns`` relative to ``centre`` (three arrays each)."""
    return tuple(column[index] - c for column, c in zip(columns, centre))


#: Relative slack of the candidate searches of the NumPy path: a cell at the search radius
#: itself (up to the k-d tree's rounding) is a candidate, the exact tests decide.
_SEARCH_SLACK = 1e-9


def _candidate_pairs(
    centre_points: np.ndarray,
    centroids: np.ndarray,
    reach: np.ndarray,
    radius,
    chunk_size: int = CHUNK,
    *,
    refuse: bool = True,
) -> Iterator[tuple[slice, np.ndarray, np.ndarray]]:
    """Yield ``(chunk, i, c)`` per chunk of centres: cell ``c`` may meet the ball ``B(centre_points[i], radius)``.

    ``i`` indexes the chunk (0 and up). A superset of the cells that meet each
    ball: those whose centroid is within ``radius`` plus the largest reach of
    their size group (:func:`_size_groups`) of the centre, by k-d trees; the
    caller tests each pair exactly. The chunks hold at most ``chunk_size`` centres
    and about :data:`PAIRS_PER_CHUNK` pairs, all the groups' pairs of a centre in the same chunk.
    ``radius``: one for all, or a (C,) array of one per centre (each chunk is then
    searched with its largest: callers order the centres by radius).
    ``refuse``: check each group's work (:func:`check_ball_work`, as the compiled
    ``ball_cell_sums`` is called); False where the caller has made the check
    of the compiled path already (the connected balls), so that both backends
    refuse the same radii.

    Raises
    ------
    InvalidOptionError
        With ``refuse``, more than :data:`MAX_BALL_PAIRS` pairs in a group (:func:`check_ball_work`).
    """
    from scipy.spatial import cKDTree

    n = centre_points.shape[0]
    per_centre = np.ndim(radius) > 0  # one radius per centre: each chunk searched with its largest
    searches = []
    largest = 0.0
    if centroids.shape[0] and n:
        index = np.arange(centroids.shape[0])
        for group in _size_groups(reach, float(np.max(radius))):
            group_reach = float(reach[group].max())
            cutoff = radius + group_reach
            largest += (
                check_ball_work(centroids[group], cutoff, n, centres=centre_points)
                if refuse
                else _estimate_ball_pairs(centroids[group], cutoff, centre_points)
            )[1]
            searches.append((cKDTree(centroids[group]), index[group], group_reach))
    chunk_size = max(1, min(int(chunk_size), int(PAIRS_PER_CHUNK // max(4.0 * largest, 1.0))))
    empty = np.zeros(0, dtype=np.int64)
    for chunk in _chunks(n, chunk_size):
        rows, cells = [empty], [empty]
        top = float(radius[chunk].max()) if per_centre else radius
        for tree, index, group_reach in searches:
            i, c = _pairs(tree, centre_points[chunk], (top + group_reach) * (1 + _SEARCH_SLACK))
            rows.append(i)
            cells.append(index[c])
        yield chunk, np.concatenate(rows), np.concatenate(cells)


def _segments_meet_ball(a: tuple, b: tuple, radius2: float) -> np.ndarray:
    """(P,) whether each segment ``[a, b]`` (ends relative to the ball's centre, three coordinate arrays
    each) passes through the ball of squared radius ``radius2`` between its ends: its closest point to the
    centre is inside and not an end, found from the end nearer the centre. The operations of the compiled
    ``_segment_meets_ball``."""
    swap = _squared(*b) < _squared(*a)
    near = tuple(np.where(swap, q, p) for p, q in zip(a, b))
    d = tuple(np.where(swap, p, q) - n for p, q, n in zip(a, b, near))
    along = -((near[0] * d[0] + near[1] * d[1]) + near[2] * d[2])
    length2 = _squared(*d)
    with np.errstate(invalid="ignore", divide="ignore"):
        share = along / length2
        h2 = _squared(*(n + share * q for n, q in zip(near, d)))
    return (along > 0) & (along < length2) & (h2 <= radius2)


def _unique_sorted(keys: np.ndarray) -> np.ndarray:
    """``np.unique(keys)`` of a 1-d array by a sort (NumPy 2's hashing ``unique`` took 14 ms on 60,000 int64 keys
    where the sort takes 0.8)."""
    ordered = np.sort(keys)
    first = np.ones(ordered.shape[0], dtype=bool)
    np.not_equal(ordered[1:], ordered[:-1], out=first[1:])
    return ordered[first]


def _unique_inverse(keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``np.unique(keys, return_inverse=True)`` by one unstable argsort (several times faster)."""
    order = np.argsort(keys)
    ordered = keys[order]
    first = np.ones(ordered.shape[0], dtype=bool)
    np.not_equal(ordered[1:], ordered[:-1], out=first[1:])
    inverse = np.empty(keys.shape[0], dtype=np.int64)
    inverse[order] = np.cumsum(first) - 1
    return ordered[first], inverse


def _linked_to_centre(
    n: int, rows: np.ndarray, corners: list[np.ndarray], centre_vertices: np.ndarray
) -> tuple[np.ndarray, np.ndarray, list[np.ndarray]]:
    """The nodes ``(centre, vertex)`` of a chunk of balls and whether each is joined to its centre.

    Cell ``p`` (of centre ``rows[p]``, its vertices ``corners[k][p]``) joins
    its corners: the nodes joined to the centre's own node (``centre_vertices[i]``
    of centre ``i``) through such cells are the vertices a breadth-first walk
    from the centre over the cells reaches. Returns ``(keys, linked, nodes)``:
    the sorted node keys ``i * n + vertex``, (N,) whether each is joined to
    its centre and, per corner, the node of each cell's corner.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    m = centre_vertices.shape[0]
    base = rows * n
    keys, inverse = _unique_inverse(
        np.concatenate([base + corner for corner in corners] + [np.arange(m, dtype=np.int64) * n + centre_vertices])
    )
    size = rows.shape[0]
    nodes = [inverse[k * size : (k + 1) * size] for k in range(len(corners))]
    starts = np.concatenate([nodes[0]] * (len(corners) - 1))  # cell p joins its first corner to each other one
    graph = coo_matrix(
        (np.ones(starts.size, dtype=np.int8), (starts, np.concatenate(nodes[1:]))), shape=(keys.size, keys.size)
    )
    _, labels = connected_components(graph, directed=True, connection="weak")
    centre_labels = labels[inverse[len(corners) * size :]]
    return keys, labels == centre_labels[keys // n], nodes


def _connected_face_sums_numpy(
    vertices: np.ndarray, faces: np.ndarray, radius, values: np.ndarray, usable: np.ndarray | None
) -> np.ndarray:
    """:func:`ball_face_sums` over the surface-connected piece of each ball: the compiled
    ``connected_face_sums``'s faces, found for all centres of a chunk at once.

    A face is passed through when it meets the closed ball (its centroid
    within the radius plus its reach, and a corner or the centroid inside or a
    side crossing the sphere); the faces summed are those passed through that
    are joined to the centre by such faces (:func:`_linked_to_centre`), each
    weighted by its share (:func:`face_in_ball_ratios`, from squared distances
    as the kernel computes them). ``radius``: one for all, or (V,) one per
    vertex (the centres are then taken by increasing radius, so that each
    chunk's search reaches little beyond its own balls).
    """
    n = vertices.shape[0]
    centroids, reach = cell_centres(vertices, faces)
    check_ball_work(centroids, radius + float(reach.max()), n, centres=vertices)  # the compiled path's check
    points, middles = _columns(vertices), _columns(centroids)
    corners = [np.ascontiguousarray(faces[:, k]) for k in range(3)]
    out = np.zeros((n, values.shape[1]))
    order = np.arange(n) if np.ndim(radius) == 0 else np.argsort(radius, kind="stable")
    radii = np.broadcast_to(radius, (n,))[order]  # by centre, in the order taken
    for chunk, i, f in _candidate_pairs(
        vertices[order], centroids, reach, radii if np.ndim(radius) else radius, refuse=False
    ):
        ids = order[chunk][i]
        centre = tuple(column[ids] for column in points)
        middle = _squared(*_offsets(middles, f, centre))
        pair_radius = radii[chunk][i]
        near = np.flatnonzero(~(middle > (pair_radius + reach[f]) ** 2))
        i, f, middle, centre = i[near], f[near], middle[near], tuple(c[near] for c in centre)
        ball = pair_radius[near]
        radius2 = ball * ball
        offsets = [_offsets(points, corner[f], centre) for corner in corners]
        low, high = middle.copy(), middle.copy()
        for offset in offsets:
            squared = _squared(*offset)
            np.minimum(low, squared, out=low)
            np.maximum(high, squared, out=high)
        inside = high <= radius2
        partial = ~inside & (low < radius2)
        meets = inside | partial
        for k in range(3):  # corners and centroid outside: through the face when a side crosses the ball
            rest = np.flatnonzero(~meets)
            meets[rest] = _segments_meet_ball(
                tuple(c[rest] for c in offsets[k]), tuple(c[rest] for c in offsets[(k + 1) % 3]), radius2[rest]
            )
        i, f, low, high, inside, partial = i[meets], f[meets], low[meets], high[meets], inside[meets], partial[meets]
        ball = ball[meets]
        _, linked, nodes = _linked_to_centre(n, i, [corner[f] for corner in corners], order[chunk])
        root = np.sqrt(low)
        with np.errstate(invalid="ignore", divide="ignore"):
            share = np.where(inside, 1.0, np.where(partial, (ball - root) / (np.sqrt(high) - root), 0.0))
        keep = linked[nodes[0]] & (share != 0.0)
        if usable is not None:
            keep &= usable[f]
        out[order[chunk]] += _gathered(i[keep], f[keep], share[keep], chunk, values)
    return out


def connected_ball_pairs(
    vertices: np.ndarray,
    centres: np.ndarray,
    radius: float,
    adjacency: tuple,
    allowed: np.ndarray | None = None,
    *,
    chunk_size: int = CHUNK,
) -> Iterator[tuple[slice, np.ndarray, np.ndarray]]:
    """Yield ``(chunk, centre, neighbour)``: the vertices of the surface-connected piece of each ball.

    The NumPy twin of the compiled walk of the jet fits (``_connected_members``):
    the vertices within ``radius`` (one for all, or a (M,) array of one per
    centre: each chunk is then searched with its largest, so callers order the
    centres by radius) of vertex ``centres[centre]`` reached from it
    over the edges of ``adjacency`` (CSR lists, :attr:`MeshTopology.neighbour_lists`)
    that meet the closed ball (an end inside, or the segment passing through it),
    and ``allowed`` (V,) bool (default: all); every centre is its own first
    neighbour when allowed. ``centre`` indexes ``centres`` (absolute), by
    chunks of at most ``chunk_size`` of them as :func:`vertex_pairs_in_ball`;
    ``neighbour`` is a vertex id. Trusted inputs (``centres`` int64 ids in range).

    The caller checks the work (:func:`check_ball_work` of the vertices, as
    ``jets.fit_jets`` does on both backends).

    Raises
    ------
    InvalidMeshError
        ``adjacency`` is not CSR lists of the vertices (:func:`checked_adjacency`).
    """
    n = vertices.shape[0]
    edges = adjacency_edges(adjacency, n)
    mids, half = cell_centres(vertices, edges)
    points = _columns(vertices)
    first, second = np.ascontiguousarray(edges[:, 0]), np.ascontiguousarray(edges[:, 1])
    squares = np.broadcast_to(radius * radius, centres.shape)  # by centre
    for chunk, i, e in _candidate_pairs(vertices[centres], mids, half, radius, chunk_size, refuse=False):
        ids = centres[chunk]
        centre = tuple(column[ids[i]] for column in points)
        radius2 = squares[chunk][i]
        a, b = _offsets(points, first[e], centre), _offsets(points, second[e], centre)
        meets = (_squared(*a) <= radius2) | (_squared(*b) <= radius2)
        rest = np.flatnonzero(~meets)
        meets[rest] = _segments_meet_ball(tuple(c[rest] for c in a), tuple(c[rest] for c in b), radius2[rest])
        i, e = i[meets], e[meets]
        keys, linked, _ = _linked_to_centre(n, i, [first[e], second[e]], ids)
        keys = keys[linked]
        rows, neighbour = np.divmod(keys, n)
        inside = (
            _squared(*_offsets(points, neighbour, tuple(column[ids[rows]] for column in points)))
            <= squares[chunk][rows]
        )
        if allowed is not None:
            inside &= allowed[neighbour]
        yield chunk, rows[inside] + chunk.start, neighbour[inside]


def checked_adjacency(adjacency, n: int) -> tuple[np.ndarray, np.ndarray]:
    """``(indptr, indices)``: CSR neighbour lists of ``n`` vertices, as contiguous arrays: ``indptr`` int64,
    ``indices`` int32 when given so (:attr:`MeshTopology.neighbour_lists` of a mesh that fits), else int64.

    Raises
    ------
    InvalidMeshError
        ``indptr`` does not hold ``n + 1`` offsets ending at the length of
        ``indices``, or an index is not a vertex.
    """
    indptr, indices = adjacency
    indptr = np.ascontiguousarray(indptr, dtype=np.int64)
    indices = np.asarray(indices)
    indices = np.ascontiguousarray(indices, dtype=np.int32 if indices.dtype == np.int32 else np.int64)
    if indptr.shape != (n + 1,) or indices.ndim != 1 or indptr[-1] != indices.shape[0]:
        raise InvalidMeshError(f"`adjacency` must be CSR lists of {n} vertices; got indptr {indptr.shape}")
    if indices.size and (indices.min() < 0 or indices.max() >= n):
        raise InvalidMeshError(f"`adjacency` must hold vertex indices in 0..{n - 1}")
    return indptr, indices


def adjacency_edges(adjacency: tuple, n: int) -> np.ndarray:
    """(E, 2) int64 edges ``a < b`` of CSR neighbour lists ``(indptr, indices)`` of ``n`` vertices, each once.

    Raises
    ------
    InvalidMeshError
        ``adjacency`` is not CSR lists of the vertices (:func:`checked_adjacency`).
    """
    indptr, indices = checked_adjacency(adjacency, n)
    starts = np.repeat(np.arange(n, dtype=np.int64), np.diff(indptr))
    low, high = np.minimum(starts, indices), np.maximum(starts, indices)
    keys = np.unique((low * n + high)[low != high])
    return np.column_stack([keys // n, keys % n])


def call_ranges(n: int, pairs_per_centre: float, weights: np.ndarray | None = None) -> list[tuple[int, int]]:
    """``(start, stop)`` of each call of a compiled ball kernel over ``n`` centres, in order.

    About :data:`PAIRS_PER_CALL` (centre, point) pairs per call (``pairs_per_centre`` on
    average, as :func:`check_ball_work` estimates it): between calls Python gets control back,
    so that Ctrl-C gets through. One call at least, none of them empty when ``n > 0``.
    ``weights`` (n,): the relative work of each centre (the square of its radius, for
    balls on a surface of one radius per centre): the calls then split the total
    weight evenly rather than the centres.
    """
    n_calls = max(1, min(n, int(np.ceil(pairs_per_centre * n / PAIRS_PER_CALL))))
    if weights is None or n_calls == 1:
        return [(call * n // n_calls, (call + 1) * n // n_calls) for call in range(n_calls)]
    cumulative = np.cumsum(weights, dtype=np.float64)
    cuts = np.searchsorted(cumulative, cumulative[-1] * np.arange(1, n_calls) / n_calls, side="right")
    bounds = np.unique(np.concatenate([[0], np.clip(cuts, 1, n - 1), [n]]))
    return [(int(a), int(b)) for a, b in zip(bounds[:-1], bounds[1:])]


def _face_sum_scratch(
    n_chunks: int, n_vertices: int, n_faces: int, nested: bool = False, *, filled: bool = True, kernels=None
) -> tuple[np.ndarray, ...]:
    """The per-thread scratch of the compiled ``connected_face_sums``:
    ``(seen, mark, known, squared, queue, levels, spare)`` (and of ``connected_face_sums_nested``).

    ``seen`` (n_chunks, F), ``mark`` and ``known`` (n_chunks, V) filled with -1, ``squared``
    (n_chunks, V) float and ``queue`` (n_chunks, V). Allocated once for all the calls over
    one mesh: each array is stamped with the centre it was last written for, and every centre is
    summed once, so no call needs it cleared again. The stamps and the queue hold vertex
    indices: int32 while the vertex and face counts fit in it (half the memory: 40 bytes per vertex
    on 2 threads), int64 beyond. ``levels``: (n_chunks, V) with ``nested`` (several radii in one
    walk: the smallest ball each queued vertex was reached through), (n_chunks, 0) otherwise; ``spare``:
    (n_chunks, 0), the place of the clusters' scratch (``clustered_face_sums``). ``filled`` False: the three
    stamps not filled here (``connected_face_sums`` with ``ready`` has each thread fill its own row, in parallel).

    ``kernels`` (the compiled modules' ``neighborhoods``): the arrays from numba's allocator, not numpy's
    (``kernels._unadvised_array``): numpy advises huge pages for them, and where the kernel gives huge pages to
    advised memory only, the first write to each 2 MB of a fresh array waits while it compacts memory (issue
    31, at 1M vertices: 0.2-0.36 s of system time in the ball sums' threads, for 56 MB of scratch).
    """
    index = np.int32 if max(n_vertices, n_faces) < np.iinfo(np.int32).max else np.int64
    empty = np.empty if kernels is None else kernels._unadvised_array

    def stamps(shape: tuple[int, int]) -> np.ndarray:
        array = empty(shape, index)
        if filled:
            array.fill(-1)
        return array

    return (
        stamps((n_chunks, n_faces)),
        stamps((n_chunks, n_vertices)),
        stamps((n_chunks, n_vertices)),
        empty((n_chunks, n_vertices), np.float64),
        empty((n_chunks, n_vertices), index),
        empty((n_chunks, n_vertices if nested else 0), index),
        empty((n_chunks, 0), index),
    )


def _connected_face_sums(
    kernels,
    vertices: np.ndarray,
    faces: np.ndarray,
    radii: np.ndarray,
    values: np.ndarray,
    usable: np.ndarray | None,
    n_centres: int | None = None,
) -> np.ndarray:
    """(R, V, k) :func:`ball_face_sums` over the surface-connected piece of each ball (compiled kernel,
    breadth-first), at the R nested radii ``radii`` (R, 1) (one for all vertices) or (R, V) (one per vertex),
    of ``values`` (1, F, k) (the same for every radius) or (R, F, k) (one set per radius). One radius:
    ``connected_face_sums``; several: ``connected_face_sums_nested`` (one walk per vertex, that of the largest).
    ``n_centres``: only the balls of the first ``n_centres`` vertices (the other rows are 0)."""
    n = vertices.shape[0]
    m = n if n_centres is None else n_centres
    usable = np.ones(faces.shape[0], dtype=bool) if usable is None else usable
    centres, reach = kernels.cell_centres(vertices, faces)
    outer = radii[-1, 0] if radii.shape[1] == 1 else radii[-1, :m]  # the largest ball leads the walk
    mean, _ = check_ball_work(centres, outer + float(reach.max()), m, centres=vertices[:m])
    indptr, indices = kernels.vertex_face_lists(faces, n, kernel_threads())
    values = np.ascontiguousarray(values)
    clustered = radii.shape[0] == 1 and mean >= CLUSTER_MIN_FACES  # dense balls: clusters inside a ball added whole
    plain = radii.shape[0] == 1 and not clustered  # one ball: the kernel without the passes
    shape = (radii.shape[0], n, values.shape[2])
    # the plain kernel writes each of its rows (every row when m == n): no zeros first (a memset of 72 MB at 1M)
    out = kernels._unadvised_array(shape, np.float64, zero=not (plain and m == n))
    rows = max(1, min(kernel_threads(), n))
    # the plain kernel's threads fill their own rows of the stamps (``ready``): no serial fill of (rows, F + 2 V)
    scratch = _face_sum_scratch(rows, n, faces.shape[0], radii.shape[0] > 1, filled=not plain, kernels=kernels)
    ready = np.zeros(rows, dtype=bool)
    clusters = None
    if clustered:
        clusters = _face_clusters(vertices, faces, centres, reach, values[0], usable)
        scratch = scratch[:5] + tuple(
            np.full((scratch[0].shape[0], clusters[1].shape[0]), -1, scratch[0].dtype) for _ in range(3)
        )
    for start, stop in call_ranges(m, mean, None if radii.shape[1] == 1 else outer * outer):
        if radii.shape[0] > 1:
            kernels.connected_face_sums_nested(
                vertices, faces, centres, reach, usable, values, radii, indptr, indices, out, scratch, start, stop
            )
            continue
        ball = (vertices, faces, centres, reach, usable, values[0], radii[0], indptr, indices)
        if plain:
            kernels.connected_face_sums(*ball, out[0], scratch, start, stop, ready)
        else:
            kernels.clustered_face_sums(*ball, clusters, out[0], scratch, start, stop)
    return out


def coarse_face_sums(
    vertices: np.ndarray, faces: np.ndarray, radius, values: np.ndarray, *, usable: np.ndarray | None = None
) -> np.ndarray:
    """(V, k) :func:`ball_face_sums` (``connected=True``) approximated on clusters of faces, in a time that does
    not grow with the density of the faces in a ball.

    The faces are grouped in connected clusters of about :data:`COARSE_CLUSTER_FACES` (:func:`_face_clusters`);
    each ball walks the clusters from those of the faces around its vertex through the clusters that share a
    vertex, and each cluster adds its sums times its share of the ball, by its bounding sphere (1 inside, 0
    outside, linear in between: :func:`face_in_ball_ratios` for a cluster); a cluster of share 0 leads the
    walk no further. Where a ball holds many clusters the sums differ from the exact ones by the rim's
    shares only. Balls of fewer than :data:`CLUSTER_MIN_FACES` faces on average take the exact sums. Both
    backends compute the same clusters and shares (the NumPy path by connected components, as
    :func:`_connected_face_sums_numpy`).
    """
    vertices, faces = _checked_cells(vertices, faces)
    return _coarse_face_sums(vertices, faces, centre_radii(radius, vertices.shape[0]), values, usable=usable)


def _coarse_face_sums(
    vertices: np.ndarray, faces: np.ndarray, radius, values: np.ndarray, *, usable: np.ndarray | None = None
) -> np.ndarray:
    """:func:`coarse_face_sums` of checked ``vertices`` and ``faces`` (:func:`_checked_cells`) and ``radius``."""
    n = vertices.shape[0]
    radius = _trusted_radius(radius, n)
    values, usable = _checked_values(faces, values, usable)
    kernels = numba_kernels("neighborhoods")
    if faces.shape[0] == 0:
        return np.zeros((n, values.shape[1]))
    centres, reach = cell_centres(vertices, faces) if kernels is None else kernels.cell_centres(vertices, faces)
    mean, _ = check_ball_work(centres, radius + float(reach.max()), n, centres=vertices)
    if mean < CLUSTER_MIN_FACES:
        return _ball_sums(vertices, faces, radius, values, usable, face_in_ball_ratios, True)
    usable = np.ones(faces.shape[0], dtype=bool) if usable is None else usable
    clusters = _face_clusters(vertices, faces, centres, reach, values, usable, size=COARSE_CLUSTER_FACES)
    if kernels is None:
        return _coarse_face_sums_numpy(vertices, faces, radius, clusters)
    indptr, indices = kernels.vertex_face_lists(faces, n, kernel_threads())
    n_chunks = max(1, min(kernel_threads(), n))
    index = np.int32 if max(n, faces.shape[0]) < np.iinfo(np.int32).max else np.int64
    n_clusters = clusters[1].shape[0]
    scratch = (
        np.full((n_chunks, n_clusters), -1, index),
        np.zeros((n_chunks, n_clusters)),
        np.zeros((n_chunks, n_clusters), index),
    )
    out = np.zeros((n, values.shape[1]))
    radii = np.array([radius]) if np.ndim(radius) == 0 else radius
    kernels.coarse_face_sums(vertices, indptr, indices, radii, clusters, out, scratch, 0, n)
    return out


def coarse_share(distance: np.ndarray, span: np.ndarray, radius) -> np.ndarray:
    """The share of a cluster of faces in a ball of ``radius`` by its bounding sphere (its middle at
    ``distance`` from the ball's centre, of radius ``span``): 1 inside, 0 outside, linear in between by the
    distances of its nearest and farthest points from the sphere of radius ``m = sqrt(radius^2 - span^2 / 3)``.

    A ramp centred on ``radius`` counts ``pi (radius^2 + span^2 / 3)`` of a plane sampled evenly (the clusters
    outside the rim outnumber those inside it: 2.2% too much area for clusters of 16 faces in balls of 600
    faces, 7.9% for 64; ``tests/test_neighborhoods_clusters.py``); centred on ``m`` it counts ``pi radius^2``,
    the ball's area (0.9% and 1.6% too much there: the surface is not a plane)."""
    middle = np.sqrt(np.maximum(radius * radius - span * span / 3.0, 0.0))
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(
            distance + span <= middle,
            1.0,
            np.where(distance - span < middle, (middle - (distance - span)) / (2.0 * span), 0.0),
        )


def _coarse_face_sums_numpy(vertices: np.ndarray, faces: np.ndarray, radius, clusters: tuple) -> np.ndarray:
    """The compiled ``coarse_face_sums`` for all centres of a chunk at once: the (centre, cluster) pairs of
    positive share (k-d tree pairs of centres and cluster middles, the kernel's share), joined through the
    clusters' links; those connected to a cluster of a face around the centre are summed."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    of, middles, spans, sums, links_indptr, links, _, _, _ = clusters
    n = vertices.shape[0]
    n_clusters = middles.shape[0]
    out = np.zeros((n, sums.shape[1]))
    order = np.arange(n) if np.ndim(radius) == 0 else np.argsort(radius, kind="stable")
    radii = np.broadcast_to(radius, (n,))[order]
    # the clusters of the faces around each vertex: where its walk starts
    starts = np.unique(faces.ravel() * n_clusters + np.repeat(of, 3))
    start_vertex, start_cluster = starts // n_clusters, starts % n_clusters
    for chunk, i, c in _candidate_pairs(
        vertices[order], middles, spans, radii if np.ndim(radius) else radius, refuse=False
    ):
        ids = order[chunk][i]
        ball = radii[chunk][i]
        d = np.sqrt(_squared(*(middles[c] - vertices[ids]).T))
        share = coarse_share(d, spans[c], ball)
        positive = share > 0.0
        i, c, share = i[positive], c[positive], share[positive]
        keys = i * n_clusters + c  # the nodes (centre, cluster), sorted
        node_order = np.argsort(keys, kind="stable")
        keys, i, c, share = keys[node_order], i[node_order], c[node_order], share[node_order]
        # links (centre, cluster) -> (centre, neighbour) between nodes
        count = links_indptr[c + 1] - links_indptr[c]
        tails = np.repeat(np.arange(keys.size), count)
        firsts = np.repeat(links_indptr[c] - np.concatenate([[0], np.cumsum(count)[:-1]]), count)
        heads_key = i[tails] * n_clusters + links[firsts + np.arange(tails.size)]
        at = np.minimum(np.searchsorted(keys, heads_key), max(keys.size - 1, 0))
        joined = keys[at] == heads_key if keys.size else np.zeros(0, dtype=bool)
        # a root node per centre, joined to the nodes of the clusters around its vertex
        centre_of = np.full(n, -1, dtype=np.int64)
        centre_of[order[chunk]] = np.arange(chunk.stop - chunk.start)
        owner = centre_of[start_vertex]
        mine = owner >= 0
        root_key = owner[mine] * n_clusters + start_cluster[mine]
        found = np.minimum(np.searchsorted(keys, root_key), max(keys.size - 1, 0))
        hit = keys[found] == root_key if keys.size else np.zeros(0, dtype=bool)
        m = chunk.stop - chunk.start
        size = keys.size + m
        graph = coo_matrix(
            (
                np.ones(int(joined.sum()) + int(hit.sum()), dtype=np.int8),
                (
                    np.concatenate([tails[joined], keys.size + owner[mine][hit]]),
                    np.concatenate([at[joined], found[hit]]),
                ),
            ),
            shape=(size, size),
        )
        _, labels = connected_components(graph, directed=False)
        reached = labels[: keys.size] == labels[keys.size + i]
        out[order[chunk]] += _gathered(i[reached], c[reached], share[reached], chunk, sums)
    return out


def _face_clusters(
    vertices: np.ndarray,
    faces: np.ndarray,
    centres: np.ndarray,
    reach: np.ndarray,
    values: np.ndarray,
    usable,
    size: float = CLUSTER_FACES,
) -> tuple:
    """The clusters of faces of the compiled ``clustered_face_sums``: ``(of, centres, spans, sums, links_indptr,
    links, shared_indptr, shared, slack)``.

    The faces are grouped by the cube of side ``sqrt(size * median area)`` (``size``: :data:`CLUSTER_FACES`, or
    :data:`COARSE_CLUSTER_FACES` for :func:`coarse_face_sums`) that holds their
    centroid, and each cube's faces split into the pieces connected through their corners (a cluster is
    connected: once the walk of a ball reaches one of its faces, and it lies inside the ball, the walk
    reaches all of them). ``of`` (F,): each face's cluster; ``centres`` (C, 3) and ``spans`` (C,): a sphere
    holding every face of a cluster (the middle of its corners' bounding box, the largest distance from it to
    a corner); ``sums`` (C, k): the sums of the usable faces' ``values``; ``links``: the clusters that share a
    vertex with each cluster (CSR over the clusters, each list increasing), ``shared``: the shared vertices of
    each link (CSR over the links, increasing); ``slack``: the round-off of the coordinates, a margin of the
    inside and outside tests.
    """
    n_faces = faces.shape[0]
    twice = np.linalg.norm(
        np.cross(vertices[faces[:, 1]] - vertices[faces[:, 0]], vertices[faces[:, 2]] - vertices[faces[:, 0]]), axis=1
    )
    area = 0.5 * float(np.median(twice))
    side = np.sqrt(size * area) if area > 0 else float(reach.max()) + 1.0
    from .jets import turned_cubes  # (jets imports this module)

    # cubes beyond 2^20 per axis share the last one (a face flung far away): the key fits in an int64; no cube
    # boundary through a voxel surface's lattice of centroids, where round-off (a scaled mesh) would make other
    # clusters; a mirror image of the mesh gets the mirrored clusters (turned_cubes)
    cube = turned_cubes(centres, side)[0]
    _, cell = _unique_inverse(cube[:, 0] << 42 | cube[:, 1] << 21 | cube[:, 2])
    kept = np.ones(n_faces, dtype=bool) if usable is None else usable
    kernels = numba_kernels("neighborhoods")
    if kernels is None:
        parts = _face_cluster_parts(vertices, faces, cell, values, kept)
    else:  # the same parts to the bit, compiled (tests/test_face_clusters_D30.py)
        indptr, indices = kernels.vertex_face_lists(faces, vertices.shape[0], kernel_threads())
        parts = kernels._face_cluster_parts(vertices, faces, cell, values, kept, indptr, indices)
    of, middle, spans, sums, links_indptr, links, shared_indptr, at = parts
    n_clusters = middle.shape[0]
    scale = float(np.abs(vertices).max()) if vertices.size else 0.0
    slack = 64 * np.finfo(np.float64).eps * (scale + float(spans.max()) if n_clusters else scale)
    return (*parts, slack)


def _face_cluster_parts(
    vertices: np.ndarray, faces: np.ndarray, cell: np.ndarray, values: np.ndarray, kept: np.ndarray
) -> tuple:
    """:func:`_face_clusters`' clusters of faces whose cube ``cell`` (F,) is given, their spheres, sums and links:
    ``(of, middle, spans, sums, links_indptr, links, shared_indptr, shared)`` (the compiled
    ``_face_cluster_parts`` computes the same, to the bit)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    n_faces = faces.shape[0]
    # faces linked through (vertex, cube) nodes: two faces of one cube that share a corner are connected
    _, node = _unique_inverse(faces.ravel() * (int(cell.max()) + 1) + np.repeat(cell, 3))
    n_nodes = n_faces + int(node.max()) + 1
    graph = coo_matrix(
        (np.ones(3 * n_faces, dtype=np.int8), (np.repeat(np.arange(n_faces), 3), n_faces + node.ravel())),
        shape=(n_nodes, n_nodes),
    )
    _, label = connected_components(graph, directed=False)
    _, of = _unique_inverse(label[:n_faces])
    n_clusters = int(of.max()) + 1
    # each cluster's sphere: the middle of its corners' bounding box, to the farthest corner
    order = np.argsort(of, kind="stable")
    firsts = np.concatenate([[0], np.cumsum(np.bincount(of, minlength=n_clusters))[:-1]])
    corners = vertices[faces[order]]
    # (the three corners compared pairwise: a reduction over the middle axis of (F, 3, 3) is five times slower)
    lowest = np.minimum(np.minimum(corners[:, 0], corners[:, 1]), corners[:, 2])
    highest = np.maximum(np.maximum(corners[:, 0], corners[:, 1]), corners[:, 2])
    middle = 0.5 * (np.minimum.reduceat(lowest, firsts) + np.maximum.reduceat(highest, firsts))
    distance = np.linalg.norm(corners - middle[of[order], None], axis=2)
    far = np.maximum(np.maximum(distance[:, 0], distance[:, 1]), distance[:, 2])
    spans = np.maximum.reduceat(far, firsts)
    sums = np.stack(
        [np.bincount(of[kept], weights=values[kept, k], minlength=n_clusters) for k in range(values.shape[1])], axis=1
    )
    # the (vertex, cluster) incidences, by vertex; each ordered pair of clusters at a vertex is a link
    keys = _unique_sorted(faces.ravel() * n_clusters + np.repeat(of, 3))
    vertex, cluster = keys // n_clusters, keys % n_clusters
    per_vertex = np.bincount(vertex, minlength=vertices.shape[0])
    firsts = np.concatenate([[0], np.cumsum(per_vertex)])[vertex]
    repeats = per_vertex[vertex]
    tails = np.repeat(np.arange(keys.size), repeats)
    heads = np.repeat(firsts - np.concatenate([[0], np.cumsum(repeats)[:-1]]), repeats) + np.arange(tails.size)
    pair = cluster[tails] != cluster[heads]
    tails, heads = cluster[tails[pair]], cluster[heads[pair]]
    at = vertex[np.repeat(np.arange(keys.size), repeats)[pair]]
    order = np.lexsort((at, heads, tails))
    tails, heads, at = tails[order], heads[order], at[order]
    starts = np.flatnonzero(np.concatenate([[True], (tails[1:] != tails[:-1]) | (heads[1:] != heads[:-1])]))
    starts = starts if tails.size else starts[:0]
    links = heads[starts].astype(np.int64)
    links_indptr = np.concatenate([[0], np.cumsum(np.bincount(tails[starts], minlength=n_clusters))]).astype(np.int64)
    shared_indptr = np.concatenate([starts, [tails.size]]).astype(np.int64)
    return (
        of,
        np.ascontiguousarray(middle),
        np.ascontiguousarray(spans, dtype=np.float64),
        np.ascontiguousarray(sums),
        links_indptr,
        links,
        shared_indptr,
        np.ascontiguousarray(at, dtype=np.int64),
    )


def _trusted_radius(radius, n: int):
    """A radius the caller checked (:func:`centre_radii`): a float as it is; a (n,) array through
    :func:`centre_radii` (no entry into :mod:`meshcurv._validation`)."""
    return float(radius) if np.ndim(radius) == 0 else centre_radii(radius, n)


def _checked_cells(vertices, cells) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and (C, 3) faces or (C, 2) edges, checked (indices in range)."""
    vertices = checked_points(vertices)
    shape = np.shape(cells)
    columns = shape[1] if len(shape) == 2 and shape[1] in (2, 3) else 3
    return vertices, checked_indices(
        cells, vertices.shape[0], columns=columns, name="edges" if columns == 2 else "faces"
    )


def ball_face_sums(
    vertices: np.ndarray,
    faces: np.ndarray,
    radius: float,
    values: np.ndarray,
    *,
    usable: np.ndarray | None = None,
    connected: bool = False,
    centres: np.ndarray | None = None,
) -> np.ndarray:
    """(V, k) ``sum_f ratio(f, B(x_v, r)) * values[f]`` over the faces meeting each ball.

    ``values`` is (F, k); ``ratio`` is :func:`face_in_ball_ratios`. Faces not
    ``usable`` (F,) bool are left out. With ``connected``, only the faces
    reached from those around each vertex through faces that meet the closed
    ball (the centroid within the radius plus the face's reach, and a corner
    or the centroid inside or a side crossing the sphere; faces not ``usable``
    lead on but add nothing): the faces of the ball wherever its part of the
    surface is connected; another sheet of the surface inside the ball is left
    out. The compiled kernel walks each ball breadth-first (no search
    structure over the whole mesh); the NumPy path finds the same faces by
    connected components (see the module's doc).

    ``radius``: one for all vertices (a float), or with ``connected`` a (V,)
    array of one per vertex (positive, finite): the sums of each vertex are
    then those of the float call at its own radius.

    ``centres`` (M,) vertex indices, with ``connected``: the (M, k) sums of
    those vertices' balls only (the rows of the call without ``centres``, to
    round-off; the compiled kernel walks no other ball).

    Raises
    ------
    InvalidOptionError
        ``radius`` is not a number >= 0 or an array of V positive finite
        numbers, or is an array without ``connected``; ``centres`` without
        ``connected``.
    InvalidMeshError
        ``centres`` is not a 1-d array of vertex indices in range.
    """
    if centres is not None and not connected:
        raise InvalidOptionError("`centres` takes the surface-connected balls (`connected=True`)")
    vertices, faces = _checked_cells(vertices, faces)
    n = vertices.shape[0]
    radius = centre_radii(radius, n)
    ids = None if centres is None else _checked_ids(centres, n)
    return _ball_face_sums(vertices, faces, radius, values, usable=usable, connected=connected, centres=ids)


def _ball_face_sums(
    vertices: np.ndarray,
    faces: np.ndarray,
    radius,
    values: np.ndarray,
    *,
    usable: np.ndarray | None = None,
    connected: bool = False,
    centres: np.ndarray | None = None,
) -> np.ndarray:
    """:func:`ball_face_sums` of checked ``vertices`` and ``faces`` (:func:`_checked_cells`), ``radius`` and
    ``centres`` ((M,) int64 vertex indices)."""
    radius = _trusted_radius(radius, vertices.shape[0])
    if centres is None:
        return _ball_sums(vertices, faces, radius, values, usable, face_in_ball_ratios, connected)
    if not connected:
        raise InvalidOptionError("`centres` takes the surface-connected balls (`connected=True`)")
    n = vertices.shape[0]
    kernels = numba_kernels("neighborhoods")
    if kernels is None or faces.shape[0] == 0:
        return _ball_sums(vertices, faces, radius, values, usable, face_in_ball_ratios, connected)[centres]
    values, usable = _checked_values(faces, values, usable)
    # the centres relabelled first, so that the kernel's range of rows is theirs
    unique, inverse = np.unique(centres, return_inverse=True)
    order = np.concatenate([unique, np.setdiff1d(np.arange(n), unique, assume_unique=True)])
    relabel = np.empty(n, dtype=np.int64)
    relabel[order] = np.arange(n)
    radii = np.array([[radius]]) if np.ndim(radius) == 0 else np.asarray(radius)[order][None, :]
    summed = _connected_face_sums(kernels, vertices[order], relabel[faces], radii, values[None], usable, unique.size)
    return summed[0, inverse.ravel()]


def ball_face_sums_nested(
    vertices: np.ndarray, faces: np.ndarray, radii, values: np.ndarray, *, usable: np.ndarray | None = None
) -> np.ndarray:
    """(R, V, k) :func:`ball_face_sums` with ``connected=True`` at R nested radii, one walk per vertex.

    Row ``r`` equals ``ball_face_sums(vertices, faces, radii[r], values,
    usable=usable, connected=True)`` (``values[r]`` when ``values`` holds one
    set per radius) to round-off (the same faces and shares,
    added in another order; the largest radius's row to the bit). The compiled
    kernel walks the largest ball of each vertex once and adds each face it
    reaches to the rows of the smaller balls whose pieces the walk shows it is in
    (it reached the face through faces that meet that ball); a smaller ball the
    walk cannot vouch for (a face it meets reached only through a larger one) is
    walked on its own, for that vertex alone. The NumPy path computes each radius
    on its own.

    Parameters
    ----------
    vertices : array_like of shape (V, 3)
    faces : array_like of shape (F, 3)
    radii : array_like of shape (R,) or (R, V)
        R >= 1 radii, one for all vertices, or one row per radius with a radius
        per vertex; positive, finite and non-decreasing along the first axis.
    values : array_like of shape (F, k) or (R, F, k)
        The same values for every radius, or one set per radius (the face
        measures of normals fitted at each scale).
    usable : array_like of bool of shape (F,), optional
        Faces that add to the sums (the others lead the walks on); default: all.

    Returns
    -------
    ndarray of shape (R, V, k)

    Raises
    ------
    InvalidOptionError
        ``radii`` is empty, not of shape (R,) or (R, V), holds a radius that is not
        positive and finite, or decreases.
    """
    vertices, faces = _checked_cells(vertices, faces)
    return _ball_face_sums_nested(vertices, faces, radii, values, usable=usable)


def _ball_face_sums_nested(
    vertices: np.ndarray, faces: np.ndarray, radii, values: np.ndarray, *, usable: np.ndarray | None = None
) -> np.ndarray:
    """:func:`ball_face_sums_nested` of checked ``vertices`` and ``faces`` (:func:`_checked_cells`)."""
    n = vertices.shape[0]
    try:
        nested = np.array(radii, dtype=np.float64, ndmin=1)
    except (TypeError, ValueError):
        raise InvalidOptionError(
            f"`radii` must be an increasing sequence of positive radii or an (R, {n}) array of them"
        ) from None
    if nested.ndim == 1:
        nested = nested[:, None]
    if nested.ndim != 2 or nested.shape[0] == 0 or nested.shape[1] not in (1, n):
        raise InvalidOptionError(f"`radii` must have shape (R,) or (R, {n}) with R >= 1; got {np.shape(radii)}")
    if not (np.isfinite(nested).all() and (nested > 0).all()):
        raise InvalidOptionError("`radii` must hold positive finite radii")
    if (np.diff(nested, axis=0) < 0).any():
        raise InvalidOptionError("`radii` must not decrease from one radius to the next (nested balls)")
    values = np.asarray(values, dtype=np.float64)
    if values.ndim == 3 and values.shape[0] != nested.shape[0]:
        raise InvalidMeshError(
            f"`values` must have shape (F, k) or ({nested.shape[0]}, F, k): one set per radius; got {values.shape}"
        )
    sets = values if values.ndim == 3 else values[None]
    for one in sets[1:]:  # each set checked; no copy of them (three sets of a 1M-face mesh: 430 MB)
        _checked_values(faces, one, usable)
    _, usable = _checked_values(faces, sets[0], usable)
    kernels = numba_kernels("neighborhoods")
    if faces.shape[0] == 0:
        return np.zeros((nested.shape[0], n, sets.shape[2]))
    if kernels is not None:
        return _connected_face_sums(kernels, vertices, faces, np.ascontiguousarray(nested), sets, usable)
    return np.stack(
        [
            _connected_face_sums_numpy(
                vertices, faces, row[0] if row.size == 1 else row, sets[r if sets.shape[0] > 1 else 0], usable
            )
            for r, row in enumerate(nested)
        ]
    )


def ball_edge_sums(
    vertices: np.ndarray, edges: np.ndarray, radius: float, values: np.ndarray, *, usable: np.ndarray | None = None
) -> np.ndarray:
    """(V, k) ``sum_e |e ∩ B(x_v, r)| * values[e]`` over the edges meeting each ball (exact lengths)."""
    vertices, edges = _checked_cells(vertices, edges)
    return _ball_edge_sums(vertices, edges, centre_radii(radius, vertices.shape[0]), values, usable=usable)


def _ball_edge_sums(
    vertices: np.ndarray, edges: np.ndarray, radius, values: np.ndarray, *, usable: np.ndarray | None = None
) -> np.ndarray:
    """:func:`ball_edge_sums` of checked ``vertices`` and ``radius``, and ``edges`` of vertex indices in range
    (int64 as :func:`_checked_cells` makes them; :attr:`MeshTopology.edges` are int32)."""
    return _ball_sums(
        vertices,
        np.ascontiguousarray(edges, dtype=np.int64),
        _trusted_radius(radius, vertices.shape[0]),
        values,
        usable,
        lambda ends, centres, r: segment_in_ball_lengths(ends[:, 0], ends[:, 1], centres, r),
    )


def ring_sums(neighbour_lists: tuple, rings: int, *arrays: np.ndarray) -> list[np.ndarray]:
    """Each of ``arrays`` summed ``rings`` times over every vertex and its edge neighbours.

    Parameters
    ----------
    neighbour_lists : tuple of ndarray
        ``(indptr, indices)``: the edge neighbours of every vertex in CSR form, each list increasing and without
        the vertex itself (:attr:`meshcurv.topology.MeshTopology.neighbour_lists`).
    rings : int
        How many times the sums are taken (0: the arrays as float64).
    *arrays : ndarray of shape (V,) or (V, k)
        The values per vertex.

    Returns
    -------
    list of ndarray
        One float64 array per array given, of its shape: ``S^rings x`` with ``S`` the matrix of the lists plus
        the identity.

    Notes
    -----
    Both backends give the same numbers to the bit: each sum runs from 0 over the vertex and its neighbours in
    increasing order (what SciPy's product of ``x`` by the CSR matrix ``S`` does, the NumPy path's). The
    compiled one runs on threads, without the (V, V) matrix.
    """
    indptr, indices = neighbour_lists
    n = indptr.size - 1
    kernels = numba_kernels("neighborhoods")
    if kernels is None:
        from scipy import sparse  # imported on use: keeps `import meshcurv` fast

        ring = sparse.csr_matrix((np.ones(indices.size), indices, indptr), shape=(n, n)) + sparse.identity(n)
        sums = [np.asarray(array, dtype=np.float64) for array in arrays]
        for _ in range(rings):
            sums = [ring @ array for array in sums]
        return sums
    # one pass per ring over all the arrays' columns side by side: the lists are read once, not once per array
    columns = [np.asarray(array, dtype=np.float64).reshape(n, -1) for array in arrays]
    if not columns:
        return []
    summed = _ring_passes(kernels, indptr, indices, np.concatenate(columns, axis=1), rings, False)
    bounds = np.cumsum([0] + [block.shape[1] for block in columns])
    return [
        np.ascontiguousarray(summed[:, lo:hi]).reshape(np.shape(array))
        for lo, hi, array in zip(bounds[:-1], bounds[1:], arrays)
    ]


def ring_max(neighbour_lists: tuple, rings: int, values: np.ndarray) -> np.ndarray:
    """(V,) the largest of ``values`` over each vertex and the vertices within ``rings`` edges of it.

    Parameters
    ----------
    neighbour_lists : tuple of ndarray
        ``(indptr, indices)``: the edge neighbours of every vertex in CSR form
        (:attr:`meshcurv.topology.MeshTopology.neighbour_lists`).
    rings : int
        How many rings of neighbours are read.
    values : ndarray of shape (V,)
        The values per vertex.

    Returns
    -------
    ndarray of shape (V,)
        float64; NaN where any value within the rings is NaN (as ``np.maximum``); a largest value 0 is 0.0,
        never -0.0.

    Notes
    -----
    Both backends give the same numbers to the bit: each ring takes ``np.maximum`` of a vertex's own value and
    of the running largest of its neighbours' in their order (``np.maximum.reduceat``, the NumPy path's).
    """
    indptr, indices = neighbour_lists
    kernels = numba_kernels("neighborhoods")
    if kernels is None:
        rows = np.flatnonzero(np.diff(indptr) > 0)
        out = np.array(values, dtype=np.float64, copy=True)
        for _ in range(rings if rows.size else 0):
            # the rows without neighbours are skipped: each start then ends where the next row with any begins
            out[rows] = np.maximum(out[rows], np.maximum.reduceat(out[indices], indptr[rows]))
        out += 0.0  # -0.0 -> 0.0: which of two equal zeros np.maximum keeps depends on its loop (SIMD or not)
        return out
    return _ring_passes(kernels, indptr, indices, values, rings, True)


def _ring_passes(kernels, indptr, indices, array, rings: int, largest: bool) -> np.ndarray:
    """``rings`` passes of the compiled :func:`ring_sums` (``largest`` False) or :func:`ring_max` over ``array``
    (V,) or (V, k), float64 in two buffers taken in turn."""
    values = np.array(array, dtype=np.float64, copy=True)
    shape = values.shape
    if rings > 0:
        values = values.reshape(shape[0], -1)
        spare = np.zeros_like(values)
        for _ in range(rings):
            kernels._ring_pass(indptr, indices, values, spare, largest)
            values, spare = spare, values
    if largest:
        values += 0.0  # -0.0 -> 0.0, as the NumPy path
    return values.reshape(shape)
