"""Geometric quantities of triangle meshes, as pure functions over arrays.

Inputs are ``vertices`` of shape (V, 3) and ``faces`` of shape (F, 3)
(0-based); outputs are new float64 arrays. Each function checks its arrays
cheaply (:func:`meshcurv._validation.checked_mesh`: dtype, shape, finite
coordinates, indices in range; no copy of arrays that are already float64 and
int64), so that the compiled kernels never read out of bounds, then computes
with the core of the same name in :mod:`meshcurv._geometry`. The library
calls those cores directly on the arrays it has checked once
(:func:`meshcurv._prepared.prepare_mesh`).

Length scales: every tolerance of the core is relative to a *robust* length
scale, the median edge length of the vertex's connected component
(:func:`vertex_length_scales`), never to the mean over the whole mesh: one
vertex at 1e10 (a scanner's sentinel) moves the mean edge length of a mesh by
orders of magnitude but not its median, and a mesh made of a part at 1e-3 and a
part at 1e3 has a scale for each.
"""

from __future__ import annotations

import numpy as np

from . import _geometry
from ._geometry import (  # noqa: F401  (normalize_normal_sums: named here by the kernels' docs and tests)
    COMPONENT_SCALE_SPREAD,
    DEGENERATE_AREA_RATIO,
    MEDIAN_SAMPLE,
    OUTLIER_EDGE_RATIO,
    normalize_normal_sums,
)
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
    return _geometry.face_cross_products(*checked_mesh(vertices, faces))


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
    return _geometry.face_areas(*checked_mesh(vertices, faces))


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
    cross = _geometry.face_cross_products(*checked_mesh(vertices, faces))
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
        areas = _geometry.face_areas(vertices, faces)
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
    return _geometry.vertex_normals(vertices, faces, cross=cross)


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
    return _geometry.edge_lengths(*checked_mesh(vertices, edges, columns=2, name="edges"))


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
    points, edges = checked_mesh(vertices, edges, columns=2, name="edges")
    return _geometry.vertex_edge_lengths(points, edges, points.shape[0])


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
    return _geometry.mean_edge_length(*checked_mesh(vertices, edges, columns=2, name="edges"))


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
    return _geometry.median_edge_length(*checked_mesh(vertices, edges, columns=2, name="edges"))


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
    return _geometry.robust_mean_edge_length(*checked_mesh(vertices, edges, columns=2, name="edges"))


def vertex_length_scales(vertices: np.ndarray, topology) -> np.ndarray:
    """(V,) the length scale at each vertex: the median edge length of its connected component.

    The scale of every tolerance in the core (zero-area faces, zero-length
    edges, the local scale ratios of the radius rules). On a connected mesh
    it is the median of every edge (not a sample by index: the vertex order
    chose it, and with it the radii); about 70 ms per million vertices
    (``benchmarks/docstring_figures.md``). On a mesh whose components are of
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
    return _geometry.vertex_length_scales(checked_topology_points(vertices, topology), topology)


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
    return _geometry.degenerate_face_mask(areas, scale)


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
    return _geometry.degenerate_faces(
        checked_topology_points(vertices, topology),
        topology,
        cross=_optional_floats(cross, "cross", topology.faces.shape),
        mean_edge_length=mean_edge_length,
        double_areas=_optional_floats(double_areas, "double_areas", (topology.n_faces,)),
        scales=_optional_floats(scales, "scales", (topology.n_vertices,)),
    )


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
        In radians, in ``(-pi, pi]``: positive where the surface is convex
        across the edge on a consistently wound mesh (every edge of an
        outward-wound sphere), negative where it is concave; ``pi`` at an
        exact fold (the two faces on each other, whatever the signs of the
        zeros of their coordinates); 0 on edges that are not usable.
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
    return _geometry.edge_dihedral_angles(vertices, topology, unit_normals, usable_edges)


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
    return _geometry.corner_cotangents(*checked_mesh(vertices, faces))


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
    return _geometry.corner_angles(*checked_mesh(vertices, faces))


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
    return _geometry.mixed_voronoi_corner_areas(*checked_mesh(vertices, faces))
