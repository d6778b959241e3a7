"""Per-face second fundamental form from normal differences (Rusinkiewicz 2004).

On each face with orthonormal frame ``(e_u, e_v)`` in its plane, the second
fundamental form ``II = [[L, M], [M, N]]`` is fitted by least squares to the
three edges ``e`` and the differences ``Δn`` of the vertex normals at their ends:

.. math::

    II \\begin{pmatrix} e \\cdot e_u \\\\ e \\cdot e_v \\end{pmatrix}
    = \\begin{pmatrix} \\Delta n \\cdot e_u \\\\ \\Delta n \\cdot e_v \\end{pmatrix}

(six equations, three unknowns; with normals pointing outward ``dn = S dx``, so
a sphere of radius ``r`` gives ``II = I / r``). Each face tensor is turned
into the tangent plane of each of its corners (the rotation that takes the face
normal to the vertex normal) and averaged with the corner's mixed Voronoi area
as weight; the eigen-decomposition of the average in the vertex tangent plane
gives the principal curvatures and directions. The vertex normals are the
area-weighted means of the face normals, except on the boundary.

Boundary vertices are kept (their average runs over the faces they have), with
a normal fitted to the positions around them: the mean of the normals of a part
of a fan (a rim's half fan, the one or two faces a hole leaves) leans towards
the faces kept, by about a third of their angle across the vertex, and the
normal differences along the edges then read that lean as curvature (issue 29: on
an icosphere with half of its faces removed, 42 of the 148 valid vertices
keeping an angle sum of 1 to 2 radians were off by more than half the
curvature, and a hemisphere's rim had a median H error of 21%). Each boundary
vertex takes the normal of a quadric (a jet of degree
:data:`BOUNDARY_NORMAL_DEGREE`) fitted to the referenced vertices of a ball of
:data:`BOUNDARY_NORMAL_RADIUS` length scales around it (:func:`meshcurv.jets.fit_jets`,
over Euclidean neighbours: across a hole too), a smaller ball where the quadric
bends across it by more than :data:`BOUNDARY_NORMAL_BEND` (a ball wrapped around a
bend tilts the quadric at a rim: up to 25 degrees where the radius of curvature is
an edge, fuzz 402/396), down to :data:`BOUNDARY_NORMAL_MIN_RADIUS` length scales; a
vertex whose ball holds too few points for the fit, or the other side of the
surface, is NaN with ``valid=False``.
The vertices whose fan is not one disk (bow-ties, non-manifold edges,
inconsistently oriented faces: :data:`OPEN_FAN_DEFECTS`) are invalid, but their
valid neighbours' face tensors read their normals: those take the same fitted
normal (issue 29: faces detached by cracks wider than the weld, some welded back
by one corner, left valid vertices whose faces' other corners were such bow-ties,
whose mean normal leaned towards the tilted face: H off by up to twice the
largest curvature). Where such a fit fails (a part thinner than its ball), the
vertex keeps the mean of its faces' normals.

References
----------
S. Rusinkiewicz (2004). Estimating curvatures and their derivatives on triangle
meshes. Proc. 2nd International Symposium on 3D Data Processing, Visualization
and Transmission (3DPVT), 486-493. https://doi.org/10.1109/TDPVT.2004.1335277
"""

from __future__ import annotations

import numpy as np

from .._tensors import principal_from_shape_operator
from .._geometry import mixed_voronoi_corner_areas
from ..jets import _fit_jets, jet_normals
from .._prepared import PreparedMesh
from ..defects import DEFECTS
from ._ring_noise import noisy_rings, noisy_rings_note
from ._support import Stages, finish, staircase_undefined

#: Per-face systems whose determinant, with the matrix scaled to a largest entry of 1, is at
#: most this are not solved (the face's tensor is NaN): a collapsed or sliver face.
SINGULAR_DETERMINANT = 1e-14

#: The degree of the jet whose normal a boundary vertex takes (a quadric: the slope at the vertex with the
#: bending around it, stable on the one-sided ball of a rim).
BOUNDARY_NORMAL_DEGREE = 2

#: The radius of that fit, in length scales (the median edge length of the vertex's component,
#: :attr:`meshcurv._prepared.PreparedMesh.length_scales`). 2 and 3 were as good on clean rims and holed
#: spheres but made the noisy rims worse (cylinder with noise 0.1 h: median H error 21% -> 29% at 3),
#: where the mean of the faces' normals had averaged the noise; at 4 every rim of
#: ``benchmarks/accuracy.py --quick`` has a lower median H error than with the faces' normals but the
#: clean cylinder's (0.036% -> 0.39%, its k_min 3.6% -> 0.96%).
BOUNDARY_NORMAL_RADIUS = 4.0

#: The most a boundary normal's quadric may bend across its ball: ``|k| r``, the ball's radius over the
#: radius of curvature its fit reads. A fit that bends more is made again over the ball that would bend by
#: this much (:func:`_bounded_normals`). A one-sided ball wrapped around a bend tilts the quadric: on the
#: rim of the lower half of a coarse ellipsoid (3, 2, 1) (its equator, whose radius of curvature across the
#: rim is one or two edges) the fitted normals were off by up to 12-25 degrees and H by 51-59% of its own
#: value, by 1.4-3.5 degrees and 16-29% now (``tests/test_wide_cracks_R18.py``); on a cylinder's one-sided
#: ball the normal's error stays below a degree up to a bend of 2 (fuzz 402/396: a rim vertex's normal 25
#: degrees off at a bend of 5.3).
BOUNDARY_NORMAL_BEND = 1.5

#: The smallest ball of those fits, in length scales. Below two, a rim's one-sided ball holds about ten
#: points for the quadric's six coefficients, and its slope leans again (the tip of a half ellipsoid's rim:
#: 0.1 degrees off at 2 length scales, 7 at 1.75 and 1.5).
BOUNDARY_NORMAL_MIN_RADIUS = 2.0

#: How many times a fit is made again over a smaller ball (the bend read over the smaller ball differs).
BOUNDARY_NORMAL_PASSES = 3

#: The defect codes (:data:`meshcurv.defects.DEFECTS`) of vertices whose fan of faces is not one disk: fans
#: meeting at a point (a bow-tie), a non-manifold edge, inconsistently oriented faces. Such a vertex is
#: invalid, but the face tensors of its valid neighbours read its normal, and the mean of its faces' normals
#: leans like a boundary vertex's: it takes a fitted normal too (issue 29: faces detached by cracks wider
#: than the weld, some welded back by one corner, left valid vertices with one or two faces whose other
#: corners were bow-ties: H off by up to twice the largest curvature).
OPEN_FAN_DEFECTS = tuple(
    defect.code for defect in DEFECTS if defect.name in ("nonmanifold_edges", "bowtie_vertices", "inconsistent_edges")
)

STAGES = ("compute normals", "fit face tensors", "average vertex tensors", "retrieve curvatures")

_SIX = (np.array([0, 1, 2, 0, 0, 1]), np.array([0, 1, 2, 1, 2, 2]))  # 3x3 -> (xx, yy, zz, xy, xz, yz)


#: The noise gain of the face tensors averaged at a vertex (:func:`~meshcurv.estimators._ring_noise.noisy_rings`):
#: H moves by about ``NOISE_GAIN sigma / l^2`` for vertices scattered by ``sigma`` along the normal (measured on
#: welded soups of icospheres: 0.37 against meyer's 2.0, the normals fitted over 2-rings).
NOISE_GAIN = 0.4


#: Its gain for the noise of the normals it reads (fitted ones at open fans): ``H`` moves by about
#: ``NORMAL_NOISE_GAIN theta / l`` for normals off by ``theta`` (RMS over the ring). 0: off. At 0.3-1 it caught
#: a uv sphere's half-detached pole (H off by 1.0, fuzz 395/37's class) but left 42 of the 102 sphere vertices of
#: tests/test_needle_cracks.py valid (the test asks for half).
NORMAL_NOISE_GAIN = 0.0


def face_second_fundamental_forms(
    vertices: np.ndarray, faces: np.ndarray, normals: np.ndarray, face_unit_normals: np.ndarray
) -> np.ndarray:
    """(F, 3, 3) least-squares shape operator of every face, as a 3D tensor in its plane."""
    x = [vertices[faces[:, k]] for k in range(3)]
    u = [normals[faces[:, k]] for k in range(3)]
    e_u = x[1] - x[0]
    e_u /= np.linalg.norm(e_u, axis=1, keepdims=True)
    e_v = np.cross(face_unit_normals, e_u)
    lhs = np.zeros((faces.shape[0], 3, 3))
    rhs = np.zeros((faces.shape[0], 3))
    for k in range(3):
        edge = x[(k + 2) % 3] - x[(k + 1) % 3]
        dn = u[(k + 2) % 3] - u[(k + 1) % 3]
        a, b = np.einsum("ij,ij->i", edge, e_u), np.einsum("ij,ij->i", edge, e_v)
        p, q = np.einsum("ij,ij->i", dn, e_u), np.einsum("ij,ij->i", dn, e_v)
        # rows (a, b, 0) . (L, M, N) = p and (0, a, b) . (L, M, N) = q
        lhs[:, 0, 0] += a * a
        lhs[:, 0, 1] += a * b
        lhs[:, 1, 1] += b * b + a * a
        lhs[:, 1, 2] += a * b
        lhs[:, 2, 2] += b * b
        rhs[:, 0] += a * p
        rhs[:, 1] += b * p + a * q
        rhs[:, 2] += b * q
    lhs[:, 1, 0], lhs[:, 2, 1] = lhs[:, 0, 1], lhs[:, 1, 2]
    # only well-posed systems are solved: a singular one (a collapsed face) or one with a
    # non-finite entry would make numpy raise LinAlgError for the whole batch; its face is NaN
    with np.errstate(over="ignore", invalid="ignore"):
        size = np.abs(lhs).max(axis=(1, 2))
        unit = lhs / np.where(size > 0, size, 1.0)[:, None, None]
        solvable = (
            np.isfinite(lhs).all(axis=(1, 2))
            & np.isfinite(rhs).all(axis=1)
            & (size > 0)
            & (np.abs(np.linalg.det(np.where(np.isfinite(unit), unit, 0.0))) > SINGULAR_DETERMINANT)
        )
    lmn = np.full(rhs.shape, np.nan)
    lmn[solvable] = np.linalg.solve(lhs[solvable], rhs[solvable][:, :, None])[:, :, 0]
    uu = e_u[:, :, None] * e_u[:, None, :]
    vv = e_v[:, :, None] * e_v[:, None, :]
    uv = e_u[:, :, None] * e_v[:, None, :]
    return (
        lmn[:, 0, None, None] * uu + lmn[:, 1, None, None] * (uv + uv.transpose(0, 2, 1)) + lmn[:, 2, None, None] * vv
    )


def rotations_between(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(N, 3, 3) the smallest rotations taking unit vectors ``a`` to ``b`` (Rodrigues).

    Antiparallel pairs (no unique smallest rotation) get the identity.
    """
    axis = np.cross(a, b)
    cos = np.einsum("ij,ij->i", a, b)
    skew = np.zeros((a.shape[0], 3, 3))
    skew[:, 0, 1], skew[:, 0, 2], skew[:, 1, 2] = -axis[:, 2], axis[:, 1], -axis[:, 0]
    skew -= skew.transpose(0, 2, 1)
    with np.errstate(invalid="ignore", divide="ignore"):
        factor = np.where(cos > -1 + 1e-12, 1.0 / (1.0 + cos), 0.0)
    return np.eye(3) + skew + factor[:, None, None] * (skew @ skew)


def boundary_normals(mesh: PreparedMesh, normals: np.ndarray, valid: np.ndarray, codes: np.ndarray) -> np.ndarray:
    """(V, 3) ``normals`` with those of the open fans that the ``valid`` vertices read fitted (NaN where no fit
    was possible at a valid vertex; an invalid one then keeps its normal).

    An open fan is that of a boundary vertex or of a vertex with a defect of its fan (:data:`OPEN_FAN_DEFECTS`:
    fans meeting at a point, a non-manifold edge, inconsistently oriented faces); its normal is fitted where
    the vertex is ``valid`` or a corner of a face with a ``valid`` corner (the face tensors of a valid vertex
    read the normals of all its faces' corners). The fits are quadrics (:data:`BOUNDARY_NORMAL_DEGREE`) over
    the referenced vertices within :data:`BOUNDARY_NORMAL_RADIUS` length scales, or fewer where the quadric
    bends across that ball (:func:`_bounded_normals`), started from ``normals`` and refused where the ball
    holds the other side of the surface (``facing`` of :func:`meshcurv.jets.fit_jets`).
    ``codes`` are the vertices' defect codes (:attr:`meshcurv.defects.VertexDefects.codes`).
    """
    topology = mesh.topology
    faces = topology.faces
    read = np.zeros(len(normals), dtype=bool)
    read[faces[valid[faces].any(axis=1)]] = True
    open_fan = topology.boundary_vertices | np.isin(codes, OPEN_FAN_DEFECTS)
    rows = np.flatnonzero(open_fan & read & np.isfinite(normals).all(axis=1) & (mesh.length_scales > 0))
    if rows.size == 0:
        return normals
    fitted = normals.copy()
    # the valid vertices' fits first, checked against the valid normals alone (as before the open fans were
    # fitted: an open fan's leaning normal must not refuse them); then the invalid ones', each also against
    # its own normal
    for centres in (rows[valid[rows]], rows[~valid[rows]]):
        if centres.size == 0:
            continue
        known = valid.copy()
        known[centres] = True
        fitted[centres] = _bounded_normals(mesh, np.where(known[:, None], normals, [0.0, 0.0, 1.0]), known, centres)
    # an invalid vertex whose fit failed (its ball holds the other side of a part thinner than 4 length scales)
    # keeps the mean of its faces' normals: its faces stay in its valid neighbours' averages, as before the fits
    kept = rows[~valid[rows] & ~np.isfinite(fitted[rows]).all(axis=1)]
    fitted[kept] = normals[kept]
    return fitted


def _bounded_normals(mesh: PreparedMesh, normals: np.ndarray, known: np.ndarray, centres: np.ndarray) -> np.ndarray:
    """(M, 3) the normals of quadrics fitted at ``centres``, over balls that the surface bends across by at most
    :data:`BOUNDARY_NORMAL_BEND` (NaN where a fit failed).

    Each fit starts over :data:`BOUNDARY_NORMAL_RADIUS` length scales; one whose quadric bends more (``|k| r``
    from its coefficients) is fitted again over the ball that would bend by the limit, not below
    :data:`BOUNDARY_NORMAL_MIN_RADIUS` length scales, up to :data:`BOUNDARY_NORMAL_PASSES` times. ``normals``
    start the fits; the balls' points of ``known`` normals check them (``facing``).
    """
    scales = mesh.length_scales[centres]
    radii = BOUNDARY_NORMAL_RADIUS * scales
    floor = BOUNDARY_NORMAL_MIN_RADIUS * scales
    result = np.full((centres.size, 3), np.nan)
    todo = np.arange(centres.size)
    for _ in range(BOUNDARY_NORMAL_PASSES):
        found, frame, _ = _fit_jets(
            mesh.vertices,
            normals,
            radii[todo],
            degree=BOUNDARY_NORMAL_DEGREE,
            centres=centres[todo],
            neighbours=mesh.topology.referenced_vertices,
            facing=np.where(known[:, None], normals, np.nan),
            compact=True,
        )
        result[todo] = jet_normals(found, frame)
        # |k| r of the quadric c20 x^2 + c11 x y + c02 y^2 in units of r: twice its largest |eigenvalue|
        half_sum, half_difference = (
            (found[:, 3] + found[:, 5]) / 2,
            np.hypot((found[:, 3] - found[:, 5]) / 2, found[:, 4] / 2),
        )
        with np.errstate(invalid="ignore"):
            bend = 2 * (np.abs(half_sum) + half_difference)
            over = (bend > BOUNDARY_NORMAL_BEND) & (radii[todo] > floor[todo] * (1 + 1e-9))
        todo, bend = todo[over], bend[over]
        if todo.size == 0:
            break
        radii[todo] = np.maximum(radii[todo] * BOUNDARY_NORMAL_BEND / bend, floor[todo])
    return result


def estimate(mesh: PreparedMesh, *, stages: Stages):
    """Rusinkiewicz's per-face curvature tensors averaged on vertices. Returns ``(result, problems)``."""
    vertices, topology = mesh.vertices, mesh.topology
    stages.start("compute normals")
    n = vertices.shape[0]
    cross, degenerate, normals = mesh.cross, mesh.degenerate, mesh.vertex_normals
    defects, valid = mesh.start(boundary=True)
    normals = boundary_normals(mesh, normals, valid, defects.codes)
    valid &= np.isfinite(normals).all(axis=1)
    usable = ~degenerate & np.isfinite(normals[topology.faces]).all(axis=(1, 2))
    faces = topology.faces[usable]
    face_unit_normals = cross[usable] / np.linalg.norm(cross[usable], axis=1, keepdims=True)

    stages.start("fit face tensors")
    tensors = face_second_fundamental_forms(vertices, faces, normals, face_unit_normals)

    stages.start("average vertex tensors")
    weights = mixed_voronoi_corner_areas(vertices, faces)
    summed = np.zeros((n, 6))
    total = np.bincount(faces.ravel(), weights=weights.ravel(), minlength=n)
    for k in range(3):
        corner = faces[:, k]
        rotation = rotations_between(face_unit_normals, normals[corner])
        turned = rotation @ tensors @ rotation.transpose(0, 2, 1)
        six = turned[:, _SIX[0], _SIX[1]] * weights[:, k, None]
        for c in range(6):
            summed[:, c] += np.bincount(corner, weights=six[:, c], minlength=n)

    stages.start("retrieve curvatures")
    valid &= total > 0
    with np.errstate(invalid="ignore", divide="ignore"):
        shape_operator = summed / total[:, None]
    k_min, k_max, dir_min, dir_max = principal_from_shape_operator(
        np.where(valid[:, None], shape_operator, 0.0), np.where(valid[:, None], normals, [0.0, 0.0, 1.0])
    )
    valid, staircase = staircase_undefined(mesh, defects, valid, stages=stages)
    noisy = noisy_rings(mesh, valid, NOISE_GAIN, normals=normals, normal_gain=NORMAL_NOISE_GAIN)
    valid &= ~noisy
    extra = (*staircase, noisy_rings_note(int(noisy.sum())))
    return finish("rusinkiewicz", {}, valid, normals, k_min, k_max, dir_min, dir_max, defects, extra)
