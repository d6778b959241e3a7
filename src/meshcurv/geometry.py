"""Geometric quantities of triangle meshes, as pure functions over arrays.

Inputs are ``vertices`` of shape (V, 3) and ``faces`` of shape (F, 3)
(0-based); outputs are new float64 arrays. Each function checks its arrays
cheaply (:func:`meshcurv._validation.checked_mesh`: dtype, shape, finite
coordinates, indices in range; no copy of arrays that are already float64 and
int64), so that the compiled kernels never read out of bounds.

Length scales: every tolerance of the core is relative to a *robust* length
scale, the median edge length of the vertex's connected component
(:func:`vertex_length_scales`), never to the mean over the whole mesh: one
vertex at 1e10 (a scanner's sentinel) moves the mean edge length of a mesh by
orders of magnitude but not its median, and a mesh made of a part at 1e-3 and a
part at 1e3 has a scale for each.
"""

from __future__ import annotations

import numpy as np

from ._backend import numba_kernels
from ._validation import checked_mesh, checked_points
from .errors import InvalidMeshError, InvalidOptionError
from .topology import MeshTopology

__all__ = [
    "degenerate_faces",
    "edge_dihedral_angles",
    "face_cross_products",
    "face_areas",
    "face_normals",
    "signed_volume",
    "vertex_areas",
    "vertex_normals",
    "edge_lengths",
    "vertex_edge_lengths",
    "mean_edge_length",
    "median_edge_length",
    "robust_mean_edge_length",
    "vertex_length_scales",
    "degenerate_face_mask",
    "checked_topology_points",
    "corner_cotangents",
    "corner_angles",
    "mixed_voronoi_corner_areas",
]

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


def face_cross_products(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """The cross product ``cross(b - a, c - a)`` of every face ``(a, b, c)``.

    Written out component by component (faster than :func:`numpy.cross`, same values).

    Parameters
    ----------
    vertices : array_like of shape (V, 3)
        Finite coordinates.
    faces : array_like of shape (F, 3), int
        0-based vertex indices of the triangles (F may be 0).

    Returns
    -------
    ndarray of shape (F, 3), float64
        Twice the face's area times its unit normal (right-hand rule on the
        vertex order), in length^2; 0 on zero-area faces.

    Raises
    ------
    InvalidMeshError
        ``vertices`` or ``faces`` of the wrong shape or dtype, coordinates not
        finite, or indices out of range.
    """
    vertices, faces = checked_mesh(vertices, faces)
    kernels = numba_kernels("geometry")
    if kernels is not None:
        return kernels.face_cross_products(vertices, faces)
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
    """The area of every face, ``|cross(b - a, c - a)| / 2``.

    Parameters
    ----------
    vertices : array_like of shape (V, 3)
    faces : array_like of shape (F, 3), int
        0-based.

    Returns
    -------
    ndarray of shape (F,), float64
        In length^2, >= 0 (0 for a repeated corner or collinear corners).

    Raises
    ------
    InvalidMeshError
        As :func:`face_cross_products`.
    """
    return 0.5 * np.linalg.norm(face_cross_products(vertices, faces), axis=1)


def face_normals(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """The unit normal of every face, by the right-hand rule on its vertex order.

    Parameters
    ----------
    vertices : array_like of shape (V, 3)
    faces : array_like of shape (F, 3), int
        0-based.

    Returns
    -------
    ndarray of shape (F, 3), float64
        ``cross / |cross|`` (:func:`face_cross_products`); a face with zero
        area has no normal: its row is NaN.

    Raises
    ------
    InvalidMeshError
        As :func:`face_cross_products`.
    """
    cross = face_cross_products(vertices, faces)
    norm = np.linalg.norm(cross, axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(norm > 0, cross / norm, np.nan)


def signed_volume(vertices: np.ndarray, faces: np.ndarray) -> float:
    """Signed volume enclosed by the faces (positive for a closed, outward-wound mesh).

    ``V = sum(a . (b x c)) / 6`` over the faces ``(a, b, c)``, with the
    coordinates taken relative to the centroid of the vertices, which reduces
    rounding and makes the value independent of translation on closed meshes
    (on an open mesh it depends on that origin).

    Parameters
    ----------
    vertices : array_like of shape (V, 3)
    faces : array_like of shape (F, 3), int
        0-based.

    Returns
    -------
    float
        In length^3; reversing every face negates it; 0 when there are no faces.

    Raises
    ------
    InvalidMeshError
        As :func:`face_cross_products`.
    """
    vertices, faces = checked_mesh(vertices, faces)
    centred = vertices - vertices.mean(axis=0)
    a, b, c = (centred[faces[:, k]] for k in range(3))
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def vertex_areas(vertices: np.ndarray, faces: np.ndarray, *, areas: np.ndarray | None = None) -> np.ndarray:
    """Barycentric vertex areas: a third of the area of every incident face.

    Parameters
    ----------
    vertices : array_like of shape (V, 3)
    faces : array_like of shape (F, 3), int
        0-based.
    areas : array_like of shape (F,), optional
        The face areas when already computed (:func:`face_areas`).

    Returns
    -------
    ndarray of shape (V,), float64
        In length^2; they sum to the total area of the mesh; an unreferenced
        vertex gets 0.

    Raises
    ------
    InvalidMeshError
        As :func:`face_cross_products`, or ``areas`` not real numbers of shape (F,).
    """
    vertices, faces = checked_mesh(vertices, faces)
    if areas is None:
        areas = face_areas(vertices, faces)
    else:
        areas = _real_array(areas, "areas")
        if areas.shape != faces.shape[:1]:
            raise InvalidMeshError(f"`areas` must have shape {faces.shape[:1]} (one per face); got {areas.shape}")
    return np.bincount(faces.ravel(), weights=np.repeat(areas / 3.0, 3), minlength=vertices.shape[0])


def vertex_normals(vertices: np.ndarray, faces: np.ndarray, *, cross: np.ndarray | None = None) -> np.ndarray:
    """Unit vertex normals, the area-weighted mean of the incident face normals.

    ``n_v = s / |s|`` with ``s`` the sum of :func:`face_cross_products` over
    the faces at ``v`` (each weighted by twice its area).

    Parameters
    ----------
    vertices : array_like of shape (V, 3)
    faces : array_like of shape (F, 3), int
        0-based.
    cross : array_like of shape (F, 3), optional
        The face cross products when already computed.

    Returns
    -------
    ndarray of shape (V, 3), float64
        Oriented like the faces (outward on an outward-wound closed mesh). NaN
        where ``s`` is 0: a vertex with no incident face of non-zero area, or
        whose face normals cancel exactly.

    Raises
    ------
    InvalidMeshError
        As :func:`face_cross_products`, or ``cross`` not real numbers of shape (F, 3).
    """
    vertices, faces = checked_mesh(vertices, faces)
    if cross is not None:
        cross = np.ascontiguousarray(_real_array(cross, "cross"))
        if cross.shape != faces.shape:
            raise InvalidMeshError(f"`cross` must have shape {faces.shape} (one row per face); got {cross.shape}")
    if cross is None:
        cross = face_cross_products(vertices, faces)
    n = vertices.shape[0]
    kernels = numba_kernels("geometry")
    if kernels is not None:
        return kernels.normalize_normal_sums(kernels.vertex_normal_sums(cross, faces, n))
    flat = faces.ravel()
    summed = np.stack([np.bincount(flat, weights=np.repeat(cross[:, k], 3), minlength=n) for k in range(3)], axis=1)
    return normalize_normal_sums(summed)


def normalize_normal_sums(summed: np.ndarray) -> np.ndarray:
    """Unit vectors from (V, 3) sums of face cross products; NaN where a sum is 0.

    (The test ``|s| > 1e-12 max(max|s_k|, tiny)`` fails only for a zero or
    subnormal sum, since ``|s| >= max|s_k|``.)
    """
    norm = np.linalg.norm(summed, axis=1, keepdims=True)
    scale = np.abs(summed).max(axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(norm > 1e-12 * np.maximum(scale, np.finfo(float).tiny), summed / norm, np.nan)


def edge_lengths(vertices: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """The length of each of the given edges.

    Parameters
    ----------
    vertices : array_like of shape (V, 3)
    edges : array_like of shape (E, 2), int
        0-based vertex indices of the edges' ends (E may be 0).

    Returns
    -------
    ndarray of shape (E,), float64
        ``|x_j - x_i|`` for each edge ``(i, j)``.

    Raises
    ------
    InvalidMeshError
        ``vertices`` or ``edges`` of the wrong shape or dtype, coordinates not
        finite, or indices out of range.
    """
    vertices, edges = checked_mesh(vertices, edges, columns=2, name="edges")
    kernels = numba_kernels("geometry")
    if kernels is not None:
        return kernels.edge_lengths(vertices, edges)
    d = vertices[edges[:, 1]] - vertices[edges[:, 0]]
    return np.sqrt(np.einsum("ij,ij->i", d, d))


def vertex_edge_lengths(vertices: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """The mean length of the given edges at each vertex: the local resolution.

    Parameters
    ----------
    vertices : array_like of shape (V, 3)
    edges : array_like of shape (E, 2), int
        0-based; each edge counts at both its ends.

    Returns
    -------
    ndarray of shape (V,), float64
        NaN at a vertex that is the end of no edge.

    Raises
    ------
    InvalidMeshError
        As :func:`edge_lengths`.
    """
    vertices, edges = checked_mesh(vertices, edges, columns=2, name="edges")
    n = vertices.shape[0]
    kernels = numba_kernels("geometry")
    if kernels is not None:
        return kernels.vertex_edge_lengths(vertices, edges, n)
    flat = edges.ravel()
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.bincount(flat, weights=np.repeat(edge_lengths(vertices, edges), 2), minlength=n) / np.bincount(
            flat, minlength=n
        )


def mean_edge_length(vertices: np.ndarray, edges: np.ndarray) -> float:
    """Mean length of the given edges.

    Not robust: one edge to a vertex at 1e10 sets it. Tolerances and default
    radii use :func:`median_edge_length`, :func:`robust_mean_edge_length` or
    :func:`vertex_length_scales` instead.

    Parameters
    ----------
    vertices : array_like of shape (V, 3)
    edges : array_like of shape (E, 2), int
        0-based.

    Returns
    -------
    float
        0 when there are no edges.

    Raises
    ------
    InvalidMeshError
        As :func:`edge_lengths`.
    """
    vertices, edges = checked_mesh(vertices, edges, columns=2, name="edges")
    if edges.shape[0] == 0:
        return 0.0
    kernels = numba_kernels("geometry")
    if kernels is not None:
        return float(kernels.mean_edge_length(vertices, edges))
    return float(edge_lengths(vertices, edges).mean())


def median_edge_length(vertices: np.ndarray, edges: np.ndarray) -> float:
    """Median length of the given edges: a scale no outlier moves.

    Parameters
    ----------
    vertices : array_like of shape (V, 3)
    edges : array_like of shape (E, 2), int
        0-based.

    Returns
    -------
    float
        0 when there are no edges.

    Raises
    ------
    InvalidMeshError
        As :func:`edge_lengths`.
    """
    lengths = edge_lengths(vertices, edges)
    return float(np.median(lengths)) if lengths.size else 0.0


def robust_mean_edge_length(vertices: np.ndarray, edges: np.ndarray) -> float:
    """Mean length of the given edges, leaving out those beyond ``OUTLIER_EDGE_RATIO`` medians.

    Equal to :func:`mean_edge_length` on any mesh whose longest edge is within
    :data:`OUTLIER_EDGE_RATIO` (1000) times its median, so default radii keep
    their values there; an edge to a spike vertex (a scanner's sentinel at
    1e10) is left out instead of multiplying the mean. The median is that of
    an even sample of at most about :data:`MEDIAN_SAMPLE` edges.

    Parameters
    ----------
    vertices : array_like of shape (V, 3)
    edges : array_like of shape (E, 2), int
        0-based.

    Returns
    -------
    float
        0 when there are no edges.

    Raises
    ------
    InvalidMeshError
        As :func:`edge_lengths`.
    """
    lengths = edge_lengths(vertices, edges)
    if lengths.size == 0:
        return 0.0
    median = float(np.median(lengths[:: max(1, lengths.size // MEDIAN_SAMPLE)]))  # a threshold: a sample will do
    longest = float(lengths.max())
    if longest <= OUTLIER_EDGE_RATIO * median:  # no outlier: the plain mean, to the last bit
        return mean_edge_length(vertices, edges)
    kept = lengths[lengths <= OUTLIER_EDGE_RATIO * median]
    return float(kept.mean())


def vertex_length_scales(vertices: np.ndarray, topology) -> np.ndarray:
    """(V,) the length scale at each vertex: the median edge length of its connected component.

    The scale of every tolerance in the core (zero-area faces, zero-length
    edges). On a connected mesh it is the median of at most about
    :data:`MEDIAN_SAMPLE` edges evenly spaced in index order (a tolerance
    needs no more; how close to the median of all and how fast:
    ``benchmarks/docstring_figures.md``). On a mesh whose components are of
    one scale (each component's
    geometric-mean edge within :data:`COMPONENT_SCALE_SPREAD` of the mesh's
    median edge) it is the mesh's median edge length everywhere, found in one
    pass; otherwise each component gets its own median (a sort of the edges by
    component). Unreferenced vertices, and components without an edge (a face
    ``(a, a, a)``), get 0.

    Parameters
    ----------
    vertices : array_like of shape (V, 3)
        Finite coordinates.
    topology : MeshTopology
        The connectivity, with ``topology.n_vertices == V``.

    Returns
    -------
    ndarray of shape (V,), float64
        In the vertices' length unit, >= 0.

    Raises
    ------
    InvalidMeshError
        ``topology`` not a :class:`~meshcurv.topology.MeshTopology` (a face
        array: build the topology with ``MeshTopology.from_faces``), or
        ``vertices`` unusable or not one row per vertex of ``topology``.
    """
    vertices = checked_topology_points(vertices, topology)
    edges = topology.edges
    n = topology.n_vertices
    if edges.shape[0] == 0:
        return np.zeros(n)
    referenced = topology.referenced_vertices
    n_components, labels = topology.vertex_components
    if n_components <= 1:  # one scale: the median of an even sample of the edges
        step = max(1, edges.shape[0] // MEDIAN_SAMPLE)
        overall = float(np.median(edge_lengths(vertices, edges[::step])))
        return np.where(referenced, overall, 0.0)
    lengths = edge_lengths(vertices, edges)
    overall = float(np.median(lengths))
    edge_label = labels[edges[:, 0]]
    positive = lengths > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        log_sums = np.bincount(edge_label[positive], weights=np.log2(lengths[positive]), minlength=n_components)
        typical = log_sums / np.bincount(edge_label[positive], minlength=n_components)
    spread = np.abs(typical[np.isfinite(typical)] - np.log2(overall)) if overall > 0 else np.array([np.inf])
    if spread.size and spread.max() <= np.log2(COMPONENT_SCALE_SPREAD):
        return np.where(referenced, overall, 0.0)
    order = np.lexsort((lengths, edge_label))
    counts = np.bincount(edge_label, minlength=n_components)
    starts = np.cumsum(counts) - counts
    ranked = lengths[order]
    medians = np.zeros(n_components)
    some = counts > 0  # a component of faces (a, a, a) only has no edge: scale 0
    low = ranked[starts[some] + (counts[some] - 1) // 2]
    high = ranked[starts[some] + counts[some] // 2]
    medians[some] = 0.5 * (low + high)
    return np.where(referenced, medians[np.maximum(labels, 0)], 0.0)


def checked_topology_points(vertices, topology) -> np.ndarray:
    """``vertices`` checked (:func:`~meshcurv._validation.checked_points`), one row per vertex of ``topology``.

    Parameters
    ----------
    vertices : array_like of shape (V, 3)
    topology : MeshTopology
        With ``topology.n_vertices == V``.

    Returns
    -------
    ndarray of shape (V, 3), float64
        C-contiguous; ``vertices`` itself when it already is such an array.

    Raises
    ------
    InvalidMeshError
        ``topology`` not a MeshTopology, ``vertices`` unusable or of another length.
    """
    if not isinstance(topology, MeshTopology):
        hint = (
            " (a face array: build one with MeshTopology.from_faces(faces, len(vertices)))"
            if isinstance(topology, (np.ndarray, list, tuple))
            else ""
        )
        raise InvalidMeshError(f"`topology` must be a MeshTopology; got {type(topology).__name__}{hint}")
    vertices = checked_points(vertices)
    if vertices.shape[0] != topology.n_vertices:
        raise InvalidMeshError(
            f"`vertices` has {vertices.shape[0]} rows but the topology has {topology.n_vertices} vertices"
        )
    return vertices


def degenerate_face_mask(areas: np.ndarray, length_scale) -> np.ndarray:
    """(F,) bool: faces whose area is negligible relative to ``length_scale ** 2``.

    Parameters
    ----------
    areas : array_like of shape (F,)
        Face areas (:func:`face_areas`).
    length_scale : float or array_like of shape (F,)
        The length scale of every face (:func:`vertex_length_scales`), >= 0.

    Returns
    -------
    ndarray of shape (F,), bool
        ``areas <= DEGENERATE_AREA_RATIO * length_scale ** 2``.

    Raises
    ------
    InvalidMeshError
        ``areas`` not a flat array of real numbers.
    InvalidOptionError
        ``length_scale`` not a number >= 0 nor an array of them, one per face.
    """
    areas = _real_array(areas, "areas")
    if areas.ndim != 1:
        raise InvalidMeshError(f"`areas` must have shape (F,); got {areas.shape}")
    try:
        scale = _real_array(length_scale, "length_scale")
    except InvalidMeshError as error:
        raise InvalidOptionError(str(error)) from None
    if scale.ndim not in (0, 1) or (scale.ndim == 1 and scale.shape != areas.shape):
        raise InvalidOptionError(
            f"`length_scale` must be a number or an array of shape {areas.shape} (one per face); got {scale.shape}"
        )
    if not (scale >= 0).all():
        raise InvalidOptionError("`length_scale` must be >= 0 (not NaN)")
    with np.errstate(over="ignore"):  # a scale beyond 1e154 squares to inf: every face is below it
        return areas <= DEGENERATE_AREA_RATIO * scale**2


def degenerate_faces(
    vertices: np.ndarray,
    topology: MeshTopology,
    *,
    cross: np.ndarray | None = None,
    mean_edge_length: float | None = None,
    double_areas: np.ndarray | None = None,
    scales: np.ndarray | None = None,
) -> np.ndarray:
    """(F,) bool: faces with a repeated corner or an area below 1e-12 x (length scale)^2.

    The length scale of a face is the median edge length of its connected
    component (:func:`meshcurv.geometry.vertex_length_scales`; ``scales`` passes
    them when already computed), or ``mean_edge_length`` when given (one scale
    for all). Relative to the mesh's own scale, the same mesh gives the same
    answer at any scale (coordinates around 1e-9 or 1e9 alike); a median, it is
    not moved by a few outlier vertices (a spike at 1e10 leaves the other faces
    alone); per component, a part at 1e-3 and a part at 1e3 are each measured
    against their own edges.

    Parameters
    ----------
    vertices : array_like of shape (V, 3)
    topology : MeshTopology
        With ``topology.n_vertices == V``.
    cross : array_like of shape (F, 3), optional
        The face cross products (:func:`face_cross_products`), when already computed.
    mean_edge_length : float, optional
        One length scale for every face, instead of the per-component medians.
    double_areas : array_like of shape (F,), optional
        Twice the face areas, when already computed.
    scales : array_like of shape (V,), optional
        The length scale of each vertex (:func:`vertex_length_scales`), when
        already computed; a face takes that of its first corner.

    Returns
    -------
    ndarray of shape (F,), bool
        True for a face with a repeated corner
        (``topology.degenerate_faces``) or with
        ``area <= DEGENERATE_AREA_RATIO * scale ** 2``.

    Raises
    ------
    InvalidMeshError
        ``topology`` not a MeshTopology, ``vertices`` unusable, or ``cross``
        (F, 3), ``double_areas`` (F,), ``scales`` (V,) not real arrays of
        those shapes.
    """
    vertices = checked_topology_points(vertices, topology)
    cross = _optional_floats(cross, "cross", topology.faces.shape)
    double_areas = _optional_floats(double_areas, "double_areas", (topology.n_faces,))
    scales = _optional_floats(scales, "scales", (topology.n_vertices,))
    kernels = numba_kernels("geometry")
    if scales is None and mean_edge_length is None:
        scales = vertex_length_scales(vertices, topology)
    if kernels is not None and double_areas is None:
        # the kernel computes the cross products inline: ``cross`` only spares the NumPy path that work
        if scales is None and mean_edge_length is not None:  # always, when no scales were computed above
            scales = np.full(topology.n_vertices, float(mean_edge_length))
        return kernels.degenerate_faces(vertices, topology.faces, scales, DEGENERATE_AREA_RATIO)
    face_scale = scales[topology.faces[:, 0]] if scales is not None else mean_edge_length
    if double_areas is None:
        if cross is None:
            cross = face_cross_products(vertices, topology.faces)
        double_areas = np.sqrt(np.einsum("ij,ij->i", cross, cross))
    return degenerate_face_mask(0.5 * double_areas, face_scale) | topology.degenerate_faces


def _optional_floats(value, name: str, shape: tuple) -> np.ndarray | None:
    """``value`` as a C-contiguous float64 array of ``shape`` (None stays None)."""
    return None if value is None else _floats(value, name, shape)


def _floats(value, name: str, shape: tuple) -> np.ndarray:
    """``value`` as a C-contiguous float64 array of ``shape``."""
    array = np.asarray(value)
    if array.shape != shape or array.dtype.kind not in "fiu":
        raise InvalidMeshError(f"`{name}` must be a real array of shape {shape}; got {array.dtype} {array.shape}")
    return np.ascontiguousarray(array, dtype=np.float64)


def edge_dihedral_angles(
    vertices: np.ndarray, topology: MeshTopology, unit_normals: np.ndarray, usable_edges: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Signed angle between the two face normals of each usable edge.

    ``beta = atan2((n1 x n2) . e, n1 . n2)`` with ``n1, n2`` the normals of
    the edge's faces ``topology.edge_faces`` and ``e`` its unit vector.

    Parameters
    ----------
    vertices : array_like of shape (V, 3)
    topology : MeshTopology
        With ``topology.n_vertices == V``.
    unit_normals : array_like of shape (F, 3)
        The unit face normals (:func:`face_normals`).
    usable_edges : ndarray of shape (E,), bool
        The edges to measure: interior manifold edges between proper faces.

    Returns
    -------
    beta : ndarray of shape (E,), float64
        In radians, in ``[-pi, pi]``: positive where the surface is convex
        across the edge on a consistently wound mesh (every edge of an
        outward-wound sphere), negative where it is concave; 0 on edges that
        are not usable.
    lengths : ndarray of shape (E,), float64
        The edges' lengths.
    unit_edges : ndarray of shape (E, 3), float64
        The edges' unit vectors from ``topology.edges[:, 0]`` to
        ``topology.edges[:, 1]``; 0 on zero-length edges.

    Raises
    ------
    InvalidMeshError
        ``topology`` not a MeshTopology, ``vertices`` unusable, ``unit_normals``
        not a real (F, 3) array or ``usable_edges`` not an (E,) bool array.
    """
    vertices = checked_topology_points(vertices, topology)
    unit_normals = _floats(unit_normals, "unit_normals", topology.faces.shape)
    usable_edges = np.asarray(usable_edges)
    if usable_edges.shape != (topology.edges.shape[0],) or usable_edges.dtype != bool:
        raise InvalidMeshError(
            f"`usable_edges` must be a bool array of shape ({topology.edges.shape[0]},); got "
            f"{usable_edges.dtype} {usable_edges.shape}"
        )
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
    beta[usable_edges] = np.arctan2(sine, cosine)
    return beta, lengths, unit


def _real_array(value, name: str) -> np.ndarray:
    """``value`` as a float64 array, refusing what is not real numbers (strings, None, complex, objects)."""
    array = value if isinstance(value, np.ndarray) else None
    if array is None:
        if value is None or isinstance(value, (str, bytes)):
            raise InvalidMeshError(f"`{name}` must hold real numbers; got {type(value).__name__}")
        try:
            array = np.asarray(value)
        except (TypeError, ValueError, OverflowError) as exc:
            raise InvalidMeshError(f"`{name}` must hold real numbers ({exc})") from None
    if array.dtype == bool or not (np.issubdtype(array.dtype, np.floating) or np.issubdtype(array.dtype, np.integer)):
        raise InvalidMeshError(f"`{name}` must hold real numbers; got dtype {array.dtype}")
    return array.astype(np.float64, copy=False)


def corner_cotangents(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """The cotangent of the angle at each corner of every face.

    ``cot = (a . b) / |a x b|`` for the two edge vectors ``a, b`` leaving the
    corner.

    Parameters
    ----------
    vertices : array_like of shape (V, 3)
    faces : array_like of shape (F, 3), int
        0-based.

    Returns
    -------
    ndarray of shape (F, 3), float64
        Column ``k`` for corner ``faces[:, k]``. Not finite on a zero-area
        face: +-inf at collinear corners, NaN at a repeated one.

    Raises
    ------
    InvalidMeshError
        As :func:`face_cross_products`.
    """
    vertices, faces = checked_mesh(vertices, faces)
    out = np.zeros(faces.shape, dtype=np.float64)
    for k in range(3):
        p = vertices[faces[:, k]]
        a = vertices[faces[:, (k + 1) % 3]] - p
        b = vertices[faces[:, (k + 2) % 3]] - p
        with np.errstate(invalid="ignore", divide="ignore"):
            out[:, k] = np.einsum("ij,ij->i", a, b) / np.linalg.norm(np.cross(a, b), axis=1)
    return out


def corner_angles(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """The interior angle at each corner of every face.

    ``atan2(|a x b|, a . b)`` for the two edge vectors ``a, b`` leaving the corner.

    Parameters
    ----------
    vertices : array_like of shape (V, 3)
    faces : array_like of shape (F, 3), int
        0-based.

    Returns
    -------
    ndarray of shape (F, 3), float64
        In radians, in ``[0, pi]``; column ``k`` for corner ``faces[:, k]``.
        The angles of a face sum to ``pi``; a face of collinear corners gets
        ``0, 0, pi`` and one with a repeated corner 0 everywhere.

    Raises
    ------
    InvalidMeshError
        As :func:`face_cross_products`.
    """
    vertices, faces = checked_mesh(vertices, faces)
    out = np.zeros(faces.shape, dtype=np.float64)
    for k in range(3):
        p = vertices[faces[:, k]]
        a = vertices[faces[:, (k + 1) % 3]] - p
        b = vertices[faces[:, (k + 2) % 3]] - p
        out[:, k] = np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.einsum("ij,ij->i", a, b))
    return out


def mixed_voronoi_corner_areas(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(F, 3) the share of each face in the mixed Voronoi area of each of its corners.

    Meyer, Desbrun, Schroeder and Barr (2003), Fig. 4: on a non-obtuse triangle
    the Voronoi region of corner ``i``, ``(|e_ij|^2 cot k + |e_ik|^2 cot j) / 8``;
    on an obtuse one, half the area for the obtuse corner and a quarter for the
    other two.

    Parameters
    ----------
    vertices : array_like of shape (V, 3)
    faces : array_like of shape (F, 3), int
        0-based.

    Returns
    -------
    ndarray of shape (F, 3), float64
        In length^2, >= 0; column ``k`` for corner ``faces[:, k]``. The shares
        of a face sum to its area; summed per vertex
        (``np.bincount(faces.ravel(), shares.ravel())``) they tile the surface.
        0 on zero-area faces.

    Raises
    ------
    InvalidMeshError
        As :func:`face_cross_products`.

    References
    ----------
    M. Meyer, M. Desbrun, P. Schroeder, A. H. Barr (2003). Discrete
    differential-geometry operators for triangulated 2-manifolds.
    Visualization and Mathematics III, 35-57.
    https://doi.org/10.1007/978-3-662-05105-4_2
    """
    vertices, faces = checked_mesh(vertices, faces)
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
