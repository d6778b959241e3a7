"""Connectivity of triangle meshes: edges, their faces, rings, boundary, manifoldness.

Everything here depends on the faces only (never on coordinates), so a
:class:`MeshTopology` built once serves every later computation on meshes with the
same connectivity, whatever the vertex positions and whatever the method.

Conventions
-----------
- Vertex and face indices are 0-based.
- Side ``k`` of face ``f`` runs from ``faces[f, k]`` to ``faces[f, (k + 1) % 3]``.
- An edge is an unordered pair ``(p, q)`` with ``p < q``; ``edges`` is sorted
  lexicographically.
- ``edge_faces[e, 0]`` is a face that traverses edge ``e`` from ``p`` to ``q``,
  ``edge_faces[e, 1]`` one that traverses it from ``q`` to ``p`` (on a consistently
  oriented manifold mesh); -1 where there is none (boundary).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np

from ._backend import numba_kernels, twin
from ._validation import (
    MAX_VERTICES,
    Ragged,
    as_faces,
    check_vertex_count,
    checked_triangles,
    fan_triangles,
    polygon_arrays,
)
from .errors import InvalidMeshError

if TYPE_CHECKING:
    import scipy.sparse

__all__ = ["triangulate_faces", "strip_triangles", "MeshTopology"]

#: :meth:`MeshTopology.from_faces` without ``n_vertices`` refuses a largest index beyond this many
#: vertices per face corner (or :data:`INFERRED_VERTICES_FLOOR`): the count is then read from the
#: largest index, and every per-vertex array is sized by it.
INFERRED_VERTICES_PER_CORNER = 64

#: Inferred vertex counts up to this are always accepted (16.7 million: 400 MB of coordinates).
INFERRED_VERTICES_FLOOR = 2**24


def strip_triangles(connectivity: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """(T, 3) the triangles of triangle strips, strip ``s`` being ``connectivity[ends[s - 1]:ends[s]]``.

    A strip's points ``p0, p1, p2, ...`` make the triangles ``(p_j, p_j+1, p_j+2)``, every other one wound the
    other way round (``(p_j+1, p_j, p_j+2)`` for odd ``j``) so that all face the strip's side, as VTK's
    ``vtkTriangleStrip`` makes them; a triangle with a repeated point (the join of two strips in one) is none.

    Parameters
    ----------
    connectivity : array_like of int, shape (P,)
        The strips' points, one strip after the other.
    ends : array_like of int, shape (S,)
        The end (exclusive) of each strip in ``connectivity``.

    Returns
    -------
    ndarray of shape (T, 3), int64
        The triangles, strip by strip, without the joins.
    """
    connectivity, ends = np.asarray(connectivity, dtype=np.int64).ravel(), np.asarray(ends, dtype=np.int64).ravel()
    starts = np.concatenate([[0], ends])[:-1]
    counts = np.maximum(ends - starts - 2, 0)  # a strip of n points holds n - 2 triangles
    strip = np.repeat(np.arange(ends.size), counts)
    j = np.arange(strip.size) - np.repeat(np.cumsum(counts) - counts, counts)  # the triangle's place in its strip
    first = starts[strip] + j
    corners = np.stack([connectivity[first], connectivity[first + 1], connectivity[first + 2]], axis=1)
    odd = j % 2 == 1
    corners[odd, :2] = corners[odd, 1::-1]
    joins = (corners[:, 0] == corners[:, 1]) | (corners[:, 1] == corners[:, 2]) | (corners[:, 0] == corners[:, 2])
    return corners[~joins]


def triangulate_faces(polygons) -> np.ndarray:
    """Fan-triangulate polygonal faces exactly as matGeom's ``triangulateFaces``.

    Parameters
    ----------
    polygons : array_like of shape (F, k), list of index sequences, or MeshTopology
        Faces with ``k >= 3`` corners each (0-based vertex indices). A list may
        hold faces of different lengths. A :class:`MeshTopology` gives a copy of
        its triangles.

    Returns
    -------
    triangles : ndarray of shape (T, 3), int64
        Face ``(f0, f1, ..., f(k-1))`` gives the triangles ``(f0, f(j-1), f(j))``
        for ``j = 2 .. k-1``, kept next to each other in the order of the faces:
        a quad ``a, b, c, d`` gives ``(a, b, c)`` then ``(a, c, d)``. No check of
        convexity or planarity is made (matGeom makes none). Computed in one
        gather over all faces, whatever the mix of lengths.

    Raises
    ------
    InvalidMeshError
        ``polygons`` not an array of shape (F, k) with k >= 3 nor a list of
        index lists, empty, a face of fewer than 3 corners, non-integer or
        negative indices, indices beyond int64.

    Examples
    --------
    >>> triangulate_faces([[0, 1, 2, 3]]).tolist()
    [[0, 1, 2], [0, 2, 3]]
    >>> triangulate_faces([[0, 1, 2], [2, 1, 3, 4]]).tolist()
    [[0, 1, 2], [2, 1, 3], [2, 3, 4]]
    """
    if isinstance(polygons, MeshTopology):
        return polygons.faces.copy()
    shaped = polygon_arrays(polygons, name="polygons")
    flat = shaped.flat if isinstance(shaped, Ragged) else shaped
    low = int(flat.min())
    if low < 0:
        raise InvalidMeshError(f"`polygons` has negative vertex indices (smallest {low}); indices are 0-based and >= 0")
    return np.array(fan_triangles(shaped), dtype=np.int64, order="C", copy=True)


@dataclass(frozen=True, eq=False)
class MeshTopology:
    """The connectivity of a triangle mesh, computed once and reused.

    Build it with :meth:`from_faces`; pass it as ``faces`` to
    :func:`meshcurv.principal_curvatures` to skip the topology step on later calls.

    Attributes
    ----------
    faces : ndarray of shape (F, 3), int64
        The triangles.
    n_vertices : int
        Number of vertices (unreferenced ones included).
    edges : ndarray of shape (E, 2), int32 or int64
        Unique undirected edges ``(p, q)`` with ``p < q``, sorted.
    face_edges : ndarray of shape (F, 3), int32 or int64
        Edge of side ``k`` of each face (``faces[f, k] -> faces[f, (k+1) % 3]``);
        -1 for a side whose two ends are the same vertex.
    edge_faces : ndarray of shape (E, 2), int32 or int64
        Two faces of each edge: column 0 one that runs ``p -> q``, column 1 one
        that runs ``q -> p`` where the mesh is consistently oriented; -1 = none.
        On a non-manifold edge these are two of its faces.
    edge_face_counts : ndarray of shape (E,), int32 or int64
        Number of faces of each edge (1 = boundary, 2 = interior, 3+ = non-manifold).

    Notes
    -----
    The four edge arrays are int32 when ``2 * n_vertices + 1`` and ``3 * n_faces``
    are below ``2**31`` (every mesh up to about 700 million faces), else int64
    (:func:`index_dtype`; the convention of ``scipy.sparse`` for its index
    arrays): half the memory, and half the memory traffic of every pass over
    them. ``faces`` stays int64 (the validated input).
    """

    faces: np.ndarray
    n_vertices: int
    edges: np.ndarray
    face_edges: np.ndarray
    edge_faces: np.ndarray
    edge_face_counts: np.ndarray
    _edge_forward_counts: np.ndarray = field(repr=False)
    #: (3 F,) the other side ``3 g + j`` of the edge of each side ``3 f + k`` where the edge joins exactly two
    #: faces, -1 elsewhere (``_kernels.topology.build_edges_into``); None when not built (the NumPy path) or let go
    #: (:meth:`_release_side_twins`)
    _side_twins: np.ndarray | None = field(default=None, repr=False)
    #: (V,) corners of the faces without a repeated corner at each vertex, and (V,) the side leaving each vertex of
    #: its first such face (-1: unreferenced, -2: only in faces with a repeated corner), from the compiled build's
    #: first pass (``_kernels.topology.build_edges_into``); None on the NumPy path
    _corner_counts: np.ndarray | None = field(default=None, repr=False)
    _first_sides: np.ndarray | None = field(default=None, repr=False)

    @classmethod
    def from_faces(cls, faces, n_vertices: int | None = None) -> MeshTopology:
        """Compute the topology of ``faces``.

        Parameters
        ----------
        faces : array_like of shape (F, 3) or (F, k), or list of index lists
            0-based vertex indices; polygons are fan-triangulated (with a warning).
        n_vertices : int, optional
            Number of vertices, 1 to :data:`~meshcurv._validation.MAX_VERTICES`;
            default ``faces.max() + 1``, which must then stay within
            :data:`INFERRED_VERTICES_PER_CORNER` times the number of corners
            (or :data:`INFERRED_VERTICES_FLOOR`): one stray index of 2**40 must
            not size every array of the topology.

        Raises
        ------
        InvalidMeshError
            Faces unusable (see :func:`triangulate_faces`), indices out of range
            for ``n_vertices``, or no ``n_vertices`` with an index far beyond
            the faces' size.
        InvalidOptionError
            ``n_vertices`` not an integer in ``[1, MAX_VERTICES]``.
        """
        if n_vertices is not None:
            n_vertices = check_vertex_count(n_vertices)
        shaped = polygon_arrays(faces)
        if n_vertices is None:
            flat = shaped.flat if isinstance(shaped, Ragged) else shaped
            largest = int(flat.max())
            limit = min(MAX_VERTICES, max(INFERRED_VERTICES_FLOOR, INFERRED_VERTICES_PER_CORNER * flat.size))
            if largest >= limit:
                raise InvalidMeshError(
                    f"`faces` reference vertex index {largest} but hold only {flat.size} corners: pass "
                    f"`n_vertices` (the number of vertices) if the mesh really has {largest + 1} of them"
                    if largest < MAX_VERTICES
                    else f"`faces` reference vertex index {largest}, beyond the largest mesh meshcurv takes "
                    f"(n_vertices up to {MAX_VERTICES})"
                )
            n_vertices = largest + 1
        triangles = checked_triangles(shaped, n_vertices, stacklevel=3)
        return cls._build(triangles, n_vertices)

    def for_vertices(self, n_vertices: int) -> MeshTopology:
        """This topology, given with ``n_vertices`` vertices: its vertex count checked, nothing else (its faces
        were checked when it was built).

        Parameters
        ----------
        n_vertices : int
            The rows of the vertices it comes with.

        Returns
        -------
        MeshTopology
            ``self``.

        Raises
        ------
        InvalidMeshError
            The topology was built for another number of vertices.
        """
        if self.n_vertices != n_vertices:
            raise InvalidMeshError(
                f"`faces` is a MeshTopology of {self.n_vertices} vertices but `vertices` has {n_vertices} rows"
            )
        return self

    @classmethod
    def _build(cls, faces: np.ndarray, n_vertices: int) -> MeshTopology:
        """Build from already validated int64 (F, 3) triangles."""
        kernels = numba_kernels("topology")
        twins = corners = first = None
        if kernels is not None:
            edges, face_edges, edge_faces, counts, forward_counts, twins, corners, first = kernels.build_topology(
                faces, n_vertices, _bucket_template(n_vertices, faces.shape[0]), True
            )
        else:
            index = index_dtype(n_vertices, faces.shape[0])
            edges, face_edges, edge_faces, counts, forward_counts = (
                array.astype(index, copy=False) for array in _build_edges(faces, n_vertices)
            )
        return cls(
            faces=_readonly(faces),
            n_vertices=n_vertices,
            edges=_readonly(edges),
            face_edges=_readonly(face_edges),
            edge_faces=_readonly(edge_faces),
            edge_face_counts=_readonly(counts),
            _edge_forward_counts=_readonly(forward_counts),
            _side_twins=None if twins is None else _readonly(twins),
            _corner_counts=None if corners is None else _readonly(corners),
            _first_sides=None if first is None else _readonly(first),
        )

    # -- sizes ------------------------------------------------------------------
    @property
    def n_faces(self) -> int:
        """The number of faces."""
        return int(self.faces.shape[0])

    @property
    def n_edges(self) -> int:
        """The number of unique undirected edges."""
        return int(self.edges.shape[0])

    # -- edge classes -----------------------------------------------------------
    @cached_property
    def boundary_edges(self) -> np.ndarray:
        """(E,) bool: edges with exactly one face."""
        return _readonly(self.edge_face_counts == 1)

    @cached_property
    def nonmanifold_edges(self) -> np.ndarray:
        """(E,) bool: edges with three or more faces."""
        return _readonly(self.edge_face_counts > 2)

    @cached_property
    def inconsistent_edges(self) -> np.ndarray:
        """(E,) bool: two-face edges whose faces run it in the same direction."""
        two = self.edge_face_counts == 2
        return _readonly(two & (self._edge_forward_counts != 1))

    @cached_property
    def interior_edges(self) -> np.ndarray:
        """(E,) bool: manifold edges with two consistently oriented faces."""
        return _readonly((self.edge_face_counts == 2) & (self._edge_forward_counts == 1))

    # -- vertex classes ---------------------------------------------------------
    @cached_property
    def referenced_vertices(self) -> np.ndarray:
        """(V,) bool: vertices used by at least one face."""
        if self._first_sides is not None:  # found by the compiled build
            return _readonly(self._first_sides != -1)
        used = np.zeros(self.n_vertices, dtype=bool)
        used[self.faces.ravel()] = True
        return _readonly(used)

    def edge_vertices(self, edge_mask: np.ndarray) -> np.ndarray:
        """(V,) bool: vertices that are an end of an edge selected by ``edge_mask``, a (E,) bool array."""
        edge_mask = np.asarray(edge_mask)
        if edge_mask.dtype != bool or edge_mask.shape != (self.n_edges,):
            raise InvalidMeshError(
                f"`edge_mask` must be a bool array of shape ({self.n_edges},) (one per edge); "
                f"got {edge_mask.dtype} {edge_mask.shape}"
            )
        marked = np.zeros(self.n_vertices, dtype=bool)
        marked[self.edges[edge_mask].ravel()] = True
        return marked

    @cached_property
    def boundary_vertices(self) -> np.ndarray:
        """(V,) bool: vertices on a boundary edge."""
        return _readonly(self.edge_vertices(self.boundary_edges))

    @cached_property
    def bowtie_vertices(self) -> np.ndarray:
        """(V,) bool: vertices whose faces form more than one fan.

        Two faces at a vertex are in the same fan when a chain of faces at that
        vertex joins them, each sharing with the next a manifold edge (exactly
        two faces) at the vertex. A manifold vertex has one fan (a disc, or a
        half-disc on the boundary); two cones touching at their tips, or two
        sheets glued at a corner, give two. Faces with a repeated corner are
        left out. Vertices on non-manifold edges usually have several fans too
        and are included.
        """
        kernels = numba_kernels("topology")
        if kernels is None:
            return _readonly(_bowtie_vertices(self))
        if self._side_twins is not None and self._first_sides is not None and self._corner_counts is not None:
            return _readonly(kernels.bowtie_walks(self._side_twins, self._first_sides, self._corner_counts))
        if self._side_twins is not None:
            return _readonly(kernels.bowtie_from_twins(self.faces, self._side_twins, self.n_vertices))
        linked = (self.edge_face_counts == 2) & (self.edge_faces[:, 0] != self.edge_faces[:, 1])
        return _readonly(
            kernels.bowtie_vertices(
                self.faces, self.face_edges, self.edge_faces, linked, ~self.degenerate_faces, self.n_vertices
            )
        )

    def _release_side_twins(self) -> None:
        """Let go of the twin sides (12 bytes a face) once :attr:`bowtie_vertices`, their one reader, is found."""
        if "bowtie_vertices" in self.__dict__:
            object.__setattr__(self, "_side_twins", None)

    @cached_property
    def degenerate_faces(self) -> np.ndarray:
        """(F,) bool: faces that repeat a vertex index (no area whatever the positions)."""
        if self._corner_counts is not None and int(self._corner_counts.sum()) == 3 * self.n_faces:
            return _readonly(np.zeros(self.n_faces, dtype=bool))  # the build counted three corners for every face
        f = self.faces
        return _readonly((f[:, 0] == f[:, 1]) | (f[:, 1] == f[:, 2]) | (f[:, 2] == f[:, 0]))

    # -- adjacency --------------------------------------------------------------
    @cached_property
    def adjacency(self) -> scipy.sparse.csr_matrix:
        """(V, V) sparse symmetric 0/1 matrix: ``i ~ j`` when they share an edge."""
        n = self.n_vertices
        rows = np.concatenate([self.edges[:, 0], self.edges[:, 1]])
        cols = np.concatenate([self.edges[:, 1], self.edges[:, 0]])
        data = np.ones(rows.size, dtype=np.float64)
        # edges are unique, so no duplicate entries: convert without summing
        import scipy.sparse as sp  # imported on use: keeps `import meshcurv` fast

        return sp.coo_matrix((data, (rows, cols)), shape=(n, n)).tocsr()

    @cached_property
    def neighbour_lists(self) -> tuple[np.ndarray, np.ndarray]:
        """Edge neighbours of every vertex in CSR form: ``(indptr, indices)``.

        The neighbours of vertex ``v`` are ``indices[indptr[v]:indptr[v + 1]]``. ``indptr`` is int64;
        ``indices`` has the type of :attr:`edges` (int32 where the mesh fits: half the memory that the walks
        of the balls read).
        """
        indptr, indices = neighbour_lists(self.edges, self.n_vertices)
        return _readonly(indptr), _readonly(indices)

    def smoothing_lists(self, steps: int) -> tuple[np.ndarray, np.ndarray]:
        """The neighbour lists that ``steps`` passes of a 1-ring smoothing read.

        Parameters
        ----------
        steps : int
            Number of smoothing passes.

        Returns
        -------
        offsets, neighbours : numpy.ndarray
            :attr:`neighbour_lists` when ``steps`` is positive; empty lists (none built) when it is 0.
        """
        if steps > 0:
            return self.neighbour_lists
        return np.zeros(self.n_vertices + 1, np.int64), np.zeros(0, np.int64)

    @cached_property
    def vertex_degrees(self) -> np.ndarray:
        """(V,) int64: number of edges at each vertex."""
        return _readonly(np.bincount(self.edges.ravel(), minlength=self.n_vertices).astype(np.int64))

    @cached_property
    def face_components(self) -> tuple[int, np.ndarray]:
        """Connected components of the faces (through shared vertices).

        Returns ``(n_components, labels)`` with ``labels`` of shape (F,).
        """
        from scipy.sparse.csgraph import connected_components

        # faces sharing a vertex are joined by edges: label the vertex graph
        _, vertex_labels = connected_components(self.adjacency, directed=False)
        used, labels = np.unique(vertex_labels[self.faces[:, 0]], return_inverse=True)
        return int(used.size), _readonly(labels.astype(np.int64))

    @cached_property
    def vertex_components(self) -> tuple[int, np.ndarray]:
        """Connected components of the referenced vertices (through edges).

        Returns ``(n_components, labels)`` with ``labels`` of shape (V,): 0, 1, ...
        numbered in the order of each component's first vertex, -1 for an
        unreferenced vertex.
        """
        labels, count = component_labels(self.edges, self.referenced_vertices, self.n_vertices)
        return int(count), _readonly(labels)

    @cached_property
    def n_components(self) -> int:
        """Number of connected components of the faces."""
        return int(self.vertex_components[0])  # the labels are asked for on every call: one pass for both

    @cached_property
    def euler_characteristic(self) -> int:
        """V - E + F over the referenced vertices."""
        return int(self.referenced_vertices.sum()) - self.n_edges + self.n_faces

    @cached_property
    def n_boundary_loops(self) -> int:
        """Number of boundary loops (connected sets of boundary edges)."""
        boundary = self.edges[self.boundary_edges]
        if boundary.size == 0:
            return 0
        n = self.n_vertices
        import scipy.sparse as sp
        from scipy.sparse.csgraph import connected_components

        graph = sp.csr_matrix((np.ones(boundary.shape[0]), (boundary[:, 0], boundary[:, 1])), shape=(n, n))
        count, labels = connected_components(graph, directed=False)
        return int(np.unique(labels[boundary[:, 0]]).size)


@twin("topology")
def neighbour_lists(edges: np.ndarray, n_vertices: int) -> tuple[np.ndarray, np.ndarray]:
    """``(indptr, indices)``: the edge neighbours of every vertex in CSR form, each list in increasing order
    (:attr:`MeshTopology.neighbour_lists`); ``edges`` (E, 2) unique, ``p < q``. ``indptr`` is int64, ``indices``
    of the type of ``edges``."""
    rows = np.concatenate([edges[:, 0], edges[:, 1]]).astype(np.int64)
    columns = np.concatenate([edges[:, 1], edges[:, 0]])
    order = np.lexsort((columns, rows))
    indptr = np.zeros(n_vertices + 1, dtype=np.int64)
    np.cumsum(np.bincount(rows, minlength=n_vertices), out=indptr[1:])
    return indptr, columns[order]


@twin("topology")
def component_labels(edges: np.ndarray, referenced: np.ndarray, n_vertices: int) -> tuple[np.ndarray, int]:
    """``(labels, count)``: the (V,) int64 component of each referenced vertex through ``edges`` (0, 1, ...
    numbered in the order of each component's first vertex; -1 for an unreferenced vertex) and their number
    (:attr:`MeshTopology.vertex_components`)."""
    import scipy.sparse as sp  # imported on use: keeps `import meshcurv` fast
    from scipy.sparse.csgraph import connected_components

    graph = sp.coo_matrix((np.ones(edges.shape[0]), (edges[:, 0], edges[:, 1])), shape=(n_vertices, n_vertices))
    _, raw = connected_components(graph.tocsr(), directed=False)
    used, first = np.unique(raw[referenced], return_index=True)
    rank = np.empty(used.size, dtype=np.int64)
    rank[np.argsort(first, kind="stable")] = np.arange(used.size)
    labels = np.full(n_vertices, -1, dtype=np.int64)
    labels[referenced] = rank[np.searchsorted(used, raw[referenced])]
    return labels, int(used.size)


def index_dtype(n_vertices: int, n_faces: int) -> type[np.signedinteger]:
    """The integer type of a topology's edge arrays (and of the compiled build's buckets): int32 when
    ``2 V + 1`` (the build's sort keys) and ``3 F`` (its side ids, beyond any edge id) are below ``2**31``, else
    int64."""
    small = 2 * n_vertices + 1 < 2**31 and 3 * n_faces < 2**31
    return np.int32 if small else np.int64


def _bucket_template(n_vertices: int, n_faces: int) -> np.ndarray:
    """An empty array of :func:`index_dtype`: the compiled build makes its arrays of its type."""
    return np.zeros(0, index_dtype(n_vertices, n_faces))


def _build_edges(faces: np.ndarray, n_vertices: int):
    """NumPy path of :meth:`MeshTopology._build`: one sort of the sides by (edge, direction)."""
    n_faces = faces.shape[0]
    tail = faces.ravel()
    head = np.roll(faces, -1, axis=1).ravel()
    low = np.minimum(tail, head)
    high = np.maximum(tail, head)
    backward = (tail > head).astype(np.int64)
    proper = tail != head
    # one sort of the sides, by edge and then direction (p -> q first)
    key = (low * n_vertices + high) * 2 + backward
    side_ids = np.flatnonzero(proper)
    order = side_ids[np.argsort(key[side_ids], kind="stable")]
    edge_key = key[order] >> 1
    starts = np.ones(order.size, dtype=bool)
    starts[1:] = edge_key[1:] != edge_key[:-1]
    edge_of_sorted = np.cumsum(starts) - 1
    n_edges = int(edge_of_sorted[-1]) + 1 if order.size else 0
    face_edges = np.full(3 * n_faces, -1, dtype=np.int64)
    face_edges[order] = edge_of_sorted
    first = np.flatnonzero(starts)
    counts = np.diff(np.append(first, order.size))
    edges = np.stack([low[order[first]], high[order[first]]], axis=1)
    side_face = order // 3
    edge_faces = np.full((n_edges, 2), -1, dtype=np.int64)
    first_backward = backward[order[first]].astype(bool)
    # first side of each edge: p -> q unless the edge has no forward side
    edge_faces[~first_backward, 0] = side_face[first[~first_backward]]
    edge_faces[first_backward, 1] = side_face[first[first_backward]]
    has_second = counts >= 2
    second = first[has_second] + 1
    column = np.where(edge_faces[has_second, 1] == -1, 1, 0)
    rows = np.flatnonzero(has_second)
    edge_faces[rows, column] = side_face[second]
    forward_counts = np.bincount(edge_of_sorted, weights=1 - backward[order], minlength=n_edges).astype(np.int64)
    return edges, face_edges.reshape(n_faces, 3), edge_faces, counts.astype(np.int64), forward_counts


def _bowtie_vertices(topology: MeshTopology) -> np.ndarray:
    """NumPy path of :attr:`MeshTopology.bowtie_vertices`: components of the corner graph."""
    import scipy.sparse as sp
    from scipy.sparse.csgraph import connected_components

    faces = topology.faces
    n_corners = 3 * faces.shape[0]
    proper = np.repeat(~topology.degenerate_faces, 3)
    pairs = topology.edge_faces
    linked = (topology.edge_face_counts == 2) & (pairs[:, 0] != pairs[:, 1])
    side_edge = topology.face_edges.ravel()
    sides = np.flatnonzero(proper & (side_edge >= 0))
    sides = sides[linked[side_edge[sides]]]
    # the two sides of every linked edge, by two scatters (no sort, no search)
    first = np.full(topology.n_edges, -1, dtype=np.int64)
    first[side_edge[sides]] = sides
    second = sides[first[side_edge[sides]] != sides]
    one = first[side_edge[second]]
    tail = faces.ravel()
    position = np.arange(n_corners) % 3
    head_corner = np.arange(n_corners) - position + (position + 1) % 3
    # side s runs from corner s to corner head_corner[s]; join the corners at the same vertex
    same = tail[one] == tail[second]
    rows = np.concatenate([one, head_corner[one]])
    cols = np.concatenate([np.where(same, second, head_corner[second]), np.where(same, head_corner[second], second)])
    graph = sp.csr_matrix((np.ones(rows.size, dtype=np.int8), (rows, cols)), shape=(n_corners, n_corners))
    _, labels = connected_components(graph, directed=False)
    first_label = np.full(topology.n_vertices, -1, dtype=np.int64)
    first_label[tail[proper]] = labels[proper]
    several = np.zeros(topology.n_vertices, dtype=bool)
    several[tail[proper & (labels != first_label[tail])]] = True
    return several


def _readonly(array: np.ndarray) -> np.ndarray:
    array.flags.writeable = False
    return array


def as_topology(faces, n_vertices: int, *, stacklevel: int = 3) -> MeshTopology:
    """``faces`` (an (F, 3) array, polygons, or a :class:`MeshTopology`) as the topology of ``n_vertices`` vertices.

    Faces are checked and triangulated by :func:`meshcurv._validation.as_faces`
    (its warning attributed ``stacklevel`` frames up); a topology is taken as
    it is once its vertex count matches.

    Raises
    ------
    InvalidMeshError
        ``faces`` unusable, or a MeshTopology of another vertex count.
    """
    if isinstance(faces, MeshTopology):
        return faces.for_vertices(n_vertices)
    return MeshTopology._build(as_faces(faces, n_vertices, stacklevel=stacklevel + 1), n_vertices)
