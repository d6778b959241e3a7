"""Welding of coincident vertices: triangle soups and seams made one surface.

STL files store every facet with its own three corners, ``pyvista.read`` of an
OBJ splits the corners of faces that differ in texture or normal index, and
trimesh splits vertices along texture seams. Such meshes describe a connected
surface, but their faces share no vertex across a seam: every edge there is a
boundary edge, and the curvature of a seam vertex is that of a one-sided patch
(all NaN for methods built on dihedral angles, zero for others).

:func:`weld_vertices` finds the copies of a point and maps the faces onto one
of them. Only vertices on boundary edges are candidates: a split always leaves
boundary edges on both sides, while coincident vertices inside a surface (two
sheets touching, a point cloud stored with the mesh) are not seams and stay
apart. A closed mesh therefore costs nothing here.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .topology import MeshTopology

__all__ = ["Welding", "weld_vertices", "WELD_TOLERANCE_RATIO"]

#: Vertices closer than this times the median edge length are copies of one point.
WELD_TOLERANCE_RATIO = 1e-5


class Welding(NamedTuple):
    """What :func:`weld_vertices` returns.

    Attributes
    ----------
    vertices : ndarray of shape (W, 3)
        The welded mesh's vertices: each group of copies becomes its first
        member (lowest index); the other vertices are kept in their order.
    topology : MeshTopology
        The welded mesh's connectivity (faces re-indexed into ``vertices``).
    index : ndarray of shape (V,), int64
        For every input vertex, its vertex in the welded mesh: a per-vertex
        field ``x`` of the welded mesh is ``x[index]`` on the input.
    n_welded : int
        Input vertices merged into another one (``V - W``).
    """

    vertices: np.ndarray
    topology: MeshTopology
    index: np.ndarray  # type: ignore[assignment]  # a field that shadows tuple.index (public name, kept)
    n_welded: int


def weld_vertices(vertices: np.ndarray, topology: MeshTopology, *,
                  tolerance_ratio: float = WELD_TOLERANCE_RATIO) -> Welding:
    """Merge coincident boundary vertices of a mesh (soups, seams).

    Parameters
    ----------
    vertices : ndarray of shape (V, 3), float64
        Validated coordinates.
    topology : MeshTopology
        The mesh's connectivity.
    tolerance_ratio : float, default: 1e-5
        Two boundary vertices closer than ``tolerance_ratio`` times the median
        length of the mesh's edges of non-zero length are one point.

    Returns
    -------
    Welding
        ``vertices``, ``topology`` and ``index`` of the welded mesh; the
        inputs themselves when nothing was welded (``n_welded == 0``).

    Notes
    -----
    Candidates are the vertices on boundary edges. Their pairs within the
    tolerance (:meth:`scipy.spatial.cKDTree.query_pairs`) are joined by
    connected components, so that a chain of near copies becomes one vertex.
    Faces that collapse (two corners welded together) are kept as they are:
    they were of (near) zero area before and are reported as such.

    Examples
    --------
    A triangle soup (every face with its own corners) becomes the closed surface:

    >>> from meshcurv import shapes, MeshTopology
    >>> from meshcurv.weld import weld_vertices
    >>> sphere = shapes.icosphere(3)
    >>> soup = sphere.vertices[sphere.faces.ravel()]
    >>> welded = weld_vertices(soup, MeshTopology.from_faces(np.arange(soup.shape[0]).reshape(-1, 3)))
    >>> welded.vertices.shape == sphere.vertices.shape, int(welded.topology.boundary_edges.sum())
    (True, 0)
    """
    n_vertices = vertices.shape[0]
    unchanged = Welding(vertices, topology, np.arange(n_vertices), 0)
    if not topology.boundary_edges.any():
        return unchanged
    candidates = np.flatnonzero(topology.boundary_vertices)
    lengths = np.linalg.norm(vertices[topology.edges[:, 0]] - vertices[topology.edges[:, 1]], axis=1)
    lengths = lengths[lengths > 0]
    if candidates.size < 2 or lengths.size == 0:
        return unchanged
    tolerance = tolerance_ratio * float(np.median(lengths))
    from scipy.sparse import coo_matrix  # imported on use: keeps `import meshcurv` fast
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    pairs = cKDTree(vertices[candidates]).query_pairs(tolerance, output_type="ndarray")
    if pairs.size == 0:
        return unchanged
    n = candidates.size
    graph = coo_matrix((np.ones(pairs.shape[0], dtype=np.int8), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, labels = connected_components(graph, directed=False)
    # the first (lowest-index) candidate of each group stands for the group
    _, first = np.unique(labels, return_index=True)
    representative = np.arange(n_vertices)
    representative[candidates] = candidates[first[labels]]
    kept = representative == np.arange(n_vertices)
    compact = np.cumsum(kept) - 1
    index = compact[representative]
    faces = index[topology.faces]
    welded_topology = MeshTopology._build(np.ascontiguousarray(faces), int(kept.sum()))
    return Welding(vertices[kept], welded_topology, index, int(n_vertices - kept.sum()))
