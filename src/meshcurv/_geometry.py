"""The cores of :mod:`meshcurv.geometry`: the same quantities over arrays already checked.

Each function here has the name, the arguments and the result of the public
function of :mod:`meshcurv.geometry` that checks its input and calls it (its
docstring holds the contract and the formula). They trust their input:
``vertices`` a C-contiguous float64 (V, 3) array of finite coordinates, faces
and edges C-contiguous int64 arrays of indices in range, a
:class:`~meshcurv.topology.MeshTopology` of ``V`` vertices. The library calls
them on the arrays of a :class:`~meshcurv._prepared.PreparedMesh`, checked once
by :func:`meshcurv._prepared.prepare_mesh`; a check here would be the second.
"""

from __future__ import annotations

import numpy as np

from ._backend import numba_kernels, twin

#: Faces with area below this fraction of the squared length scale of their component
#: (:func:`vertex_length_scales`, the median edge length) count as degenerate.
DEGENERATE_AREA_RATIO = 1e-12

#: :func:`robust_mean_edge_length` leaves out edges longer than this many median edge lengths.
OUTLIER_EDGE_RATIO = 1000.0

#: :func:`vertex_length_scales` takes the median of a connected mesh over about this many edges.
MEDIAN_SAMPLE = 65536

#: Components whose typical edge (geometric mean) is within this factor of the mesh's median
#: edge length share that median as their scale (one pass, no sort); others get their own.
COMPONENT_SCALE_SPREAD = 16.0


def finite_rows(array: np.ndarray) -> np.ndarray:
    """(N,) bool: the rows of the (N, k) ``array`` whose entries are all finite.

    ``np.isfinite(array).all(axis=1)`` column by column: a reduction along the short axis of an (N, 3) array
    walks it in steps of a few elements (20 ms at a million rows); ``k`` passes over the columns take 3 ms, the
    same booleans (issue 31).
    """
    out = np.ones(array.shape[0], dtype=bool)
    for k in range(array.shape[1]):
        out &= np.isfinite(array[:, k])
    return out


@twin("geometry")
def face_cross_products(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(F, 3) ``cross(b - a, c - a)`` of every face ``(a, b, c)`` (:func:`meshcurv.geometry.face_cross_products`)."""
    a = vertices[faces[:, 0]]
    u = vertices[faces[:, 1]] - a
    w = vertices[faces[:, 2]] - a
    return np.stack(
        [
            u[:, 1] * w[:, 2] - u[:, 2] * w[:, 1],
            u[:, 2] * w[:, 0] - u[:, 0] * w[:, 2],
            u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0],
        ],
        axis=1,
    )


def face_areas(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(F,) the area of every face (:func:`meshcurv.geometry.face_areas`)."""
    return 0.5 * np.linalg.norm(face_cross_products(vertices, faces), axis=1)


def vertex_normals(vertices: np.ndarray, faces: np.ndarray, *, cross: np.ndarray | None = None) -> np.ndarray:
    """(V, 3) area-weighted unit vertex normals (:func:`meshcurv.geometry.vertex_normals`).

    ``cross``, when given, is a C-contiguous float64 (F, 3) array.
    """
    if cross is None:
        cross = face_cross_products(vertices, faces)
    return normalize_normal_sums(vertex_normal_sums(cross, faces, vertices.shape[0]))


@twin("geometry")
def vertex_normal_sums(cross: np.ndarray, faces: np.ndarray, n_vertices: int) -> np.ndarray:
    """(V, 3) the sums of the (F, 3) face cross products ``cross`` at each vertex, in face order."""
    flat = faces.ravel()
    return np.stack(
        [np.bincount(flat, weights=np.repeat(cross[:, k], 3), minlength=n_vertices) for k in range(3)], axis=1
    )


@twin("geometry")
def vertex_normal_and_area_sums(
    cross: np.ndarray, faces: np.ndarray, dropped: np.ndarray, n_vertices: int
) -> tuple[np.ndarray, np.ndarray]:
    """``(sums, areas)``: (V, 3) the sums of the (F, 3) face cross products ``cross`` at each vertex and (V,) a
    third of the areas of the faces at each vertex, both over the faces not ``dropped`` ((F,) bool), in face
    order: the vertex normals (:func:`normalize_normal_sums`) and the vertex areas of one pass."""
    used = np.where(dropped[:, None], 0.0, cross)
    third = np.linalg.norm(used, axis=1) / 6.0
    return vertex_normal_sums(used, faces, n_vertices), np.bincount(
        faces.ravel(), weights=np.repeat(third, 3), minlength=n_vertices
    )


@twin("geometry")
def normalize_normal_sums(summed: np.ndarray) -> np.ndarray:
    """Unit vectors from (V, 3) sums of face cross products; NaN where a sum is 0.

    (The test ``|s| > 1e-12 max(max|s_k|, tiny)`` fails only for a zero or
    subnormal sum, since ``|s| >= max|s_k|``.)
    """
    norm = np.linalg.norm(summed, axis=1, keepdims=True)
    scale = np.abs(summed).max(axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(norm > 1e-12 * np.maximum(scale, np.finfo(float).tiny), summed / norm, np.nan)


@twin("geometry")
def edge_lengths(vertices: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """(E,) ``|x_j - x_i|`` for each edge ``(i, j)`` (:func:`meshcurv.geometry.edge_lengths`)."""
    d = vertices[edges[:, 1]] - vertices[edges[:, 0]]
    return np.sqrt(np.einsum("ij,ij->i", d, d))


@twin("geometry")
def vertex_edge_lengths(vertices: np.ndarray, edges: np.ndarray, n_vertices: int) -> np.ndarray:
    """(V,) the mean length of the edges at each vertex, NaN at none (:func:`meshcurv.geometry.vertex_edge_lengths`);
    ``n_vertices`` is ``vertices.shape[0]``."""
    n = n_vertices
    flat = edges.ravel()
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.bincount(flat, weights=np.repeat(edge_lengths(vertices, edges), 2), minlength=n) / np.bincount(
            flat, minlength=n
        )


@twin("geometry")
def mean_edge_length(vertices: np.ndarray, edges: np.ndarray) -> float:
    """Mean length of the edges, 0 without edges (:func:`meshcurv.geometry.mean_edge_length`)."""
    if edges.shape[0] == 0:
        return 0.0
    return float(edge_lengths(vertices, edges).mean())


def median_edge_length(vertices: np.ndarray, edges: np.ndarray) -> float:
    """Median length of the edges, 0 without edges (:func:`meshcurv.geometry.median_edge_length`)."""
    lengths = edge_lengths(vertices, edges)
    # partitioned in place: the lengths are this function's own (no copy of 3 V lengths, issue 31)
    return float(np.median(lengths, overwrite_input=True)) if lengths.size else 0.0


def robust_mean_edge_length(vertices: np.ndarray, edges: np.ndarray) -> float:
    """Mean length of the edges within :data:`OUTLIER_EDGE_RATIO` medians
    (:func:`meshcurv.geometry.robust_mean_edge_length`)."""
    if edges.shape[0] == 0:
        return 0.0
    step = max(1, edges.shape[0] // MEDIAN_SAMPLE)  # the median is a threshold: a sample will do
    kernels = numba_kernels("geometry")
    if kernels is not None:  # the sample's lengths alone, then the mean and the longest in one pass (issue 31)
        median = float(np.median(edge_lengths(vertices, np.ascontiguousarray(edges[::step]))))
        mean, longest = kernels._mean_and_longest_edge(vertices, edges)  # mean_edge_length's mean, to the bit
        return _mean_within(vertices, edges, OUTLIER_EDGE_RATIO * median, mean, longest)
    lengths = edge_lengths(vertices, edges)
    median = float(np.median(lengths[::step]))
    # lengths.mean(): the NumPy mean_edge_length's, to the bit (the same lengths, the same reduction)
    return _mean_within(vertices, edges, OUTLIER_EDGE_RATIO * median, lengths.mean(), lengths.max(), lengths)


def _mean_within(
    vertices: np.ndarray, edges: np.ndarray, bound: float, mean, longest, lengths: np.ndarray | None = None
) -> float:
    """:func:`robust_mean_edge_length` from the plain ``mean`` and the ``longest`` length of ``edges``: the plain
    mean where no edge is longer than ``bound``, else the mean of the ``lengths`` (computed here when None) within
    it."""
    if longest <= bound:
        return float(mean)
    if lengths is None:
        lengths = edge_lengths(vertices, edges)
    return float(lengths[lengths <= bound].mean())


def vertex_length_scales(vertices: np.ndarray, topology) -> np.ndarray:
    """(V,) the median edge length of each vertex's component (:func:`meshcurv.geometry.vertex_length_scales`);
    a prepared mesh holds them (:attr:`meshcurv._prepared.PreparedMesh.length_scales`)."""
    return length_scales_and_median(vertices, topology)[0]


def length_scales_and_median(vertices: np.ndarray, topology) -> tuple[np.ndarray, float]:
    """``(scales, median)``: :func:`vertex_length_scales` and the median length of every edge
    (:func:`median_edge_length` of ``topology.edges``, to the bit; 0 without edges), which the scales are taken
    from: a prepared mesh keeps both (:attr:`meshcurv._prepared.PreparedMesh.median_edge_length`)."""
    edges = topology.edges
    n = topology.n_vertices
    if edges.shape[0] == 0:
        return np.zeros(n), 0.0
    referenced = topology.referenced_vertices
    n_components, labels = topology.vertex_components
    if n_components <= 1:  # one scale: the median of every edge (a sample by index follows the vertex order, and
        # so did the radii that divide local edge lengths by it: nefertiti.obj, fuzz 419/58)
        overall = median_edge_length(vertices, edges)
        return np.where(referenced, overall, 0.0), overall
    lengths = edge_lengths(vertices, edges)
    overall = float(np.median(lengths))  # median_edge_length's
    edge_label = labels[edges[:, 0]]
    positive = lengths > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        log_sums = np.bincount(edge_label[positive], weights=np.log2(lengths[positive]), minlength=n_components)
        typical = log_sums / np.bincount(edge_label[positive], minlength=n_components)
    spread = np.abs(typical[np.isfinite(typical)] - np.log2(overall)) if overall > 0 else np.array([np.inf])
    if spread.size and spread.max() <= np.log2(COMPONENT_SCALE_SPREAD):
        return np.where(referenced, overall, 0.0), overall
    order = np.lexsort((lengths, edge_label))
    counts = np.bincount(edge_label, minlength=n_components)
    starts = np.cumsum(counts) - counts
    ranked = lengths[order]
    medians = np.zeros(n_components)
    some = counts > 0  # a component of faces (a, a, a) only has no edge: scale 0
    low = ranked[starts[some] + (counts[some] - 1) // 2]
    high = ranked[starts[some] + counts[some] // 2]
    medians[some] = 0.5 * (low + high)
    return np.where(referenced, medians[np.maximum(labels, 0)], 0.0), overall


def degenerate_face_mask(areas: np.ndarray, length_scale) -> np.ndarray:
    """(F,) bool: ``areas <= DEGENERATE_AREA_RATIO * length_scale ** 2``
    (:func:`meshcurv.geometry.degenerate_face_mask`); ``length_scale`` >= 0, a number or one per face."""
    with np.errstate(over="ignore"):  # a scale beyond 1e154 squares to inf: every face is below it
        return areas <= DEGENERATE_AREA_RATIO * np.asarray(length_scale, dtype=np.float64) ** 2


def degenerate_faces(
    vertices: np.ndarray,
    topology,
    *,
    cross: np.ndarray | None = None,
    mean_edge_length: float | None = None,
    double_areas: np.ndarray | None = None,
    scales: np.ndarray | None = None,
) -> np.ndarray:
    """(F,) bool: faces with a repeated corner or an area below 1e-12 x (length scale)^2
    (:func:`meshcurv.geometry.degenerate_faces`); the optional arrays C-contiguous float64 of their shapes."""
    if scales is None:
        if mean_edge_length is None:
            scales = vertex_length_scales(vertices, topology)
        else:
            scales = np.full(topology.n_vertices, float(mean_edge_length))
    if double_areas is None:
        if cross is None:
            return cross_and_degenerate(vertices, topology.faces, scales, DEGENERATE_AREA_RATIO)[1]
        double_areas = np.sqrt(np.einsum("ij,ij->i", cross, cross))
    return degenerate_face_mask(0.5 * double_areas, scales[topology.faces[:, 0]]) | topology.degenerate_faces


@twin("geometry")
def cross_and_degenerate(
    vertices: np.ndarray, faces: np.ndarray, scales: np.ndarray, area_ratio: float
) -> tuple[np.ndarray, np.ndarray]:
    """``(cross, degenerate)``: the (F, 3) :func:`face_cross_products` and the (F,) bool zero-area faces, a repeated
    corner or an area at most ``area_ratio`` x ``scales[a]^2`` at the first corner ``a`` (as
    :func:`degenerate_faces` with ``scales``), from one pass over the faces."""
    cross = face_cross_products(vertices, faces)
    with np.errstate(over="ignore"):  # a scale beyond 1e154 squares to inf: every face is below it
        small = 0.5 * np.sqrt(np.einsum("ij,ij->i", cross, cross)) <= area_ratio * scales[faces[:, 0]] ** 2
    repeated = (faces[:, 0] == faces[:, 1]) | (faces[:, 1] == faces[:, 2]) | (faces[:, 2] == faces[:, 0])
    return cross, small | repeated


#: An edge whose two faces lie on each other within this angle (radians) is a fold and its dihedral angle reads pi,
#: as an exact fold's does: the sign of ``pi - epsilon`` (a fin) against ``-(pi - epsilon)`` (a slit) is decided by the
#: last bits of the coordinates there (ogre.obj turned and shifted: epsilon 5e-12 to 2e-11 of either sign at its
#: four exact folds; fuzz_api 421/64). Far above the round-off of a mesh moved by 2^20 sizes, far below a knife edge
#: that is not a fold (0.001 degrees is 2e-5).
FOLD_ANGLE = 1e-6


def fold_angles(beta: np.ndarray) -> np.ndarray:
    """(E,) the dihedral angles ``beta`` in ``(-pi, pi]`` with those within :data:`FOLD_ANGLE` of ``+-pi`` read as
    ``pi``: an exact fold reads pi on both backends (tests/test_exact_folds.py), and so does one that round-off
    turned by a few last bits either way (a rigid motion of the mesh)."""
    return np.where(np.pi - np.abs(beta) <= FOLD_ANGLE, np.pi, beta)


def edge_dihedral_angles(
    vertices: np.ndarray, topology, unit_normals: np.ndarray, usable_edges: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(beta, lengths, unit_edges)``: the signed angle between the face normals of each usable edge, the
    edges' lengths and unit vectors (:func:`meshcurv.geometry.edge_dihedral_angles`)."""
    edges = topology.edges
    vectors = vertices[edges[:, 1]] - vertices[edges[:, 0]]
    lengths = np.linalg.norm(vectors, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        unit = np.where(lengths[:, None] > 0, vectors / lengths[:, None], 0.0)
    beta = np.zeros(edges.shape[0])
    faces = topology.edge_faces[usable_edges]
    n1 = unit_normals[faces[:, 0]]
    n2 = unit_normals[faces[:, 1]]
    sine = np.einsum("ij,ij->i", np.cross(n1, n2), unit[usable_edges])
    cosine = np.einsum("ij,ij->i", n1, n2)
    beta[usable_edges] = fold_angles(np.arctan2(sine + 0.0, cosine))  # (+ 0.0: an exact fold, a sine of -0.0)
    return beta, lengths, unit


def corner_cotangents(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(F, 3) the cotangent of the angle at each corner (:func:`meshcurv.geometry.corner_cotangents`)."""
    out = np.zeros(faces.shape, dtype=np.float64)
    for k in range(3):
        a, b = _corner_sides(vertices, faces, k)
        with np.errstate(invalid="ignore", divide="ignore"):
            out[:, k] = np.einsum("ij,ij->i", a, b) / np.linalg.norm(np.cross(a, b), axis=1)
    return out


def corner_angles(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(F, 3) the interior angle at each corner (:func:`meshcurv.geometry.corner_angles`)."""
    out = np.zeros(faces.shape, dtype=np.float64)
    for k in range(3):
        a, b = _corner_sides(vertices, faces, k)
        out[:, k] = np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.einsum("ij,ij->i", a, b))
    return out


def _corner_sides(vertices: np.ndarray, faces: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """The (F, 3) vectors of the two sides that leave corner ``k`` of every face, in the faces' order."""
    p = vertices[faces[:, k]]
    return vertices[faces[:, (k + 1) % 3]] - p, vertices[faces[:, (k + 2) % 3]] - p


def mixed_voronoi_corner_areas(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(F, 3) each face's share of the mixed Voronoi area of its corners
    (:func:`meshcurv.geometry.mixed_voronoi_corner_areas`, Meyer et al. 2003)."""
    cot = corner_cotangents(vertices, faces)
    area = face_areas(vertices, faces)
    squared = np.zeros(faces.shape, dtype=np.float64)  # squared length of the side opposite corner k
    for k in range(3):
        d = vertices[faces[:, (k + 2) % 3]] - vertices[faces[:, (k + 1) % 3]]
        squared[:, k] = np.einsum("ij,ij->i", d, d)
    voronoi = np.zeros(faces.shape, dtype=np.float64)
    with np.errstate(invalid="ignore", over="ignore"):  # the infinite cotangents of zero-area faces: 0 below
        for k in range(3):
            j, m = (k + 1) % 3, (k + 2) % 3
            # sides at corner k: k-j (opposite m) and k-m (opposite j)
            voronoi[:, k] = (squared[:, m] * cot[:, m] + squared[:, j] * cot[:, j]) / 8.0
    obtuse_corner = cot < 0
    obtuse = obtuse_corner.any(axis=1, keepdims=True)
    mixed = np.where(obtuse, np.where(obtuse_corner, area[:, None] / 2, area[:, None] / 4), voronoi)
    return np.where(np.isfinite(mixed), mixed, 0.0)
