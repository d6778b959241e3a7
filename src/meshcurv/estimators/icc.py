"""Interpolated corrected curvature measures over a ball (Lachaud, Romon, Thibert, Coeurjolly 2020).

The vertex normals ``u_i`` are those of a weighted degree-3 jet fitted over the
ball ``B(x_i, 3 r)`` with one normal re-estimation
(:func:`meshcurv.jets.fit_jets`; Cazals and Pouget 2005), not the
area-weighted mean of the face normals: the corrected measures are only as
good as the normals they interpolate, and the mean of the face normals has an
error of order ``h`` on an irregular triangulation (a median error of H of 2%
on a random sphere, against 0.04% with the fitted normals) and is one-sided at
a boundary, where the fit extrapolates (where a fit fails, the mean of the face
normals is kept). The normal fit takes three times the measure radius
(:data:`NORMAL_RADIUS_RATIO`): a degree-3 jet needs ten points, and its normals
have an error of order ``r^3`` where those of a degree-2 jet have ``r^2``
(on a regular ellipsoid, 0.5% against 1.8% in H).

The default radius follows the noise of the mesh (:func:`noise_level`, ``nu``
in units of the local edge length) and its mean edge length ``h``:
``r = h (1 + 9 sqrt(max(nu - 0.005, 0)))``,
one edge length on a clean mesh, where the smallest ball has the smallest bias,
about 2.2 h under normal noise of amplitude 0.1 h and 3.3 h under 0.3 h, where
a larger ball averages the noise out. The constants come from a sweep of both
radii over the surfaces of ``benchmarks/accuracy.py``.

The normals ``u_i`` are interpolated linearly over each triangle ``(x_i, x_j, x_k)``; the curvature
measures of the corrected normal current then have closed forms per face, with
``ū = (u_i + u_j + u_k) / 3``:

.. math::

    \\mu_0 &= \\tfrac12 \\langle ū \\mid (x_j - x_i) \\times (x_k - x_i) \\rangle
    \\quad\\text{(corrected area)}\\\\
    \\mu_1 &= \\tfrac12 \\langle ū \\mid (u_k - u_j) \\times x_i + (u_i - u_k) \\times x_j
    + (u_j - u_i) \\times x_k \\rangle \\quad (2H\\,dA)\\\\
    \\mu_2 &= \\tfrac12 \\langle u_i \\mid u_j \\times u_k \\rangle \\quad (K\\,dA)\\\\
    \\mu^{X,Y} &= \\tfrac12 \\langle ū \\mid \\langle Y \\mid u_k - u_i \\rangle X \\times (x_j - x_i)
    - \\langle Y \\mid u_j - u_i \\rangle X \\times (x_k - x_i) \\rangle

Each measure is summed over the ball ``B(x_v, r)`` (every face weighted by its
approximate share inside the ball, see :func:`meshcurv.neighborhoods.face_in_ball_ratios`)
and divided by the corrected area ``mu_0(B)``: ``H = mu_1 / (2 mu_0)``,
``K = mu_2 / mu_0``, and the shape operator is ``-sym(mu^{X,Y}) / mu_0``
restricted to the tangent plane of ``u_v``; its eigenvectors are the principal
directions. The principal curvatures are taken from the two scalar measures,
whose convergence the paper proves, ``k = H -/+ sqrt(max(H^2 - K, 0))``: the
eigenvalues of the ball-summed tensor carry a bias of order ``(r k)^2`` (the
tangent planes turn inside the ball), several times larger than that of
``mu_1`` and ``mu_2`` (on a torus with 2.5 edge lengths: 5% against 0.5%).

Boundaries need no special case beyond the fitted normals: the measures and
the corrected area both stop at the boundary, so boundary vertices are valid.

Every ball (of the noise fits, the normal fits and the sums) is the piece of
the Euclidean ball connected to its vertex on the mesh through the edges and
faces that meet it (``adjacency=`` of :func:`~meshcurv.jets.fit_jets`,
``connected=`` of :func:`~meshcurv.neighborhoods.ball_face_sums`): the
Euclidean ball wherever the surface inside it is connected; a ball that
reaches another sheet of the surface (the far side of a part thinner than the
ball) leaves it out. Both backends compute these balls (the compiled kernels
walk them breadth-first, the NumPy path finds them by connected components),
so the default radius and the curvatures do not depend on whether numba is
installed (issue 29: a 3 x 3 x 0.15 ellipsoid had a default radius of 0.118
with numba and 0.538 without).

References
----------
F. Cazals and M. Pouget (2005). Estimating differential quantities using
polynomial fitting of osculating jets. Computer Aided Geometric Design 22(2),
121-146. https://doi.org/10.1016/j.cagd.2004.09.004

J.-O. Lachaud, P. Romon, B. Thibert, D. Coeurjolly (2020). Interpolated
corrected curvature measures for polygonal surfaces. Computer Graphics Forum
39(5), 41-54. https://doi.org/10.1111/cgf.14067
"""

from __future__ import annotations

import numpy as np

from .._backend import numba_kernels
from .._tensors import principal_from_mean_gaussian, principal_from_shape_operator
from ..geometry import robust_mean_edge_length, vertex_edge_lengths
from ..jets import fit_jet_normals, fit_jets
from ..lattice import voxel_grid
from ..neighborhoods import ball_face_sums, check_radius, default_radii
from ..topology import MeshTopology
from ._common import Stages, nan_where
from ._support import finish, prepare

#: Degree of the jets whose normals the measures interpolate.
NORMAL_DEGREE = 3

#: The normals are fitted over balls this many times the measure radius.
NORMAL_RADIUS_RATIO = 3.0

#: Fits per normal: the first in the frame of the mean of the face normals, the next in that of the first fit.
NORMAL_ITERATIONS = 2

#: The noise level is measured with degree-2 jets over balls of this many local edge lengths.
NOISE_FIT_RADIUS = 2.0

#: A fitted normal is kept where its cosine with the mean of the face normals exceeds this (60 degrees).
NORMAL_AGREEMENT = 0.5

#: A vertex whose first fit tilts its normal less than 0.5 degrees from the first frame
#: (slope ``c10^2 + c01^2`` below this) keeps that fit: the second, in the frame of the
#: fit's normal, would turn it by 2e-6 degrees on a clean sphere (random or regular),
#: 0.04 on a noisy ellipsoid, 0.5 at most on a scanned or CAD model. Every vertex of a clean,
#: regular mesh is spared the second fit (the mean of its face normals is within 0.03
#: degrees), about half of those of a scan. From a sweep over the surfaces of
#: ``benchmarks/accuracy.py`` (all families and levels, and the ``--voxel`` family):
#: 0.25, 0.5 and 1 degree move no error by more than the coarsest torus moves between
#: them (a few percent, either way; the others within 1.6%), 2 degrees make that torus's
#: median k_max error 65% larger.
NORMAL_SETTLED = float(np.tan(np.radians(0.5)) ** 2)

#: Noise levels (in mean edge lengths) up to this count as a clean mesh: the
#: fit's own bias on smooth surfaces sampled with 8 or more edges per radius of curvature.
NOISE_FLOOR = 0.005

#: Growth of the default radius, in edge lengths, with the square root of the noise above the floor.
NOISE_GAIN = 9.0

#: The noise level of a larger mesh is measured on this many of its vertices, evenly spaced in index order.
NOISE_SAMPLE = 65536

#: A given radius below this many median edge lengths is named in the warning (the registry's
#: ``radius_warning_edges``): on random spheres of 200
#: and 2,000 vertices 15-16% of the vertices are off by more than half the curvature at 0.35 edges, 0-0.7% at
#: 0.5, none from 0.7 (the default is one mean edge on a clean mesh).
RADIUS_WARNING_EDGES = 0.6


STAGES = ("compute normals", "measure noise", "fit normals", "compute face measures", "sum over balls",
          "retrieve curvatures")


def face_measures(vertices: np.ndarray, faces: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """(F, 9) per-face ``mu_0, mu_1, mu_2`` and the symmetrized ``mu^{X,Y}`` (xx, yy, zz, xy, xz, yz).

    Written relative to the first corner, so that a translation of the mesh
    changes nothing (the sum ``(u_k - u_j) + (u_i - u_k) + (u_j - u_i)`` is 0).
    The compiled kernel when numba is there (0.4 s for 2M faces against 3 s).
    """
    kernels = numba_kernels("icc")
    if kernels is not None:
        return kernels.face_measures(np.ascontiguousarray(vertices, dtype=np.float64),
                                     np.ascontiguousarray(faces, dtype=np.int64),
                                     np.ascontiguousarray(normals, dtype=np.float64))
    x0, x1, x2 = (vertices[faces[:, k]] for k in range(3))
    u0, u1, u2 = (normals[faces[:, k]] for k in range(3))
    x01, x02 = x1 - x0, x2 - x0
    u01, u02 = u1 - u0, u2 - u0
    um = (u0 + u1 + u2) / 3
    mu0 = 0.5 * np.einsum("ij,ij->i", um, np.cross(x01, x02))
    mu1 = 0.5 * np.einsum("ij,ij->i", um, np.cross(u0 - u2, x01) + np.cross(u1 - u0, x02))
    mu2 = 0.5 * np.einsum("ij,ij->i", u0, np.cross(u1, u2))
    # mu^{X,Y} = X^T M Y with M = 1/2 [ (x01 x um) (u02)^T - (x02 x um) (u01)^T ]
    a, b = np.cross(x01, um), np.cross(x02, um)
    m = 0.5 * (a[:, :, None] * u02[:, None, :] - b[:, :, None] * u01[:, None, :])
    sym = np.stack([m[:, 0, 0], m[:, 1, 1], m[:, 2, 2], 0.5 * (m[:, 0, 1] + m[:, 1, 0]),
                    0.5 * (m[:, 0, 2] + m[:, 2, 0]), 0.5 * (m[:, 1, 2] + m[:, 2, 1])], axis=1)
    return np.column_stack([mu0, mu1, mu2, sym])


def curvatures_from_measures(summed: np.ndarray, normals: np.ndarray):
    """``k_min, k_max, dir_min, dir_max`` of (N, 9) corrected measures summed over balls (rows of :func:`face_measures`).

    ``H = mu_1 / (2 mu_0)``, ``K = mu_2 / mu_0``, ``k = H -/+ sqrt(max(H^2 - K, 0))``
    (:func:`meshcurv._tensors.principal_from_mean_gaussian`), and the
    directions of the shape operator ``-sym(mu^{X,Y}) / mu_0`` restricted to
    the plane normal to each row of ``normals`` (N, 3), unit. All NaN in a row
    whose corrected area ``mu_0`` is not positive or whose normal is not finite.
    One pass with the compiled kernels.
    """
    kernels = numba_kernels("icc")
    if kernels is not None:
        return kernels.curvatures_from_measures(np.ascontiguousarray(summed, dtype=np.float64),
                                                np.ascontiguousarray(normals, dtype=np.float64))
    area = summed[:, 0]
    good = (area > 0) & np.isfinite(normals).all(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = summed[:, 1] / (2 * area)
        gaussian = summed[:, 2] / area
        shape_operator = -summed[:, 3:] / area[:, None]
    k_min, k_max = principal_from_mean_gaussian(mean, gaussian)
    _, _, dir_min, dir_max = principal_from_shape_operator(np.where(good[:, None], shape_operator, 0.0),
                                                           np.where(good[:, None], normals, [0.0, 0.0, 1.0]))
    nan_where(~good, k_min, k_max, dir_min, dir_max)
    return k_min, k_max, dir_min, dir_max


def fitted_normals(vertices: np.ndarray, normals: np.ndarray, valid: np.ndarray, radius: float, *,
                   neighbours: np.ndarray | None = None, adjacency: tuple | None = None) -> np.ndarray:
    """(V, 3) unit normals of weighted degree-:data:`NORMAL_DEGREE` jets over balls of ``radius``.

    Only the ``neighbours`` (V,) bool vertices enter the balls (default: all;
    the estimator passes the referenced vertices). ``normals`` (the first
    frames) is kept where no jet could be fitted, and
    where the fitted normal turns more than 60 degrees (:data:`NORMAL_AGREEMENT`)
    from it: the ball then reached another sheet of the surface (the far side
    of a part thinner than the ball, a voxel surface's tip) and the fit
    describes neither. ``adjacency``: the mesh's edge lists, so that each ball
    is its surface-connected piece (:func:`meshcurv.jets.fit_jets`).
    """
    start = np.where(valid[:, None], normals, [0.0, 0.0, 1.0])
    fitted = fit_jet_normals(vertices, start, radius, degree=NORMAL_DEGREE, iterations=NORMAL_ITERATIONS,
                             neighbours=neighbours, adjacency=adjacency, settled=NORMAL_SETTLED)
    with np.errstate(invalid="ignore"):
        usable = valid & (np.einsum("ij,ij->i", fitted, start) > NORMAL_AGREEMENT)
    return np.where(usable[:, None], fitted, normals)


def noise_level(vertices: np.ndarray, normals: np.ndarray, valid: np.ndarray, edges: np.ndarray, *,
                neighbours: np.ndarray | None = None, adjacency: tuple | None = None) -> float:
    """Median distance of the vertices to degree-2 jets fitted around them, in local edge lengths.

    The local edge length ``h_v`` of a vertex is the mean length of its edges.
    The vertices are taken by class of ``h_v`` (powers of two around the
    median, so that a mesh of even resolution is one class), and each jet is
    fitted over the ball of :data:`NOISE_FIT_RADIUS` times the mean ``h_v`` of
    its class, the vertex included; its distance is measured in that mean. On a
    smooth, clean mesh the distance is the fit's bias (below
    :data:`NOISE_FLOOR`); under normal noise of uniform amplitude ``a h`` it is
    about ``0.23 a`` (0.1 h: 0.020-0.028). Local classes keep a mesh whose
    resolution varies (a decimated model, 40x between its shortest and longest
    edges) from reading its fine detail as noise at the scale of its mean edge.
    On a mesh of more than :data:`NOISE_SAMPLE` valid vertices, the median is
    taken over that many of them, evenly spaced in index order (the median of
    65536 draws is within about 1% of that of all vertices; a re-indexing then
    changes the level, and the default radius, by that much). A fit whose first
    frame is settled (:data:`NORMAL_SETTLED`) is not refitted in its own frame, as
    for the normals: the level moves by less than 0.1% (7e-4 at most on clean and
    noisy spheres and tori; none above 0.02 h of noise), and a clean mesh needs
    half the fits. 0 when no jet could be fitted.
    """
    local = vertex_edge_lengths(vertices, edges)
    centres = np.flatnonzero(valid & (local > 0))
    if centres.size > NOISE_SAMPLE:
        centres = centres[np.linspace(0, centres.size - 1, NOISE_SAMPLE).round().astype(np.int64)]
    if centres.size == 0:
        return 0.0
    scale = local[centres]
    level = np.round(np.log2(scale / np.median(scale))).astype(np.int64)
    distances = np.full(centres.size, np.nan)
    for k in np.unique(level):
        members = np.flatnonzero(level == k)
        radius = NOISE_FIT_RADIUS * scale[members].mean()
        coefficients, _, _ = fit_jets(vertices, normals, radius, degree=2, centres=centres[members],
                                      neighbours=neighbours, adjacency=adjacency, compact=True,
                                      settled=NORMAL_SETTLED)
        # the constant term is in units of the radius: NOISE_FIT_RADIUS class mean edge lengths
        distances[members] = np.abs(coefficients[:, 0]) * NOISE_FIT_RADIUS
    distances = distances[np.isfinite(distances)]
    return float(np.median(distances)) if distances.size else 0.0


def default_radius(noise: float, edge_length: float) -> float:
    """The default measure radius of a mesh of this noise level and mean edge length."""
    return edge_length * (1.0 + NOISE_GAIN * np.sqrt(max(noise - NOISE_FLOOR, 0.0)))


def voxel_radius(spacing: np.ndarray, curvature_radius: float) -> float:
    """The default measure radius of a voxel surface: ``min(1.5 sqrt(h R), R / 2)``, at least ``h``.

    ``h`` is the largest voxel size, ``R`` the typical radius of curvature of
    the surface. The staircase of the voxels is noise of amplitude ``h`` that
    a ball of radius ``r`` averages down as ``h / r``, while the ball's own
    bias grows as ``(r / R)^2``: the error is smallest for ``r`` of order
    ``sqrt(h R)`` (Lachaud et al. 2020, digitised surfaces). The factor 1.5
    and the cap ``R / 2`` (beyond it the normals, fitted over three radii,
    reach round the shape) come from a sweep over the marching-cubes meshes of
    ``benchmarks/accuracy.py`` (spheres, ellipsoids and tori, voxels 1:1:1 to
    4:1:1, ``python benchmarks/accuracy.py --voxel-sweep``).
    """
    h = float(np.max(spacing))
    return float(max(h, min(VOXEL_GAIN * np.sqrt(h * curvature_radius), VOXEL_CAP * curvature_radius)))


#: The voxel radius rule ``min(VOXEL_GAIN sqrt(h R), VOXEL_CAP R)`` (see :func:`voxel_radius`).
VOXEL_GAIN = 1.5
VOXEL_CAP = 0.5

#: The typical radius of curvature of a voxel surface is measured with a first pass at this many voxels.
VOXEL_PILOT = 2.0
#: The percentile of the pilot's curvedness ``max(|k_min|, |k_max|)`` over the
#: surface's vertices whose inverse is the typical radius of curvature ``R``.
#: The 75th rather than the median: on the benchmark's ellipsoids (voxel sizes
#: 0.2-1, isotropic and 1 x 0.5 x 0.5 and 2 x 0.5 x 0.5) the median let the most
#: curved quarter of the surface be averaged over balls larger than its radius
#: of curvature (median H error of a flat ellipsoid 33% against 11%); the tori
#: lose at most 2 points (benchmarks/accuracy_voxel.md).
VOXEL_CURVEDNESS_PERCENTILE = 75.0


def voxel_surface_radius(vertices: np.ndarray, topology: MeshTopology) -> tuple[float, dict] | None:
    """The default radius of a voxel surface and what it was derived from, or None for other meshes.

    The grid is found on the referenced vertices (:func:`meshcurv.lattice.voxel_grid`);
    the typical radius of curvature ``R`` is the inverse of the
    :data:`VOXEL_CURVEDNESS_PERCENTILE` th percentile of ``max(|k_min|, |k_max|)``
    over the referenced, valid vertices, from a first pass of this estimator at
    :data:`VOXEL_PILOT` voxels; the radius is :func:`voxel_radius`. Used for every method that
    takes a radius, so that ``quadric`` and ``normal_cycle_ball`` average the
    staircase out as ``icc`` does.
    """
    referenced = topology.referenced_vertices
    grid = voxel_grid(vertices[referenced])
    if grid is None:
        return None
    _, degenerate, _, normals, valid = prepare(vertices, topology)
    pilot = VOXEL_PILOT * float(np.max(grid.spacing))
    k_min, k_max, *_ = _curvatures(vertices, topology.faces, degenerate, normals, valid, pilot,
                                   neighbours=referenced, adjacency=_adjacency(topology))
    curvedness = np.maximum(np.abs(k_min), np.abs(k_max))
    curvedness = curvedness[referenced & valid & np.isfinite(curvedness) & (curvedness > 0)]
    if curvedness.size == 0:
        return None
    curvature_radius = 1.0 / float(np.percentile(curvedness, VOXEL_CURVEDNESS_PERCENTILE))
    return voxel_radius(grid.spacing, curvature_radius), {
        "surface": "voxel", "voxel_spacing": tuple(float(x) for x in grid.spacing),
        "curvature_radius": curvature_radius}


def _adjacency(topology: MeshTopology) -> tuple:
    """The edge lists the ball searches walk (both backends: the surface-connected balls)."""
    return topology.neighbour_lists


def _curvatures(vertices, faces, degenerate, normals, valid, radius, stages: Stages | None = None, *,
                neighbours: np.ndarray | None = None, adjacency: tuple | None = None):
    """``k_min, k_max, dir_min, dir_max, normals, valid`` of the measures over balls of ``radius``.

    ``valid`` is not changed: the vertices whose ball has no corrected area
    are left out of the one returned. The balls of the normal fits and of the
    sums are the surface-connected pieces of the Euclidean balls when
    ``adjacency`` is given (the same wherever the surface within the ball is
    connected; see :func:`meshcurv.neighborhoods.ball_face_sums`).
    """
    def start(stage):
        if stages is not None:
            stages.start(stage)

    start("fit normals")
    if radius > 0:
        normals = fitted_normals(vertices, normals, valid, NORMAL_RADIUS_RATIO * radius, neighbours=neighbours,
                                 adjacency=adjacency)

    start("compute face measures")
    finite = np.isfinite(normals).all(axis=1)
    kept = ~degenerate if finite.all() else ~degenerate & finite[faces].all(axis=1)
    measures = face_measures(vertices, faces, normals)  # rows of the faces left out are not read

    start("sum over balls")
    summed = ball_face_sums(vertices, faces, radius, measures, usable=None if kept.all() else kept, connected=True)

    start("retrieve curvatures")
    k_min, k_max, dir_min, dir_max = curvatures_from_measures(summed, normals)
    valid = valid & np.isfinite(k_min)
    return k_min, k_max, dir_min, dir_max, normals, valid


def estimate(vertices: np.ndarray, topology: MeshTopology, *, radius, stages: Stages):
    """Interpolated corrected curvature measures over balls. Returns ``(result, problems)``."""
    stages.start("compute normals")
    _, degenerate, defects, normals, valid = prepare(vertices, topology)

    stages.start("measure noise")
    referenced = topology.referenced_vertices
    if radius is None:  # each group of components of one scale (usually the whole mesh) at its own default
        groups, levels = [], []
        for _group_radius, members in default_radii(vertices, topology):
            inside = valid if members is None else valid & np.isin(np.arange(vertices.shape[0]), members)
            edges = topology.edges if members is None else topology.edges[inside[topology.edges[:, 0]]]
            edge_length = robust_mean_edge_length(vertices, edges)
            level = (noise_level(vertices, normals, inside, edges, neighbours=referenced,
                                 adjacency=_adjacency(topology))
                     if edge_length > 0 else 0.0)
            groups.append((float(default_radius(level, edge_length)), members))
            levels.append(level)
        found = {"surface": "smooth", "noise": levels[0] if len(levels) == 1 else levels}
    else:
        groups, found = [(check_radius(radius, vertices, topology), None)], {}
    # one radius; a list of them (one per group of components of one scale) when the scales differ
    radii = [group_radius for group_radius, _ in groups]
    parameters = {"radius": radii[0] if len(radii) == 1 else radii,
                  "normal_radius": NORMAL_RADIUS_RATIO * radii[0] if len(radii) == 1
                  else [NORMAL_RADIUS_RATIO * r for r in radii], **found}
    fields: tuple[np.ndarray, ...] | None = None
    for group_radius, members in groups:
        computed = _curvatures(vertices, topology.faces, degenerate, normals, valid, group_radius,
                               stages if fields is None else None, neighbours=referenced,
                               adjacency=_adjacency(topology))
        if members is None:
            fields = computed
            continue
        if fields is None:
            fields = tuple(np.array(field, copy=True) for field in computed)
        for field, values in zip(fields, computed):
            field[members] = values[members]
    if fields is None:
        raise RuntimeError("default_radii gave no group")
    k_min, k_max, dir_min, dir_max, normals, valid = fields
    return finish("icc", parameters, valid, normals, k_min, k_max, dir_min, dir_max, defects)
