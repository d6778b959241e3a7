"""Consistent, outward face orientation.

A face is *reversed* by swapping its last two corners, ``(a, b, c) -> (a, c, b)``,
which turns its normal around and keeps its first corner. Two faces sharing a
manifold edge (exactly two faces) are consistently oriented when they run that
edge in opposite directions.

The algorithm is a two-colouring of the face-adjacency graph, done without a
loop over faces: every face ``f`` gets two nodes, ``(f, kept)`` and
``(f, reversed)``; a consistent edge links ``(f, kept)`` to ``(g, kept)`` and
``(f, reversed)`` to ``(g, reversed)``, an inconsistent one links
``(f, kept)`` to ``(g, reversed)`` and the other way round. The connected
components of this doubled graph (:func:`scipy.sparse.csgraph.connected_components`)
are the consistent orientations of each patch: an orientable patch gives two
mirror components, one of which is chosen per patch; a non-orientable patch
(a Moebius band) gives a single component in which ``(f, kept)`` and
``(f, reversed)`` meet, and is left as given.
"""

from __future__ import annotations

import numpy as np

from ._backend import twin
from ._validation import as_vertices
from .errors import InvalidOptionError
from .defects import _needle_vertices
from ._geometry import vertex_length_scales
from .topology import MeshTopology, as_topology

__all__ = ["orient_faces", "ORIENT_CHOICES"]

#: The values of ``orient=`` in :func:`meshcurv.principal_curvatures`.
ORIENT_CHOICES = ("auto", "outward", "consistent", "keep")


def orient_faces(vertices, faces, *, outward: bool = True) -> tuple[np.ndarray, int]:
    """Reverse faces so that orientation is consistent within each patch, and outward on closed ones.

    Parameters
    ----------
    vertices : array_like of shape (V, 3)
        Vertex coordinates (used only to decide which side is outward).
    faces : array_like of shape (F, 3), or MeshTopology
        0-based triangles (polygons are fan-triangulated with a warning).
    outward : bool, default: True
        Turn every closed patch so that its signed volume is positive (normals
        outward). With ``outward=False``, and on open patches in any case, the
        orientation of the majority of a patch's faces is kept (the fewest
        faces are reversed).

    Returns
    -------
    faces : ndarray of shape (F, 3), int64
        A new array: the same faces in the same order, some with their last two
        corners swapped.
    n_flipped : int
        Number of faces reversed.

    Notes
    -----
    A *patch* is a set of faces connected through manifold edges (edges with
    exactly two faces); non-manifold edges (three or more faces) and boundary
    edges separate patches, and faces with a repeated corner are never
    reversed. A patch is *closed* when none of its faces has a boundary edge;
    its signed volume is taken about the mean of its faces' first corners. *Outward*
    means out of the material: a closed patch inside an odd number of other
    closed patches bounds a cavity (a hollow ball's inner wall, a nucleus
    counted as a hole) and faces into it (negative volume); nesting is decided
    by the winding number of the enclosing patches at one corner. A closed
    patch whose volume is within rounding of zero (a double-sided sheet) keeps
    its majority orientation. Non-orientable patches are left as given: some of
    their edges stay inconsistently oriented.

    The cost is one :func:`~scipy.sparse.csgraph.connected_components` call on
    a graph of ``2 F`` nodes and about ``3 F`` links (none when the mesh is
    manifold and consistently wound already), and a few passes over the
    faces; there is no Python loop over faces or edges, and a loop over pairs
    of closed patches only where one's bounding box holds a corner of the other.

    Examples
    --------
    Reverse half of the faces of a sphere; orientation comes back outward:

    >>> import numpy as np
    >>> from meshcurv import shapes
    >>> from meshcurv.orient import orient_faces
    >>> sphere = shapes.icosphere(4)
    >>> faces = sphere.faces.copy()
    >>> faces[::2] = faces[::2, [0, 2, 1]]
    >>> fixed, n_flipped = orient_faces(sphere.vertices, faces)
    >>> n_flipped, bool((fixed == sphere.faces).all())
    (160, True)
    """
    if not isinstance(outward, (bool, np.bool_)):
        raise InvalidOptionError(f"`outward` must be True or False; got {outward!r}")
    points = as_vertices(vertices)
    topology = as_topology(faces, points.shape[0])
    flip = face_flips(points, topology, outward=outward)
    oriented = np.array(topology.faces, dtype=np.int64, copy=True)
    oriented[flip] = oriented[flip][:, [0, 2, 1]]
    return oriented, int(flip.sum())


def face_flips(
    vertices: np.ndarray, topology: MeshTopology, *, outward: bool = True, needles: np.ndarray | None = None
) -> np.ndarray:
    """(F,) bool: the faces :func:`orient_faces` reverses (validated inputs, no copy of the faces); ``needles``:
    the (V,) needle vertices when known (:func:`meshcurv.defects.needle_vertices`, found here otherwise)."""
    n_faces = topology.n_faces
    counts = topology.edge_face_counts
    pairs = topology.edge_faces
    proper = ~topology.degenerate_faces
    if not proper.any():  # every face has a repeated corner: nothing to orient
        return proper
    if (
        proper.all()
        and not (counts > 2).any()
        and not topology.inconsistent_edges.any()
        and not topology.bowtie_vertices.any()
    ):
        # consistently wound already, and the patches are the components through shared vertices
        # (faces that share only a vertex would make it a bow-tie): no graph of face sides needed,
        # only each closed patch's side (a fifth of the time at a million vertices)
        flip = np.zeros(n_faces, dtype=bool)
        if not outward:
            return flip
        n_labels, vertex_labels = topology.vertex_components
        if n_labels == 1:  # one patch: labels of zeros never written (calloc's pages), a flag for every face
            patch = np.zeros(n_faces, dtype=np.int64)
            return np.full(n_faces, _outward(vertices, topology, patch, flip, np.zeros(1, dtype=bool), 1, needles)[0])
        patch = vertex_labels[topology.faces[:, 0]]
        invert = _outward(vertices, topology, patch, flip, np.zeros(n_labels, dtype=bool), n_labels, needles)
        return invert[patch]
    linked = (counts == 2) & (pairs[:, 0] != pairs[:, 1])
    linked &= proper[np.maximum(pairs[:, 0], 0)] & proper[np.maximum(pairs[:, 1], 0)]
    f, g = pairs[linked, 0], pairs[linked, 1]
    crossed = topology.inconsistent_edges[linked].astype(np.int64)
    # (f, s) is node f + s * F; a consistent edge keeps s, an inconsistent one swaps it
    rows = np.concatenate([f, f + n_faces])
    cols = np.concatenate([g + crossed * n_faces, g + (1 - crossed) * n_faces])
    import scipy.sparse as sp  # imported on use: keeps `import meshcurv` fast
    from scipy.sparse.csgraph import connected_components

    graph = sp.csr_matrix((np.ones(rows.size, dtype=np.int8), (rows, cols)), shape=(2 * n_faces, 2 * n_faces))
    _, labels = connected_components(graph, directed=False)
    kept, reversed_ = labels[:n_faces], labels[n_faces:]
    orientable = kept != reversed_
    # one of the two mirror components per patch: the one with the smaller label is "as given"
    flip = orientable & (kept > reversed_)
    patch = np.minimum(kept, reversed_)
    n_labels = int(labels.max()) + 1 if labels.size else 0
    size = np.bincount(patch, minlength=n_labels)
    flipped = np.bincount(patch, weights=flip, minlength=n_labels)
    invert = 2 * flipped > size  # keep the majority orientation
    if outward:
        invert = _outward(vertices, topology, patch, flip, invert, n_labels, needles)
    flip ^= invert[patch] & orientable
    return flip & proper


def _outward(vertices, topology, patch, flip, invert, n_labels, needles) -> np.ndarray:
    """Patch inversions that make every closed patch face out of the solid it bounds.

    A closed patch gets positive signed volume (normals away from what it
    encloses), unless it lies inside an odd number of other closed patches:
    then it bounds a cavity of the solid around it, and its normals must face
    into the cavity (negative volume), out of the material.
    """
    faces = topology.faces
    if topology.boundary_edges.any():
        on_boundary = topology.boundary_edges[np.maximum(topology.face_edges, 0)] & (topology.face_edges >= 0)
        open_patch = np.bincount(patch, weights=on_boundary.any(axis=1), minlength=n_labels) > 0
    else:
        open_patch = np.zeros(n_labels, dtype=bool)

    # a needle's slivers bound no solid (issue 29: a uv sphere's vertex flung 30 sizes inward turned it inside out)
    if needles is None:
        needles = _needle_vertices(vertices, topology, vertex_length_scales(vertices, topology))
    kept = ~needles[faces].any(axis=1) if needles.any() else slice(None)
    signed, magnitude = _patch_volumes(vertices, faces[kept], patch[kept], flip[kept], n_labels)
    decided = ~open_patch & (np.abs(signed) > 1e-9 * magnitude)
    inverted = np.where(decided, signed < 0, invert)
    cavity = _nesting_depth(vertices, faces, patch, decided) % 2 == 1
    return np.where(decided & cavity, ~inverted, inverted)


def _patch_volumes(
    vertices: np.ndarray, faces: np.ndarray, patch: np.ndarray, flip: np.ndarray, n_labels: int
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`patch_volumes` of the arrays of :func:`face_flips` (csgraph's labels are int32)."""
    patch = np.ascontiguousarray(patch, dtype=np.int64)
    return patch_volumes(vertices, faces, patch, np.ascontiguousarray(flip, dtype=bool), int(n_labels))


@twin("orient")
def patch_volumes(
    vertices: np.ndarray, faces: np.ndarray, patch: np.ndarray, flip: np.ndarray, n_labels: int
) -> tuple[np.ndarray, np.ndarray]:
    """(P,) signed and (P,) absolute sums of six times the volume of each patch's faces.

    A face's volume is that of the tetrahedron of its corners and the mean of
    its patch's faces' first corners (a point near the patch: no cancellation
    between far-off coordinates); a face to ``flip`` counts reversed. The
    inputs are checked arrays: ``patch`` (F,) int64 in ``[0, n_labels)``,
    ``flip`` (F,) bool, both C-contiguous.
    """
    first = vertices[faces[:, 0]]
    weight = np.maximum(np.bincount(patch, minlength=n_labels), 1).astype(np.float64)
    centre = (
        np.stack([np.bincount(patch, weights=first[:, k], minlength=n_labels) for k in range(3)], axis=1)
        / weight[:, None]
    )
    a = first - centre[patch]
    b = vertices[faces[:, 1]] - centre[patch]
    c = vertices[faces[:, 2]] - centre[patch]
    volume6 = np.einsum("ij,ij->i", a, np.cross(b, c))
    signed = np.bincount(patch, weights=np.where(flip, -volume6, volume6), minlength=n_labels)
    return signed, np.bincount(patch, weights=np.abs(volume6), minlength=n_labels)


def _nesting_depth(vertices, faces, patch, closed) -> np.ndarray:
    """(patches,) how many other closed patches enclose each closed patch (0 for the others).

    One corner of each closed patch is tested against every other closed patch
    whose bounding box holds it, by the winding number of that patch (the sum
    of the solid angles of its faces, Van Oosterom and Strackee 1983): about 1
    inside, 0 outside. A corner within 1e-6 of the other patch's size from one
    of its corners (a part stored twice, its copy coincident) is inside
    neither. The loop runs over these (patch, patch) candidates only, none on
    a mesh with one closed part.
    """
    depth = np.zeros(closed.shape[0], dtype=np.int64)
    ids = np.flatnonzero(closed)
    if ids.size < 2:
        return depth
    face_closed = closed[patch]
    corners = vertices[faces[face_closed]]  # (F', 3, 3)
    owner = patch[face_closed]
    order = np.argsort(owner, kind="stable")
    corners, owner = corners[order], owner[order]
    starts = np.searchsorted(owner, ids)
    ends = np.searchsorted(owner, ids, side="right")
    lower = np.minimum.reduceat(corners.min(axis=1), starts)
    upper = np.maximum.reduceat(corners.max(axis=1), starts)
    probe = corners[starts, 0]  # a corner of each closed patch
    inside_box = ((probe[:, None, :] >= lower[None]) & (probe[:, None, :] <= upper[None])).all(axis=2)
    np.fill_diagonal(inside_box, False)
    for i, j in zip(*np.nonzero(inside_box)):  # candidate pairs: probe of patch i in the box of patch j
        tri = corners[starts[j] : ends[j]] - probe[i]
        p, q, r = tri[:, 0], tri[:, 1], tri[:, 2]
        lp, lq, lr = (np.linalg.norm(x, axis=1) for x in (p, q, r))
        numerator = np.einsum("ij,ij->i", p, np.cross(q, r))
        denominator = (
            lp * lq * lr
            + np.einsum("ij,ij->i", p, q) * lr
            + np.einsum("ij,ij->i", p, r) * lq
            + np.einsum("ij,ij->i", q, r) * lp
        )
        winding = np.sum(2 * np.arctan2(numerator, denominator)) / (4 * np.pi)
        # a probe on a corner of patch j (a part stored twice) is on its surface, inside neither
        touching = np.min(np.minimum(np.minimum(lp, lq), lr)) <= 1e-6 * np.linalg.norm(upper[j] - lower[j])
        depth[ids[i]] += (abs(winding) > 0.5) and not touching
    return depth


def oriented_topology(
    vertices: np.ndarray, topology: MeshTopology, orient: str, needles: np.ndarray | None = None
) -> tuple[MeshTopology, int]:
    """Apply ``orient=`` of :func:`meshcurv.principal_curvatures`: ``(topology, n_flipped)``.

    ``'keep'`` returns ``topology`` untouched; otherwise the reversed faces get
    a new topology (the given one is returned when nothing had to change).
    ``orient`` is one of :data:`ORIENT_CHOICES`, checked by the caller
    (:func:`meshcurv._prepared.prepare_mesh`); ``needles`` as for :func:`face_flips`.
    """
    if orient in ("keep", "auto"):  # 'auto' is resolved by the caller, which knows the method
        return topology, 0
    flip = face_flips(vertices, topology, outward=orient == "outward", needles=needles)
    n_flipped = int(flip.sum())
    if n_flipped == 0:
        return topology, 0
    faces = np.array(topology.faces, dtype=np.int64, copy=True)
    faces[flip] = faces[flip][:, [0, 2, 1]]
    return MeshTopology._build(faces, topology.n_vertices), n_flipped
