"""Euclidean balls around vertices: which faces, edges and vertices they hold, and how much.

Every estimator that takes ``radius=`` uses it through this module, so the
option has one meaning: the closed Euclidean ball ``B(x_v, radius)`` around
each vertex position, in the units of the coordinates. The default radius is
:data:`DEFAULT_RADIUS_FACTOR` times the mean edge length of the mesh.

Queries run on :class:`scipy.spatial.cKDTree` pair searches, in chunks of
centres so that memory stays bounded on large meshes; all per-pair work is
vectorized (no Python loop over vertices, edges or faces). With numba, the
face and edge sums (and the jet fits of :mod:`meshcurv.estimators.quadric`)
run on a grid of cells at least as wide as the ball instead, in compiled
kernels that find the same points (tests/test_backends.py compares the two).
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from ._backend import numba_kernels
from ._validation import check_positive_float
from .geometry import mean_edge_length
from .topology import MeshTopology

__all__ = [
    "DEFAULT_RADIUS_FACTOR",
    "default_radius",
    "resolve_radius",
    "vertex_pairs_in_ball",
    "ball_face_sums",
    "ball_edge_sums",
    "face_in_ball_ratios",
    "segment_in_ball_lengths",
]

#: The default ``radius`` is this many mean edge lengths.
DEFAULT_RADIUS_FACTOR = 2.5

#: Centres per chunk of a ball query (bounds the memory of the pair lists).
CHUNK = 32768

#: Cells of different sizes share one search while its radius (radius + largest reach) grows
#: by at most this factor over that of their smallest size class.
GROUP_GROWTH = 1.5


def default_radius(vertices: np.ndarray, topology: MeshTopology) -> float:
    """``DEFAULT_RADIUS_FACTOR`` times the mean edge length (0 for a mesh without edges)."""
    return DEFAULT_RADIUS_FACTOR * mean_edge_length(vertices, topology.edges)


def resolve_radius(radius, vertices: np.ndarray, topology: MeshTopology) -> float:
    """The radius to use: ``radius`` checked, or the mesh's default when None.

    Raises
    ------
    InvalidOptionError
        ``radius`` is not a positive finite number.
    """
    if radius is None:
        return default_radius(vertices, topology)
    return check_positive_float(radius, "radius")


def _chunks(n: int, size: int = CHUNK) -> Iterator[slice]:
    for start in range(0, n, size):
        yield slice(start, min(n, start + size))


def _pairs(tree, centers: np.ndarray, cutoff: float) -> tuple[np.ndarray, np.ndarray]:
    """(i, j): centre ``i`` and point ``j`` of ``tree`` (a ``cKDTree``) no farther apart than ``cutoff``."""
    from scipy.spatial import cKDTree  # imported on use: scipy.spatial costs import time

    found = cKDTree(centers).sparse_distance_matrix(tree, cutoff, output_type="ndarray")
    return found["i"].astype(np.int64), found["j"].astype(np.int64)


def vertex_pairs_in_ball(points: np.ndarray, radius: float, *, centres: np.ndarray | None = None,
                         chunk_size: int = CHUNK) -> Iterator[tuple[slice, np.ndarray, np.ndarray]]:
    """Yield ``(chunk, centre, neighbour)``: every point within ``radius`` of each centre.

    The centres are the points ``centres`` (default: all), taken by chunk of
    ``chunk_size``; ``centre`` indexes them (absolute: ``chunk.start`` and up),
    ``neighbour`` indexes ``points``: the point within the ball (the centre itself included).
    """
    from scipy.spatial import cKDTree

    tree = cKDTree(points)
    centres = np.arange(points.shape[0]) if centres is None else centres
    for chunk in _chunks(centres.shape[0], chunk_size):
        i, j = _pairs(tree, points[centres[chunk]], radius)
        yield chunk, i + chunk.start, j


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
    """(P,) exact length of each segment ``[start, end]`` inside the ball around its centre."""
    d = ends - starts
    f = starts - centers
    a = np.einsum("ij,ij->i", d, d)
    b = 2 * np.einsum("ij,ij->i", d, f)
    c = np.einsum("ij,ij->i", f, f) - radius * radius
    disc = b * b - 4 * a * c
    root = np.sqrt(np.maximum(disc, 0.0))
    with np.errstate(invalid="ignore", divide="ignore"):
        t0 = np.clip((-b - root) / (2 * a), 0.0, 1.0)
        t1 = np.clip((-b + root) / (2 * a), 0.0, 1.0)
    inside = np.where((disc > 0) & (a > 0), t1 - t0, 0.0)
    return inside * np.sqrt(a)


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
            first = k
        label[k] = first
    firsts = np.unique(label[largest > 0])
    if firsts.size == 1:
        return [slice(None)]
    return [np.flatnonzero(label[level] == first) for first in firsts]


def _ball_sums(vertices: np.ndarray, cells: np.ndarray, radius: float, values: np.ndarray,
               usable: np.ndarray | None, weight) -> np.ndarray:
    """(V, k) ``sum_c weight(c, B(x_v, r)) * values[c]`` over cells (faces or edges) given by corner indices."""
    import scipy.sparse as sp
    from scipy.spatial import cKDTree

    if usable is not None:
        keep = np.flatnonzero(usable)
        cells, values = cells[keep], values[keep]
    n = vertices.shape[0]
    out = np.zeros((n, values.shape[1]))
    if cells.shape[0] == 0:
        return out
    kernels = numba_kernels()
    if kernels is not None:
        centres, reach = kernels.cell_centres(vertices, cells)
    else:
        corners = vertices[cells]
        centres = corners.mean(axis=1)
        reach = np.linalg.norm(corners - centres[:, None, :], axis=2).max(axis=1)
    # Cells are searched by their centres within radius + their own reach. One
    # search radius for all would be set by the largest cell: on a mesh with a
    # few long edges (a scan with a coarse patch) every ball would then gather
    # thousands of small cells. So cells are grouped by size: each group is
    # searched with its own largest reach, and a group takes the next power of
    # two of reach as long as its search radius grows by at most GROUP_GROWTH.
    for group in _size_groups(reach, radius):
        if kernels is not None:
            sums = kernels.ball_cell_sums(vertices, cells[group], centres[group], np.ascontiguousarray(values[group]),
                                          radius, radius + reach[group].max(), 64 * kernels.threads())
            if isinstance(group, slice):  # one group: its sums are the result
                return sums
            out += sums
            continue
        tree = cKDTree(centres[group])
        cutoff = radius + reach[group].max()
        index = np.arange(cells.shape[0])[group]  # group position -> cell
        for chunk in _chunks(n):
            i, c = _pairs(tree, vertices[chunk], cutoff)
            c = index[c]
            weights = weight(vertices[cells[c]], vertices[chunk][i], radius)
            gather = sp.csr_matrix((weights, (i, c)), shape=(chunk.stop - chunk.start, values.shape[0]))
            out[chunk] += np.asarray(gather @ values)
    return out


def ball_face_sums(vertices: np.ndarray, faces: np.ndarray, radius: float, values: np.ndarray,
                   *, usable: np.ndarray | None = None) -> np.ndarray:
    """(V, k) ``sum_f ratio(f, B(x_v, r)) * values[f]`` over the faces meeting each ball.

    ``values`` is (F, k); ``ratio`` is :func:`face_in_ball_ratios`. Faces not
    ``usable`` (F,) bool are left out.
    """
    return _ball_sums(vertices, faces, radius, values, usable, face_in_ball_ratios)


def ball_edge_sums(vertices: np.ndarray, edges: np.ndarray, radius: float, values: np.ndarray,
                   *, usable: np.ndarray | None = None) -> np.ndarray:
    """(V, k) ``sum_e |e ∩ B(x_v, r)| * values[e]`` over the edges meeting each ball (exact lengths)."""
    return _ball_sums(vertices, edges, radius, values, usable,
                      lambda ends, centres, r: segment_in_ball_lengths(ends[:, 0], ends[:, 1], centres, r))
