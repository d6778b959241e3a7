"""matGeom's ``meshCurvatures``, reproduced number for number.

This is the compatibility mode. It follows the MATLAB code of matGeom
(github.com/mattools/matGeom, ``meshes3d/meshCurvatures.m``, D. Legland, 2021),
itself adapted from G. Peyre's toolbox_graph ``compute_curvature``:

1. pair every edge with two faces through a sparse matrix of summed 1-based face
   ids, enumerated twice (the pairing is exact on closed, consistently oriented
   meshes and drifts on open ones; reproduced literally);
2. edge lengths divided by their mean; unit edge vectors;
3. signed angle between the two face normals,
   ``beta = arccos(n1 . n2) * sign((n1 x n2) . e)`` (0 at a fold, within
   :data:`~meshcurv._geometry.FOLD_ANGLE` of pi, as at an exact one, whose side is 0: in every pose);
4. edge tensor ``T_e = d_e * beta_e * e e^T``;
5. vertex tensor = sum of the tensors of its edges divided by their number;
6. ``smoothing_steps`` passes of a plain 1-ring mean of every tensor component;
7. eigen-decomposition; eigenpairs sorted by absolute eigenvalue; the two
   largest are the curvatures, the smallest one's vector is the "normal";
   swapped so that ``C1 <= C2``.

Where the normal's eigenvalue equals another one (to :data:`NORMAL_GAP` of the
largest magnitude), its eigenvector is any vector of a plane (or of space), and
matGeom's choice is that of its eigen-solver's round-off: flat or exactly
coplanar neighbourhoods (a zero tensor), a cube's edge (a rank-1 tensor), a
staircase of coordinates quantised at round-off, and every vertex of a closed
mesh after thousands of smoothing passes (the mean tensor of a sphere is a
multiple of the identity). There the normal is NaN and the vertex is
``valid=False``, on both backends; the curvatures are kept (eigenvalues are
defined, and a tie of magnitudes gives the smaller value to the normal, as
matGeom's sort does for exact ties). Where the magnitudes of the two smallest
eigenvalues are apart by less than the round-off of the dihedral angles
(:data:`ANGLE_NOISE`), the choice of the normal depends on the mesh's pose (a
flat patch is a zero tensor in the axes, round-off in another pose): the vertex
is ``valid=False`` too (matGeom's normal kept), so that the valid mask is the
same in every pose.

On a voxel surface (a marching-cubes staircase, or a mesh on a voxel grid:
:func:`._support.on_staircase`) every vertex is ``valid=False``, matGeom's numbers
kept: a ring of faces reads the one-voxel steps as curvature.

The outputs are dimensionless (see the README: not curvatures in 1/length).

References
----------
D. Cohen-Steiner and J.-M. Morvan (2003). Restricted Delaunay triangulations and
normal cycle. Proc. 19th ACM Symposium on Computational Geometry, 312-321.
https://doi.org/10.1145/777792.777839

P. Alliez, D. Cohen-Steiner, O. Devillers, B. Levy, M. Desbrun (2003).
Anisotropic polygonal remeshing. ACM Trans. Graph. 22(3), 485-493.
https://doi.org/10.1145/882262.882296
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .._backend import kernel_threads, numba_kernels
from .._tensors import outer6
from .._geometry import DEGENERATE_AREA_RATIO, FOLD_ANGLE, mean_edge_length, vertex_edge_lengths
from ..defects import STAIRCASE
from ..result import CurvatureResult
from ..smoothing import STEPS_PER_CALL, _smooth_vertex_field
from .._prepared import PreparedMesh
from ..topology import MeshTopology
from ._support import Stages, on_staircase
from ._eigen import sorted_by_magnitude

#: Relative gap (of the tensor's largest eigenvalue magnitude) within which two eigenvalues are taken as
#: equal in step 7. Both solvers (LAPACK, the compiled Jacobi) are within some 16 eps of |T| per
#: eigenvalue and an eigenvector within that over its gap: at 1e-8 the normals of the two backends are
#: within some 1e-6 of each other, while the meshes measured (matGeom's reference cases, thin, open,
#: noisy and voxel meshes) have gaps either 0 (below 1e-14) or above 1e-7.
NORMAL_GAP = 1e-8

#: Bound of the round-off of matGeom's dihedral angle ``arccos(n1 . n2)`` between coplanar faces (radians).
#: ``arccos`` is ill-conditioned at 1: a dot product ``k`` ulps below 1 gives ``1.49e-8 sqrt(k)``, so two
#: faces coplanar to round-off get an angle of 0 in one pose (normals along an axis: the dot exactly 1)
#: and up to 3e-8 in another (measured on fandisk, rocker-arm, igea under 10 rigid motions each; 1e-7 is
#: 45 ulps). Eigenvalues of a vertex's tensor that differ by less than this noise (times its edges'
#: weights, :func:`_noise_floors`) are equal: whether they tie must not depend on the mesh's pose.
ANGLE_NOISE = 1e-7

STAGES = ("compute adjacencies", "compute edge tensors", "average vertex tensors", "retrieve curvatures")


def matgeom_pairing(faces: np.ndarray, n_vertices: int):
    """matGeom's edge/face pairing (its step 1), literally.

    Returns
    -------
    ev1, ev2 : ndarray of shape (E,)
        Kept edges, ``ev1 < ev2``.
    ef1, ef2 : ndarray of shape (E,)
        0-based face indices as matGeom uses them (the sum of the 1-based ids of
        the faces sharing a directed side, minus 1: may be out of range, or a face
        that does not contain the edge, on open or non-manifold meshes).
    """
    n_faces = faces.shape[0]
    tail = faces.T.ravel()  # matGeom concatenates the columns
    head = np.roll(faces, -1, axis=1).T.ravel()
    ids = np.tile(np.arange(1, n_faces + 1, dtype=np.int64), 3)
    keys, inverse = np.unique(tail * n_vertices + head, return_inverse=True)
    sums = np.bincount(inverse.ravel(), weights=ids).astype(np.int64)
    rows, cols = np.divmod(keys, n_vertices)  # keys sorted by (row, column)
    by_column = np.lexsort((rows, cols))
    ef1 = sums[by_column]
    ev1, ev2, ef2 = cols, rows, sums
    keep = ev1 < ev2
    return ev1[keep], ev2[keep], ef1[keep] - 1, ef2[keep] - 1


def _row_dots(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``sum(a .* b, 2)`` summed left to right, as Octave does."""
    return (a[:, 0] * b[:, 0] + a[:, 1] * b[:, 1]) + a[:, 2] * b[:, 2]


def _row_norms(a: np.ndarray) -> np.ndarray:
    return np.sqrt(_row_dots(a, a))


def _matgeom_face_normals(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """matGeom's meshFaceNormals: cross product of the sides from corner 1, normalised."""
    a = vertices[faces[:, 0]]
    cross = np.cross(vertices[faces[:, 1]] - a, vertices[faces[:, 2]] - a)
    with np.errstate(invalid="ignore", divide="ignore"):
        return cross / _row_norms(cross)[:, None]


def _vertex_tensors(vertices, faces, ev1, ev2, ef1, ef2, out_of_range):
    """NumPy path of matGeom's steps 2 to 5: edge tensors pooled on vertices."""
    n_vertices = vertices.shape[0]
    # Operations in matGeom's order: arccos is ill-conditioned near 1, so the
    # dot products of nearly parallel normals must match bit for bit.
    edge_vectors = vertices[ev2] - vertices[ev1]
    lengths = _row_norms(edge_vectors)
    with np.errstate(invalid="ignore", divide="ignore"):
        edge_vectors = edge_vectors / lengths[:, None]
        lengths = lengths / (lengths.mean() if lengths.size else 1.0)  # no edges: nothing to scale
    normals = _matgeom_face_normals(vertices, faces)
    n1 = normals[ef1]
    n2 = normals[ef2]
    with np.errstate(invalid="ignore"):
        beta = np.arccos(np.clip(_row_dots(n1, n2), -1.0, 1.0))
        # a fold (two faces on each other) reads 0 in every pose, as matGeom reads an exact one (a side of 0): turned,
        # its side is a few last bits of either sign and the angle jumped to +-pi (ogre.obj, fuzz_api 433/68)
        beta[beta >= np.pi - FOLD_ANGLE] = 0.0
        beta *= np.sign(_row_dots(np.cross(n1, n2), edge_vectors))
    weight = lengths * beta
    weight[out_of_range] = np.nan  # where matGeom stops with an index error
    edge_tensors = outer6(edge_vectors, weight)
    ends = np.concatenate([ev1, ev2])
    counts = np.bincount(ends, minlength=n_vertices).astype(np.float64)
    counts[counts < np.finfo(float).eps] = 1.0
    return (
        np.stack(
            [np.bincount(ends, weights=np.tile(edge_tensors[:, k], 2), minlength=n_vertices) for k in range(6)],
            axis=1,
        )
        / counts[:, None]
    )


def matgeom_tensors(vertices: np.ndarray, topology: MeshTopology, smoothing_steps: int, stages: Stages | None = None):
    """matGeom's smoothed vertex tensors (steps 1 to 6).

    Returns
    -------
    tensors : ndarray of shape (V, 6)
        ``(xx, yy, zz, xy, xz, yz)``; NaN where matGeom's arithmetic gives NaN or
        where it stops with an index error.
    n_kept_edges, n_wrong_face, n_out_of_range : int
        How matGeom's pairing went: edges kept, edges paired with a face that
        does not contain them, face-id sums beyond the number of faces.
    mispaired : ndarray of shape (V,), bool
        Ends of the edges paired with a face that does not contain them.
    """
    stages = stages or Stages(STAGES)
    tensors, n_kept, n_wrong_face, n_out_of_range, mispaired, _, _ = _edge_tensors(vertices, topology, stages)
    stages.start("average vertex tensors")
    return _smooth_vertex_field(tensors, topology, smoothing_steps), n_kept, n_wrong_face, n_out_of_range, mispaired


def _edge_tensors(vertices: np.ndarray, topology: MeshTopology, stages: Stages, mesh: PreparedMesh | None = None):
    """Steps 1 to 5 of :func:`matgeom_tensors`: the vertex tensors before the smoothing, and the same counts.

    With ``mesh`` (the prepared mesh of ``vertices`` and ``topology``), the compiled path also finds its
    zero-area faces (:attr:`PreparedMesh.degenerate`) in its pass over the faces, when not found yet."""
    faces = topology.faces
    n_vertices = vertices.shape[0]
    n_faces = faces.shape[0]

    stages.start("compute adjacencies")
    if topology.interior_edges.all() and not topology.degenerate_faces.any():
        # closed, consistently oriented, manifold: the pairing is each edge
        # p < q with the face running p -> q and the one running q -> p
        edges = topology.edges
        ev1, ev2 = edges[:, 0], edges[:, 1]
        ef1, ef2 = topology.edge_faces[:, 0], topology.edge_faces[:, 1]
        out_of_range = np.zeros(ev1.size, dtype=bool)
        wrong_face = out_of_range
    else:
        ev1, ev2, ef1, ef2 = matgeom_pairing(faces, n_vertices)
        edges = np.stack((ev1, ev2), axis=1)
        out_of_range = (ef1 >= n_faces) | (ef2 >= n_faces)
        # a face "contains" the edge when both ends are among its corners
        f1 = faces[np.where(out_of_range, 0, ef1)]
        contains = (f1 == ev1[:, None]).any(1) & (f1 == ev2[:, None]).any(1)
        wrong_face = ~out_of_range & ~contains

    stages.start("compute edge tensors")
    kernels = numba_kernels("matgeom")
    if kernels is not None:
        # columns of the topology's arrays as they are (strided views): numba reads them without a copy
        if mesh is not None and "degenerate" not in mesh.__dict__:
            tensors, degenerate = kernels.matgeom_vertex_sums(
                vertices, faces, ev1, ev2, ef1, ef2, kernel_threads(), mesh.length_scales, DEGENERATE_AREA_RATIO, True
            )
            mesh.found_degenerate(degenerate)  # the test of mesh.degenerate (the twin tests): not made twice
        else:
            tensors = kernels.matgeom_vertex_tensors(vertices, faces, ev1, ev2, ef1, ef2, kernel_threads())
    else:
        tensors = _vertex_tensors(
            vertices, faces, ev1, ev2, np.where(out_of_range, 0, ef1), np.where(out_of_range, 0, ef2), out_of_range
        )

    mispaired = np.zeros(n_vertices, dtype=bool)
    mispaired[ev1[wrong_face]] = True
    mispaired[ev2[wrong_face]] = True
    return (
        tensors,
        ev1.size,
        int(wrong_face.sum()),
        int(out_of_range.sum()),
        mispaired,
        _noise_floors(vertices, edges),
        (ev1, ev2, ef1, ef2, out_of_range),
    )


def _noise_floors(vertices: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """(V,) bound of the round-off of each vertex's tensor before the smoothing, in its eigenvalues.

    The tensor is the mean over the vertex's edges of ``(d_e / mean d) beta_e e e^T``;
    ``beta_e`` carries up to :data:`ANGLE_NOISE` of round-off and ``e e^T`` has norm 1, so the
    eigenvalues move by at most ``ANGLE_NOISE`` x the mean of ``d_e / mean d``, and the gap between
    two of them (or between their magnitudes) by twice that (0 at a vertex of no edge). Edge lengths only:
    the same in every pose. ``edges`` (E, 2): the pairs of the edge tensors.
    """
    # two compiled passes over the edges (the lengths gathered in NumPy cost 0.21 CPU s at a million
    # vertices, a quarter of the method's call: issue 31)
    lengths = vertex_edge_lengths(vertices, edges, vertices.shape[0])  # NaN at a vertex of no edge
    alone = np.isnan(lengths)
    with np.errstate(invalid="ignore", divide="ignore"):
        relative = lengths / (mean_edge_length(vertices, edges) if edges.shape[0] else 1.0)
    relative[alone] = 0.0
    return 2.0 * ANGLE_NOISE * relative


def _principal(tensors: np.ndarray):
    """NumPy path of matGeom's step 7: ``(c1, c2, u1, u2, normal)`` of (V, 6) tensors.

    Eigenpairs by magnitude (:func:`sorted_by_magnitude`); magnitudes within
    :data:`NORMAL_GAP` x the largest give the smaller value to the normal (matGeom's
    order of exact ties); the normal is NaN where its eigenvalue is within that
    of the middle one (its eigenspace then a plane); the two others are the
    curvatures, swapped so that ``c1 <= c2``.
    """
    values, vectors = sorted_by_magnitude(tensors)
    with np.errstate(invalid="ignore"):
        tolerance = NORMAL_GAP * np.abs(values[:, 2])
        tie = (np.abs(values[:, 1]) - np.abs(values[:, 0]) <= tolerance) & (values[:, 0] > values[:, 1])
        values[tie] = values[tie][:, [1, 0, 2]]
        vectors[tie] = vectors[tie][:, :, [1, 0, 2]]
        undefined = np.abs(values[:, 1] - values[:, 0]) <= tolerance
    c1, c2 = values[:, 1].copy(), values[:, 2].copy()
    u1, u2, normal = vectors[:, :, 2].copy(), vectors[:, :, 1].copy(), vectors[:, :, 0].copy()
    normal[undefined] = np.nan
    swap = c1 > c2
    c1[swap], c2[swap] = c2[swap], c1[swap]
    u1[swap], u2[swap] = u2[swap], u1[swap]
    return c1, c2, u1, u2, normal


def _tied_to_round_off(
    c1: np.ndarray,
    c2: np.ndarray,
    traces: np.ndarray,
    floors: np.ndarray,
    exact_gaps: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]],
) -> np.ndarray:
    """(V,) bool: the normal's eigenvalue may be the middle one's, or tie with it, in some pose of the mesh.

    The normal's eigenvalue is ``trace - c1 - c2``; ``c1`` and ``c2`` are the eigenvalues of middle and
    largest magnitude. matGeom's ``arccos`` puts up to :data:`ANGLE_NOISE` of round-off on every dihedral
    angle, which moves each eigenvalue (magnitude) by up to half the vertex's floor (``floors``,
    :func:`_noise_floors` smoothed): a flat patch is a zero tensor in the axes and round-off in any other
    pose, a crease a rank-1 tensor plus round-off. So the gap between the magnitudes of the two smallest
    eigenvalues is known to within the floor, and the decision is taken on the tensor of the exact angles
    (``exact_gaps``, :func:`_exact_gaps`: the same in every pose to some 1e-16, not to 1e-8): tied where its
    gap is within the floor plus :data:`NORMAL_GAP` x its largest magnitude (the tie of step 7 that this
    round-off can reach). A test on the round-off tensor's own gap (before: ``middle - smallest <= floors``)
    was itself round-off at its bound: fandisk's vertex 1306 (``smallest`` 7e-10 or 7e-11 by the pose,
    the floor 1.944e-7, ``middle`` 1.948e-7) flipped under a rigid motion (fuzz_api 551/171).

    Only the vertices whose round-off gap leaves the decision open (within twice the floor of its bound)
    need the exact tensor; ``exact_gaps(band)`` returns their ``(gap, largest magnitude)``.
    """
    with np.errstate(invalid="ignore"):
        smallest = np.abs(traces - c1 - c2)
        middle = np.minimum(np.abs(c1), np.abs(c2))
        largest = np.maximum(np.abs(c1), np.abs(c2))
        gap = middle - smallest
        # the round-off gap is within a floor of the exact one: below half the step-7 tie it is tied in every
        # pose, beyond two floors and the tie (a hundredth of a floor of slack) apart in every pose
        tied = gap <= 0.5 * NORMAL_GAP * largest
        band = ~tied & (gap <= 2.01 * floors + 2.0 * NORMAL_GAP * largest)
    if band.any():
        exact_gap, exact_largest = exact_gaps(band)
        tied[band] = exact_gap <= floors[band] + NORMAL_GAP * exact_largest
    return tied


def _neighbours(indptr: np.ndarray, indices: np.ndarray, rows: np.ndarray):
    """``(owners, neighbours)``: each of the ``rows``' edge neighbours (CSR ``indptr, indices``) and its row."""
    starts, degrees = indptr[rows], indptr[rows + 1] - indptr[rows]
    offsets = np.repeat(starts - np.concatenate([[0], np.cumsum(degrees)[:-1]]), degrees)
    return np.repeat(rows, degrees), indices[np.arange(int(degrees.sum())) + offsets].astype(np.int64)


def _exact_gaps(vertices, topology, smoothing_steps, pairing, band, mean):
    """``(gap, largest)`` at the ``band`` vertices: matGeom's smoothed tensor with exact dihedral angles.

    The tensor of steps 2 to 6 on the same edges and faces (``pairing``: ``ev1, ev2, ef1, ef2, out_of_range``
    of :func:`_edge_tensors`), its angles ``atan2(|n1 x n2|, n1 . n2)`` (well conditioned: within some
    1e-16 of the exact angle in every pose, where ``arccos(n1 . n2)`` is within 1e-8), only on the edges
    within the smoothing's reach of the band. ``gap`` is the middle eigenvalue magnitude minus the smallest,
    ``largest`` the largest magnitude.
    """
    ev1, ev2, ef1, ef2, out_of_range = pairing
    n_vertices = vertices.shape[0]
    indptr, indices = topology.neighbour_lists
    # the band's smoothed tensors read the vertex tensors within smoothing_steps rings, which read their edges:
    # everything below on those rings only (a few vertices of a large mesh: no pass over the whole mesh)
    reach = band.copy()
    for _ in range(smoothing_steps):
        reach[_neighbours(indptr, indices, np.flatnonzero(reach))[1]] = True
    rows = np.flatnonzero(reach)
    near = np.flatnonzero(reach[ev1] | reach[ev2])
    p, q = ev1[near], ev2[near]
    lengths = _row_norms(vertices[q] - vertices[p])
    faces = topology.faces
    lost = out_of_range[near]
    f1, f2 = np.where(lost, 0, ef1[near]), np.where(lost, 0, ef2[near])
    with np.errstate(invalid="ignore", divide="ignore"):
        units = (vertices[q] - vertices[p]) / lengths[:, None]
        n1 = _matgeom_face_normals(vertices, faces[f1])
        n2 = _matgeom_face_normals(vertices, faces[f2])
        cross = np.cross(n1, n2)
        beta = np.arctan2(_row_norms(cross), _row_dots(n1, n2))
        beta[beta >= np.pi - FOLD_ANGLE] = 0.0  # matGeom's fold rule (step 3)
        weight = (lengths / mean) * beta * np.sign(_row_dots(cross, units))
    weight[lost] = np.nan
    edge_tensors = outer6(units, weight)
    local = np.full(n_vertices, -1, dtype=np.int64)
    local[rows] = np.arange(rows.size)
    ends = local[np.concatenate([p, q])]
    keep = ends >= 0
    counts = np.bincount(ends[keep], minlength=rows.size).astype(np.float64)  # all the edges of a reached vertex
    counts[counts == 0] = 1.0
    tensors = (
        np.stack(
            [
                np.bincount(
                    ends[keep],
                    weights=np.tile(edge_tensors[:, k], 2)[keep],
                    minlength=rows.size,
                )
                for k in range(6)
            ],
            axis=1,
        )
        / counts[:, None]
    )
    # smoothing_steps passes of the 1-ring mean on the reached vertices (each with its whole degree): a vertex at
    # the reach's edge misses neighbours, an error that moves one ring a pass and stops short of the band
    owners, neighbours = _neighbours(indptr, indices, rows)
    inside = local[neighbours] >= 0
    owners, neighbours = local[owners[inside]], local[neighbours[inside]]
    scale = 1.0 / (np.diff(indptr)[rows] + 1.0)
    for _ in range(smoothing_steps):
        tensors = (
            tensors
            + np.stack(
                [np.bincount(owners, weights=tensors[neighbours, k], minlength=rows.size) for k in range(6)],
                1,
            )
        ) * scale[:, None]
    tensors = tensors[local[np.flatnonzero(band)]]
    xx, yy, zz, xy, xz, yz = tensors.T
    matrices = np.stack([xx, xy, xz, xy, yy, yz, xz, yz, zz], axis=1).reshape(-1, 3, 3)
    finite = np.isfinite(matrices).all(axis=(1, 2))
    magnitudes = np.full((matrices.shape[0], 3), np.nan)
    magnitudes[finite] = np.sort(np.abs(np.linalg.eigvalsh(matrices[finite])), axis=1)
    return magnitudes[:, 1] - magnitudes[:, 0], magnitudes[:, 2]


def estimate(mesh: PreparedMesh, *, smoothing_steps: int, stages: Stages):
    """Run matGeom's algorithm. Returns ``(result, problems)``."""
    vertices, topology = mesh.vertices, mesh.topology
    kernels = numba_kernels("matgeom")
    problems: list[str] = []
    tensors, n_kept, n_wrong_face, n_out_of_range, mispaired, floors, pairing = _edge_tensors(
        vertices, topology, stages, mesh if kernels is not None else None
    )
    # the trace and the round-off bound, smoothed as the tensors are: the third eigenvalue (the normal's)
    # is the trace minus the two curvatures, to be compared with the round-off (:func:`_tied_to_round_off`)
    stages.start("average vertex tensors")
    traces_and_floors = np.stack([(tensors[:, 0] + tensors[:, 1]) + tensors[:, 2], floors], axis=1)
    if kernels is not None and smoothing_steps <= STEPS_PER_CALL:
        # the smoothing and the eigen-decomposition in one kernel (the same sums in the same order as
        # smooth_vertex_field's kernel): no copy of the tensors, the last pass straight into the eigen-solver,
        # the traces and floors smoothed in place in the same passes (one read of the lists)
        indptr, indices = topology.smoothing_lists(smoothing_steps)
        stages.start("retrieve curvatures")
        c1, c2, u1, u2, normal = kernels.matgeom_finish(
            np.ascontiguousarray(tensors), indptr, indices, smoothing_steps, NORMAL_GAP, traces_and_floors
        )
    else:
        traces_and_floors = _smooth_vertex_field(traces_and_floors, topology, smoothing_steps)
        tensors = _smooth_vertex_field(tensors, topology, smoothing_steps)
        stages.start("retrieve curvatures")
        if kernels is not None:
            c1, c2, u1, u2, normal = kernels.matgeom_principal(np.ascontiguousarray(tensors), NORMAL_GAP)
        else:
            c1, c2, u1, u2, normal = _principal(tensors)
    # matGeom's normal is kept there (it is the one matGeom computes in this pose), the vertex invalid
    tied = _tied_to_round_off(
        c1,
        c2,
        traces_and_floors[:, 0],
        traces_and_floors[:, 1],
        lambda band: _exact_gaps(
            vertices,
            topology,
            smoothing_steps,
            pairing,
            band,
            mean_edge_length(vertices, np.stack(pairing[:2], axis=1)),
        ),
    )

    finite = ~np.isnan(c1)  # NaN exactly where a tensor component is not finite
    no_normal = finite & (np.isnan(normal[:, 0]) | tied)  # the normal's eigenvalue not apart from the middle one
    # matGeom's numbers are kept everywhere it computes them; valid=False marks
    # where they are not an estimate: vertices whose tensor drew on a defect
    # (boundary, non-manifold, bow-tie, flipped or zero-area neighbourhood, or an
    # edge paired with a wrong face), spread over the smoothing rings as the
    # smoothing spreads it
    doubtful = mesh.defects().invalid_vertices | mispaired
    doubtful &= topology.referenced_vertices
    if doubtful.any() and smoothing_steps:
        doubtful = _smooth_vertex_field(doubtful.astype(np.float64), topology, smoothing_steps) > 0
    valid = topology.referenced_vertices & finite & ~doubtful & ~no_normal

    n_boundary = int(topology.boundary_edges.sum())
    if n_boundary:
        n_dropped = topology.n_edges - n_kept
        problems.append(
            f"open mesh ({n_boundary} boundary edges): matGeom's edge/face pairing drops "
            f"{n_dropped} edges and pairs {n_wrong_face} edges with a face that does not "
            "contain them, so values near the boundary are wrong (reproduced as matGeom computes them)"
        )
    n_bad_edges = int((topology.nonmanifold_edges | topology.inconsistent_edges).sum())
    if n_bad_edges:
        problems.append(
            f"{n_bad_edges} non-manifold or inconsistently oriented edges: matGeom sums the ids of "
            f"their faces ({n_out_of_range} sums out of range, where matGeom stops with an "
            "index error: NaN there)"
        )
    n_nan_vertices = int((topology.referenced_vertices & ~finite).sum())
    if n_nan_vertices:
        problems.append(
            f"{n_nan_vertices} vertices have undefined tensors (zero-area faces, zero-length edges "
            "or the index errors above; matGeom stops with 'EIG: matrix contains Inf or NaN values'): "
            "they are NaN and valid=False"
        )
    n_no_normal = int((no_normal & topology.referenced_vertices & ~doubtful).sum())  # not counted below
    if n_no_normal:
        problems.append(
            f"{n_no_normal} vertices have no normal: their tensor's smallest eigenvalue equals the next one "
            f"(to {NORMAL_GAP:g} of the largest, or their magnitudes to the round-off of the dihedral angles; a flat or coplanar neighbourhood, a crease, coordinates "
            f"quantised at round-off, or a tensor smoothed into a multiple of the identity: "
            f"{smoothing_steps} smoothing passes), so the eigenvector matGeom calls the normal is any vector "
            "of a plane, decided by round-off: valid=False (the curvatures kept; the normal NaN where the "
            "eigenvalues tie, matGeom's where only the round-off of the angles could part them)"
        )
    n_unreferenced = int((~topology.referenced_vertices).sum())
    if n_unreferenced:
        problems.append(f"{n_unreferenced} unreferenced vertices: matGeom's zeros, valid=False")
    if problems:
        problems.append("method='normal_cycle' handles such meshes correctly")
    if on_staircase(mesh, mesh.defects(), valid, stages=stages):
        # a ring of faces reads the voxels' steps as curvature (on voxel_sphere(10) every vertex off the exact H
        # by some 120%): matGeom's numbers are kept, as matGeom computes them, but none is marked an estimate
        problems.append(
            f"{int(valid.sum())} vertices of this voxel surface are valid=False: matGeom's ring of faces reads the "
            "voxels' staircase as curvature (its numbers kept, as matGeom computes them; method='icc' scales its "
            "balls to the voxels)"
        )
        method_codes = np.where(valid, STAIRCASE, 0).astype(np.int8)  # the others keep their own reason
        valid = np.zeros_like(valid)
    else:
        method_codes = None
    result = CurvatureResult._of_arrays(
        k_min=c1,
        k_max=c2,
        dir_min=u1,
        dir_max=u2,
        normals=normal,
        valid=valid,
        invalid_reason=method_codes,
        method="matgeom",
        parameters={"smoothing_steps": smoothing_steps},
    )
    return result, problems
