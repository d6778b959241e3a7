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

Faces detached from their neighbours by more than that tolerance (a mesh whose
faces were moved one by one, a soup written with rounding) leave cracks: pairs
of boundary edges lying on top of each other. Their ends are welded too, up to
:data:`CRACK_TOLERANCE_RATIO` of the edges' length; a real boundary has no
second edge on it and is left alone.
"""

from __future__ import annotations

import itertools
from typing import NamedTuple

import numpy as np

from ._backend import twin
from ._geometry import vertex_length_scales
from .defects import _needle_vertices
from .errors import InvalidMeshError, InvalidOptionError
from .geometry import checked_topology_points
from .orient import face_flips
from .topology import MeshTopology

__all__ = [
    "Welding",
    "weld_vertices",
    "WELD_TOLERANCE_RATIO",
    "CRACK_TOLERANCE_RATIO",
    "OneSided",
    "drop_double_sided",
    "drop_closed_copies",
    "tangled_vertices",
]

#: Vertices closer than this times the median edge length are copies of one point (of their own part's edges
#: where the parts of a mesh differ in scale: :func:`meshcurv.geometry.vertex_length_scales`).
WELD_TOLERANCE_RATIO = 1e-5

#: Two boundary edges sharing no vertex whose ends lie pairwise within this times the shorter edge's length are
#: the two sides of a crack between detached faces, and their ends are welded. A crack this narrow is far below
#: any curvature the faces resolve (a corner moved by it moves the normals by about as many radians), and far
#: above the round-off of exported coordinates; a real boundary has no second edge on it. Kept well below 1/2 so
#: that an edge is never paired with its neighbours along a boundary. Tests: tests/test_unwelded_faces.py.
CRACK_TOLERANCE_RATIO = 0.05


class Welding(NamedTuple):
    """What :func:`weld_vertices` returns.

    Attributes
    ----------
    vertices : ndarray of shape (W, 3)
        The welded mesh's vertices: each group of copies becomes its first
        member (lowest index), a group joined across cracks at the point of
        the member :func:`_crack_representatives` chooses (not by the
        order); the other vertices are kept in their order.
    topology : MeshTopology
        The welded mesh's connectivity (faces re-indexed into ``vertices``).
    index : ndarray of shape (V,), int64
        For every input vertex, its vertex in the welded mesh: a per-vertex
        field ``x`` of the welded mesh is ``x[index]`` on the input.
    n_welded : int
        Input vertices merged into another one (``V - W``).
    n_cracked : int, default: 0
        Of those, the vertices merged only across cracks (the ends of boundary edges on top of each other,
        :data:`CRACK_TOLERANCE_RATIO`), farther apart than the weld tolerance.
    """

    vertices: np.ndarray
    topology: MeshTopology
    index: np.ndarray  # type: ignore[assignment]  # a field that shadows tuple.index (public name, kept)
    n_welded: int
    n_cracked: int = 0


def weld_vertices(
    vertices: np.ndarray,
    topology: MeshTopology,
    *,
    tolerance_ratio: float = WELD_TOLERANCE_RATIO,
    crack_ratio: float = CRACK_TOLERANCE_RATIO,
) -> Welding:
    """Merge coincident boundary vertices of a mesh (soups, seams), and the ends of cracks between detached faces.

    Parameters
    ----------
    vertices : ndarray of shape (V, 3), float64
        Validated coordinates.
    topology : MeshTopology
        The mesh's connectivity.
    tolerance_ratio : float, default: 1e-5
        Two boundary vertices closer than ``tolerance_ratio`` times the median
        length of the mesh's edges of non-zero length are one point; where the
        mesh's components differ in scale
        (:func:`meshcurv.geometry.vertex_length_scales`), each vertex's tolerance
        is that times its component's median edge length, and a pair within
        the smaller of its two.
    crack_ratio : float, default: 0.05
        Two boundary edges that share no vertex, whose ends lie pairwise within
        ``crack_ratio`` times the shorter edge's length, are the sides of a
        crack: their ends are welded (:data:`CRACK_TOLERANCE_RATIO`). 0 welds
        no crack.

    Returns
    -------
    Welding
        ``vertices``, ``topology`` and ``index`` of the welded mesh; the
        inputs themselves when nothing was welded (``n_welded == 0``).

    Raises
    ------
    InvalidOptionError
        ``crack_ratio`` is not in [0, 0.5).

    Notes
    -----
    Candidates are the vertices on boundary edges. Their pairs within the
    tolerance (:meth:`scipy.spatial.cKDTree.query_pairs`) are joined by
    connected components, so that a chain of near copies becomes one vertex.
    The boundary edges left then are matched by their midpoints, in classes of
    edge lengths within a factor 2 (the two sides of a crack differ in length
    by at most twice the crack), so that the search radius follows the local
    resolution; either pairing of the ends is accepted (consistent or opposite
    windings), and the pairs are joined by connected components again. Faces
    that collapse (two corners welded together) are kept as they are: they
    were of (near) zero area before and are reported as such.

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

    Its faces moved apart by a thousandth of their edges are welded across the cracks:

    >>> rng = np.random.default_rng(0)
    >>> moved = soup + rng.normal(scale=1e-3 * 0.07, size=soup.shape)
    >>> welded = weld_vertices(moved, MeshTopology.from_faces(np.arange(soup.shape[0]).reshape(-1, 3)))
    >>> welded.vertices.shape == sphere.vertices.shape, welded.n_cracked == welded.n_welded
    (True, True)
    """
    if not 0.0 <= crack_ratio < 0.5:  # a wider "crack" would take an edge for its neighbour along a boundary
        raise InvalidOptionError(f"`crack_ratio` must be in [0, 0.5); got {crack_ratio!r}")
    strict = _weld_coincident(vertices, topology, tolerance_ratio)
    if crack_ratio <= 0.0 or not strict.topology.boundary_edges.any():
        return strict
    cracks = _weld_cracks(strict.vertices, strict.topology, crack_ratio)
    if cracks.n_welded == 0:
        return strict
    return Welding(
        cracks.vertices,
        cracks.topology,
        cracks.index[strict.index],
        strict.n_welded + cracks.n_welded,
        cracks.n_welded,
    )


def tangled_vertices(vertices: np.ndarray, topology: MeshTopology) -> np.ndarray:
    """(V,) bool: the vertices in a tangle of copies of one part left unwelded (:data:`meshcurv.defects.TANGLE`).

    The copies the weld would join (:func:`weld_vertices`: coincident boundary
    vertices, and the ends of cracks) are joined within each connected part:
    where the joined faces make a sheet, the copies were a seam split open (a
    texture seam of a file read unwelded), and each copy has half a
    neighbourhood, measured as a boundary vertex. Where the joined vertex, or
    a corner of a face of a copy, is on a non-manifold edge or a bow-tie (more
    than one fan of faces), the faces of the copies overlap there: no sheet,
    and a curvature measured over them is undefined. The methods over balls
    read every face the ball holds, from any copy: issue 29, fuzz 557/23, a
    thin plate given as a triangle soup whose faces were chained into one part
    by polygons of corners of two faces (6 copies at each point),
    ``weld=False``: ``icc`` kept 839 boundary vertices valid, a third of them
    more than 50% off in H, and its two backends' numbers apart. Copies in
    different parts (a closed surface stored twice, the faces of a soup each
    alone) are left alone: each part is measured on its own.

    Parameters
    ----------
    vertices : ndarray of shape (V, 3), float64
    topology : MeshTopology
        Their faces' connectivity (a welded mesh has no copies left to join).

    Returns
    -------
    ndarray of shape (V,), bool
        The copies and the corners of their faces whose joined vertex is on a
        non-manifold edge or a bow-tie vertex (those already such before the
        join included: their own defect comes first,
        :data:`meshcurv.defects.DEFECTS`).

    Raises
    ------
    InvalidMeshError
        ``topology`` not a MeshTopology, ``vertices`` unusable or not one row
        per vertex of ``topology``.

    Examples
    --------
    A sphere's triangle soup whose faces are chained into one part by faces across two of them:

    >>> from meshcurv import shapes, MeshTopology
    >>> sphere = shapes.icosphere(3)
    >>> soup = sphere.vertices[sphere.faces.ravel()]
    >>> faces = np.arange(soup.shape[0]).reshape(-1, 3)
    >>> chained = np.concatenate([faces, np.column_stack([faces[:-1, 0], faces[:-1, 2], faces[1:, 0]])])
    >>> int(tangled_vertices(soup, MeshTopology.from_faces(chained, soup.shape[0])).sum())
    540
    >>> int(tangled_vertices(soup, MeshTopology.from_faces(faces, soup.shape[0])).sum())  # faces apart
    0
    """
    if not isinstance(topology, MeshTopology):
        raise InvalidMeshError(f"`topology` must be a MeshTopology; got {type(topology).__name__}")
    vertices = checked_topology_points(vertices, topology)
    tangled = _tangled_vertices(vertices, topology, vertex_length_scales(vertices, topology))
    return np.zeros(topology.n_vertices, dtype=bool) if tangled is None else tangled


def _tangled_vertices(vertices: np.ndarray, topology: MeshTopology, scales: np.ndarray) -> np.ndarray | None:
    """:func:`tangled_vertices` of a checked mesh whose vertices have the length scales ``scales``, None where there
    is none: a closed mesh (no pass at all), or no boundary vertex as near another as the weld joins (one query of
    their nearest neighbours, not the weld: its median edges cost 0.1 s of CPU at 200,000 vertices)."""
    if not topology.boundary_edges.any():
        return None
    from scipy.spatial import cKDTree  # imported on use: keeps `import meshcurv` fast

    candidates = np.flatnonzero(topology.boundary_vertices)
    points = vertices[candidates]
    ends = topology.edges[topology.boundary_edges]
    longest = float(np.linalg.norm(vertices[ends[:, 0]] - vertices[ends[:, 1]], axis=1).max())
    reach = max(CRACK_TOLERANCE_RATIO * longest, WELD_TOLERANCE_RATIO * float(scales[candidates].max()))
    if candidates.size < 2 or not (cKDTree(points).query(points, k=2)[0][:, 1] <= reach).any():
        return None
    welding = weld_vertices(vertices, topology)
    if not welding.n_welded:
        return None
    n = topology.n_vertices
    _, parts = topology.vertex_components
    # the weld's groups split by part, each standing on its first (lowest-index) member
    _, group, sizes = np.unique(
        np.column_stack([welding.index, parts]), axis=0, return_inverse=True, return_counts=True
    )
    group = group.reshape(-1)
    first = np.full(sizes.size, n, dtype=np.int64)
    np.minimum.at(first, group, np.arange(n))
    copies = (sizes[group] > 1) & topology.referenced_vertices
    if not copies.any():  # no copies in one part (the faces of a soup each alone)
        return None
    representative = first[group]
    # the faces at the copies and at the corners of their faces: every face at such a vertex holds it, so the
    # joined edges and fans there are those of the whole mesh joined
    faces = topology.faces
    near = np.zeros(n, dtype=bool)
    near[faces[copies[faces].any(axis=1)].ravel()] = True
    around = representative[faces[near[faces].any(axis=1)]]
    # a face whose corners join (a zero-area face at a grid sphere's pole, given between copies of the pole) is no
    # face of the joined surface: kept, it would stand as a third face on its edge (R28: 130 of a MATLAB grid
    # sphere's vertices were read as a tangle, 2 right ones lost)
    around = around[(around[:, 0] != around[:, 1]) & (around[:, 1] != around[:, 2]) & (around[:, 2] != around[:, 0])]
    joined = MeshTopology._build(np.ascontiguousarray(around), n)
    broken = joined.edge_vertices(joined.nonmanifold_edges) | joined.bowtie_vertices
    tangled = near & broken[representative]
    return tangled if tangled.any() else None


def _weld_coincident(vertices: np.ndarray, topology: MeshTopology, tolerance_ratio: float) -> Welding:
    """The boundary vertices within ``tolerance_ratio`` times the median edge length (their parts' where the
    parts differ in scale) welded (:func:`weld_vertices`).

    Exact copies of a point are joined first, and the search runs on one copy each (the largest tolerance of
    its copies stands for it: a point within the tolerance of one copy joins them all); the pairs within the
    tolerance are taken in chunks (:func:`_pairs_near`) and kept as the components they join
    (:class:`_Components`): a collapsed soup (18,000 corners at one point, another apart) made 160 M pairs.
    """
    n_vertices = vertices.shape[0]
    unchanged = Welding(vertices, topology, np.arange(n_vertices), 0)
    if not topology.boundary_edges.any():
        return unchanged
    candidates = np.flatnonzero(topology.boundary_vertices)
    if candidates.size < 2:
        return unchanged
    scales = vertex_length_scales(vertices, topology)
    used = scales[topology.referenced_vertices]
    if used.min() < used.max():  # parts of different scales: each within its own tolerance
        tolerances = tolerance_ratio * scales[candidates]
    else:
        tolerance = _tolerance(vertices, topology, tolerance_ratio)
        if tolerance == 0.0:
            return unchanged
        tolerances = np.full(candidates.size, tolerance)
    points = vertices[candidates]
    components = _Components(candidates.size)
    single, copies = _exact_copies(points)
    components.add(copies)
    widest = tolerances.copy()
    np.maximum.at(widest, copies[:, 0], tolerances[copies[:, 1]])  # a copy's tolerance reaches its first's
    if used.min() < used.max():
        for i, j in _pairs_within(points[single], widest[single]):
            components.add(np.column_stack([single[i], single[j]]))
    else:
        for i, j in _pairs_near(points[single], tolerance):
            components.add(np.column_stack([single[i], single[j]]))
    pairs = components.links()
    if pairs.size == 0:
        return unchanged
    return _merge(vertices, topology, pairs, candidates)


def _exact_copies(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The rows of ``points`` ((N, 3)) that are the first of their exact copies (or the only one, or not
    finite), and (C, 2) each later copy paired with its first."""
    finite = np.flatnonzero(np.isfinite(points).all(axis=1))
    values = points[finite]
    order = np.lexsort((values[:, 2], values[:, 1], values[:, 0]))  # stable: each run of copies by index
    ordered = values[order]
    starts = np.r_[True, (ordered[1:] != ordered[:-1]).any(axis=1)]
    first = order[starts][np.cumsum(starts) - 1]
    copies = np.column_stack([finite[first[~starts]], finite[order[~starts]]])
    single = np.ones(points.shape[0], dtype=bool)
    single[copies[:, 1]] = False
    return np.flatnonzero(single), copies


def _pairs_near(points: np.ndarray, radius: float):
    """Yield ``(i, j)``: the index pairs ``i < j`` of ``points`` within ``radius`` of each other, at once
    (:meth:`scipy.spatial.cKDTree.query_pairs`) when they are few (:func:`_few_pairs`), in chunks
    (:func:`_near_pairs`) otherwise."""
    from scipy.spatial import cKDTree  # imported on use: keeps `import meshcurv` fast

    tree = cKDTree(points)
    if _few_pairs(points, radius, tree=tree):
        pairs = tree.query_pairs(radius, output_type="ndarray")
        yield pairs[:, 0], pairs[:, 1]
        return
    for i, j, _ in _near_pairs(tree, points, radius):
        keep = i < j
        yield i[keep], j[keep]


#: The pairs of points within a weld's radius found at once are at most this many per point (and
#: :data:`PAIR_CHUNK` in all): 16 bytes each; more are taken in chunks.
PAIRS_PER_POINT = 16


def _few_pairs(points: np.ndarray, radius: float, others: np.ndarray | None = None, *, tree=None) -> bool:
    """Whether the ordered pairs of ``points`` and ``others`` (default: ``points``, each with itself too) within
    ``radius`` are at most :data:`PAIRS_PER_POINT` per point or :data:`PAIR_CHUNK`.

    First by a bound, linear in time and memory: the two points of a pair within ``radius`` lie in the same or
    neighbouring cells of the grid of side ``radius``, so the sum over ``points`` of the counts of ``others`` in
    the 27 cells around each (cells hashed into buckets, which only adds) is at least the number of pairs (about
    3 times it on a surface sampled evenly). Where the bound is larger, the pairs are counted (a search as long
    as finding them, no memory): ``tree`` is ``others``' ``cKDTree`` when given.
    """
    from scipy.spatial import cKDTree  # imported on use: keeps `import meshcurv` fast

    other = points if others is None else others
    n = points.shape[0] + other.shape[0]
    limit = max(PAIR_CHUNK, PAIRS_PER_POINT * n)
    if points.shape[0] * other.shape[0] <= limit:  # however close
        return True
    size = 1 << int(np.ceil(np.log2(2 * n + 1)))
    keys = _cell_keys(points, radius)
    counts = np.bincount(_bucket(keys if others is None else _cell_keys(other, radius), size), minlength=size)
    bound = 0
    for offset in _NEIGHBOUR_OFFSETS:
        bound += int(counts[_bucket(keys + offset, size)].sum())
        if bound > limit:
            break
    else:
        return True
    tree = cKDTree(other) if tree is None else tree
    queries = tree if others is None else cKDTree(points)
    return int(queries.count_neighbors(tree, radius)) <= limit


#: Odd 64-bit multipliers mixing a cell's three integer coordinates into one key (:func:`_cell_keys`).
_MIXERS = np.array([-7046029254386353131, -4658895280553007687, 1], dtype=np.int64)

#: The keys of the 27 cells around a cell less its own key (:func:`_cell_keys` is linear in the cell, modulo 2^64).
_NEIGHBOUR_OFFSETS = np.array(list(itertools.product((-1, 0, 1), repeat=3)), dtype=np.int64) @ _MIXERS


def _cell_keys(points: np.ndarray, radius: float) -> np.ndarray:
    """(N,) int64: the cells of side ``radius`` holding ``points`` ((N, 3) or more columns: the first three
    taken, within ``radius`` when the points are), their integer coordinates mixed into one key (cells beyond
    2^62 clipped: points within ``radius`` stay in neighbouring cells)."""
    with np.errstate(over="ignore", invalid="ignore"):
        cells = np.floor(np.clip(points[:, :3] / radius, -(2.0**62), 2.0**62)).astype(np.int64)
    return cells @ _MIXERS  # wraps modulo 2^64


def _bucket(keys: np.ndarray, size: int) -> np.ndarray:
    """(N,) the buckets in [0, size) (a power of 2) of cell ``keys``."""
    return (keys ^ (keys >> 29)) & (size - 1)


def _pairs_within(points: np.ndarray, tolerances: np.ndarray):
    """Yield ``(i, j)``: index pairs of ``points`` (distinct) closer than the smaller of their two ``tolerances``
    (>= 0), in chunks (:func:`_near_pairs`); a pair may come more than once.

    A mesh of parts at different scales (a part of 2 units beside one of 1e12) welds each part within its own
    tolerance: one taken from the largest part's edges would merge a whole small part into a point (issue 29).
    One search within the largest tolerance when :func:`_few_pairs` finds its pairs few (the
    tolerances of a soup, each face a part of its own, span a few octaves: one bound and one search per weld);
    otherwise one search per octave of tolerances, each against the points of that octave and above, so that no
    search is wider than the smaller tolerance of the pairs it finds. Either finds every pair of the rule. A
    tolerance of 0 (a part whose edges all have length 0) joins exact copies only, which ``points`` holds no more
    (:func:`_exact_copies`).
    """
    from scipy.spatial import cKDTree  # imported on use: keeps `import meshcurv` fast

    positive = np.flatnonzero(tolerances > 0)
    if positive.size < 2:
        return
    widest = float(tolerances[positive].max())
    tree = cKDTree(points[positive])
    if _few_pairs(points[positive], widest, tree=tree):
        found = tree.sparse_distance_matrix(tree, widest, output_type="ndarray")
        i, j = positive[found["i"]], positive[found["j"]]
        keep = (i != j) & (found["v"] <= np.minimum(tolerances[i], tolerances[j]))
        yield i[keep], j[keep]
        return
    _, octave = np.frexp(tolerances[positive])
    for c in np.unique(octave).tolist():
        these = positive[octave == c]
        wider = positive[octave >= c]
        for rows, columns, distances in _near_pairs(cKDTree(points[wider]), points[these], np.ldexp(1.0, c)):
            i, j = these[rows], wider[columns]
            keep = (i != j) & (distances <= np.minimum(tolerances[i], tolerances[j]))
            yield i[keep], j[keep]


def _weld_cracks(vertices: np.ndarray, topology: MeshTopology, crack_ratio: float) -> Welding:
    """The ends of boundary edges on top of each other welded (:func:`weld_vertices`); ``n_cracked`` = ``n_welded``.

    The candidates are the pairs of edges whose midpoints are within the largest ``limit`` of their class: all
    classes in one search within the largest class's when :func:`_few_pairs` finds those pairs few (one check
    and one search per weld, the common case), one search per class otherwise. Where they are
    many more than the edges (edges on top of each other in bulk: a collapsed soup, its vertices
    collinear, fuzz 342/923, had 8.6 M pairs for 17,795 edges and took 1.3 GiB), they are searched among the
    edges' pairs of ends instead, as points ``(first, second)`` of 6-D space against the edges' ``(first,
    second)`` and ``(second, first)`` (two ends each within ``limit`` of the other edge's are within
    ``sqrt(2) * limit`` there: a fifth of the candidates on that soup, but a slower search on any mesh), taken in
    chunks (:func:`_near_pairs`); the pairs found are kept as the components they join (:class:`_Components`).
    Both searches find every pair of the rule, so the welds are the same; the memory is bounded by the mesh's
    size.
    """
    n_vertices = vertices.shape[0]
    unchanged = Welding(vertices, topology, np.arange(n_vertices), 0)
    ends = topology.edges[topology.boundary_edges]
    first, second = vertices[ends[:, 0]], vertices[ends[:, 1]]
    lengths = np.linalg.norm(second - first, axis=1)
    usable = np.isfinite(lengths) & (lengths > 0)
    if np.count_nonzero(usable) < 2:
        return unchanged
    ends, first, second, lengths = ends[usable], first[usable], second[usable], lengths[usable]
    midpoints = 0.5 * (first + second)
    if not np.isfinite(midpoints).all():  # overflow of huge coordinates: those edges take no part
        finite = np.isfinite(midpoints).all(axis=1)
        ends, first, second, lengths, midpoints = (a[finite] for a in (ends, first, second, lengths, midpoints))
        if lengths.size < 2:
            return unchanged
    from scipy.spatial import cKDTree  # imported on use: keeps `import meshcurv` fast

    # the two sides of a crack differ in length by at most twice the crack (far below a factor 2): the pairs of
    # each class of lengths [2^(c-1), 2^c) and the next are within crack_ratio * 2^c of each other, end by end
    _, exponent = np.frexp(lengths)
    components = _Components(n_vertices)
    widest = crack_ratio * np.ldexp(1.0, int(exponent.max()))
    tree = cKDTree(midpoints)
    if _few_pairs(midpoints, widest, tree=tree):  # one bound (or count) and one search for all the classes
        found = tree.query_pairs(widest, output_type="ndarray")
        for k in range(0, found.shape[0], PAIR_CHUNK):
            i, j = found[k : k + PAIR_CHUNK].T
            components.add(_crack_links(ends, first, second, lengths, i, j, crack_ratio))
        return _merge_cracks(vertices, topology, components)
    for c in np.unique(exponent).tolist():  # one search per octave of edge lengths, not per edge
        members = np.flatnonzero((exponent == c) | (exponent == c + 1))
        if members.size < 2:
            continue
        radius = crack_ratio * np.ldexp(1.0, c)
        tree = cKDTree(midpoints[members])
        if _few_pairs(midpoints[members], radius, tree=tree):
            found = members[tree.query_pairs(radius, output_type="ndarray")]
            for k in range(0, found.shape[0], PAIR_CHUNK):
                i, j = found[k : k + PAIR_CHUNK].T
                components.add(_crack_links(ends, first, second, lengths, i, j, crack_ratio))
            continue
        forward = np.hstack([first[members], second[members]])
        queries = np.vstack([forward, np.hstack([second[members], first[members]])])
        for rows, columns, _ in _near_pairs(cKDTree(forward), queries, np.sqrt(2.0) * radius):
            i, j = members[rows % members.size], members[columns]
            keep = i < j  # each pair once (as the same and the crossed pairing's query: either finds it)
            components.add(_crack_links(ends, first, second, lengths, i[keep], j[keep], crack_ratio))
    return _merge_cracks(vertices, topology, components)


def _merge_cracks(vertices: np.ndarray, topology: MeshTopology, components: _Components) -> Welding:
    """The mesh with the crack ends joined in ``components`` welded (:func:`_weld_cracks`), each group at the point
    of the member :func:`_crack_representatives` chooses (in the place of its first member in the vertices' order)."""
    pairs = components.links()
    if pairs.size == 0:
        return Welding(vertices, topology, np.arange(vertices.shape[0]), 0)
    # each group at one of its members, as a weld of coincident copies: the mean of the copies (d4e1e6a) moved the
    # corners of a voxel surface off its grid (no longer read as one: another radius, H off by 0.57 of |k|) and
    # flung a vertex whose copies the crack search paired along a needle's long edges (issue 29, fuzz round 17,
    # 312/2774 and 312/4373, 296/119); quadric's rims are steadied by their fits instead (quadric.STEADY_*)
    welding = _merge(vertices, topology, pairs)
    return welding._replace(vertices=_crack_representatives(vertices, topology, welding), n_cracked=welding.n_welded)


#: Of a group of crack ends welded into one vertex (:func:`_crack_representatives`), the members whose squared distances
#: to the group's mean are within this share of the least are as near as it.
CRACK_MEAN_TIE = 1e-9

#: ... and within this many units of round-off of the group's largest coordinate (times the distance, or the root
#: of the area, compared): far from the origin the rounding of the coordinates alone parts two ends equally near the
#: mean (``voxel_sphere(6)``'s soup moved 1e5 sizes away: 2 to 29 groups at another end than at the origin).
CRACK_ROUNDING = 64.0


def _crack_representatives(vertices: np.ndarray, topology: MeshTopology, welding: Welding) -> np.ndarray:
    """The welded vertices of ``welding`` (a weld of crack ends, :func:`_merge`), each group of two or more ends at
    the point of the member that the order of the vertices does not choose: the one in the most faces, then the
    one whose faces' corners are in the most faces, then the one nearest the group's mean (within
    :data:`CRACK_MEAN_TIE`), then the one whose faces have the largest area, then the first.

    The group's first member chose its point, and so the surface measured, by the order of the vertices: a soup's
    copies lie a few hundredths of an edge apart, and every method's numbers on it changed with a permutation of
    its vertices (``quadric`` on ``voxel_sphere(6)`` turned, every face detached by 0.05 edges: 12 vertices valid in
    one order only, H 0.19 of ``|k|`` apart; issue 29, R30). The member in the most faces is the corner that kept its
    place where a share of the faces was detached (on the grid of a voxel surface), and where it is left in as many
    faces as a copy (one), its faces share their corners with their neighbours, a detached face's copies are in that
    face alone; the one nearest the mean of copies moved at random, the least moved; the area decides between two
    copies equally near (a pair's).
    """
    index, points = welding.index, welding.vertices
    sizes = np.bincount(index, minlength=points.shape[0])
    members = np.flatnonzero(sizes[index] > 1)
    if members.size == 0:
        return points
    slots, groups = np.unique(index[members], return_inverse=True)
    n = slots.size
    ends = vertices[members]
    every = np.bincount(topology.faces.ravel(), minlength=vertices.shape[0])
    counts = every[members]
    corners = vertices[topology.faces]
    areas = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)
    area = np.bincount(topology.faces.ravel(), weights=np.repeat(areas, 3), minlength=vertices.shape[0])[members]
    # the mean summed in the order of the coordinates within each group (the same sum in any order of the vertices),
    # of the ends less the group's first end in that order: the differences of nearby coordinates are exact wherever
    # the mesh sits, so the two ends of a pair are equally near their mean far from the origin too (absolute
    # coordinates' round-off at 1e5 mesh sizes chose either end, and another surface than at the origin: R30's
    # translated soup, tests/test_quadric_soups_V30.py, read no grid)
    order = np.lexsort((ends[:, 2], ends[:, 1], ends[:, 0], groups))
    starts = np.flatnonzero(np.diff(groups[order], prepend=-1))  # each group's first end in that order
    # the round-off of a group's coordinates (the ties below hold within it: a group's ends equally near their mean
    # or of equal areas in exact arithmetic, as the copies of one corner moved by one gap, stay tied wherever it sits)
    rounding = np.zeros(n)
    np.maximum.at(rounding, groups, np.abs(ends).max(axis=1))
    rounding *= CRACK_ROUNDING * np.finfo(float).eps
    ends = ends - ends[order[starts]][groups]
    sums = np.column_stack([np.bincount(groups[order], weights=ends[order, k], minlength=n) for k in range(3)])
    mean = sums / np.bincount(groups, minlength=n)[:, None]
    apart = np.einsum("ij,ij->i", ends - mean[groups], ends - mean[groups])
    most = np.zeros(n, dtype=np.int64)
    np.maximum.at(most, groups, counts)
    held = counts == most[groups]
    # of members in as many faces, the one whose faces' corners are in the most faces: the corner left in place shares
    # its faces' corners with their neighbours, a detached face's copies are in its face alone (a soup's pair ties
    # on the mean exactly and the area chose a moved copy over the clean corner: 63-91 of about 1,900 groups on N21's
    # uv sphere, 442 of 15,038 on N25's icosphere(40); ncb valid 4-6% fewer; W33)
    reach = np.bincount(
        topology.faces.ravel(), weights=np.repeat(every[topology.faces].sum(axis=1), 3), minlength=vertices.shape[0]
    )[members]
    widest = np.zeros(n)
    np.maximum.at(widest, groups[held], reach[held])
    held &= reach == widest[groups]
    least = np.full(n, np.inf)
    np.minimum.at(least, groups[held], apart[held])
    held &= apart <= least[groups] * (1.0 + CRACK_MEAN_TIE) + rounding[groups] * np.sqrt(least[groups])
    largest = np.full(n, -np.inf)
    np.maximum.at(largest, groups[held], area[held])
    held &= area >= largest[groups] * (1.0 - CRACK_MEAN_TIE) - rounding[groups] * np.sqrt(largest[groups])
    chosen = np.full(n, vertices.shape[0], dtype=np.int64)
    np.minimum.at(chosen, groups[held], members[held])
    points = points.copy()
    points[slots] = vertices[chosen]
    return points


def _crack_links(
    ends: np.ndarray,
    first: np.ndarray,
    second: np.ndarray,
    lengths: np.ndarray,
    i: np.ndarray,
    j: np.ndarray,
    crack_ratio: float,
) -> np.ndarray:
    """(P, 2) the vertex pairs welded by the edge pairs ``(i, j)`` that are the two sides of a crack: their ends
    pairwise within ``crack_ratio`` times the shorter edge's length, in either pairing (the same pairing first),
    and sharing no vertex (so no face: a face's edges do)."""
    a, b, c, d = ends[i, 0], ends[i, 1], ends[j, 0], ends[j, 1]
    apart = (a != c) & (a != d) & (b != c) & (b != d)
    limit = crack_ratio * np.minimum(lengths[i], lengths[j])
    same = np.maximum(_distance(first[i], first[j]), _distance(second[i], second[j])) <= limit
    crossed = np.maximum(_distance(first[i], second[j]), _distance(second[i], first[j])) <= limit
    same &= apart
    crossed &= apart & ~same
    return np.concatenate(
        [
            np.column_stack([a[same], c[same]]),
            np.column_stack([b[same], d[same]]),
            np.column_stack([a[crossed], d[crossed]]),
            np.column_stack([b[crossed], c[crossed]]),
        ]
    )


#: The candidate pairs of a weld's search taken at once (:func:`_near_pairs`), beside one query's own: a few tens of
#: MiB of coordinates, whatever the number of points on top of each other.
PAIR_CHUNK = 1 << 18


def _near_pairs(tree, queries: np.ndarray, radius: float, chunk: int = PAIR_CHUNK):
    """Yield ``(rows, columns, distances)``: the ``queries`` and the points of ``tree`` (a ``cKDTree``) within
    ``radius`` of each other, in chunks of consecutive queries holding at most ``chunk`` pairs each, beyond a
    single query's own (at most the tree's size): memory bounded by the points', not by their pairs."""
    from scipy.spatial import cKDTree  # imported on use: keeps `import meshcurv` fast

    if _few_pairs(queries, radius, tree.data, tree=tree):
        found = cKDTree(queries).sparse_distance_matrix(tree, radius, output_type="ndarray")
        yield found["i"].astype(np.int64), found["j"].astype(np.int64), found["v"]
        return
    counts = np.asarray(tree.query_ball_point(queries, radius, return_length=True), dtype=np.int64)
    total = np.cumsum(counts)
    if total.size == 0 or total[-1] == 0:
        return
    starts = np.unique(np.r_[0, np.searchsorted(total, np.arange(chunk, total[-1], chunk), side="left") + 1])
    stops = np.r_[starts[1:], queries.shape[0]]
    for start, stop in zip(starts.tolist(), stops.tolist()):
        if start >= stop or total[stop - 1] == (total[start - 1] if start else 0):
            continue
        found = cKDTree(queries[start:stop]).sparse_distance_matrix(tree, radius, output_type="ndarray")
        yield found["i"].astype(np.int64) + start, found["j"].astype(np.int64), found["v"]


class _Components:
    """The vertices joined by pairs given in chunks, kept as the components they make (a forest of links to each
    component's first vertex) whenever the links held exceed twice the forest's and the larger of the vertices'
    number and :data:`PAIR_CHUNK`: memory bounded by the vertices, and each reduction, linear in the vertices and
    links, comes after at least as many new links (linear time in all)."""

    def __init__(self, n_vertices: int) -> None:
        self.n_vertices = n_vertices
        self.held: list[np.ndarray] = []
        self.size = 0
        self.forest = 0

    def add(self, pairs: np.ndarray) -> None:
        """Join the vertices of ``pairs`` ((P, 2) vertex indices)."""
        if pairs.size == 0:
            return
        self.held.append(pairs.astype(np.int64, copy=False))
        self.size += pairs.shape[0]
        if self.size > 2 * self.forest + max(self.n_vertices, PAIR_CHUNK) and len(self.held) > 1:
            self.held = [self._forest()]
            self.size = self.forest = self.held[0].shape[0]

    def links(self) -> np.ndarray:
        """(L, 2) pairs joining the same components as all the pairs added."""
        return np.concatenate(self.held) if self.held else np.empty((0, 2), dtype=np.int64)

    def _forest(self) -> np.ndarray:
        """(L, 2) each joined vertex and its component's first (lowest-index) vertex."""
        from scipy.sparse import coo_matrix  # imported on use: keeps `import meshcurv` fast
        from scipy.sparse.csgraph import connected_components

        pairs, n = self.links(), self.n_vertices
        graph = coo_matrix((np.ones(pairs.shape[0], dtype=np.int8), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
        _, labels = connected_components(graph, directed=False)
        _, first = np.unique(labels, return_index=True)
        root = first[labels]
        joined = np.flatnonzero(root != np.arange(n))
        return np.column_stack([root[joined], joined])


def _distance(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """(N,) the distances between the rows of ``p`` and ``q``."""
    return np.linalg.norm(p - q, axis=1)


def _merge(
    vertices: np.ndarray,
    topology: MeshTopology,
    pairs: np.ndarray,
    candidates: np.ndarray | None = None,
) -> Welding:
    """The mesh with the vertices joined by ``pairs`` ((P, 2) indices into ``candidates``, sorted vertex indices;
    None: vertex indices) and their chains made one vertex each, at its first member."""
    from scipy.sparse import coo_matrix  # imported on use: keeps `import meshcurv` fast
    from scipy.sparse.csgraph import connected_components

    n_vertices = vertices.shape[0]
    if candidates is None:
        candidates, inverse = np.unique(pairs, return_inverse=True)
        local = np.reshape(inverse, (-1, 2))
    else:
        local = pairs
    n = candidates.size
    graph = coo_matrix((np.ones(local.shape[0], dtype=np.int8), (local[:, 0], local[:, 1])), shape=(n, n))
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


class OneSided(NamedTuple):
    """What :func:`drop_double_sided` returns.

    Attributes
    ----------
    topology : MeshTopology
        The mesh without the dropped faces (the input itself when none was dropped).
    dropped : ndarray of shape (F,), bool
        The input faces that were dropped.
    n_dropped : int
        Their number.
    length_scales, needles : ndarray of shape (V,), or None
        When faces were dropped: the length scales (float64) and needle vertices (bool, read-only) of
        ``topology`` (:func:`meshcurv.geometry.vertex_length_scales`, :func:`meshcurv.defects.needle_vertices`),
        found to choose the side kept; a caller that needs them takes these. None when nothing was dropped.
    """

    topology: MeshTopology
    dropped: np.ndarray
    n_dropped: int
    length_scales: np.ndarray | None = None
    needles: np.ndarray | None = None


def drop_double_sided(vertices: np.ndarray, topology: MeshTopology) -> OneSided:
    """Keep one side of a double-sided mesh: drop the faces that repeat another face with the opposite winding.

    A double-sided mesh stores every face twice, once per side, with opposite
    windings (renderers without back faces need them). Its edges then have
    four faces each (non-manifold: every estimator leaves their vertices
    undefined), and its integrals count the surface twice (the total Gaussian
    curvature of a double-sided sphere is ``8 pi``, or more when the windings
    alternate). The surface it describes is the one-sided mesh.

    Parameters
    ----------
    vertices : ndarray of shape (V, 3), float64
        Validated coordinates (to tell the outside of a closed part).
    topology : MeshTopology
        The mesh's connectivity, after welding (a double-sided triangle soup
        shares its vertices only once welded).

    Returns
    -------
    OneSided
        ``topology`` of the kept faces, the ``dropped`` mask and ``n_dropped``.

    Notes
    -----
    Faces with the same three vertices form a group; in a group holding
    both windings, the faces of one winding are kept and the others
    dropped. The winding kept is the one of the group's first face (lowest
    index), unless the other one makes the kept faces consistently oriented
    and the closed parts outward (:func:`meshcurv.orient.face_flips`): the
    input gives no side there, so the side taken is the one ``orient='outward'``
    would give, whatever the order of the faces, and ``orient='keep'`` gets a
    consistent side too. Faces repeated with the same winding
    are kept (they stay non-manifold and are reported as such), and so are
    faces with a repeated corner. Only faces on non-manifold edges are
    candidates (every face of a double-sided patch has one), and so are the
    faces on an edge whose two faces share their third corner (a lone
    triangle's two sides: a closed pillow of manifold edges): a manifold mesh
    costs one look at its edge classes and corner sums. Vertices are never dropped: a kept face has the corners of the
    faces it stands for.

    Examples
    --------
    >>> import numpy as np
    >>> from meshcurv import shapes, MeshTopology
    >>> from meshcurv.weld import drop_double_sided
    >>> sphere = shapes.icosphere(3)
    >>> both = MeshTopology.from_faces(np.vstack([sphere.faces, sphere.faces[:, ::-1]]))
    >>> one = drop_double_sided(sphere.vertices, both)
    >>> one.n_dropped == sphere.faces.shape[0], bool((one.topology.faces == sphere.faces).all())
    (True, True)
    """
    faces = topology.faces
    n_faces = faces.shape[0]
    none = OneSided(topology, np.zeros(n_faces, dtype=bool), 0)
    suspect = _suspect_edges(topology)
    if not suspect.any():
        return none
    sides = topology.face_edges
    candidate = (suspect[sides] & (sides >= 0)).any(axis=1) & ~topology.degenerate_faces
    rows = np.flatnonzero(candidate)
    if rows.size < 2:
        return none
    corners = faces[rows]
    ordered = np.sort(corners, axis=1)
    # winding: even when the corners are a rotation of their sorted order (an even number of inversions)
    a, b, c = corners.T
    even = ((a > b) ^ (b > c) ^ (a > c)) == 0
    order = np.lexsort((rows, ordered[:, 2], ordered[:, 1], ordered[:, 0]))  # groups, each by face index
    key = ordered[order]
    starts = np.r_[True, (key[1:] != key[:-1]).any(axis=1)]
    group = np.cumsum(starts) - 1
    first_even = even[order][starts][group]
    mixed = even[order] != first_even
    group_both = np.bincount(group, weights=mixed) > 0
    dropped = np.zeros(n_faces, dtype=bool)
    dropped[rows[order]] = mixed
    n_dropped = int(dropped.sum())
    if n_dropped == 0:
        return none
    kept_faces = np.ascontiguousarray(faces[~dropped])
    kept = MeshTopology._build(kept_faces, topology.n_vertices)
    # the length scales and needles of the kept faces, for the choice of their side and for the caller
    scales = vertex_length_scales(vertices, kept)
    needles = _needle_vertices(vertices, kept, scales)
    needles.flags.writeable = False
    # the other copies where they make the kept faces consistent and outward, a whole group at a time
    flips = np.zeros(n_faces, dtype=bool)
    flips[~dropped] = face_flips(vertices, kept, outward=True, needles=needles)
    group_flips = flips[rows[order][starts]] & group_both
    other = np.zeros(n_faces, dtype=bool)
    other[rows[order]] = group_flips[group]
    other = other[~dropped]
    if other.any():
        kept = MeshTopology._build(np.where(other[:, None], kept_faces[:, ::-1], kept_faces), topology.n_vertices)
        # the same edges (so the same scales), but the reversed faces' corner angles in another order of their
        # corners: found again, to the last bit those of the faces returned
        needles = _needle_vertices(vertices, kept, scales)
        needles.flags.writeable = False
    return OneSided(kept, dropped, n_dropped, scales, needles)


def _tolerance(vertices: np.ndarray, topology: MeshTopology, tolerance_ratio: float) -> float:
    """``tolerance_ratio`` times the median length of the mesh's edges of non-zero length (0 with none)."""
    lengths = np.linalg.norm(vertices[topology.edges[:, 0]] - vertices[topology.edges[:, 1]], axis=1)
    lengths = lengths[lengths > 0]
    return tolerance_ratio * float(np.median(lengths)) if lengths.size else 0.0


def drop_closed_copies(
    vertices: np.ndarray, topology: MeshTopology, *, tolerance_ratio: float = WELD_TOLERANCE_RATIO
) -> Welding:
    """Measure a closed part stored twice once: drop the faces of its coincident copies.

    Two closed parts whose vertices coincide point for point (a part exported
    twice, a scene holding an object and its copy in place) describe one
    surface. Each copy alone has the right curvature, but every total counts
    the surface as often as it is stored (the total Gaussian curvature of a
    sphere stored twice is ``8 pi``). Welding does not see them: their
    vertices are on no boundary edge.

    Parameters
    ----------
    vertices : ndarray of shape (V, 3), float64
        Validated coordinates.
    topology : MeshTopology
        The mesh's connectivity (after welding).
    tolerance_ratio : float, default: 1e-5
        A vertex of a copy lies within ``tolerance_ratio`` times the median
        edge length (the two parts' smaller one, where the mesh's components
        differ in scale) of a vertex of the part it repeats.

    Returns
    -------
    Welding
        The mesh without the copies' vertices and faces; ``index`` maps every
        input vertex to its vertex (a copy's vertex to the one it repeats);
        ``n_welded`` is the number of vertices of the dropped copies. The
        inputs themselves when no copy was found.

    Notes
    -----
    Candidates are the closed components (no boundary edge) with the same
    number of vertices and centroids within the tolerance; a candidate is a
    copy of the lowest-numbered such component when each of its vertices has
    one of that component's vertices within the tolerance, whatever the order
    of the vertices and faces and the winding. Only meshes with two closed
    components or more cost more than a look at their component sizes.
    """
    return _closed_copies(vertices, topology, tolerance_ratio)[0]


def _closed_copies(
    vertices: np.ndarray, topology: MeshTopology, tolerance_ratio: float = WELD_TOLERANCE_RATIO
) -> tuple[Welding, np.ndarray | None]:
    """:func:`drop_closed_copies`, and the (F,) bool faces of the copies it dropped (None: none dropped)."""
    n_vertices = vertices.shape[0]
    unchanged = Welding(vertices, topology, np.arange(n_vertices), 0), None
    n_components, labels = topology.vertex_components
    if n_components < 2:
        return unchanged
    referenced = labels >= 0
    sizes = np.bincount(labels[referenced], minlength=n_components)
    open_parts = np.zeros(n_components, dtype=bool)
    open_parts[labels[topology.boundary_vertices & referenced]] = True
    repeated_size = np.bincount(sizes[~open_parts], minlength=sizes.max() + 1)[sizes] > 1
    closed = np.flatnonzero(~open_parts & repeated_size & (sizes >= 4))
    if closed.size < 2:
        return unchanged
    # each part within its own tolerance when the parts differ in scale (a small part beside a huge one is
    # no copy of another small part a few of its edges away)
    scales = vertex_length_scales(vertices, topology)
    part_tolerance = np.full(n_components, _tolerance(vertices, topology, tolerance_ratio))
    if scales[referenced].min() < scales[referenced].max():
        part_tolerance[labels[referenced]] = tolerance_ratio * scales[referenced]
    from scipy.spatial import cKDTree  # imported on use: keeps `import meshcurv` fast

    members = referenced & np.isin(labels, closed)
    centroids = (
        np.column_stack([np.bincount(labels[members], vertices[members, k], minlength=n_components) for k in range(3)])[
            closed
        ]
        / sizes[closed, None]
    )
    pairs = cKDTree(centroids).query_pairs(max(float(part_tolerance[closed].max()), 0.0), output_type="ndarray")
    if pairs.size == 0:
        return unchanged
    order = np.argsort(labels, kind="stable")
    starts = np.r_[0, np.cumsum(np.bincount(labels[referenced], minlength=n_components))]
    first = np.sum(~referenced)  # the unreferenced vertices (-1) come first in ``order``
    representative = np.arange(n_vertices)
    copy_of: dict[int, int] = {}
    candidates = np.sort(closed[pairs], axis=1)  # (a, b), a < b, in order: the first part of a group is kept
    for a, b in candidates[np.lexsort((candidates[:, 1], candidates[:, 0]))].tolist():
        if sizes[a] != sizes[b] or b in copy_of:
            continue
        a = copy_of.get(a, a)  # a copy of a copy repeats the first
        part_a = order[first + starts[a] : first + starts[a + 1]]
        part_b = order[first + starts[b] : first + starts[b + 1]]
        distance, nearest = cKDTree(vertices[part_a]).query(vertices[part_b])
        if np.all(distance <= min(part_tolerance[a], part_tolerance[b])) and np.unique(nearest).size == nearest.size:
            representative[part_b] = part_a[nearest]
            copy_of[b] = a
    if not copy_of:
        return unchanged
    kept = representative == np.arange(n_vertices)
    compact = np.cumsum(kept) - 1
    index = compact[representative]
    dropped_faces = np.isin(labels[topology.faces[:, 0]], list(copy_of))
    faces = np.ascontiguousarray(compact[topology.faces[~dropped_faces]])
    welding = Welding(vertices[kept], MeshTopology._build(faces, int(kept.sum())), index, int(n_vertices - kept.sum()))
    return welding, dropped_faces


def _suspect_edges(topology: MeshTopology) -> np.ndarray:
    """(E,) bool: the edges whose faces :func:`drop_double_sided` looks at (its Notes)."""
    return double_sided_suspects(
        topology.faces, topology.edge_faces, topology.edge_face_counts, topology._edge_forward_counts
    )


@twin("topology")
def double_sided_suspects(
    faces: np.ndarray, edge_faces: np.ndarray, counts: np.ndarray, forward: np.ndarray
) -> np.ndarray:
    """(E,) bool: the non-manifold edges (``counts`` > 2), and the interior edges (two faces, ``forward`` 1:
    consistently oriented) whose two faces have the same third corner: a lone triangle's two sides make a
    closed pillow of manifold edges (the same corner sums, as both faces hold the edge's ends)."""
    corner_sums = faces[:, 0] + faces[:, 1] + faces[:, 2]
    pairs = np.maximum(edge_faces, 0)  # both >= 0 on an interior edge
    pillow = (counts == 2) & (forward == 1) & (corner_sums[pairs[:, 0]] == corner_sums[pairs[:, 1]])
    return (counts > 2) | pillow
