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

from typing import NamedTuple

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
        outward), and every nearly closed one (small holes: see Notes). With
        ``outward=False``, and on wide open patches (a hemisphere, a saddle, a
        tube as long as it is wide) in any case, the orientation of the majority
        of a patch's faces is kept (the fewest faces are reversed).

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
    by the winding number of the enclosing patches at all of its vertices. A closed
    patch whose volume is within rounding of zero (a double-sided sheet) keeps
    its majority orientation. Non-orientable patches are left as given: some of
    their edges stay inconsistently oriented.

    An open patch is closed for the purpose by a fan over each of its boundary
    loops (holes meeting at a vertex are told apart by the order of their edges
    around it) and turned outward like a closed one when that volume is more
    than :data:`FILLED_MARGIN` times what the fans could be wrong by (a half
    ball on a disc of each loop's area, the length of the sum of its fan's area
    vectors: a long branched hole's fan folds over itself and cancels): a
    sphere or torus with small holes is turned outward whichever way it was
    wound; a hemisphere (its volume is the bound) keeps its majority. Pieces
    that are not decided on their own take the side of decided patches whose
    face normals they follow at shared vertices; pieces that touch only each
    other (a sphere with half of its faces removed) are oriented from their
    largest and decided together, as one patch. Pieces still undecided near
    decided ones (faces detached into the holes of a decided piece) take the
    side the decided faces' winding number gives them: larger behind a face
    than in front of it. The rest (half of a sphere's faces detached, no piece
    decided: isolated faces and pieces whose holes are too wide) take the side
    where the winding number of the undecided faces themselves, as oriented, is
    positive, when it clearly is and they enclose something (their area vectors
    nearly cancel); a piece that is wide open on its own (a hemisphere, a tube)
    keeps its majority.
    These winding numbers are the fast ones of Barill et al. (2018): a tree of
    the undecided faces, whose nodes count by their expansions (to third order)
    where the query is more than :data:`WINDING_BETA` times a node's radius
    away, and the faces' exact solid angles nearer: ``O(F log F)``.

    The cost is one :func:`~scipy.sparse.csgraph.connected_components` call on
    a graph of ``2 F`` nodes and about ``3 F`` links (none when the mesh is
    manifold and consistently wound already), and a few passes over the
    faces; there is no Python loop over faces or edges, and a loop over pairs
    of closed patches only where one's bounding box holds a corner of the other.
    Open patches add a few passes over the faces and a sort of their boundary
    edges, and a breadth-first walk over the patches that share vertices
    where pieces take their side from their neighbours; the fast winding
    numbers, a sort of the undecided faces per level of their tree and a walk
    of it per undecided face (about 5 CPU s for half a million).

    References
    ----------
    Barill, G., Dickson, N. G., Schmidt, R., Levin, D. I. W., Jacobson, A.
    (2018). Fast winding numbers for soups and clouds. ACM Transactions on
    Graphics 37(4), 43. https://doi.org/10.1145/3197517.3201337

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
    if needles.any():
        kept = kept_faces = ~needles[faces].any(axis=1)
    else:  # (no copy of the arrays for the volumes)
        kept, kept_faces = slice(None), np.ones(faces.shape[0], dtype=bool)
    signed, magnitude = _patch_volumes(vertices, faces[kept], patch[kept], flip[kept], n_labels)
    decided = ~open_patch & (np.abs(signed) > 1e-9 * magnitude)
    if open_patch.any():  # a nearly closed patch (small holes): the side of its volume with the holes filled
        filled, doubt = _filled_volumes(vertices, topology, patch, flip, kept_faces & open_patch[patch], n_labels)
        signed = np.where(open_patch, signed + filled, signed)
        decided |= open_patch & (np.abs(signed) > FILLED_MARGIN * doubt)
    inverted = np.where(decided, signed < 0, invert)
    cavity = _nesting_depth(vertices, faces, patch, decided) % 2 == 1
    inverted = np.where(decided & cavity, ~inverted, inverted)
    pending = open_patch & ~decided
    if pending.any():  # pieces between the holes of a decided patch, or of a surface with half its faces gone
        inverted, settled, group = _sides_of_pieces(
            vertices, topology, patch, flip, inverted, decided, pending, kept_faces
        )
        if (pending & ~settled).any():  # the rest near decided faces: the side their winding number says
            inverted, settled = _sides_by_decided(
                vertices, faces, patch, flip, inverted, settled, pending & ~settled, group, kept_faces
            )
        if (pending & ~settled).any():  # the rest: the side the whole mesh's winding number says, where it is clear
            inverted = _winding_sides(vertices, faces, patch, flip, inverted, pending & ~settled, group, kept_faces)
    return inverted


def _sides_by_decided(vertices, faces, patch, flip, inverted, settled, undecided, group, kept) -> tuple:
    """``(inverted, settled)`` with the ``undecided`` pieces turned to the side the ``settled`` faces give them.

    The winding number ``w`` of the settled faces (``kept``, a face to ``flip`` reversed when its patch is not
    ``inverted``, and the other way round) falls from inside what they bound to outside it; across a hole of
    theirs it falls smoothly. Each undecided face is tested at two points, half of its size ``sqrt(2 area) / 2``
    in front of its centroid and behind it: an outward face has the larger ``w`` behind. A ``group`` (P,) whose
    area-weighted mean of ``w(behind) - w(front)`` is beyond :data:`SIDE_MARGIN` either way is decided (turned
    when negative): a sphere's faces detached into its holes, wound either way. A piece far from the settled faces
    (a separate open surface) sees ``w`` nearly flat and is left to :func:`_winding_sides`. The winding numbers are
    the fast ones of the settled faces (:func:`face_winding_numbers`).
    """
    rows = np.flatnonzero(kept)
    known = settled[patch[rows]]
    asked = undecided[patch[rows]]
    if not known.any() or not asked.any():
        return inverted, settled
    corners, vector, areas = _wound_corners(vertices, faces[rows], flip[rows] ^ inverted[patch[rows]])
    asked &= areas > 0
    if not asked.any():
        return inverted, settled
    centroid = corners[asked].mean(axis=1)
    step = 0.5 * vector[asked] * (np.sqrt(2.0 * areas[asked]) / areas[asked])[:, None]  # half its size along n
    w = _fast_winding_numbers(corners[known], np.concatenate([centroid - step, centroid + step]))
    behind, front = np.split(w, 2)
    owner = group[patch[rows[asked]]]
    n_groups = int(group.max()) + 1
    weight = np.bincount(owner, weights=areas[asked], minlength=n_groups)
    total = np.bincount(owner, weights=areas[asked] * (behind - front), minlength=n_groups)
    score = total / np.maximum(weight, np.finfo(float).tiny)
    sure = (weight > 0) & (np.abs(score) > SIDE_MARGIN)
    turn = sure & (score < 0)
    inverted = np.where(undecided & turn[group], ~inverted, inverted)
    return inverted, settled | (undecided & sure[group])


def _winding_sides(vertices, faces, patch, flip, inverted, undecided, group, kept) -> np.ndarray:
    """``inverted`` with the ``undecided`` pieces turned so that the winding number of these pieces is positive.

    The undecided faces (``kept``, a face to ``flip`` reversed when its patch is not ``inverted``, and the other
    way round) are taken together: when they enclose something (the sum of their area vectors is at most
    :data:`WINDING_OPEN` times their area: a sphere with half of its faces detached, not a hemisphere (a half)
    or a saddle (nearly 1)), their winding number ``w`` at each one's centroid (the others' solid angles) is about
    the share of the sphere they cover over 2, positive when they face out of what they enclose, negative when
    inward. The patches of each ``group`` (P,) (the pieces :func:`_sides_of_pieces` linked, or one patch) whose
    area-weighted mean ``w`` is below ``-``:data:`WINDING_MARGIN` are turned, when the undecided faces are all
    pieces: no patch holds more than :data:`WINDING_PIECE` of their area (a hemisphere or a tube in one patch
    keeps the winding given, its side is the user's choice, and the faces detached from it keep theirs). The decided
    faces are left out of the sums: a sphere's pieces turned outward and its detached faces wound inward would
    cancel. The winding numbers are the fast winding numbers of the undecided faces (:func:`_winding_tree`,
    :func:`face_winding_numbers`): the faces' exact solid angles near each query, a tree's dipoles farther off,
    ``O(F log F)`` for ``F`` undecided faces.
    """
    rows = np.flatnonzero(kept)
    corners, vector, areas = _wound_corners(vertices, faces[rows], flip[rows] ^ inverted[patch[rows]])
    asked = undecided[patch[rows]] & (areas > 0)
    if not asked.any() or np.linalg.norm(vector[asked].sum(axis=0)) > WINDING_OPEN * areas[asked].sum():
        return inverted
    queries = np.flatnonzero(asked)
    w = _fast_winding_numbers(corners[queries])
    n_labels, tiny = inverted.shape[0], np.finfo(float).tiny
    patch_area = np.bincount(patch[rows[queries]], weights=areas[queries], minlength=n_labels)
    n_groups = int(group.max()) + 1
    owner = group[patch[rows[queries]]]
    weight = np.bincount(owner, weights=areas[queries], minlength=n_groups)
    score = np.bincount(owner, weights=areas[queries] * w, minlength=n_groups) / np.maximum(weight, tiny)
    largest = np.zeros(n_groups)
    np.maximum.at(largest, group, patch_area)
    if largest.max() > WINDING_PIECE * areas[queries].sum():  # a wide open patch keeps its winding, and its pieces
        return inverted
    turn = (weight > 0) & (score < -WINDING_MARGIN)
    return np.where(undecided & turn[group], ~inverted, inverted)


def _wound_corners(vertices: np.ndarray, faces: np.ndarray, reversed_: np.ndarray) -> tuple:
    """``(corners, vector, areas)`` of the triangles ``faces`` (S, 3) as they are wound: each one ``reversed_`` (S,)
    taken in the order (0, 2, 1). ``corners`` (S, 3, 3), ``vector`` (S, 3) their area vectors, ``areas`` (S,)."""
    corners = vertices[faces]
    corners = np.where(reversed_[:, None, None], corners[:, [0, 2, 1]], corners)
    vector = 0.5 * np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    return corners, vector, np.linalg.norm(vector, axis=1)


def _fast_winding_numbers(corners: np.ndarray, positions: np.ndarray | None = None) -> np.ndarray:
    """(S,) the generalized winding number of the triangles ``corners`` (S, 3, 3) at each one's centroid, the
    triangle itself left out, or (M,) at ``positions`` (M, 3) when given (:func:`_winding_tree`,
    :func:`face_winding_numbers`).

    The winding number does not change with a shift or a scale: the corners (and positions) are taken about the
    corners' mean, in units of their largest coordinate, so that the solid angles' products stay finite (fuzz_api
    seed 361, case 111: a mesh at 1e75 overflowed in the NumPy twin). A position farther than :data:`WINDING_FAR`
    of those units gets 0 without the tree."""
    origin = corners.reshape(-1, 3).mean(axis=0)
    corners = corners - origin
    extent = float(np.max(np.abs(corners))) if corners.size else 0.0
    if not (extent > 0 and np.isfinite(extent)):
        extent = 1.0
    corners = corners / extent
    tree = _winding_tree(corners)
    given = positions is not None
    if positions is None:
        positions = tree.corners.mean(axis=1)  # (in the tree's order and frame)
        own = np.arange(corners.shape[0], dtype=np.int64)  # each query is the centroid of the face at its place
    else:  # in the tree's frame: about its corners' mean
        with np.errstate(over="ignore"):  # a query beyond float64 in this frame is far: 0 below
            positions = (positions - origin) / extent - corners.reshape(-1, 3).mean(axis=0)
        own = np.full(positions.shape[0], -1, dtype=np.int64)
    near = np.abs(positions).max(axis=1, initial=0.0) <= WINDING_FAR
    w = np.zeros(positions.shape[0])
    w[near] = face_winding_numbers(
        tree.corners,
        tree.centres,
        tree.dipoles,
        tree.moments,
        tree.radii,
        positions[near],
        own[near],
        tree.depth,
        WINDING_BETA,
    )
    if given:
        return w
    result = np.zeros(corners.shape[0])
    result[tree.order] = w
    return result


class _WindingTree(NamedTuple):
    """The tree of :func:`_winding_tree`: ``order`` (S,) the faces in Morton order, ``corners`` (S, 3, 3) theirs in
    that order (about the mean centroid), and per node, level by level (node ``k``'s children ``2 k + 1`` and
    ``2 k + 2``; the ``2**depth`` leaves last, leaf ``i`` the faces ``i S // 2**depth`` to ``(i + 1) S // 2**depth
    - 1``): ``centres`` (K, 3) the area-weighted mean of its faces' centroids, ``dipoles`` (K, 3) the sum of their
    area vectors, ``moments`` (K, 3, 12): in its first 3 columns ``M = sum_j v_j (t_j - c)^T`` of their area
    vectors ``v_j`` and centroids ``t_j`` about the centre ``c``, in the other 9 (column ``3 + 3 a + b``) the
    second moments ``T[:, a, b] = sum_j v_j ((t_j - c)_a (t_j - c)_b + C_j[a, b])`` with ``C_j`` the covariance of
    face ``j``'s points about its centroid (a twelfth of the sum of ``d d^T`` over its corners' offsets ``d`` from
    it), and ``radii`` (K,) a bound on the distance of its faces' corners from the
    centre."""

    order: np.ndarray
    corners: np.ndarray
    centres: np.ndarray
    dipoles: np.ndarray
    moments: np.ndarray
    radii: np.ndarray
    depth: int


def _winding_tree(corners: np.ndarray) -> _WindingTree:
    """The bounding-volume tree of the triangles ``corners`` (S, 3, 3) for :func:`face_winding_numbers`.

    The faces are cut in halves, level by level, down to leaves of at most :data:`WINDING_LEAF` faces, each node's
    faces sorted along the longest side of the box of their centroids first (a median split): a balanced tree whose
    nodes are ranges of the order (no pointers). Each node's sums come from its leaves' (``np.add.reduceat``) and
    its children's; a sort per level, ``O(S log^2 S)``.
    """
    n_faces = corners.shape[0]
    origin = corners.reshape(-1, 3).mean(axis=0)  # coordinates about the middle: no cancellation in the moments
    corners = corners - origin
    centroids = corners.mean(axis=1)
    depth = max(int(np.ceil(np.log2(n_faces / WINDING_LEAF))), 0) if n_faces > WINDING_LEAF else 0
    order = np.arange(n_faces)
    for level in range(depth):  # each node's faces sorted along the longest side of their centroids' box
        starts = np.arange(2**level) * n_faces // 2**level
        node = np.repeat(np.arange(2**level), np.diff(np.append(starts, n_faces)))
        points = centroids[order]
        low = np.minimum.reduceat(points, starts)
        extent = np.maximum.reduceat(points, starts) - low
        axis = np.argmax(extent, axis=1)[node]
        side = np.maximum(extent[node, axis], np.finfo(float).tiny)
        # the node's index plus its share of the side, in [0, 0.5]: the nodes stay in their order
        key = node + 0.5 * np.clip((points[np.arange(n_faces), axis] - low[node, axis]) / side, 0.0, 1.0)
        order = order[np.argsort(key)]
    corners = np.ascontiguousarray(corners[order])
    centroids = centroids[order]
    vectors = 0.5 * np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    areas = np.linalg.norm(vectors, axis=1)
    n_leaves = 2**depth
    starts = np.arange(n_leaves) * n_faces // n_leaves
    area = np.add.reduceat(areas, starts)
    weighted = np.add.reduceat(areas[:, None] * centroids, starts)
    dipole = np.add.reduceat(vectors, starts)
    product = np.add.reduceat(vectors[:, :, None] * centroids[:, None, :], starts)  # sum v_j t_j^T
    # sum v_j (t_j t_j^T + C_j), C_j the covariance of face j's points (a twelfth of its corners' d d^T)
    offsets = corners - centroids[:, None, :]
    spread = (
        centroids[:, :, None] * centroids[:, None, :] + np.einsum("fka,fkb->fab", offsets, offsets) / 12.0
    ).reshape(-1, 9)
    second = np.stack([np.add.reduceat(vectors[:, a, None] * spread, starts) for a in range(3)], axis=1)
    levels: list[list[np.ndarray]] = [[area, weighted, dipole, product, second]]
    for _ in range(depth):  # the parents of the last level made: the sums of their two children
        levels.append([x[0::2] + x[1::2] for x in levels[-1]])
    levels.reverse()  # the root first
    area, weighted, dipole, product, second = (np.concatenate(parts) for parts in zip(*levels))
    centres = weighted / np.maximum(area, np.finfo(float).tiny)[:, None]
    moments = product - dipole[:, :, None] * centres[:, None, :]
    # about the centre: sum v_a (t - c)_b (t - c)_d = second - c_b P_ad - c_d P_ab + c_b c_d N_a (P = product)
    shifted = (
        second.reshape(-1, 3, 3, 3)
        - centres[:, None, :, None] * product[:, :, None, :]
        - centres[:, None, None, :] * product[:, :, :, None]
        + dipole[:, :, None, None] * centres[:, None, :, None] * centres[:, None, None, :]
    )
    moments = np.concatenate([moments, shifted.reshape(-1, 3, 9)], axis=2)
    # radii: the leaves' from their corners; a parent's the smaller of the bounds from its box (the farthest corner
    # of the box of its leaves' corners) and from its children's (their radii plus their centres' distances)
    first_leaf = n_leaves - 1
    leaf_of = np.repeat(np.arange(n_leaves), np.diff(np.append(starts, n_faces)))
    reach = np.linalg.norm(corners - centres[first_leaf + leaf_of][:, None, :], axis=2).max(axis=1)
    radii = np.zeros(centres.shape[0])
    radii[first_leaf:] = np.maximum.reduceat(reach, starts)
    lows = [np.minimum.reduceat(corners.min(axis=1), starts)]
    highs = [np.maximum.reduceat(corners.max(axis=1), starts)]
    for _ in range(depth):
        lows.append(np.minimum(lows[-1][0::2], lows[-1][1::2]))
        highs.append(np.maximum(highs[-1][0::2], highs[-1][1::2]))
    low, high = np.concatenate(lows[::-1]), np.concatenate(highs[::-1])
    boxed = np.sqrt((np.maximum(high - centres, centres - low) ** 2).sum(axis=1))
    for level in range(depth - 1, -1, -1):
        parents = np.arange(2**level - 1, 2 ** (level + 1) - 1)
        children = 2 * parents[:, None] + np.array([1, 2])
        gap = np.linalg.norm(centres[children] - centres[parents][:, None, :], axis=2)
        radii[parents] = np.minimum((radii[children] + gap).max(axis=1), boxed[parents])
    return _WindingTree(order, corners, centres, dipole, np.ascontiguousarray(moments), radii, depth)


@twin("orient")
def face_winding_numbers(
    corners: np.ndarray,
    centres: np.ndarray,
    dipoles: np.ndarray,
    moments: np.ndarray,
    radii: np.ndarray,
    positions: np.ndarray,
    own: np.ndarray,
    depth: int,
    beta: float,
) -> np.ndarray:
    """(M,) the generalized winding number of the triangles ``corners`` (S, 3, 3) at ``positions`` (M, 3).

    ``w(q) = 1 / (4 pi) sum_j Omega_j(q)``, the solid angles of the faces (Barill et al. 2018), the face
    ``own[m]`` (-1: none) left out at ``positions[m]`` (its centroid). The tree (:func:`_winding_tree`: ``centres``,
    ``dipoles``, ``moments``, ``radii`` per node, ``depth``) is walked from its root: a node farther from the query
    than ``beta`` times its radius counts by its expansion to third order (Barill et al.'s three terms), ``N . r /
    |r|^3 + tr(M) / |r|^3 - 3 r . M r / |r|^5 + 15 / 2 T[r, r, r] / |r|^7 - 3 / 2 (2 T_aab r_b + T_abb r_a) / |r|^5``
    (``r`` from the query to its centre, ``N`` its dipole, ``M`` and ``T`` its first and second moments: the
    second order left the winding numbers of a closed sphere's faces at 0.490-0.492 for 1/2); the faces of a leaf that
    is not, exactly: ``Omega = 2 atan2(a . (b x c), |a||b||c| + (a . b)|c| + (a . c)|b| + (b . c)|a|)`` with
    ``a, b, c`` the corners less the query (Van Oosterom and Strackee 1983), 0 for a query in the face's plane
    (``|a . (b x c)|`` at most ``1e-12 |a||b||c|``: on the face, the mean of its two sides). Here level by level,
    the queries in chunks; compiled, a walk per query.
    """
    n_leaves = 2**depth
    n_faces = corners.shape[0]
    first_leaf = n_leaves - 1
    total = np.zeros(positions.shape[0])
    limit = (beta * radii) ** 2
    # (first query of the chunk, queries, their nodes, level): a stack, so that a chunk whose queries are near many
    # nodes (a soup of faces across the whole shape) is halved instead of growing past WINDING_PAIRS pairs
    stack: list[tuple[int, np.ndarray, np.ndarray, int]] = []
    for lo in range(0, positions.shape[0], WINDING_CHUNK)[::-1]:
        query = np.arange(lo, min(lo + WINDING_CHUNK, positions.shape[0]))
        stack.append((lo, query, np.zeros(query.size, dtype=np.int64), 0))
    while stack:
        lo, query, node, level = stack.pop()
        if query.size > WINDING_PAIRS:
            half = query.size // 2
            stack.append((lo, query[half:], node[half:], level))
            stack.append((lo, query[:half], node[:half], level))
            continue
        part = total[lo : lo + WINDING_CHUNK]  # a view: this chunk's sums
        r = centres[node] - positions[query]
        squared = np.einsum("ij,ij->i", r, r)
        far = squared > limit[node]
        rf, mf, qf = r[far], moments[node[far]], squared[far]
        first, second = mf[:, :, :3], mf[:, :, 3:].reshape(-1, 3, 3, 3)
        # |r|^7 leaves float64 where the tree's faces span more than 1e44 of each other's sizes (fuzz_api seed 480,
        # case 75's kind: a spike 1e74 sizes long, the other faces' queries near them): the compiled twin computes the
        # same IEEE values without a word, so here too
        with np.errstate(over="ignore", under="ignore", divide="ignore", invalid="ignore"):
            cubed = qf * np.sqrt(qf)
            term = (
                np.einsum("ij,ij->i", dipoles[node[far]], rf) + np.trace(first, axis1=1, axis2=2)
            ) / cubed - 3.0 * np.einsum("ij,ijk,ik->i", rf, first, rf) / (cubed * qf)
            traces = 2.0 * np.einsum("iaab,ib->i", second, rf) + np.einsum("iabb,ia->i", second, rf)
            cubic = np.einsum("ia,iabc,ib,ic->i", rf, second, rf, rf)
            term += 7.5 * cubic / (cubed * qf * qf) - 1.5 * traces / (cubed * qf)
        part[:] += np.bincount(query[far] - lo, weights=term, minlength=part.size)
        query, node = query[~far], node[~far]
        if level < depth:
            if query.size:
                stack.append((lo, np.repeat(query, 2), (2 * node[:, None] + np.array([1, 2])).ravel(), level + 1))
            continue
        leaf = node - first_leaf
        start, stop = leaf * n_faces // n_leaves, (leaf + 1) * n_faces // n_leaves
        count = stop - start
        query = np.repeat(query, count)
        face = np.repeat(start - np.cumsum(count) + count, count) + np.arange(count.sum())
        counted = face != own[query]
        query, face = query[counted], face[counted]
        numerator, denominator, lengths = _solid_angle_terms(corners[face] - positions[query][:, None, :])
        angle = np.where(
            np.abs(numerator) > 1e-12 * lengths.prod(axis=1), 2.0 * np.arctan2(numerator, denominator), 0.0
        )
        part[:] += np.bincount(query - lo, weights=angle, minlength=part.size)
    return total / (4.0 * np.pi)


def _sides_of_pieces(vertices, topology, patch, flip, inverted, decided, pending, kept) -> tuple[np.ndarray, ...]:
    """``(inverted, settled, group)``: ``inverted`` with the ``pending`` patches (open, undecided on their own) given
    the side of their neighbours, (P,) the patches whose side is decided (by a decided neighbour or their set's
    volume), and (P,) a label per patch: that of its set where the set was grown from a seed, its own otherwise.

    Two patches that share vertices are linked when their face normals there clearly agree or clearly disagree
    (the sum of the dot products of their unit normals at the shared vertices is at least half of the sum of
    the magnitudes): a piece between the holes of a sphere follows its neighbours. The links of a spanning tree
    of the clearest ones (:func:`scipy.sparse.csgraph.minimum_spanning_tree`) are walked from the decided
    patches, whose sides are kept, and from the largest pending patch of each set of linked patches that holds no decided one; each
    such set (the pieces of a sphere with half of its faces removed) is then one patch of
    :func:`_filled_volumes`, turned outward when its volume with the holes filled is decided, as a nearly
    closed patch's is. Patches with no clear link, and sets whose volume is not decided, are left to
    :func:`_winding_sides`.
    """
    import scipy.sparse as sp  # imported on use: keeps `import meshcurv` fast
    from scipy.sparse.csgraph import breadth_first_order, connected_components, minimum_spanning_tree

    faces = topology.faces
    n_vertices, n_labels = np.int64(vertices.shape[0]), inverted.shape[0]
    asked = pending[patch]
    touched = np.zeros(vertices.shape[0], dtype=bool)
    touched[faces[asked]] = True
    rows = np.flatnonzero(asked | (decided[patch] & touched[faces].any(axis=1)))
    corners = vertices[faces[rows]]
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    normal /= np.maximum(np.linalg.norm(normal, axis=1), np.finfo(float).tiny)[:, None]
    normal = np.where((flip[rows] ^ inverted[patch[rows]])[:, None], -normal, normal)
    # nodes: (patch, vertex) with the sum of the patch's unit normals there; links between the patches at a vertex
    nodes, node_of = np.unique(patch[rows].astype(np.int64)[:, None] * n_vertices + faces[rows], return_inverse=True)
    node_of = node_of.reshape(-1)
    sums = np.stack([np.bincount(node_of, np.repeat(normal[:, j], 3), nodes.size) for j in range(3)], axis=1)
    owner, vertex = nodes // n_vertices, nodes % n_vertices
    order = np.lexsort((owner, vertex))
    # every pair of patches at a vertex where up to PAIRED_PATCHES meet (the next ones in order elsewhere)
    one = np.concatenate([order[:-step] for step in range(1, PAIRED_PATCHES)])
    two = np.concatenate([order[step:] for step in range(1, PAIRED_PATCHES)])
    same = vertex[one] == vertex[two]
    one, two = one[same], two[same]
    pair, pair_of = np.unique(owner[one] * n_labels + owner[two], return_inverse=True)
    score = np.bincount(pair_of, np.einsum("ij,ij->i", sums[one], sums[two]), pair.size)
    scale = np.bincount(pair_of, np.linalg.norm(sums[one], axis=1) * np.linalg.norm(sums[two], axis=1), pair.size)
    # rounded: a lattice's exact ratios (a half, at right angles) decided alike after any scaling, not by round-off
    ratio = np.round(np.abs(score) / np.maximum(scale, np.finfo(float).tiny), 9)
    clear = (ratio >= 0.5) & (scale > 0)
    first, second = pair[clear] // n_labels, pair[clear] % n_labels
    against = (score[clear] < 0).astype(np.int8) + 1  # 1: the same side, 2: opposite sides
    linked = sp.csr_matrix((against, (first, second)), shape=(n_labels, n_labels))
    n_sets, set_of = connected_components(linked, directed=False)
    # the roots: every decided patch, and the largest pending patch of each set with no decided patch
    has_decided = np.bincount(set_of, weights=decided, minlength=n_sets) > 0
    size = np.bincount(patch, minlength=n_labels)
    members = np.flatnonzero(pending & ~has_decided[set_of])
    seeds = members[np.lexsort((size[members], set_of[members]))]
    if seeds.size:
        seeds = seeds[np.r_[set_of[seeds][1:] != set_of[seeds][:-1], True]]  # the last (largest) of each set
    roots = np.flatnonzero(decided & has_decided[set_of])
    roots = np.concatenate([roots, seeds])
    root = n_labels  # one more node, joined to the roots
    ends = (np.r_[first, np.full(roots.size, root)], np.r_[second, roots])
    shape = (n_labels + 1, n_labels + 1)
    graph = sp.csr_matrix((np.r_[against, np.ones(roots.size, dtype=np.int8)], ends), shape=shape)
    graph = (graph + graph.T).tocsr()  # both directions (a pair is listed once)
    # the clearest links first: a spanning tree of the least doubt (the roots' links cheapest), walked from the root
    doubt = np.r_[1.5 - ratio[clear], np.full(roots.size, 0.1)]
    tree = minimum_spanning_tree(sp.csr_matrix((doubt, ends), shape=shape))
    reached, parent = breadth_first_order(tree, root, directed=False, return_predecessors=True)
    # the side of each reached patch relative to its root: the parity of the opposite links on its way there
    parent = np.where(parent < 0, np.arange(n_labels + 1), parent)
    turned = np.zeros(n_labels + 1, dtype=bool)
    step = reached[reached != root]
    turned[step] = np.asarray(graph[parent[step], step]).reshape(-1) == 2
    for _ in range(int(np.ceil(np.log2(n_labels + 2))) + 1):  # pointer doubling: each pass doubles the reach
        turned ^= turned[parent]
        parent = parent[parent]
    joined = np.zeros(n_labels + 1, dtype=bool)
    joined[step] = True
    joined = joined[:n_labels] & pending
    inverted = np.where(joined, inverted ^ turned[:n_labels], inverted)
    # the sets grown from a seed: one patch each, turned outward when its volume with the holes filled is decided
    grown = joined & ~has_decided[set_of]
    settled = decided | (joined & has_decided[set_of])
    group = np.where(grown, set_of, n_sets + np.arange(n_labels))  # the sets grown from a seed, the other patches
    if not grown.any():
        return inverted, settled, group
    label = np.where(grown, set_of, n_sets)[patch]  # the others: one label past the sets, not counted
    counted = kept & grown[patch]
    wound = flip ^ inverted[patch]
    signed, _ = _patch_volumes(vertices, faces[counted], label[counted], wound[counted], n_sets + 1)
    filled, doubt = _filled_volumes(vertices, topology, label, wound, counted, n_sets + 1)
    total = (signed + filled)[:n_sets]
    sure = np.abs(total) > FILLED_MARGIN * doubt[:n_sets]
    turn = sure & (total < 0)
    return np.where(grown & turn[set_of], ~inverted, inverted), settled | (grown & sure[set_of]), group


#: :func:`_sides_of_pieces` links every two of the patches at a vertex where at most this many meet.
PAIRED_PATCHES = 5

#: Angles about a vertex closer than this (radians) are ties (:func:`_next_boundary_edges`).
ANGLE_TIE = 1e-9

#: Two directions along no edge of a lattice (irrational ratios), from which :func:`_next_boundary_edges` measures
#: angles: the first, or the second where the vertex's normal is near the first.
SLANTED = np.array([[np.sqrt(2.0), np.sqrt(3.0), np.sqrt(5.0)], [np.sqrt(7.0), -np.sqrt(11.0), np.sqrt(13.0)]])
SLANTED /= np.linalg.norm(SLANTED, axis=1)[:, None]

#: An open patch is turned outward when its volume with the holes filled is more than this many times the
#: volume its fills could be wrong by (:func:`_filled_volumes`): a sphere with a few small holes is, a hemisphere
#: (its volume is a third of the bound) or a saddle is not, and keeps its majority orientation.
FILLED_MARGIN = 2.0

#: :func:`_winding_sides` turns an undecided patch whose faces' mean winding number (of the rest of the mesh) is
#: below minus this: a sphere with half of its faces removed or detached and wound inward has about -0.25.
WINDING_MARGIN = 0.1

#: :func:`_sides_by_decided` decides a piece when the mean difference of the settled faces' winding numbers behind
#: and in front of its faces is beyond this: the faces of the wide-crack draws (benchmarks/cracked_orient.py, half of
#: the faces detached) read 0.42 at the median, more than 0.2 in 99% of the pieces; a piece three radii from a
#: sphere (tests/test_orient_cracked_O20.py), 0.0003.
SIDE_MARGIN = 0.1

#: :func:`_winding_sides` turns only pieces: nothing when an undecided patch holds more than this share of the
#: undecided area (the pieces of a sphere with half of its faces gone are turned; a hemisphere or a tube is not).
WINDING_PIECE = 0.25

#: :func:`face_winding_numbers` counts a node of the tree by its expansion when the query is farther from its centre
#: than this many times its radius (Barill et al. 2018's ``beta``). With the expansion's third term, 2 is closer to
#: the exact sums than 3 was without it (a closed sphere's faces: 1/2 within 0.003 against 0.009, mean -0.001
#: against -0.006) and faster (benchmarks/orient_winding.md).
WINDING_BETA = 2.0

#: :func:`_winding_tree` cuts the faces in halves down to leaves of at most this many faces.
WINDING_LEAF = 8

#: The NumPy :func:`face_winding_numbers` walks the tree for this many queries at a time (its arrays are about a few
#: hundred faces and nodes per query) ...
WINDING_CHUNK = 2048

#: ... and halves a chunk's (query, node) pairs of one level beyond this many, so that its memory stays bounded
#: where each query is near most nodes (fuzz_api seed 366, case 5935: a voxel sphere's faces as a soup of random
#: faces, out of memory under 800 MiB).
WINDING_PAIRS = 65536

#: :func:`_fast_winding_numbers` gives 0 without the tree at a query farther than this from the faces' mean, in units
#: of their largest coordinate: there ``|w|`` is below their area over ``4 pi (1e6 - sqrt 3)^2`` (about 1e-13 of it),
#: and the expansion's ``|r|^7`` overflowed (fuzz_api seed 480, case 75: a closed part's vertex 1e45 sizes from the
#: part enclosing it, a RuntimeWarning of the NumPy twin).
WINDING_FAR = 1e6

#: :func:`_winding_sides` turns nothing when the undecided faces' summed area vectors exceed this share of their
#: area (they enclose nothing: a hemisphere has a half, a saddle nearly 1; a sphere with holes nearly 0).
WINDING_OPEN = 0.25

#: The volume of a half ball on a disc of area 1: ``2 / (3 sqrt(pi))``.
BULGE = 2.0 / (3.0 * np.sqrt(np.pi))


def _filled_volumes(
    vertices: np.ndarray, topology: MeshTopology, patch: np.ndarray, flip: np.ndarray, counted: np.ndarray, n_labels
) -> tuple[np.ndarray, np.ndarray]:
    """(P,) six times the volume of the fills that close each patch's holes, and (P,) six times their doubt.

    The boundary of the ``counted`` faces of each patch, oriented as in :func:`_patch_volumes` (a face to
    ``flip`` reversed), is split into loops (its edges joined through their ends), and each loop is closed by a
    fan to the mean of its vertices, each fan triangle running the loop's edge backwards: the patch and its fans
    bound a solid, whose volume (that of :func:`_patch_volumes` plus the fans', about the same centre) no longer
    depends on the centre, as for a closed patch (a torus's centre is outside its solid). A fan is a guess of
    the missing surface: it could bulge by up to its loop's radius, so the doubt is the sum over the loops of a
    half ball on a disc of the loop's area, the length of the sum of its fan triangles' area vectors (which does
    not depend on the apex). The sum of their areas would not do: the fan of a long branched hole (the holes of
    half of a sphere's faces detached, many of the cracks welded back) sweeps over the faces between its
    branches both ways, and a voxel sphere of radius 6 was left undecided with a doubt six times its volume
    (issue 29). A sphere with small holes is decided many times over; a hemisphere (fan area pi r^2, radius r,
    volume 2/3 pi r^3) is not. Arrays over the boundary only, no loop over faces.
    """
    faces, face_edges = topology.faces, topology.face_edges
    # an edge is inside a patch when it joins exactly two counted faces of that patch (their sides cancel)
    one, two = topology.edge_faces[:, 0], topology.edge_faces[:, 1]
    inner = (topology.edge_face_counts == 2) & (one >= 0) & (two >= 0) & (one != two)
    one, two = np.maximum(one, 0), np.maximum(two, 0)
    inner &= (patch[one] == patch[two]) & counted[one] & counted[two]
    rows, sides = np.nonzero(counted[:, None] & (face_edges >= 0) & ~inner[np.maximum(face_edges, 0)])
    empty = np.zeros(n_labels)
    if rows.size == 0:
        return empty, empty
    start, end = faces[rows, sides], faces[rows, (sides + 1) % 3]
    reversed_ = flip[rows]
    tail, head = np.where(reversed_, end, start), np.where(reversed_, start, end)
    owner = patch[rows].astype(np.int64)
    n_edges = topology.edges.shape[0]
    # sides of one edge in one patch cancel when they run it both ways: the net count per (patch, edge)
    _, first, inverse = np.unique(owner * n_edges + face_edges[rows, sides], return_index=True, return_inverse=True)
    net = np.bincount(inverse, weights=np.where(tail < head, 1.0, -1.0))
    low, high = np.minimum(tail, head)[first], np.maximum(tail, head)[first]
    remaining = net != 0
    times = np.abs(net[remaining])
    tail = np.where(net > 0, low, high)[remaining]
    head = np.where(net > 0, high, low)[remaining]
    owner = owner[first][remaining]
    if tail.size == 0:
        return empty, empty
    # loops: each boundary edge followed by the one leaving its head into the same hole
    import scipy.sparse as sp  # imported on use: keeps `import meshcurv` fast
    from scipy.sparse.csgraph import connected_components

    successor = _next_boundary_edges(vertices, faces, patch, flip, counted, tail, head, owner)
    m = tail.size
    graph = sp.csr_matrix((np.ones(m, dtype=np.int8), (np.arange(m), successor)), shape=(m, m))
    n_loops, loop = connected_components(graph, directed=False)
    node_count = np.maximum(np.bincount(loop, minlength=n_loops), 1)
    apex = np.stack([np.bincount(loop, vertices[tail, k], n_loops) for k in range(3)], axis=1) / node_count[:, None]
    # each patch's centre as in _patch_volumes: the mean of its counted faces' first corners
    counted_first = vertices[faces[counted, 0]]
    counted_patch = patch[counted]
    weight = np.maximum(np.bincount(counted_patch, minlength=n_labels), 1).astype(np.float64)
    centre = np.stack([np.bincount(counted_patch, counted_first[:, k], n_labels) for k in range(3)], axis=1)
    centre = (centre / weight[:, None])[owner]
    a, b, c = vertices[head] - centre, vertices[tail] - centre, apex[loop] - centre  # the fan runs head -> tail
    volume6 = np.einsum("ij,ij->i", a, np.cross(b, c)) * times
    vector = 0.5 * np.cross(vertices[tail] - apex[loop], vertices[head] - apex[loop]) * times[:, None]
    loop_owner = np.zeros(n_loops, dtype=np.int64)
    loop_owner[loop] = owner
    area = np.linalg.norm(np.stack([np.bincount(loop, vector[:, k], n_loops) for k in range(3)], axis=1), axis=1)
    bulge = BULGE * area**1.5  # a half ball on a disc of the fan's area
    doubt = np.bincount(loop_owner, weights=6.0 * bulge, minlength=n_labels)
    return np.bincount(owner, weights=volume6, minlength=n_labels), doubt


def _next_boundary_edges(vertices, faces, patch, flip, counted, tail, head, owner) -> np.ndarray:
    """(B,) for each boundary edge ``tail -> head`` of :func:`_filled_volumes`, the boundary edge of the same
    patch that leaves ``head`` into the same hole.

    Where one edge of the patch leaves ``head`` it is that one. Where several do (holes meeting at a vertex: the
    patch's faces around it form several fans), the edges at the vertex are ordered by their angle about the
    vertex's normal (the sum of the patch's face normals there): a fan runs counter-clockwise from an edge
    leaving the vertex to one arriving at it, and the hole after the arriving edge ends at the next edge
    counter-clockwise, one leaving into the next fan.
    """
    n_vertices = np.int64(vertices.shape[0])
    out_key = owner * n_vertices + tail
    in_key = owner * n_vertices + head
    order = np.argsort(out_key, kind="stable")
    lo = np.searchsorted(out_key[order], in_key)
    hi = np.searchsorted(out_key[order], in_key, side="right")
    successor = order[np.minimum(lo, order.size - 1)]
    successor = np.where(hi > lo, successor, np.arange(tail.size))  # no edge leaves (never on a boundary chain)
    crowded = np.unique(in_key[hi - lo > 1])
    if crowded.size == 0:
        return successor
    # the patch's normal at each crowded vertex: the sum of its counted faces' normals there
    at_crowded = np.zeros(vertices.shape[0], dtype=bool)
    at_crowded[crowded % n_vertices] = True
    near = counted & at_crowded[faces].any(axis=1)
    corners = faces[near]
    corner_keys = patch[near].astype(np.int64)[:, None] * n_vertices + corners
    normal = np.cross(
        vertices[corners[:, 1]] - vertices[corners[:, 0]], vertices[corners[:, 2]] - vertices[corners[:, 0]]
    )
    normal = np.where(flip[near][:, None], -normal, normal)
    at = np.searchsorted(crowded, corner_keys)
    hit = crowded[np.minimum(at, crowded.size - 1)] == corner_keys
    rows, _ = np.nonzero(hit)
    normals = np.zeros((crowded.size, 3))
    np.add.at(normals, at[hit], normal[rows])
    magnitudes = np.bincount(at[hit], np.linalg.norm(normal[rows], axis=1), crowded.size)
    # the edges at each crowded vertex: leaving (towards their head) and arriving (towards their tail)
    leaving = np.flatnonzero(np.isin(out_key, crowded))
    arriving = np.flatnonzero(np.isin(in_key, crowded))
    node = np.concatenate([np.searchsorted(crowded, out_key[leaving]), np.searchsorted(crowded, in_key[arriving])])
    centre = vertices[np.concatenate([tail[leaving], head[arriving]])]
    direction = vertices[np.concatenate([head[leaving], tail[arriving]])] - centre
    n = normals[node] / np.maximum(np.linalg.norm(normals[node], axis=1), np.finfo(float).tiny)[:, None]
    # the angles start from a direction along no lattice edge (the cut of (-pi, pi] on no edge)
    axis = np.where((np.abs(n @ SLANTED[0]) < 0.9 * np.linalg.norm(n, axis=1))[:, None], SLANTED[0], SLANTED[1])
    u = np.cross(n, axis)
    u /= np.maximum(np.linalg.norm(u, axis=1), np.finfo(float).tiny)[:, None]
    w = np.cross(n, u)
    angle = np.arctan2(np.einsum("ij,ij->i", direction, w), np.einsum("ij,ij->i", direction, u))
    # ties (a lattice's right angles) and a normal lost in round-off (fans facing apart) ordered by the other
    # vertex, not by round-off: the same loops after any scaling or motion of the mesh
    unsure = np.linalg.norm(normals, axis=1) <= 1e-6 * magnitudes
    angle = np.where(unsure[node], 0.0, np.round(angle / ANGLE_TIE))
    other = np.concatenate([head[leaving], tail[arriving]])
    edge = np.concatenate([leaving, arriving])
    is_leaving = np.arange(edge.size) < leaving.size
    ring = np.lexsort((other, angle, node))
    node, edge, is_leaving = node[ring], edge[ring], is_leaving[ring]
    first = np.searchsorted(node, node)  # the start of each vertex's run
    last = np.searchsorted(node, node, side="right") - 1
    following = np.where(np.arange(node.size) == last, first, np.arange(node.size) + 1)  # cyclically next
    pick = ~is_leaving & is_leaving[following]
    successor[edge[pick]] = edge[following[pick]]
    return successor


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


#: A closed patch is nested in another (a cavity's wall when their number is odd) when more than this share of its
#: vertices lie inside the other (winding number beyond 1/2): a cavity has all of them inside; a part that crosses
#: the other's surface (ogre.obj's small closed parts through its body, issue 29, fuzz round 23: one corner decided
#: and the vertex order picked the corner, 17 of 18 parts inside out after a permutation) is not nested, outward.
NESTED_SHARE = 0.9


def _nesting_depth(vertices, faces, patch, closed) -> np.ndarray:
    """(patches,) how many other closed patches enclose each closed patch (0 for the others).

    Every vertex of each closed patch whose bounding box meets that of another closed patch is tested against the
    other by its winding number (:func:`_fast_winding_numbers`, the solid angles of its faces): about 1 inside, 0
    outside. The patch is inside when more than :data:`NESTED_SHARE` of its vertices are; vertices within 1e-6 of
    the other patch's size from one of its corners (a part stored twice, its copy coincident) count neither way,
    and a patch all of whose vertices do is inside neither. Every vertex, not one corner: the answer does not
    depend on the order of the vertices or faces. The tests run per enclosing candidate, over the patches whose
    boxes meet its box only: none on a mesh with one closed part.
    """
    depth = np.zeros(closed.shape[0], dtype=np.int64)
    ids = np.flatnonzero(closed)
    if ids.size < 2:
        return depth
    from scipy.spatial import cKDTree  # imported on use, past the one-part return: scipy.spatial costs 0.13 s CPU

    face_closed = closed[patch]
    rows = np.flatnonzero(face_closed)
    owner = patch[rows]
    order = np.argsort(owner, kind="stable")
    rows, owner = rows[order], owner[order]
    starts = np.searchsorted(owner, ids)
    ends = np.searchsorted(owner, ids, side="right")
    corners = vertices[faces[rows]]  # (F', 3, 3)
    lower = np.minimum.reduceat(corners.min(axis=1), starts)
    upper = np.maximum.reduceat(corners.max(axis=1), starts)
    meets = np.asarray(((lower[:, None, :] <= upper[None]) & (upper[:, None, :] >= lower[None])).all(axis=2))
    np.fill_diagonal(meets, False)
    points = [np.unique(faces[rows[starts[i] : ends[i]]]) for i in range(ids.size)]
    # a vertex outside the other's box (grown by the touching distance) is outside it and counted: a patch with
    # at least 1 - NESTED_SHARE of its vertices there is inside neither, without its winding numbers (the touching
    # ones lie inside the grown box, so the vertices counted outnumber those outside it)
    slack = 1e-6 * np.linalg.norm(upper - lower, axis=1)[:, None]
    low, high = lower - slack, upper + slack
    for i in np.flatnonzero(meets.any(axis=1)).tolist():
        others = np.flatnonzero(meets[i])
        at = vertices[points[i]]
        inside_box = ((at[:, None, :] >= low[others][None]) & (at[:, None, :] <= high[others][None])).all(axis=2)
        meets[i, others] = np.count_nonzero(~inside_box, axis=0) < (1.0 - NESTED_SHARE) * points[i].size
    for j in np.flatnonzero(meets.any(axis=0)).tolist():  # patch j, the candidate that encloses
        inner = np.flatnonzero(meets[:, j])
        own = corners[starts[j] : ends[j]]
        queries = np.concatenate([points[i] for i in inner.tolist()])
        w = _fast_winding_numbers(own, vertices[queries])
        size = float(np.linalg.norm(upper[j] - lower[j]))
        gap, _ = cKDTree(own.reshape(-1, 3)).query(vertices[queries])
        counted = gap > 1e-6 * size  # a vertex on a corner of patch j is on its surface: inside neither
        inside = counted & (np.abs(w) > 0.5)
        split = np.cumsum([points[i].size for i in inner.tolist()])[:-1]
        for i, on, all_ in zip(inner.tolist(), np.split(inside, split), np.split(counted, split)):
            n_counted = int(np.count_nonzero(all_))
            depth[ids[i]] += n_counted > 0 and np.count_nonzero(on) > NESTED_SHARE * n_counted
    return depth


def _solid_angle_terms(corners: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(numerator, denominator, lengths)`` of the solid angles ``2 atan2(numerator, denominator)`` of the
    triangles ``corners`` (N, 3, 3) (relative to the point of view) by Van Oosterom and Strackee (1983):
    ``a . (b x c)`` and ``|a||b||c| + (a . b)|c| + (a . c)|b| + (b . c)|a|`` (N,), and ``|a|, |b|, |c|`` (N, 3)."""
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    lengths = np.linalg.norm(corners, axis=2)
    la, lb, lc = lengths[:, 0], lengths[:, 1], lengths[:, 2]
    numerator = np.einsum("ij,ij->i", a, np.cross(b, c))
    denominator = (
        la * lb * lc
        + np.einsum("ij,ij->i", a, b) * lc
        + np.einsum("ij,ij->i", a, c) * lb
        + np.einsum("ij,ij->i", b, c) * la
    )
    return numerator, denominator, lengths


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
