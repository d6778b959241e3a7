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
radii over the surfaces of ``benchmarks/accuracy.py``. Where the sampling of
the mesh changes (a part two or more times coarser or finer than the median
edge), each vertex takes that radius times its local factor
(:func:`meshcurv.radius.local_scale_ratios`; ``parameters["scale"] ==
"local"``, ``result.radius`` per vertex) and the normal fits weigh each point
by its area. Where a patch of the mesh is noisier than the rest (faces
detached off the surface, a scanned region), its vertices take the radius of
their own noise (:func:`meshcurv.radius._patch_radii`: the spread of the noise
fits' signed offsets over two rings, at least twice the group's radius to
count; ``parameters["scale"] == "local"``): a unit icosphere with Gaussian
noise of 0.19 h on a cap had 1,248 of 5,762 vertices off by more than half of
H at one edge length, 2 now; beside cracks and faces detached beyond the weld,
where a ball holds less than 0.8 of its disc while faces it cannot reach lie
within it, up to twice the radius (:func:`meshcurv.radius._holed_factor`). On dense voxel surfaces
(normal-fit balls wider than 16 edge lengths, marching cubes of fine voxels) the normals are fitted
on clusters of vertices (:func:`fitted_normals`); on other meshes at every vertex over the vertices, whatever the
radius (clusters in cubes of the coordinate axes made the numbers depend on the pose: issue 29, fuzz_api 690/40). On voxel surfaces each vertex takes the radius its
pilot pass calls for (:func:`meshcurv.radius.voxel_vertex_radii`:
``2 sqrt(h_v R)`` for the voxel extent ``h_v`` along its normal, capped where
the surface bends fast; ``parameters["scale"] == "voxel"``); the pilot runs at
about half of the vertices (:func:`voxel_pilot`; in anisotropic voxels its normals
are fitted on a coarse level too, at about one of its centres in two, and its sums
taken at a sample of its centres, :func:`_pilot_normals`, :func:`_sampled_face_sums`),
and where the balls of such a surface hold 800 faces or more (fine voxels), each
ball is summed on clusters of about 32 faces, the clusters on its rim by their
share of the ball (:func:`meshcurv.neighborhoods.coarse_face_sums`): the cost of
a ball no longer grows with the density of its faces (``benchmarks/dense_voxel.md``).

The normals ``u_i`` are interpolated linearly over each triangle; the
curvature measures ``mu_0`` (corrected area), ``mu_1`` (2H dA), ``mu_2`` (K dA)
and ``mu^{X,Y}`` of the corrected normal current then have closed forms per
face (:mod:`meshcurv.measures`).

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
The boundaries of voxel surfaces (holes, rims) are the exception
(:func:`_holed_balls`): a face of the staircase does not lie along the
surface, and its measures are the surface's curvature only summed with those
of its neighbours; with faces gone from the ball the sum is noise (issue 29:
``shapes.voxel_sphere(4)`` with half of its faces removed, 14 of 421 valid
vertices off by more than half of H). There a ball that meets a boundary edge
and holds less than :data:`HOLE_SHARE` of its disc's corrected area is grown
by ``HOLE_SHARE / share`` (at most :data:`HOLE_GROWTH`); a vertex whose grown
ball still holds less than :data:`HOLE_MIN_SHARE` (a small piece between
holes) is undefined, and so is one whose ball holds pieces of both
orientations (:data:`HOLE_FACING`: holes split a surface into patches, each
oriented on its own, and a small patch of a marching-cubes mesh keeps its
inward winding). Near the holes of other meshes (cracks, faces detached
beyond the weld: :func:`_near_holes`), a normal fit whose ball wraps around the surface (it holds
points facing away: three radii on a coarse sphere reach past its equator) is
made again over half of it, and a cubic over a dozen points of a strip gives
way to the quadric over them where the two disagree (:func:`_unwrapped_normals`):
the points left there are lopsided and tilted the fits by up to 56 degrees
(issue 29, fuzz 366/3537: H 0.35 for 1). The normals of a voxel surface, and
of any surface with boundary edges, are fitted at every corner of a face
summed (:func:`_corners_fitted`), not only at the vertices measured:
holes leave many vertices on bow-ties and strips, undefined as centres but
corners of their neighbours' faces, and the mean of their face normals (18 to
40 degrees off on a staircase) made H low by 0.1 to 0.18 of the curvature on
average (a voxel sphere in 2 x 1 x 1 voxels with half of its faces removed).
Near such holes, a vertex whose normal fit held few points (a piece of a triangle soup between cracks,
whose fit sees only its own corners) and whose faces scatter off its corners' fitted normals is undefined
(:func:`_scattered_pieces`): the scatter of a few points drives its normal, and the cracks around its small ball
carry that into H (issue 29: every face of ``icosphere(24)`` detached by 0.03 edges, 191 of 9,834 valid vertices
off the sphere's H by more than half of it); so is a vertex whose ball holds a small piece of a staircase
(:func:`_stair_pieces`: a voxel surface's soup, fuzz 395/99).

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

Where the part is thinner than the ball and its rim lies within it, the connected
ball holds the other side, round the rim, on one side of the centre. A normal fit
whose ball holds points facing away (by the vertex normals, in the fit's own walk)
is made again without that check, and where the cubic over its own side hardly
bends (:data:`SMOOTH_THIN_BEND`; a ball wraps round its own bend only where ``k r``
reaches about ``sqrt(2)``) over its own side (:func:`meshcurv.jets._thin_part_normals`;
on a voxel surface over wider balls, its terraces); a ball of the sums whose
faces' area vectors face the centre's way far less than a ball of its own
curvatures would (:data:`THIN_FACING`) holds both sides, and its vertex is
undefined with the reason "ball reaches round the surface". (Issue 29: the clean
ellipsoid (3, 3, 0.15) at 16 subdivisions, every vertex valid and H of the wrong
sign over 0.8-0.95 of its radius, 1,048 vertices off by more than half of the
largest ``|k|``; none now, 844 undefined at the rim; ``benchmarks/thin_band_T68.md``.)
Where a fit was so made again, its vertex's sums are read again over a ball :data:`THIN_WIDER` times wider, and it
is undefined for the same reason where that ball reaches round the part (:func:`_wider_reaching`): towards the rim
the curvature grows fast, and a ball that stops short of it reads up to twice the centre's H (given radii of 0.25
and 0.35 on that ellipsoid: 56 and 148 valid vertices off, none now; ``benchmarks/thin_band_T68.py --radii``). A fit
made again that turns further from the face normals than a first fit the other side did not tilt
(:data:`THIN_FURTHER`, :data:`THIN_FIRST`: a tube thinner than the ball, whose own side reads flat) keeps the first.
A coarse closed mesh whose balls wrap round its own bend (an icosahedron, a torus
of 8 x 4 vertices) keeps its values: those balls are symmetric and their fits right.

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

import dataclasses

import numpy as np

from .._geometry import face_areas, finite_rows, median_edge_length
from .._backend import numba_kernels
from .._tensors import tangent_basis
from ..jets import (
    THIN_BEND,
    THIN_WIDEN,
    AWAY_FRACTION,
    NORMAL_MIN_SPREAD,
    SAMPLED_SPREAD,
    SETTLED_SLOPE,
    _cube_samples,
    _fit_jet_normals,
    _fit_jets,
    _nearest_in_cubes,
    _sampled_jet_normals,
    _thin_part_normals,
    interpolated_normals,
    jet_normals,
    nested_jet_normals,
    turned_cubes,
)
from .._measures import curvatures_from_measures, face_measures, principal_from_measures
from ..neighborhoods import (
    _ball_face_sums,
    _ball_face_sums_nested,
    _coarse_face_sums,
    _squared,
    _unique_inverse,
    _unique_sorted,
)
from ..radius import (
    VOXEL_EXTENT_CAP,
    VOXEL_SCALE_RULE,
    _check_radius,
    _local_scale_ratios,
    _noise_radii,
    _patch_radii,
    _scale_centres,
    _vertex_radii,
    VoxelReading,
    _voxel_surface,
    scale_ladder,
    stable_scales,
)
from .._prepared import PreparedMesh
from ..topology import MeshTopology
from ..defects import REACH
from ._support import Stages, failed_fits_undefined, finish

#: Degree of the jets whose normals the measures interpolate.
NORMAL_DEGREE = 3

#: The normals are fitted over balls this many times the measure radius.
NORMAL_RADIUS_RATIO = 3.0

#: Fits whose first frame tilts the normal less than this are not refitted (:data:`meshcurv.jets.SETTLED_SLOPE`).
NORMAL_SETTLED = SETTLED_SLOPE

#: Fits per normal: the first in the frame of the mean of the face normals, the next in that of the first fit.
NORMAL_ITERATIONS = 2

#: On a voxel surface, normal fits over balls wider than this many median edge lengths are fitted
#: on a coarser level of the surface (dense voxel surfaces: 20-40 edge lengths, balls of thousands of vertices;
#: other meshes are fitted over their vertices at any radius: :func:`fitted_normals`) ...
COARSE_EDGES = 16.0
#: ... of clusters in cubes of 1 / COARSE_CELLS of the normal-fit radius (a ball then holds about 300 of them;
#: 6 and 8 made the marching-cubes sphere r 1 at voxel 0.05 of ``benchmarks/accuracy.py`` 13% worse, 10 is
#: within 4% of the fits over every vertex on each binary marching-cubes mesh there, ``benchmarks/scale_default.py``).
COARSE_CELLS = 10.0
#: Components of a unit normal within this of its largest count as the largest (:func:`_coarse_level`'s side of a
#: cluster): exact ties differ by round-off (1e-16); the normals of a lattice that differ at all, by far more.
AXIS_TIE = 1e-9
#: ... a side read from the normals summed over this many rings (:func:`_side_normals`; 0: each vertex's own).
SIDE_RINGS = 2

#: A fitted normal is kept where its cosine with the mean of the face normals exceeds this (60 degrees).
NORMAL_AGREEMENT = 0.5

#: A given radius below this many median edge lengths is named in the warning (the registry's
#: ``radius_warning_edges``): on random spheres of 200
#: and 2,000 vertices 15-16% of the vertices are off by more than half the curvature at 0.35 edges, 0-0.7% at
#: 0.5, none from 0.7 (the default is one mean edge on a clean mesh).
RADIUS_WARNING_EDGES = 0.6

#: On a voxel surface, a ball that meets a boundary edge (a hole's or a rim's) and whose corrected area is below
#: this share of its disc's ``pi r^2`` (an intact ball: 0.8 to 1) is grown (:func:`_holed_balls`; the edges of
#: holes alone, :func:`meshcurv.estimators.normal_cycle_ball.hole_edges`, gave the same errors on holed voxel
#: spheres, at twice the time: a voxel rim's teeth read as holes) ...
HOLE_SHARE = 0.8
#: ... by ``HOLE_SHARE / share``, at most this factor (the noise of a holed staircase falls with the ball's
#: radius, not only with its area: growing to the intact ball's area, ``sqrt(HOLE_SHARE / share)``, left 13 of
#: 3,987 valid vertices of a holed voxel sphere of radius 12 off by more than half of H, and a cap of 1.5 one) ...
HOLE_GROWTH = 2.0
#: ... and the vertex is undefined where the grown ball's corrected area is still below this share of its disc
#: (a piece of a few faces between holes: off by up to the whole curvature; at 0.1 a holed voxel torus read errors
#: of 0.45 of its largest curvature, at 0.2 and 0.25 0.35).
HOLE_MIN_SHARE = 0.2
#: ... or where the area vectors of the ball's faces, summed, along the vertex's normal are below this share of
#: the ball's corrected area (about 0.85 to 0.95 where the ball's faces are oriented alike): the ball holds
#: patches of both orientations (a patch between holes oriented on its own: its faces' ``mu_1`` of the other sign),
#: and H comes out of a sum that cancels (a voxel sphere in 2 x 1 x 1 voxels with 30% of its faces removed: 4 of
#: 1,549 valid vertices read H of the wrong sign, at -0.33 to -0.85 here; no other below 0.82; at 0.7, 200 more
#: vertices of a holed voxel torus undefined, none of them off).
HOLE_FACING = 0.5
#: A ball of the sums on a mesh (not a voxel surface at its default) holds the other side of a part thinner than it
#: where its faces' area vectors, summed, have a component along the centre's normal (over its corrected area: its
#: facing ``f``) below what a ball of its own curvatures would have by more than this: ``f < 1 - r^2 (k_1^2 +
#: k_2^2) / 8 - THIN_FACING`` (a sphere's ball: ``1 - (r k)^2 / 4`` exactly). Its sums then hold both sides, and
#: the vertex is undefined (reason :data:`meshcurv.defects.REACH`). Issue 29 (T68): the clean ellipsoid (3, 3, 0.15)
#: at 16 subdivisions, balls of 0.18 at its rim 0.06 to 0.13 thick: 0.72-0.86 below (H of the wrong sign at valid
#: vertices); the coarse closed meshes whose balls wrap round their own bend (an icosahedron, ``torus(3, 1, 8, 4)``,
#: ``icosphere(2)``) within 0.03, the coarse ellipsoid (3, 2, 1) at 4 subdivisions (162 vertices) up to 0.46.
THIN_FACING = 0.5
#: ... but only where the ball's area vectors ``a`` cancel too, as the two sides of a thin part do: the length of
#: their sum ``S`` over the corrected area lies more than this below the same ``1 - r^2 (k_1^2 + k_2^2) / 8`` ...
THIN_CANCEL = 0.3
#: ... and more than this of ``(n^T T n - n . S) / trace T`` (``T = sum a a^T / |a|`` the faces' sign-blind normal
#: tensor: a face at cosine ``c`` to the centre's normal ``n`` adds ``(c^2 - c)`` times its area, 2 facing away, 0
#: at right angles, at most 1/4 less facing ``n``'s way: ``g``, twice the share of the area facing away) says
#: that area faces away from ``n``. A low facing alone comes from a fold of one surface as well: the 90-degree
#: crease between a label's closing cap and its wall where the image border cuts it (T69: a hemisphere of radius 9
#: voxels cut on its equator, 19 vertices 0.5-1.5 voxels from the cap, their normals 23-57 degrees off the sphere's)
#: has ``f`` 0.11-0.41 for a ball of its curvatures' 0.88-0.93, but ``|S|`` only 0.17-0.26 below it (a fold's
#: faces at right angles, a share ``w`` of the area: ``f = 1 - w``, ``|S| = sqrt((1 - w)^2 + w^2)``, 0.71 at
#: ``w = 1/2``) and ``g`` 0.16-0.30 (0.38 at the vertex whose normal is 57 degrees off): each test alone leaves
#: a margin of 0.03-0.05 at most (the ellipsoid (1, 1, 0.08): ``g`` from 0.385; ``|S|`` alone at 0.35 let valid
#: vertices off by more than half of the largest ``|k|`` back, 288 -> 364), the two together none of the 19 and
#: the same vertices off on ``benchmarks/thin_band_T68.py`` as the facing alone. The label path leaves those
#: crease vertices out of its statistics anyway (:mod:`meshcurv.volume`).
THIN_OPPOSITE = 0.25
#: On a mesh other than a voxel surface at its default, a normal fit whose ball wraps round a part thinner than it
#: is fitted again over its own side where the same-side cubic's largest ``|k| r`` is below this
#: (:func:`meshcurv.jets._thin_part_normals`; a voxel surface's: :data:`meshcurv.jets.THIN_BEND`, its terraces'):
#: a ball wraps round its own bend only where ``k r`` reaches about ``sqrt(2)``.
SMOOTH_THIN_BEND = 1.0
#: A fit so made again is kept only where it turns no further from the mean of the face normals than the first fit,
#: by more than this many degrees, where the first lay within :data:`THIN_FIRST` of them (:func:`fitted_normals`).
#: The balls of a tube thinner than them (``torus(2, 0.08, 128, 8)`` at its default: normal fits over 0.87 round a
#: tube of 0.08) hold a strip of their own side that a cubic reads as flat; its fits turned the normals 20-23 degrees
#: off first fits within 1 degree of the face normals, and the median H error went 1.37% -> 4.45% (T68); kept: 1.37%
#: again. On the thin ellipsoids the first fits lie 8-56 degrees off the face normals and the fits made again turn
#: back towards them. With no margin the noisy and irregular coarse meshes of ``benchmarks/accuracy.py --quick``,
#: whose first fits and face normals differ by their noise, moved by up to 3 points of p95 either way; at 5 and 10
#: degrees none moved (T70). Not on a voxel surface (its wider fits, :data:`meshcurv.jets.THIN_WIDEN`): the face
#: normals of a staircase are no guide.
THIN_FURTHER = 10.0
#: ... A first fit further than this many degrees from the mean of the face normals was tilted (by the other side, a
#: fold, a feature narrower than the ball): its fit made again is kept whichever way it turns, as before
#: :data:`THIN_FURTHER`. The thin tube's first fits lie 0.2-1.0 degrees off. The real meshes' fits made again that
#: turn more than 10 degrees further start further off: ``spot`` (``tests/data/matgeom``, the README's example) one,
#: 7.2 degrees (at the tip of a horn, H 27-29: with its first fit, H no closer to the other estimators': at 12 of the
#: 34 vertices its normal moves), fandisk 15, 1.97-38.9 degrees; kept as they were (T71).
THIN_FIRST = 1.5
#: Where a normal fit was so made again (its ball reached round a thin part), the sums are read again over a ball
#: this many times wider (:func:`_wider_reaching`), and the vertex is undefined (reason
#: :data:`meshcurv.defects.REACH`) where that ball reaches round the part (:func:`_reaching`, with the curvatures
#: of the ball of the sums). Near the rim of a part thinner than the normal fits' balls the curvature grows fast
#: (the ellipsoid (3, 3, 0.15): ``|k|`` 0.2 at 0.9 of its radius, 133 at the rim), and a ball stopping short of the
#: rim reads up to twice the centre's H, with the exact normals too: at given radii of 0.25 and 0.35, 56 and 148
#: valid vertices off the exact H by more than half of the largest ``|k|``, none now; the ball ``sqrt(2)`` wider,
#: which reaches round, tells them (a bias growing as ``r^2``: twice as much). Gated on the fits made again: at every
#: fit whose ball held points facing away, the coarse ellipsoid (3, 2, 1) s4, whose balls wrap round its own bend,
#: lost 34 of its 162 vertices (errors 0.06-0.45); none so. T70 also made undefined the vertices where the wider
#: ball moved H by more than half of their largest ``|k|``: on the tuned ellipsoids no vertex so alone, but 498
#: vertices of fandisk (flat faces beside its creases, where ``|k|`` is round-off: the two backends parted at 10 of
#: them, fuzz 800/31) and one of ``spot`` (the README's example); dropped (T71).
THIN_WIDER = float(np.sqrt(2.0))


STAGES = (
    "compute normals",
    "measure noise",
    "fit normals",
    "compute face measures",
    "sum over balls",
    "retrieve curvatures",
)


def fitted_normals(
    vertices: np.ndarray,
    normals: np.ndarray,
    valid: np.ndarray,
    radius,
    *,
    neighbours: np.ndarray | None = None,
    adjacency: tuple | None = None,
    areas: np.ndarray | None = None,
    weighted: bool = False,
    failed: np.ndarray | None = None,
    fits: np.ndarray | None = None,
    edge: float | None = None,
    unwrap: np.ndarray | None = None,
    counts: np.ndarray | None = None,
    thin: bool = False,
    widen: float = THIN_WIDEN,
    coarse: bool = False,
    reaching: np.ndarray | None = None,
) -> np.ndarray:
    """(V, 3) unit normals of weighted degree-:data:`NORMAL_DEGREE` jets over balls of ``radius``.

    ``fits``: the (V, 3) jet normals at ``radius``, fitted already (:func:`estimate_multiscale`'s one
    walk, :func:`meshcurv.jets.nested_jet_normals`): used where the surface is not fitted on its
    coarse level.

    ``failed``: a (V,) bool array set True, in place, where no jet could be fitted (too few points, or a
    degenerate set).

    Only the ``neighbours`` (V,) bool vertices enter the balls (default: all;
    the estimator passes the referenced vertices). ``normals`` (the first
    frames) is kept where no jet could be fitted, and
    where the fitted normal turns more than 60 degrees (:data:`NORMAL_AGREEMENT`)
    from it: the ball then reached another sheet of the surface (the far side
    of a part thinner than the ball, a voxel surface's tip) and the fit
    describes neither. ``adjacency``: the mesh's edge lists, so that each ball
    is its surface-connected piece (:func:`meshcurv.jets.fit_jets`).

    ``edge``: the median edge length of :func:`_median_edge`, when the caller has it.

    ``unwrap`` (V,) bool: the vertices whose fits are checked for balls holding points that face away, and made
    again over smaller balls where they do (:func:`_unwrapped_normals`: the vertices near holes); ``counts`` (V,)
    float, when given, is set in place to the number of points of their first fits (unchanged elsewhere).

    ``thin``: the fits on thin flat parts (balls that wrap round a part thinner than them while their jets hardly
    bend) are made again over balls ``widen`` times wider of the points that face the centre's way
    (:func:`meshcurv.jets._thin_part_normals`; not on the coarse level): a voxel surface's over wider balls
    (:data:`meshcurv.jets.THIN_WIDEN`, its terraces; at samples of the centres), a smooth mesh's over the same balls
    at every centre (1: the other side of a
    thin rim tilted the fits of a clean ellipsoid (3, 3, 0.15) by 3.6-7 degrees over a band 0.8-0.95 of its radius,
    and H took the wrong sign there; issue 29, T68). ``reaching`` (V,) bool, when given: set True, in place, at
    the centres whose fits were so made again (a ball reaching round a thin part): :func:`_wider_reaching` reads their
    sums again over a wider ball.

    ``areas`` (V,): the vertex areas. With ``weighted``, each point of a fit
    weighs its area (a mesh whose sampling varies: a part sampled 100 times
    more densely does not outweigh its neighbour). With ``coarse`` (a voxel
    surface, :func:`_coarse_fits`, whose balls are wider than :data:`COARSE_EDGES`
    edge lengths: thousands of vertices), the jets are fitted on a coarser level
    of the surface (:func:`_coarse_level`), so that a fit costs about the same
    whatever the density. Its clusters and samples lie in cubes of the coordinate axes (a rotated
    surface gets other ones, and normals that differ within the fits' precision); on any other mesh the
    fits run over the vertices at every centre, whatever the radius: a given radius of 7.8 median edges on
    ``ogre.obj`` (fuzz_api 690/40, normal fits over 23 edges) put k apart by up to 16% of the largest
    ``|k|`` (median 1.1%) between two poses on the coarse level (issue 29), mostly from the samples'
    interpolation (fitted at every centre of the clusters: median 0.03%, largest 9-18%), at three times the
    CPU time now (6 -> 19 s; ``benchmarks/coarse_pose_C68.py``).
    """
    start = np.where(valid[:, None], normals, [0.0, 0.0, 1.0])
    level = None
    dense = False  # the coarse level's test first: an ordinary mesh's fits read no areas unless weighted
    if coarse and areas is not None and adjacency is not None:
        edge = _median_edge(vertices, adjacency) if edge is None else edge
        dense = _dense(vertices, float(np.median(radius)), adjacency, edge=edge)
    if areas is not None and (dense or weighted):  # in units of their median: weights of order 1 whatever the units
        positive = areas[areas > 0]
        areas = areas / np.median(positive) if positive.size else None
    if dense and areas is not None:
        level = _coarse_level(vertices, start, radius, areas, neighbours, adjacency, edge=edge)
    wrapped = None  # the fits refused for points facing away (a smooth mesh's thin parts: below)
    if level is not None:
        points, point_normals, allowed, lists, point_areas = level
        # the vertices measured only: the cubes of the samples start at their corner, which a vertex in no face
        # (no valid normal) would move
        centres = np.flatnonzero(valid)
        fitted = np.full((vertices.shape[0], 3), np.nan)
        fitted[centres] = _sampled_jet_normals(
            points,
            point_normals,
            radius if np.ndim(radius) == 0 else np.asarray(radius)[centres],
            degree=NORMAL_DEGREE,
            iterations=NORMAL_ITERATIONS,
            centres=centres,
            neighbours=allowed,
            adjacency=lists,
            settled=NORMAL_SETTLED,
            areas=point_areas,
            min_spread=NORMAL_MIN_SPREAD,
        )
    elif fits is not None:
        fitted = fits
        if thin and widen == 1.0 and adjacency is not None:  # the fits a first fit would refuse, as below
            wrapped = np.flatnonzero(valid & ~finite_rows(fitted))
            centres = np.flatnonzero(valid & finite_rows(fitted))
            details: dict = {}
            _fit_jets(  # the share facing away alone (the walk and the check, no moments: _thin_part_normals)
                vertices,
                start,
                radius if np.ndim(radius) == 0 else np.asarray(radius)[centres],
                degree=1,
                iterations=0,
                centres=centres,
                neighbours=neighbours,
                adjacency=adjacency,
                compact=True,
                facing=start,
                details=details,
            )
            with np.errstate(invalid="ignore"):
                wrapped = np.union1d(wrapped, centres[details["away"] > AWAY_FRACTION])
    else:
        smooth = thin and widen == 1.0 and adjacency is not None  # (a smooth mesh's thin parts: below)
        fitted = _fit_jet_normals(
            vertices,
            start,
            radius,
            degree=NORMAL_DEGREE,
            iterations=NORMAL_ITERATIONS,
            neighbours=neighbours,
            adjacency=adjacency,
            settled=NORMAL_SETTLED,
            areas=areas if weighted else None,
            min_spread=NORMAL_MIN_SPREAD,
            facing=start if smooth else None,
        )
        if smooth:  # the fits refused for holding points facing away (or failed), made again without the check
            wrapped = np.flatnonzero(valid & ~finite_rows(fitted))
            if wrapped.size:
                coefficients, frame, _ = _fit_jets(
                    vertices,
                    start,
                    radius if np.ndim(radius) == 0 else np.asarray(radius)[wrapped],
                    degree=NORMAL_DEGREE,
                    iterations=NORMAL_ITERATIONS,
                    centres=wrapped,
                    neighbours=neighbours,
                    adjacency=adjacency,
                    settled=NORMAL_SETTLED,
                    compact=True,
                    areas=areas if weighted else None,
                    min_spread=NORMAL_MIN_SPREAD,
                )
                fitted[wrapped] = jet_normals(coefficients, frame)
        if unwrap is not None and adjacency is not None:
            fitted = _unwrapped_normals(
                vertices,
                start,
                np.where(valid[:, None], fitted, normals),
                radius,
                valid & unwrap,
                neighbours,
                adjacency,
                areas if weighted else None,
                counts=counts,
            )
    if level is None and thin and adjacency is not None and (fits is None or wrapped is not None):
        if wrapped is None or wrapped.size:
            given = np.where(valid[:, None], fitted, normals)
            fitted = _thin_part_normals(
                vertices,
                given,
                radius,
                np.flatnonzero(valid) if wrapped is None else wrapped,
                neighbours=neighbours,
                adjacency=adjacency,
                degree=NORMAL_DEGREE,
                iterations=NORMAL_ITERATIONS,
                settled=NORMAL_SETTLED,
                min_spread=NORMAL_MIN_SPREAD,
                widen=widen,
                sampled=widen != 1.0,
                bend=THIN_BEND if widen != 1.0 else SMOOTH_THIN_BEND,
            )
            # a fit made again that turns further from the mean of the face normals than a first fit within
            # THIN_FIRST of them (THIN_FURTHER) keeps the first: the other side tilts a first fit off them, the same
            # side's strip of a thin tube not
            refitted = ~np.all((fitted == given) | (np.isnan(fitted) & np.isnan(given)), axis=1)
            with np.errstate(invalid="ignore"):
                first = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", given, start), -1.0, 1.0)))
                turn = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", fitted, start), -1.0, 1.0))) - first
                further = refitted & (turn > THIN_FURTHER) & (first < THIN_FIRST) & (widen == 1.0)  # (a staircase's
                # face normals: no guide)
            fitted[further] = given[further]
            refitted &= ~further
            if reaching is not None:  # the fits made again over their own side
                reaching |= refitted
    with np.errstate(invalid="ignore"):
        usable = valid & (np.einsum("ij,ij->i", fitted, start) > NORMAL_AGREEMENT)
    if failed is not None:
        failed |= valid & ~finite_rows(fitted)
    if fitted is fits:  # the caller's array: not written
        return np.where(usable[:, None], fitted, normals)
    np.copyto(fitted, normals, where=~usable[:, None])  # the fits' own array: no second (V, 3) one
    return fitted


#: Near a hole (:func:`_near_holes`), a normal fit whose ball holds more than :data:`meshcurv.jets.AWAY_FRACTION` of
#: its points facing away from its centre (the ball wraps around a bend of the surface: three measure radii on a
#: coarse mesh reach past the equator of a sphere of two edge lengths) is made again over a ball this many times
#: smaller (:func:`_unwrapped_normals`) ...
UNWRAP_SHRINK = 0.5
#: ... at most this many times (a ball still wrapped keeps its first fit). There, a fit over fewer points than
#: this (twice the ten coefficients of a cubic jet) ...
UNWRAP_STEPS = 1
FEW_POINTS = 20
#: ... is made of this degree too (a quadric: on ``shapes.uv_sphere()`` with half of its faces detached, cubics
#: over 12 points of a strip between cracks were 56 degrees off the sphere's normal, the quadric over them 2.5) ...
FEW_DEGREE = 2
#: ... whose normal replaces the cubic's where the two turn apart by more than this (the cosine of 8 degrees: at
#: the rim of an irregular hemisphere, whose one-sided balls hold 10-19 points too, they agree, and the rows of
#: ``benchmarks/accuracy.py`` are those without this; replaced everywhere, the rim's median H error went from
#: 0.40% to 0.49%; at 15 degrees 1 of 11,767 valid vertices of the cracked ``uv_sphere()`` stayed off, at 8 none).
FEW_AGREEMENT = float(np.cos(np.radians(8.0)))


def _unwrapped_normals(
    vertices, start, fitted, radius, valid, neighbours, adjacency, areas, *, counts=None
) -> np.ndarray:
    """(V, 3) :func:`fitted_normals`' jet normals near holes: ``fitted`` (V, 3), the normals of the fits over
    ``radius`` (the mean of the face normals where none was made), made again at the ``valid`` vertices whose ball
    wrapped or held few points.

    A ball of the normal fits (three measure radii) that holds points facing away from its centre (by ``fitted``;
    more than :data:`meshcurv.jets.AWAY_FRACTION` of its points: the fitted normals, not the faces', whose mean
    turns by up to 90 degrees between the vertices of a staircase) wraps around the surface, and a jet over the
    tangent plane describes no height function there. Where the surface around is whole such a ball is about
    symmetric and its normal comes out right (a coarse sphere, a cylinder under noise: smaller balls there are
    only noisier, so only the vertices near holes are checked here; the rim of a part thinner than the ball is
    the exception, :func:`fitted_normals` ``thin``); with holes, cracks or faces detached beyond the
    weld the points left are lopsided and tilt the fit (issue 29: ``shapes.uv_sphere(12, 8)``, half of its faces
    detached by 0.065 edge lengths: fitted normals 13.5 degrees off the sphere's at the median, 2.5 intact, and H
    of 0.35-0.85 for 1 at 10 of 59 valid vertices; with the exact normals the same sums give 1 to 0.004). Those
    fits are made again over balls :data:`UNWRAP_SHRINK` times smaller, at most :data:`UNWRAP_STEPS` times (one
    still wrapped keeps its first fit, and so does one left with fewer than :data:`FEW_POINTS` points unless the
    quadric over them disagrees: on the coarse torus of ``benchmarks/wide_cracks_icc.py``, 16 edges around its
    tube, cubics over half of a wrapped ball read H 0.007 for 0.06 at vertices left with one or two faces). A cubic over fewer than :data:`FEW_POINTS` points (a strip between
    cracks) gives way to the quadric over them where the two disagree (:data:`FEW_AGREEMENT`). ``counts`` (V,),
    when given, takes the number of points of each first fit (:func:`_scattered_pieces` reads them).
    """
    n = vertices.shape[0]
    facing, fitted = fitted, np.array(fitted, copy=True)
    centres = np.flatnonzero(valid & finite_rows(facing))
    radii = np.array(np.broadcast_to(np.asarray(radius, dtype=np.float64), (n,))[centres], copy=True)

    def fit(at, over, degree):
        details: dict = {}
        coefficients, frame, held = _fit_jets(
            vertices,
            start,
            over,
            degree=degree,
            iterations=NORMAL_ITERATIONS,
            centres=at,
            neighbours=neighbours,
            facing=facing,
            details=details,
            adjacency=adjacency,
            settled=NORMAL_SETTLED,
            compact=True,
            areas=areas,
            min_spread=NORMAL_MIN_SPREAD,
        )
        return jet_normals(coefficients, frame), held, details["away"]

    for step in range(UNWRAP_STEPS + 1):
        if not centres.size:
            break
        found, held, away = fit(centres, radii, NORMAL_DEGREE)
        if not step and counts is not None:
            counts[centres] = held
        with np.errstate(invalid="ignore"):
            wrapped = away > AWAY_FRACTION
        few = ~wrapped & (held < FEW_POINTS)
        if step:  # (the first fits are those given; a ball still wrapped, or left with few points, keeps them)
            fitted[centres[~wrapped & ~few]] = found[~wrapped & ~few]
        if few.any():  # a cubic through a dozen points of a lopsided ball: its slope can be the noise of the fit
            lower = fit(centres[few], radii[few], FEW_DEGREE)[0]
            with np.errstate(invalid="ignore"):
                unsteady = np.einsum("ij,ij->i", lower, fitted[centres[few]]) < FEW_AGREEMENT
            fitted[centres[few][unsteady]] = lower[unsteady]
        centres, radii = centres[wrapped], radii[wrapped] * UNWRAP_SHRINK
    return fitted


def _coarse_level(vertices, normals, radius, areas, neighbours, adjacency, *, edges=None, cells=None, edge=None):
    """The points of the normal fits of a dense surface: clusters of vertices, or None for an ordinary mesh.

    Used when the median ``radius`` exceeds ``edges`` (default :data:`COARSE_EDGES`) median edge lengths. The
    vertices that may enter the balls are grouped by cube of side ``median radius / cells`` (default
    :data:`COARSE_CELLS`; :func:`meshcurv.jets.turned_cubes`: no boundary through a voxel surface's lattice, where
    a given radius of 10 voxels put 378 vertices of a ball of 8.3 voxels when the cubes started at the lowest
    vertex, and round-off chose their cubes, 1,532 clusters at unit spacing and 1,533 at 0.7; a mirror image of the
    surface gets the mirrored cubes) and by the axis and sign of their normal's largest component (the two
    sides of a part thinner than a cube stay apart; the components tied with it, :data:`AXIS_TIE`, with theirs;
    the normals summed over :data:`SIDE_RINGS` rings, :func:`_side_normals`, not the staircase's own);
    each group is one point at its area-weighted centroid,
    weighing the group's area, linked to the groups that a mesh edge joins it to. Returns ``(points,
    normals, allowed, (indptr, indices), areas)`` over V + C points: the V vertices come first, each linked
    to its own group only and not allowed in a ball (the fit of vertex ``v`` is centred on it and walks the
    groups from its own), the C groups after them.
    """
    n = vertices.shape[0]
    inside = np.ones(n, dtype=bool) if neighbours is None else np.asarray(neighbours, dtype=bool)
    inside = inside & (areas > 0)
    if not inside.any():
        return None
    typical = float(np.median(radius))
    indptr, indices = adjacency
    if not _dense(vertices, typical, adjacency, edges=edges, edge=edge):
        return None
    tails = np.repeat(np.arange(n), np.diff(indptr))
    cell = typical / (COARSE_CELLS if cells is None else cells)
    members = np.flatnonzero(inside)
    # cells beyond 2^52 (a vertex flung far away) share the last one: a cast of such a float is undefined; the
    # cubes of meshcurv.jets.turned_cubes (a mirror image of the mesh gets the mirrored clusters)
    cube = turned_cubes(vertices[members], cell, limit=2.0**52)[0]
    # the side: the axes within round-off of the largest component, with their signs (one of 26 codes). At a voxel
    # surface's edges and corners two or three components tie exactly ((-3, 3, 1) / sqrt(19) at a slab's corner);
    # argmax let the last bits of a scaled mesh choose one (issue 29, fuzz_labels seed 460 case 313: a slab's area
    # 0.05% and H 0.1% apart between the spacings x1 and x0.7), and a first axis of the tied ones would change with
    # a permutation of the axes (a transposed image): the tied set is its own side
    facing = _side_normals(normals, np.where(inside, areas, 0.0), adjacency)[members]
    magnitude = np.abs(facing)
    dominant = magnitude >= magnitude.max(axis=1, keepdims=True) - AXIS_TIE
    side = (dominant * (1 + (facing < 0)) * np.array([1, 3, 9])).sum(axis=1)
    group = _row_groups(np.column_stack([cube, side]))
    c = int(group.max()) + 1
    weight = areas[members]
    total = np.bincount(group, weights=weight, minlength=c)
    centroid = (
        np.stack([np.bincount(group, weights=weight * vertices[members, k], minlength=c) for k in range(3)], axis=1)
        / total[:, None]
    )
    summed = np.stack([np.bincount(group, weights=weight * normals[members, k], minlength=c) for k in range(3)], axis=1)
    length = np.linalg.norm(summed, axis=1, keepdims=True)
    group_normals = np.divide(summed, length, out=np.zeros_like(summed), where=length > 0)
    of = np.full(n, -1, dtype=np.int64)
    of[members] = n + group
    a, b = of[tails], of[indices]
    joined = (a >= 0) & (b >= 0) & (a != b)
    links = _unique_pairs(a[joined], b[joined], n + c)
    own = np.flatnonzero(of >= 0)
    heads = np.concatenate([own, links[:, 0]])
    ends = np.concatenate([of[own], links[:, 1]])
    order = np.argsort(heads, kind="stable")
    count = np.bincount(heads, minlength=n + c)
    lists = (np.concatenate([[0], np.cumsum(count)]).astype(np.int64), ends[order].astype(np.int64))
    allowed = np.concatenate([np.zeros(n, dtype=bool), np.ones(c, dtype=bool)])
    point_areas = np.concatenate([np.zeros(n), total])
    return (np.concatenate([vertices, centroid]), np.concatenate([normals, group_normals]), allowed, lists, point_areas)


def _side_normals(normals: np.ndarray, weights: np.ndarray, adjacency: tuple) -> np.ndarray:
    """(V, 3) the normals that :func:`_coarse_level` reads its groups' sides from: the normalised sum of the
    ``weights``-weighted ``normals`` over :data:`SIDE_RINGS` rings of the edge lists ``adjacency`` (CSR; each vertex
    counted once per path, as :func:`_spread_normals`), ``normals`` where that sum is zero (or with 0 rings).

    A voxel surface's vertex normals jump between the staircase's treads and risers (axes and diagonals): their
    largest components split a cube's vertices into two or three sides where the surface has one. On a
    marching-cubes sphere R 6 at 0.5 x 0.2 x 0.2 the main pass's coarse level held 2,002 groups in 1,010 cubes
    and the pilot's 4,608 in 3,095; over two rings 1,223 and 3,393, so each ball walks and fits about 40% fewer
    points (the call -10% of CPU; ``benchmarks/dense_voxel.md``). The two sides of a part thinner than a cube
    keep their own groups (a slab one or two voxels thick under cubes of four: the same groups over two rings as
    over none)."""
    if SIDE_RINGS == 0:
        return normals
    ring = _ring_matrix(adjacency)
    summed = normals * weights[:, None]
    for _ in range(SIDE_RINGS):
        summed = summed + ring @ summed
    length = np.linalg.norm(summed, axis=1, keepdims=True)
    return np.divide(summed, length, out=np.array(normals, dtype=np.float64), where=length > 0)


def _row_groups(rows: np.ndarray, bits: tuple | None = None) -> np.ndarray:
    """(N,) the index of each row of ``rows`` (N, k) of int >= 0 among the distinct rows in lexicographic order
    (``np.unique(rows, axis=0, return_inverse=True)``), on one int64 key where column ``j`` fits ``bits[j]`` bits
    (default: the bits of the column's largest value; a sort of numbers instead of rows: 0.3 ms instead of 6 on a
    10,172-vertex voxel sphere's coarse level, whose fixed widths of 20 bits a cube and 5 a side, 65 in all, never
    fitted one key)."""
    if rows.shape[0] == 0:
        return np.unique(rows, axis=0, return_inverse=True)[1].ravel()
    top = rows.max(axis=0)
    if bits is None:
        bits = tuple(max(1, int(value).bit_length()) for value in top)
    if sum(bits) > 63 or np.any(top >= 2 ** np.array(bits)):
        return np.unique(rows, axis=0, return_inverse=True)[1].ravel()
    key = np.zeros(rows.shape[0], dtype=np.int64)
    for j, width in enumerate(bits):
        key = key << width | rows[:, j]
    return _unique_inverse(key)[1]


def _unique_pairs(a: np.ndarray, b: np.ndarray, n: int) -> np.ndarray:
    """(P, 2) the distinct pairs ``(a, b)`` of int in [0, n), sorted (``np.unique`` of the rows), on one int64 key."""
    if n >= 2**31:
        return np.unique(np.column_stack([a, b]), axis=0)
    key = _unique_sorted(a * np.int64(n) + b)
    return np.column_stack([key // n, key % n])


def _dense(
    vertices: np.ndarray, radius: float, adjacency: tuple, *, edges: float | None = None, edge: float | None = None
) -> bool:
    """Whether normal fits over ``radius`` run on the coarse level: wider than ``edges`` (default
    :data:`COARSE_EDGES`) median edge lengths (``edge``, or that of every edge of the CSR lists ``adjacency``:
    :func:`_median_edge`)."""
    if edge is None:
        edge = _median_edge(vertices, adjacency)
    return bool(radius > (COARSE_EDGES if edges is None else edges) * edge)


def _coarse_fits(mesh: PreparedMesh, normal_radius, invalid: np.ndarray, stages: Stages) -> bool:
    """Whether normal fits over ``normal_radius`` (its median) may run on the coarse level (:func:`fitted_normals`):
    wider than :data:`COARSE_EDGES` median edges on a voxel surface (:func:`meshcurv.radius._voxel_surface`, the
    grid read once a call: ``stages.voxel``; ``invalid`` the vertices its faces may leave out). At a given radius of
    two default radii on ``voxel_sphere(6, (0.5, 0.2, 0.2))`` (normal fits over 20 median edges) the fits over the
    vertices cost 4.6 times the CPU of the coarse level's and read H 2.4 times further off (0.046 of H at the
    median against 0.019): its clusters average the staircase. Any other mesh is fitted over its vertices."""
    if not np.all(np.isfinite(normal_radius)) or not _dense(
        mesh.vertices, float(np.median(normal_radius)), _adjacency(mesh.topology), edge=_mesh_edge(mesh)
    ):
        return False
    return _voxel_surface(mesh, invalid, reading=stages.voxel)


def _median_edge(vertices: np.ndarray, adjacency: tuple, edges: np.ndarray | None = None) -> float:
    """:func:`_dense`'s median edge length: over every edge of the CSR lists ``adjacency`` (inf without edges: no
    radius is dense), or of ``edges`` (E, 2), the same edges, when the caller has them (the compiled lengths).

    Every edge, not a sample: a median over all of them moves by round-off under a motion or a re-indexing, as each
    length does, while any sample was chosen by the pose or the index (evenly spaced in index order: fuzz 419/58; a
    hash of the coordinates' bits: a random sphere's 0.031245, 0.031113 turned, 0.031103 shifted). It costs 0.05 s
    of CPU on the 3M edges of a 1M-vertex icosphere (the sample: 0.03 s), 1% of the call."""
    if edges is None:
        indptr, indices = adjacency
        tails = np.repeat(np.arange(indptr.size - 1), np.diff(indptr))
        upper = indices > tails  # each edge once (its two directions have one length)
        edges = np.column_stack([tails[upper], indices[upper]])
    return median_edge_length(vertices, edges) if edges.shape[0] else np.inf


def _mesh_edge(mesh: PreparedMesh) -> float:
    """:func:`_median_edge` of a prepared mesh's edges, kept from its length scales
    (:attr:`~meshcurv._prepared.PreparedMesh.median_edge_length`: the same median of the same lengths, to the bit;
    0.045 s of CPU at 1M vertices not spent again, issue 31)."""
    return mesh.median_edge_length if mesh.topology.n_edges else np.inf


def voxel_pilot(mesh: PreparedMesh, *, reading: VoxelReading | None = None):
    """The first pass of :func:`meshcurv.radius.voxel_surface_radius`: ``radius -> (k_min, k_max, valid, normals)``.

    icc over balls of ``radius`` at the centres of :func:`_pilot_centres` (about one vertex in two):
    its values are read through averages over two rings and a
    percentile (:func:`meshcurv.radius.voxel_vertex_radii`), so the curvatures of the other vertices are
    NaN; their normals are the mean of the fitted normals of the nearest centres (:func:`_spread_normals`)
    (the voxel extent along each vertex's normal sets its radius).

    A mesh with needle vertices (:func:`meshcurv.defects.needle_vertices`) is read with each needle put back at
    the mean of its other neighbours, its faces kept (:func:`_needles_put_back`). Without them the pilot's balls
    at a needle's base held the hole of its faces (a voxel surface's staircase left unbalanced: curvedness up to
    44% off), and the grids of its samples and fits, which the vertex set anchors, were other ones: a small voxel
    surface's default radius moved by more than 2% in 11 of 128 draws of one vertex or two moved 1e3-1e6 sizes
    away (up to 12%; fuzz_api 575/106: 3.7%), none after (up to 1.4%). The needles themselves stay out of every
    reading (:func:`meshcurv.radius.voxel_surface_radius`).

    ``reading``: the call's :class:`meshcurv.radius.VoxelReading`; a grid turned off x, y and z is read in its
    own axes (:func:`_grid_axes`).
    """
    given = mesh
    read: list[PreparedMesh] = []  # the mesh the pilot reads: found at its first call (a smooth mesh never calls it)
    turns: list = []  # ... and the grid's axes it is turned into (None: as given)

    def run(radius: float):
        if not read:
            kept = _needles_put_back(given) if given.needles.any() else given
            turns.append(_grid_axes(given, reading))
            read.append(kept if turns[0] is None else kept.with_vertices(kept.vertices @ turns[0].T))
        mesh, axes = read[0], turns[0]
        vertices, topology = mesh.vertices, mesh.topology
        _, valid = mesh.start(boundary=True)
        valid = _scale_centres(mesh, valid, mesh.vertex_normals)  # a needle's corners: as without it
        start = np.where(valid[:, None], mesh.vertex_normals, [0.0, 0.0, 1.0])
        centres = _pilot_centres(vertices, topology, valid)
        edge = _mesh_edge(mesh)
        fitted = _pilot_normals(mesh, start, NORMAL_RADIUS_RATIO * radius, centres, edge=edge)
        with np.errstate(invalid="ignore"):
            agree = np.isfinite(fitted).all(axis=1) & (np.einsum("ij,ij->i", fitted, start[centres]) > NORMAL_AGREEMENT)
        normals = _spread_normals(
            topology.neighbour_lists, centres[agree], fitted[agree], mesh.vertex_normals, PILOT_RINGS
        )
        normals[centres[~agree]] = mesh.vertex_normals[centres[~agree]]
        measures = face_measures(vertices, topology.faces, normals)
        usable = _usable_faces(topology.faces, _dropped(mesh), normals)
        if radius > PILOT_SUM_EDGES * edge and np.isfinite(normals[centres]).all():  # anisotropic voxels
            radii = np.full(vertices.shape[0], radius)
            summed = _sampled_face_sums(
                vertices, topology.faces, radii, measures, usable, normals, centres, PILOT_SUM_SPACING * radius
            )
        else:
            summed = _ball_face_sums(
                vertices, topology.faces, radius, measures, usable=usable, connected=True, centres=centres
            )
        k_min = np.full(vertices.shape[0], np.nan)
        k_max = np.full(vertices.shape[0], np.nan)
        k_min[centres], k_max[centres], _, _ = curvatures_from_measures(summed, normals[centres])
        return k_min, k_max, valid, normals if axes is None else normals @ axes

    return run


def _grid_axes(mesh: PreparedMesh, reading: VoxelReading | None) -> np.ndarray | None:
    """(3, 3) the axes (rows) of the voxel grid of ``mesh`` that ``reading`` holds where it is turned off x, y and
    z (:attr:`meshcurv.lattice.VoxelGrid.frame`), as a rotation (the last row flipped where they are a mirror's
    axes: a mirror image would flip the faces' winding); else None.

    The voxel default's cube grids (the pilot's centres, the samples of its fits and sums, the coarse level and
    the clusters of the coarse sums: :func:`meshcurv.jets.turned_cubes`) are laid along the axes of the points
    they are given: the vertices turned into these axes get the cubes a mesh along them would (issue 29: a
    turned ``voxel_torus(10, 4)``'s k moved by up to 7.7% of its largest ``|k|``, its default radius by 0.3%).
    """
    grid = None if reading is None else reading.mesh_grid(mesh)
    if grid is None or grid.frame is None:
        return None
    axes = np.array(grid.frame, dtype=np.float64)
    if np.linalg.det(axes) < 0:
        axes[2] = -axes[2]
    return axes


def _along(vectors: np.ndarray, axes: np.ndarray | None) -> np.ndarray:
    """``vectors`` (..., 3) in the ``axes`` of :func:`_grid_axes` (rows; None: as given)."""
    return vectors if axes is None else vectors @ axes.T


def _turned_back(fields: tuple, axes: np.ndarray | None) -> tuple:
    """:func:`_curvatures`' ``fields`` of vertices turned into ``axes`` (:func:`_along`), their directions and normals
    turned back to x, y and z."""
    if axes is None:
        return fields
    k_min, k_max, dir_min, dir_max, normals, *rest = fields
    return (k_min, k_max, dir_min @ axes, dir_max @ axes, normals @ axes, *rest)


def _needles_put_back(mesh: PreparedMesh) -> PreparedMesh:
    """``mesh`` with each needle vertex at the mean of its neighbours that are no needles (where it has any): the
    same topology and vertex order, its scales and needles found again."""
    vertices, needles = mesh.vertices.copy(), mesh.needles
    indptr, indices = mesh.topology.neighbour_lists
    ends = np.repeat(np.arange(needles.size), np.diff(indptr))
    kept = needles[ends] & ~needles[indices]  # each needle's edges to a neighbour that is no needle
    counts = np.bincount(ends[kept], minlength=needles.size)
    sums = np.stack(
        [np.bincount(ends[kept], weights=vertices[indices[kept], axis], minlength=needles.size) for axis in range(3)],
        axis=1,
    )
    moved = counts > 0
    vertices[moved] = sums[moved] / counts[moved, None]
    return mesh.with_vertices(vertices)


def _pilot_normals(
    mesh: PreparedMesh, start: np.ndarray, radius: float, centres: np.ndarray, *, edge: float | None = None
) -> np.ndarray:
    """(M, 3) the jet normals of :func:`voxel_pilot` at ``centres`` over balls of ``radius`` (``start``: the
    first frames): fitted on a coarse level of the surface (:func:`_coarse_level`, cubes of ``radius /``
    :data:`PILOT_COARSE_CELLS`) where ``radius`` exceeds :data:`PILOT_COARSE_EDGES` median edge lengths, there
    at one centre per cube of :data:`PILOT_SAMPLE_EDGES` median edges (``edge``: :func:`_median_edge`, when
    given) and interpolated at the others (:func:`meshcurv.jets.sampled_jet_normals`); else over the vertices
    at every centre."""
    vertices, topology = mesh.vertices, mesh.topology
    adjacency = _adjacency(topology)
    areas = _vertex_areas(mesh)
    positive = areas[areas > 0]
    coarse = (
        _coarse_level(
            vertices,
            start,
            radius,
            areas / np.median(positive),
            topology.referenced_vertices,
            adjacency,
            edges=PILOT_COARSE_EDGES,
            cells=PILOT_COARSE_CELLS,
            edge=edge,
        )
        if positive.size
        else None
    )
    points, normals, allowed, weights = vertices, start, topology.referenced_vertices, None
    if coarse is not None:
        points, normals, allowed, adjacency, weights = coarse
        if edge is not None and edge > 0:  # (else edges of length zero: every centre fitted)
            return _sampled_jet_normals(
                points,
                normals,
                radius,
                centres=centres,
                spacing=PILOT_SAMPLE_EDGES * edge,
                degree=NORMAL_DEGREE,
                iterations=NORMAL_ITERATIONS,
                neighbours=allowed,
                adjacency=adjacency,
                settled=NORMAL_SETTLED,
                min_spread=NORMAL_MIN_SPREAD,
                areas=weights,
            )
    coefficients, frame, _ = _fit_jets(
        points,
        normals,
        radius,
        degree=NORMAL_DEGREE,
        iterations=NORMAL_ITERATIONS,
        centres=centres,
        neighbours=allowed,
        adjacency=adjacency,
        settled=NORMAL_SETTLED,
        compact=True,
        min_spread=NORMAL_MIN_SPREAD,
        areas=weights,
    )
    return jet_normals(coefficients, frame)


#: The pilot's normal fits run on a coarse level (:func:`_pilot_normals`) when wider than this many median edges
#: (anisotropic voxels: 10.8 at 2 x 1 x 1, 11.2 on a sphere at 0.5 x 0.2 x 0.2; isotropic ones: 6.0) ...
PILOT_COARSE_EDGES = 8.0
#: ... of cubes of 1 / PILOT_COARSE_CELLS of their radius: on that sphere the pilot's fits cost 0.09 CPU s instead
#: of 0.18-0.21 (0.07 s at 5 cells; 0.12 s at 10, whose groups of two or three vertices have as many links as
#: the vertices), their normals as close to the sphere's; on the 8 meshes of ``benchmarks/accuracy_voxel.md``
#: that take it (anisotropic voxels) the median H error moves by -4.6 to +4.0% of itself (5 cells: -8.3 to +6.6%).
PILOT_COARSE_CELLS = 7.0
#: ... at one centre per cube of this many median edge lengths (:func:`meshcurv.jets.sampled_jet_normals`), the
#: other centres interpolated from them over their tangent planes. The margin is thin: 1.8 and 2 edges fold the
#: Gauss image of an anisotropic torus (``tests/test_statistics.py::test_folded_gauss_image_is_flagged``;
#: ``benchmarks/dense_voxel.md``). Its other vertices keep the normals of the centres one or two rings away
#: (:func:`_spread_normals`).
PILOT_SAMPLE_EDGES = 1.6

#: The pilot's balls wider than this many median edge lengths (anisotropic voxels; isotropic ones are about 2
#: edges wide and keep the sums at every centre) are summed at one of its centres per cube of ...
PILOT_SUM_EDGES = 3.0
#: ... this share of its radius and interpolated at the other centres (:func:`_sampled_face_sums`; the spacing
#: and its alternatives measured in ``benchmarks/dense_voxel.md``).
PILOT_SUM_SPACING = 0.6

#: The pilot of a voxel surface (:func:`voxel_pilot`) fits and sums at one vertex per cube of this many
#: median edge lengths (45% of the vertices of a marching-cubes sphere; its values are only read through
#: averages over two rings). On the 19 meshes of ``benchmarks/accuracy_voxel.md`` no median H error moved by
#: more than 6% of itself against the pilot at every vertex; 1.5 moved one by 9%, 2.0 (20% of the vertices)
#: three by 16-27%.
PILOT_CELL_EDGES = 1.25
#: The other vertices take the mean of the fitted normals within one ring, or else two.
PILOT_RINGS = 2


def _pilot_centres(vertices: np.ndarray, topology: MeshTopology, valid: np.ndarray) -> np.ndarray:
    """The vertices of :func:`voxel_pilot`'s fits and sums: in each cube of side :data:`PILOT_CELL_EDGES` median
    edge lengths (:func:`meshcurv.jets.turned_cubes`), the valid referenced vertex nearest the cube's middle, ties
    taken by the turned coordinates (never by the index: re-indexed vertices give the same centres, and a mirror
    image of the mesh the mirrored ones; the cubes of the vertices' axes: :func:`voxel_pilot` turns the vertices of
    a turned grid into its axes, :func:`_grid_axes`, so that a rotated voxel surface gets the same centres)."""
    members = np.flatnonzero(valid & topology.referenced_vertices)
    if members.size == 0:
        return members
    edge = median_edge_length(vertices, topology.edges)
    if not edge > 0:
        return members
    # (meshcurv.jets.turned_cubes: no cube boundary through a voxel surface's lattice, where round-off (a scaled
    # mesh) would pick other centres; a mirror image of the mesh gets the mirrored cubes)
    cube, offset, turned = turned_cubes(vertices[members], PILOT_CELL_EDGES * edge)
    key = cube[:, 0] << 42 | cube[:, 1] << 21 | cube[:, 2]
    # (rounded: a lattice holds many vertices at one distance from the middle, whose round-off would depend on
    # the scale; their tie goes to the turned coordinates, whose order a scaling and a mirror keep)
    off_middle = np.round(_squared(*offset.T), 9)
    return members[_nearest_in_cubes(turned, key, off_middle)]


def _spread_normals(neighbour_lists: tuple, centres: np.ndarray, fitted: np.ndarray, fallback, rings: int):
    """(V, 3) unit normals: ``fitted`` at ``centres``; elsewhere the normalised sum of those one ring away, else
    of those two rings away (each counted once per path), ... up to ``rings``; ``fallback`` (V, 3) where none is."""
    ring = _ring_matrix(neighbour_lists)
    n = ring.shape[0]
    normals = np.array(fallback, dtype=np.float64, copy=True)
    summed = np.zeros((n, 3))
    summed[centres] = fitted
    done = np.zeros(n, dtype=bool)
    done[centres] = True
    normals[centres] = fitted
    for _ in range(rings):
        summed = summed + ring @ summed
        length = np.linalg.norm(summed, axis=1)
        fresh = ~done & (length > 0)
        normals[fresh] = summed[fresh] / length[fresh, None]
        done |= fresh
    return normals


def _ring_matrix(neighbour_lists: tuple):
    """The (V, V) sparse matrix (CSR, ones) of the neighbour lists ``(indptr, indices)``: ``ring @ x`` sums ``x``
    over each vertex's ring (:func:`_spread_normals`, :func:`_side_normals`)."""
    from scipy import sparse

    indptr, indices = neighbour_lists
    n = indptr.size - 1
    return sparse.csr_matrix((np.ones(indices.size), indices, indptr), shape=(n, n))


def _vertex_areas(mesh: PreparedMesh) -> np.ndarray:
    """(V,) a third of the area of the faces at each vertex (the weights of the fits).

    Degenerate faces and the slivers of a needle (faces of a vertex flung away, ``needle_cells``) count
    nothing, as in the vertex normals: a sliver's area would make its corners outweigh the surface in the
    normal fits of every vertex within three radii (H 0.04 for 1 three rings from a pair flung to 1e3).
    """
    return mesh.vertex_areas  # summed with the vertex normals, over the same faces (PreparedMesh.dropped)


def _dropped(mesh: PreparedMesh) -> np.ndarray:
    """(F,) bool: the faces left out of the sums and of the fits' weights: degenerate, or the slivers of a
    needle (``needle_cells``: the faces of a vertex flung far away, whose huge areas would outweigh the
    surface within three radii), as in the vertex normals."""
    needle = mesh.defects().needle_cells(mesh.topology.faces)
    return mesh.degenerate if needle is None else mesh.degenerate | needle


#: The pilot's sums (:func:`_sampled_face_sums`) are interpolated at the centres that are not samples from the
#: samples within this many spacings whose normals agree with the centre's (cosine above NORMAL_AGREEMENT: the
#: far side of a part thinner than the reach does not count).
SUM_WIDTH = 1.5


def _sampled_face_sums(vertices, faces, radius, values, usable, normals, centres, spacing) -> np.ndarray:
    """(M, k) the sums over the balls of ``radius`` (V,) at the ``centres`` (M,) (distinct vertices with finite
    ``normals``): summed at one centre per cube of side ``spacing`` (:func:`meshcurv.jets._cube_samples`) and
    interpolated at the other centres.

    The voxel pilot's (:func:`voxel_pilot`; its values are only read through averages over two rings). A sample's
    sums divided by its corrected area ``mu_0`` (its H, K and shape operator) vary smoothly with the centre of a
    ball of many faces; each other centre takes the value at itself of their weighted linear
    least-squares fit over its tangent plane (:func:`meshcurv.jets.interpolated_normals`: the samples within
    :data:`SUM_WIDTH` spacings whose normals agree with its own, else within twice that), with a corrected area
    of 1 (the curvatures are ratios to it). A centre without such a sample is summed over its own ball. The sums
    then cost the number of samples, not of centres. (The main pass's sums so interpolated blur a curvature that
    varies within half a radius: a dense voxel ellipsoid's median H error +26%, ``benchmarks/dense_voxel.md``.)"""
    if centres.size == 0:  # (no valid vertex to centre the pilot on: a surface left in strips and bow-ties)
        return np.zeros((0, values.shape[1]))
    sampled = _cube_samples(vertices[centres], spacing)
    others = np.setdiff1d(np.arange(centres.size), sampled, assume_unique=True)
    at, facing = vertices[centres[others]], np.ascontiguousarray(normals[centres[others]])
    t1, t2 = tangent_basis(facing)
    kernels = numba_kernels("pilot")
    interpolate = interpolated_normals if kernels is None else kernels.interpolated_normals

    summed = np.zeros((centres.size, values.shape[1]))
    summed[sampled] = _ball_face_sums(
        vertices, faces, radius, values, usable=usable, connected=True, centres=centres[sampled]
    )
    known = sampled[summed[sampled, 0] > 0]
    fields = summed[known, 1:] / summed[known, :1]
    missing = np.arange(others.size)
    # the centres that no agreeing sample within SUM_WIDTH spacings reaches (a cube's sample near its corner
    # leaves a gap) take those within twice that; the few left are summed over their own balls
    for reach in (SUM_WIDTH * spacing, 2.0 * SUM_WIDTH * spacing):
        ratios, reached = interpolate(
            at[missing],
            vertices[centres[known]],
            fields,
            t1[missing],
            t2[missing],
            reach,
            SAMPLED_SPREAD,
            facing[missing],
            normals[centres[known]],
            NORMAL_AGREEMENT,
        )
        summed[others[missing[reached]], 0] = 1.0
        summed[others[missing[reached]], 1:] = ratios[reached]
        missing = missing[~reached]
        if not missing.size:
            break
    if missing.size:
        summed[others[missing]] = _ball_face_sums(
            vertices, faces, radius, values, usable=usable, connected=True, centres=centres[others[missing]]
        )
    return summed


def _boundary_faces(topology: MeshTopology) -> np.ndarray | None:
    """(F,) bool: the faces on a boundary edge, or None where there is none (a closed surface)."""
    boundary = topology.boundary_edges
    if not boundary.any():
        return None
    faces = topology.edge_faces[boundary].ravel()
    marked = np.zeros(topology.faces.shape[0], dtype=bool)
    marked[faces[faces >= 0]] = True
    return marked


def _adjacency(topology: MeshTopology) -> tuple:
    """The edge lists the ball searches walk (both backends: the surface-connected balls)."""
    return topology.neighbour_lists


def _usable_faces(faces: np.ndarray, degenerate: np.ndarray, normals: np.ndarray) -> np.ndarray | None:
    """(F,) bool: the faces whose measures enter the sums (not degenerate, finite normals at their corners), or
    None when all do."""
    finite = finite_rows(normals)
    kept = ~degenerate if finite.all() else ~degenerate & finite[faces].all(axis=1)
    return None if kept.all() else kept


def _curvatures(
    vertices,
    faces,
    degenerate,
    normals,
    valid,
    radius,
    stages: Stages | None = None,
    *,
    neighbours: np.ndarray | None = None,
    adjacency: tuple | None = None,
    areas: np.ndarray | None = None,
    weighted: bool = False,
    normal_radius=None,
    coarse: bool = False,
    coarse_fits: bool = False,
    boundary_faces: np.ndarray | None = None,
    topology: MeshTopology | None = None,
    cracked: bool = False,
    pieces: np.ndarray | None = None,
    edge: float,
    reached: np.ndarray | None = None,
    voxel=None,
):
    """``k_min, k_max, dir_min, dir_max, normals, valid, radius`` of the measures over balls of ``radius``.

    The normals are fitted over ``normal_radius`` (default: :data:`NORMAL_RADIUS_RATIO` times ``radius``).
    ``coarse`` (a voxel surface at its default radii): dense balls summed on clusters of faces
    (:func:`meshcurv.neighborhoods.coarse_face_sums`), wide normal fits on the coarse level (:func:`fitted_normals`);
    ``coarse_fits`` (a voxel surface at a given radius, :func:`_coarse_fits`): the latter only.
    ``boundary_faces`` (F,) bool: the faces on a boundary edge of a voxel surface (:func:`_boundary_faces`),
    whose balls are grown or left undefined (:func:`_holed_balls`); the returned ``radius`` is then (V,) the
    radius of each ball summed (``radius`` as given otherwise). ``topology``: the mesh's, given where it has
    boundary edges and is not a voxel surface: the normals are fitted at every corner of a face summed
    (:func:`_corners_fitted`) and, near holes (:func:`_near_holes`), the fits whose balls wrap are made again
    (:func:`_unwrapped_normals`). ``cracked``: the mesh was welded across cracks (``PreparedMesh.n_cracked``): near
    holes, the pieces whose fits scatter (:func:`_scattered_pieces`) or whose balls hold a small piece of a staircase
    (:func:`_stair_pieces`; ``pieces``: a voxel surface's soup's, :func:`_soup_pieces`) are undefined.
    ``edge``: the median length of every edge (:func:`_mesh_edge`: the coarse level's test and the scatter's ball).

    The normal fits on thin flat parts are made again over their own side (:func:`fitted_normals` ``thin``).
    ``reached`` (V,) bool, when given (not on a voxel surface at its default): set True, in place, at the vertices
    whose ball of the sums holds the other side of a thin part (:data:`THIN_FACING`), left out of the ``valid``
    returned. ``voxel``: a callable telling whether the mesh is a voxel surface (read only where a thin part's fits
    were made again: :func:`_wider_reaching` is not read on one).

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
    failed = np.zeros(vertices.shape[0], dtype=bool)
    counts = None  # the points of the normal fits near holes, where cracks were welded (below)
    facing_columns = reached is not None and boundary_faces is None and not coarse
    wraps = (
        np.zeros(vertices.shape[0], dtype=bool) if facing_columns else None
    )  # (the fits reaching round: _wider_reaching)
    if np.all(np.asarray(radius) > 0):
        if normal_radius is None:
            normal_radius = NORMAL_RADIUS_RATIO * radius
        start_normals, fit = (
            normals,
            _corners_fitted(faces, degenerate, normals, valid) if coarse or topology is not None else valid,
        )
        near = None if topology is None else _near_holes(vertices, topology, radius, normal_radius, fit)
        # the pieces' scatter is read where cracks were welded (a soup's copies joined into fans between cracks);
        # a mesh whose holes were cut keeps its pieces intact (half of icosphere(4)'s faces removed: its coarse
        # balls' quadrics depart from the sphere by the scatter rule's bound, and no vertex was wrong)
        counts = None if near is None or not cracked else np.full(vertices.shape[0], np.inf)
        normals = fitted_normals(
            vertices,
            normals,
            fit,
            normal_radius,
            neighbours=neighbours,
            adjacency=adjacency,
            areas=areas,
            weighted=weighted,
            failed=failed,
            edge=edge,
            unwrap=near,
            counts=counts,
            thin=True,
            widen=THIN_WIDEN if coarse else 1.0,
            coarse=coarse or coarse_fits,
            reaching=wraps,
        )

        if boundary_faces is not None and adjacency is not None:
            normals = _unfitted_spread(normals, start_normals, fit, adjacency)

    start("compute face measures")
    measures = face_measures(vertices, faces, normals)  # rows of the faces left out are not read

    start("sum over balls")
    usable = _usable_faces(faces, degenerate, normals)
    if boundary_faces is not None:  # four more columns: the faces' area vectors, and whether a ball meets the boundary
        corners = vertices[faces]
        sides = 0.5 * np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
        measures = np.column_stack([measures, sides, boundary_faces.astype(np.float64)])
    if facing_columns:  # nine more columns: the faces' area vectors and normal tensors (THIN_FACING)
        measures = np.column_stack([measures, _facing_measures(vertices, faces)])
    areas_column = counts is not None and boundary_faces is None  # one more column: the faces' areas
    if areas_column:
        measures = np.column_stack([measures, face_areas(vertices, faces)])
    if coarse:
        summed = _coarse_face_sums(vertices, faces, radius, measures, usable=usable)
    else:
        summed = _ball_face_sums(vertices, faces, radius, measures, usable=usable, connected=True)
    sparse = None
    if boundary_faces is not None:
        summed, radius, sparse = _holed_balls(vertices, faces, radius, measures, summed, usable, valid, normals)
        summed = summed[:, :-4]
    ball_areas = None
    if areas_column:
        summed, ball_areas = summed[:, :-1], summed[:, -1]
    facing = None
    if facing_columns:
        summed, facing = summed[:, :-FACING_COLUMNS], summed[:, -FACING_COLUMNS:]

    start("retrieve curvatures")
    k_min, k_max, dir_min, dir_max = curvatures_from_measures(summed, normals)
    valid = valid & np.isfinite(k_min) & ~failed_fits_undefined(vertices, faces, radius, failed)
    if sparse is not None:
        valid &= ~sparse
    if facing is not None and reached is not None:
        reached |= _reaching(facing, summed[:, 0], normals, radius, k_min, k_max, valid)
        if wraps is not None and wraps.any() and not (voxel is not None and voxel()):
            reached |= _wider_reaching(
                vertices, faces, measures, usable, radius, valid & wraps & ~reached, k_min, k_max, normals
            )
        valid &= ~reached
    if counts is not None:
        valid &= ~_scattered_pieces(vertices, faces, degenerate, normals, valid, counts, k_min, k_max, edge)
        if ball_areas is not None:
            valid &= ~_stair_pieces(summed[:, 0], ball_areas, radius, valid & np.isfinite(counts), pieces)
    return k_min, k_max, dir_min, dir_max, normals, valid, radius


#: The columns of :func:`_facing_measures`.
FACING_COLUMNS = 9


def _facing_measures(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(F, :data:`FACING_COLUMNS`) each face's area vector ``a`` and its sign-blind normal tensor ``a a^T / |a|``
    (xx, yy, zz, xy, xz, yz): summed over a ball, what :func:`_reaching` reads (a degenerate face adds 0)."""
    corners = vertices[faces]
    sides = 0.5 * np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    size = np.linalg.norm(sides, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        unit = np.where(size[:, None] > 0, sides / size[:, None], 0.0)
    rows, columns = [0, 1, 2, 0, 0, 1], [0, 1, 2, 1, 2, 2]
    return np.column_stack([sides, size[:, None] * unit[:, rows] * unit[:, columns]])


def _voxel_reader(mesh: PreparedMesh, defects, stages: Stages):
    """A callable: whether ``mesh`` is a voxel surface (:func:`meshcurv.radius._voxel_surface`, read once a call:
    ``stages.voxel``). :func:`_wider_reaching` is not read on one: a label cut by the image border has a 90-degree
    crease between its closing cap and its wall, whose normal fits are made again as a thin part's and whose wider
    balls read the crease (``tests/test_volume_border.py``: 71-73 vertices of a cut hemisphere undefined, T70)."""
    found: list[bool] = []

    def read() -> bool:
        if not found:
            found.append(bool(_voxel_surface(mesh, defects.invalid_vertices, reading=stages.voxel)))
        return found[0]

    return read


def _wider_reaching(vertices, faces, measures, usable, radius, centres, k_min, k_max, normals) -> np.ndarray:
    """(V,) bool: the ``centres`` (V,) bool whose ball :data:`THIN_WIDER` times wider than ``radius`` (a float or
    (V,)) holds the other side of a thin part (:func:`_reaching`, with their ``k_min``, ``k_max`` of the balls of
    ``radius`` and ``normals``). ``measures`` (F, >= 1): the face measures, ``mu_0`` first; ``usable``:
    :func:`_usable_faces`.

    A ball's H is the mean of the surface's over it: the centre's plus a bias. Near the rim of a part thinner than
    the normal fits' balls the curvature grows fast towards the rim (on the ellipsoid (3, 3, 0.15), ``k`` from 0.2
    at 0.9 of its radius to 133 at the rim): a ball that stops short of the rim (its facing as a ball of its own
    curvatures') still reads twice the centre's H there, with the exact normals too, where the wider ball reaches
    round it.
    """
    out = np.zeros(vertices.shape[0], dtype=bool)
    ids = np.flatnonzero(centres)
    if not ids.size:
        return out
    radii = THIN_WIDER * np.broadcast_to(np.asarray(radius, dtype=np.float64), (vertices.shape[0],))
    values = np.column_stack([measures[:, :1], _facing_measures(vertices, faces)])
    wide = _ball_face_sums(vertices, faces, radii, values, usable=usable, connected=True, centres=ids)
    out[ids] = _reaching(
        wide[:, 1:], wide[:, 0], normals[ids], radii[ids], k_min[ids], k_max[ids], np.ones(ids.size, bool)
    )
    return out


def _reaching(facing, area, normals, radius, k_min, k_max, valid) -> np.ndarray:
    """(V,) bool: the ``valid`` vertices whose ball of the sums holds the other side of a thin part.

    ``facing`` (V, :data:`FACING_COLUMNS`): the sums over each ball of :func:`_facing_measures` (``S`` the area
    vectors', ``T`` the tensors'); ``area`` (V,) its corrected area; ``normals`` ``n``, ``radius`` (float or (V,)),
    ``k_min``, ``k_max`` those of the vertex. Where the ball holds the other side, its facing ``f = n . S / area``
    lies more than :data:`THIN_FACING` below a ball of its own curvatures' (``1 - r^2 (k_1^2 + k_2^2) / 8``),
    its area vectors cancel (``|S| / area`` more than :data:`THIN_CANCEL` below the same) and a share of its area
    faces away from ``n`` (:data:`THIN_OPPOSITE`); a fold of one surface tilts ``S`` off ``n`` (``f`` low) but
    cancels little.
    """
    n = normals
    tensor = facing[:, 3:]
    squared = (
        tensor[:, 0] * n[:, 0] ** 2
        + tensor[:, 1] * n[:, 1] ** 2
        + tensor[:, 2] * n[:, 2] ** 2
        + 2.0 * (tensor[:, 3] * n[:, 0] * n[:, 1] + tensor[:, 4] * n[:, 0] * n[:, 2] + tensor[:, 5] * n[:, 1] * n[:, 2])
    )
    along = np.einsum("ij,ij->i", n, facing[:, :3])
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        bent = 1.0 - np.asarray(radius) ** 2 * (k_min**2 + k_max**2) / 8.0  # a ball of its own curvatures'
        tilted = along / area < bent - THIN_FACING
        cancelled = np.linalg.norm(facing[:, :3], axis=1) / area < bent - THIN_CANCEL
        opposite = (squared - along) / (tensor[:, 0] + tensor[:, 1] + tensor[:, 2]) > THIN_OPPOSITE
    return valid & tilted & cancelled & opposite


#: Near holes (:func:`_near_holes`), a vertex is undefined where its points scatter by more than
#: :data:`SCATTER_TILT` of the curvature signal (the residuals of a quadric over three edge lengths, over ``h^2``
#: times the surface's median curvedness: :func:`_scattered_pieces`) and its normal fit held fewer points than this
#: many times that scatter ...
SCATTER_POINTS = 100.0
#: ... or fewer than this many. A piece of a soup between cracks fits its normal over its own corners, whose
#: scatter then drives the normal and, through the cracks around its small ball, its H; a normal's noise falls
#: about as ``1 / n`` for ``n`` points spread over ``sqrt(n)`` edges, hence the linear term. Every face of
#: ``icosphere(24)`` detached by 0.03 edges (issue 29, fuzz round 22): 135 of 9,141 valid vertices off the clean
#: shape's H by more than half of it, fitted over fewer than 40 points, their faces tilted by 0.3 to 0.5 signals
#: (the corners' exact normals over the same balls: none off); 35 points alone left none of them, but 50 and 94
#: of ``icosphere(40)``'s (an edge's signal 0.6 times smaller, tilts of 0.5 to 1 signals, up to 70 points) ...
SCATTER_FEW = 35
#: ... where the points scatter by more than this share of the signal (clean meshes, irregular ones and their
#: rims: 0.003 to 0.03; the face tilts of the first version read 0.3 to 0.5 at an irregular hemisphere's rim, as
#: on a soup, and undefined it): intact pieces between cracks keep their values.
SCATTER_TILT = 0.05


def _scattered_pieces(vertices, faces, dropped, normals, valid, counts, k_min, k_max, edge: float) -> np.ndarray:
    """(V,) bool: the ``valid`` vertices near holes (``counts`` (V,) the points of their normal fits; inf where not
    counted) whose points scatter by ``s`` above :data:`SCATTER_TILT` and whose fit held fewer points than
    :data:`SCATTER_FEW` or :data:`SCATTER_POINTS` ``s``. ``s``: the standard deviation of the residuals of a
    quadric over the Euclidean ball of three median edge lengths ``h`` (``edge``, :func:`meshcurv.estimators.quadric.
    residual_spreads`: the ball crosses the cracks, so it sees the scatter of the pieces around) over ``h^2`` times
    the median curvedness ``sqrt((k_min^2 + k_max^2) / 2)`` of the ``valid`` vertices (clean meshes, irregular
    ones and their rims included: 0.003 to 0.03; soups of ``icosphere(24)`` and ``icosphere(40)`` by 0.03 edges:
    0.31 to 0.39 and 0.52 to 0.66)."""
    from .quadric import residual_spreads

    near = valid & np.isfinite(counts)
    if not near.any():
        return near
    ids = np.flatnonzero(near)
    pool = np.unique(faces[~dropped].ravel())
    radii = np.full(vertices.shape[0], 3.0 * edge)
    _, sigma, _ = residual_spreads(vertices, pool, radii, np.ascontiguousarray(np.nan_to_num(normals)), ids)
    with np.errstate(invalid="ignore", divide="ignore"):
        curvedness = np.sqrt(0.5 * (k_min * k_min + k_max * k_max))
        scatter = np.full(vertices.shape[0], np.nan)
        scatter[ids] = sigma / (edge * edge * float(np.median(curvedness[valid])))
    noisy = ~(scatter <= SCATTER_TILT)  # (NaN: a scatter that could not be measured counts as noisy)
    return near & noisy & (counts < np.maximum(SCATTER_FEW, SCATTER_POINTS * np.where(noisy, scatter, 0.0)))


#: Near holes, a ball whose corrected area ``mu_0(B)`` is below this share of its faces' area (the faces tilt off
#: the fitted normals by 18 degrees on average: a staircase; a smooth mesh's balls hold 0.99 and more, a coarse
#: one's 0.97) ...
STAIR_TILT = 0.99
#: ... and below this share of its disc ``pi r^2`` holds a piece of a staircase cut by cracks, whose sum is noise
#: (a face of a staircase carries the surface's curvature only summed with its neighbours', as in
#: :func:`_holed_balls`): its vertex is undefined. ``voxel_sphere(10)`` with every face detached by 0.03 edges (the
#: weld joins some corners; no voxel surface to the default, its corners left the grid; issue 29, fuzz 395/99):
#: 61 of 172 and 82 of 530 valid vertices off the sphere's H by more than half of it, all in balls holding 0.1 to
#: 0.6 of their disc (the others 0.1 to 0.76); half of ``voxel_sphere(6)``'s faces detached by 0.065 edges: 0 of
#: 472 off, every ball above 0.4.
STAIR_SHARE = 0.4
#: On a voxel surface's soup (:func:`_soup_pieces`), a ball near holes on a piece (a component of the welded mesh)
#: whose area is below this many times its disc's ``pi r^2`` is undefined: the piece is smaller than the ball, which
#: cannot hold the steps around it, whatever share of its disc the piece fills (a flat piece of a plateau: its faces
#: lie along their normals, no tilt). Every face of ``voxel_sphere(10)`` detached by 0.031 edges (issue 29, fuzz
#: 750/289) kept 12 valid vertices off the clean shape's H by more than half of its largest ``|k|`` (a 42-face piece
#: of its top plateau: H -0.018 for 0.1), in balls of 0.403 to 0.407 of their disc, just above :data:`STAIR_SHARE`;
#: the valid vertices of such soups lie on pieces of 0.43 to 0.72 discs (seeds 0 and 3: 89 of 116 and 6 of 67 off),
#: those of soups of half of the faces on pieces of 4.3 discs and more (none off: ``voxel_sphere(6)`` by 0.065
#: edges, ``voxel_sphere(10)`` by 0.031).
STAIR_PIECE_DISCS = 2.0


def _stair_pieces(corrected, areas, radius, near, pieces: np.ndarray | None = None) -> np.ndarray:
    """(V,) bool: the ``near`` vertices whose ball's corrected area ``corrected`` (V,) is below :data:`STAIR_TILT`
    of its faces' area ``areas`` (V,) and below :data:`STAIR_SHARE` of its disc (``radius``, a float or (V,)); and
    those on a piece of area ``pieces`` (V,) (a voxel surface's soup, :func:`_soup_pieces`) below
    :data:`STAIR_PIECE_DISCS` discs."""
    with np.errstate(invalid="ignore", divide="ignore"):
        disc = np.pi * np.asarray(radius, dtype=np.float64) ** 2
        stair = corrected < STAIR_TILT * areas
        sparse = corrected < STAIR_SHARE * disc
        if pieces is not None:
            return near & ((stair & sparse) | ~(pieces >= STAIR_PIECE_DISCS * disc))
    return near & stair & sparse


def _soup_pieces(mesh: PreparedMesh, defects, valid: np.ndarray) -> np.ndarray | None:
    """(V,) the area of each vertex's piece (its component) where ``mesh`` was welded across cracks and reads a voxel
    grid as a soup (:func:`meshcurv.radius.soup_voxel_grid`, ``quadric``'s reading: its corners left the grid by the
    cracks, so the default measures it as a smooth mesh, :func:`_stair_pieces`), else None."""
    if not mesh.n_cracked:
        return None
    from ..radius import soup_voxel_grid
    from .quadric import _crack_corners

    topology = mesh.topology
    rim = topology.boundary_vertices & topology.referenced_vertices
    corners = _crack_corners(mesh.vertices, rim, mesh.scale_edge_means)
    if soup_voxel_grid(mesh, invalid=defects.invalid_vertices, valid=valid, corners=corners) is None:
        return None
    _, labels = topology.face_components
    piece_areas = np.bincount(labels, weights=face_areas(mesh.vertices, topology.faces))
    out = np.zeros(mesh.vertices.shape[0])
    out[topology.faces.ravel()] = np.repeat(piece_areas[labels], 3)
    return out


def _near_holes(vertices, topology: MeshTopology, radius, normal_radius, centres: np.ndarray) -> np.ndarray | None:
    """(V,) bool: the ``centres`` whose normal-fit ball (of ``normal_radius``) reaches the middle of an edge of a
    hole (:func:`meshcurv.estimators.normal_cycle_ball.hole_edges` over balls of ``radius``: a boundary edge with
    the surface beyond it, a crack or faces detached beyond the weld, not a rim), or None where there is none."""
    from scipy.spatial import cKDTree

    from .normal_cycle_ball import hole_edges

    n = vertices.shape[0]
    radii = np.ascontiguousarray(np.broadcast_to(np.asarray(radius, dtype=np.float64), (n,)))
    holes = hole_edges(vertices, topology, radii, topology.referenced_vertices)
    if not holes.any():
        return None
    ends = topology.edges[holes]
    reach = np.broadcast_to(np.asarray(normal_radius, dtype=np.float64), (n,))
    rows = np.flatnonzero(centres)
    distance, _ = cKDTree(0.5 * (vertices[ends[:, 0]] + vertices[ends[:, 1]])).query(vertices[rows])
    near = np.zeros(n, dtype=bool)
    near[rows] = distance <= reach[rows]
    return near


def _corners_fitted(faces: np.ndarray, dropped: np.ndarray, normals: np.ndarray, valid: np.ndarray) -> np.ndarray:
    """(V,) bool: the vertices whose normals a voxel surface fits: the ``valid`` ones and the corners of the faces
    kept in the sums (not ``dropped``) with a finite vertex normal (bow-tie vertices, strips: undefined as centres,
    but their normals enter the measures of their faces)."""
    corners = np.zeros(valid.shape[0], dtype=bool)
    corners[faces[~dropped].ravel()] = True
    return valid | (corners & finite_rows(normals))


def _unfitted_spread(normals: np.ndarray, start: np.ndarray, fit: np.ndarray, adjacency: tuple) -> np.ndarray:
    """(V, 3) ``normals`` where the ``fit`` vertices whose jet was refused kept their ``start`` frame (the mean of
    their face normals) take the mean of the fitted normals one or two rings away (:func:`_spread_normals`)."""
    refused = fit & np.all(normals == start, axis=1)
    if not refused.any():
        return normals
    fitted = np.flatnonzero(fit & ~refused)
    return _spread_normals(adjacency, fitted, normals[fitted], normals, PILOT_RINGS)


def _holed_balls(vertices, faces, radius, values, summed, usable, valid, normals):
    """``(summed, radii, sparse)``: the sums of the balls that holes emptied, taken again over larger balls.

    ``values`` (F, k): the face measures, then the faces' area vectors (3 columns) and, last, 1 at the faces
    on a boundary edge (0 elsewhere); ``summed`` (V, k): their sums over the balls of ``radius`` (a float or
    (V,)). The ``valid`` vertices whose ball meets the boundary and holds a corrected area ``mu_0(B)`` below
    :data:`HOLE_SHARE` of ``pi r^2`` take the sums of a ball of ``r min(HOLE_SHARE / share, HOLE_GROWTH)``
    (at most :data:`meshcurv.radius.VOXEL_EXTENT_CAP` of the diagonal of the faces' box, the voxel default's cap);
    ``sparse`` (V,) bool: those whose grown ball still holds less than :data:`HOLE_MIN_SHARE` of its disc, and
    those whose ball meets the boundary and holds faces of both orientations (the area vectors' sum along
    ``normals``, (V, 3), below :data:`HOLE_FACING` of ``mu_0(B)``). ``radii`` (V,): each ball's radius.

    A face of a staircase does not lie along the surface: its measures carry the surface's curvature only
    summed with its neighbours' (the sum over a patch depends on the patch's rim), and a hole takes some of
    them away. With half of the faces of ``shapes.voxel_sphere(4)`` removed at random (seeds 0-2), 14 of 421
    valid vertices were off by more than half of H (the holed mesh's default radius 1.45 against 1.78 intact, a
    third of the intact ball's faces); grown, none of 419 (the median error 0.16 -> 0.09 of H), 2 undefined.
    """
    n = vertices.shape[0]
    radii = np.array(np.broadcast_to(np.asarray(radius, dtype=np.float64), (n,)), copy=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        share = summed[:, 0] / (np.pi * radii**2)
    holed = valid & (summed[:, -1] > 0)
    ids = np.flatnonzero(holed & ~(share >= HOLE_SHARE))
    sparse = np.zeros(n, dtype=bool)
    if ids.size:
        with np.errstate(invalid="ignore", divide="ignore"):
            factor = HOLE_SHARE / share[ids]
        grown = radii[ids] * np.where(np.isfinite(factor) & (factor < HOLE_GROWTH), factor, HOLE_GROWTH)
        # at most the voxel default's own cap, a share of the extent of the faces (a ball beyond it holds it all)
        corners = vertices[faces].reshape(-1, 3)
        extent = VOXEL_EXTENT_CAP * float(np.linalg.norm(corners.max(axis=0) - corners.min(axis=0)))
        radii[ids] = np.maximum(radii[ids], np.minimum(grown, extent))
        summed = np.array(summed, copy=True)
        summed[ids] = _ball_face_sums(vertices, faces, radii, values, usable=usable, connected=True, centres=ids)
        with np.errstate(invalid="ignore", divide="ignore"):
            sparse[ids] = ~(summed[ids, 0] / (np.pi * radii[ids] ** 2) >= HOLE_MIN_SHARE)
    with np.errstate(invalid="ignore", divide="ignore"):
        facing = np.einsum("ij,ij->i", normals, summed[:, -4:-1]) / summed[:, 0]
    sparse |= holed & ~(facing >= HOLE_FACING)
    return summed, radii, sparse


def estimate(mesh: PreparedMesh, *, radius, stages: Stages, adaptive: bool = False, vertex_scale=None):
    """Interpolated corrected curvature measures over balls. Returns ``(result, problems)``.

    ``adaptive``: each vertex at its own scale (:func:`_adaptive`), from ``radius`` (the default
    radius when None) upwards. ``vertex_scale``: ``(radii, normal_radii)`` (V,) of a voxel surface's default
    (:func:`meshcurv.radius.voxel_vertex_radii`), used instead of ``radius`` (then the surface's one radius,
    :func:`meshcurv.radius.voxel_radius`) unless ``adaptive``.
    """
    vertices, topology = mesh.vertices, mesh.topology
    stages.start("compute normals")
    degenerate, normals = _dropped(mesh), mesh.vertex_normals
    defects, valid = mesh.start(boundary=True)

    stages.start("measure noise")
    referenced = topology.referenced_vertices
    bounded = topology if topology.boundary_edges.any() else None  # (a voxel surface's holes: _holed_balls)
    fits: list = []  # the noise fits at each centre, signed (the noisy patches' radii: radius._patch_radii)
    if radius is None:  # each group of components of one scale (usually the whole mesh) at its own default
        groups, levels = _noise_radii(mesh, normals, valid, adjacency=_adjacency(topology), fits=fits)
        found = {"surface": "smooth", "noise": levels[0] if len(levels) == 1 else levels}
    elif vertex_scale is not None:
        # the voxel default's radius, never refused (at most half the diagonal of the surface's box in the grid's
        # axes, more than any edge): the check's smallest enclosing ball cost 29 ms of a 10,172-vertex voxel
        # sphere's 250 (its lattice's many co-spherical points; issue 30)
        groups, found = [(float(radius), None)], {}
    else:
        groups, found = [(_check_radius(radius, mesh), None)], {}
    # one radius; a list of them (one per group of components of one scale) when the scales differ
    radii = [group_radius for group_radius, _ in groups]
    parameters = {
        "radius": radii[0] if len(radii) == 1 else radii,
        "normal_radius": NORMAL_RADIUS_RATIO * radii[0]
        if len(radii) == 1
        else [NORMAL_RADIUS_RATIO * r for r in radii],
        **found,
    }
    if adaptive and len(groups) == 1:
        return _adaptive(mesh, groups[0][0], parameters, defects, valid, stages)
    if vertex_scale is not None:  # a voxel surface: each vertex at the scale its pilot calls for
        radii_v, normal_radii = vertex_scale
        axes = _grid_axes(mesh, stages.voxel)  # (its cube grids along the grid's axes)
        computed = _curvatures(
            _along(vertices, axes),
            topology.faces,
            degenerate,
            _along(normals, axes),
            valid,
            radii_v,
            stages,
            neighbours=referenced,
            adjacency=_adjacency(topology),
            edge=_mesh_edge(mesh),
            areas=_vertex_areas(mesh),
            normal_radius=normal_radii,
            coarse=True,
            boundary_faces=_boundary_faces(topology),
        )
        k_min, k_max, dir_min, dir_max, normals, valid, radii_v = _turned_back(computed, axes)
        parameters = {
            **parameters,
            "radius": float(np.median(radii_v)),
            "normal_radius": float(np.median(normal_radii)),
            "scale": "voxel",
            "scale_rule": VOXEL_SCALE_RULE,
        }
        return finish("icc", parameters, valid, normals, k_min, k_max, dir_min, dir_max, defects, radius=radii_v)
    pieces = _soup_pieces(mesh, defects, valid)
    voxel = _voxel_reader(mesh, defects, stages)
    reached = np.zeros(vertices.shape[0], dtype=bool)  # balls holding a thin part's other side (THIN_FACING)
    if radius is None:  # the default: each vertex at its group's radius times its local sampling's factor,
        # more where its own noise calls for more (a noisy patch)
        ratios = _local_scale_ratios(mesh)
        base, radii_v = _patch_radii(mesh, groups, levels, fits, ratios, normals)
        even = np.all(ratios == 1.0)
        if np.all(np.isfinite(radii_v) & (radii_v > 0)) and not (even and np.array_equal(radii_v, base)):
            wide = _coarse_fits(mesh, NORMAL_RADIUS_RATIO * radii_v, defects.invalid_vertices, stages)
            axes = _grid_axes(mesh, stages.voxel) if wide else None  # (the coarse level along the grid's axes)
            computed = _curvatures(
                _along(vertices, axes),
                topology.faces,
                degenerate,
                _along(normals, axes),
                valid,
                radii_v,
                stages,
                neighbours=referenced,
                adjacency=_adjacency(topology),
                edge=_mesh_edge(mesh),
                areas=_vertex_areas(mesh),
                weighted=not even,
                topology=bounded,
                cracked=bool(mesh.n_cracked),
                pieces=pieces,
                coarse_fits=wide,
                reached=reached,
                voxel=voxel,
            )
            local = _turned_back(computed, axes)[:-1]
            return _finished({**parameters, "scale": "local"}, local, defects, radii_v, reached)
    fields: tuple[np.ndarray, ...] | None = None
    for group_radius, members in groups:
        group_reached = np.zeros_like(reached)
        wide = _coarse_fits(mesh, NORMAL_RADIUS_RATIO * group_radius, defects.invalid_vertices, stages)
        axes = _grid_axes(mesh, stages.voxel) if wide else None  # (the coarse level along the grid's axes)
        computed = _curvatures(
            _along(vertices, axes),
            topology.faces,
            degenerate,
            _along(normals, axes),
            valid,
            group_radius,
            stages if fields is None else None,
            neighbours=referenced,
            adjacency=_adjacency(topology),
            edge=_mesh_edge(mesh),
            areas=_vertex_areas(mesh),
            topology=bounded,
            cracked=bool(mesh.n_cracked),
            pieces=pieces,
            coarse_fits=wide,
            reached=reached if members is None else group_reached,
            voxel=voxel,
        )
        computed = _turned_back(computed, axes)[:-1]
        if members is None:
            fields = computed
            continue
        if fields is None:
            fields = tuple(np.array(field, copy=True) for field in computed)
        for field, values in zip(fields, computed):
            field[members] = values[members]
        reached[members] = group_reached[members]
    if fields is None:
        raise RuntimeError("default_radii gave no group")
    return _finished(parameters, fields, defects, _vertex_radii(groups, vertices.shape[0]), reached)


def _finished(parameters: dict, fields: tuple, defects, radius: np.ndarray, reached: np.ndarray) -> tuple:
    """:func:`finish`'s ``(result, problems)`` of ``fields`` (``k_min, k_max, dir_min, dir_max, normals, valid``)
    with the reason :data:`meshcurv.defects.REACH` at the ``reached`` (V,) vertices (balls holding a thin part's
    other side, :data:`THIN_FACING`; a defect's code still comes first)."""
    k_min, k_max, dir_min, dir_max, normals, valid = fields
    result, problems = finish("icc", parameters, valid, normals, k_min, k_max, dir_min, dir_max, defects, radius=radius)
    if not reached.any():
        return result, problems
    codes = np.where(reached & ~result.valid, REACH, 0).astype(np.int8)
    return dataclasses.replace(result, invalid_reason=codes), problems


def estimate_multiscale(mesh: PreparedMesh, *, radii, stages: Stages) -> list[tuple]:
    """:func:`estimate` at each of the increasing ``radii``, the sums of all in one walk per vertex.

    Returns one ``(result, problems)`` per radius, equal to :func:`estimate` with
    that radius to round-off (the same faces and shares, added in another
    order): the normals are fitted at each scale (over three times each radius)
    and the balls of every radius summed in one walk of the largest
    (:func:`meshcurv.neighborhoods.ball_face_sums_nested`). A mesh with boundary edges is computed by
    :func:`estimate` at each radius: its normals are fitted at every corner of a face summed and made again
    near holes (:func:`_unwrapped_normals`), which the shared walk does not do.
    """
    vertices, topology = mesh.vertices, mesh.topology
    if topology.boundary_edges.any():
        return [estimate(mesh, radius=radius, stages=stages) for radius in radii]
    faces = topology.faces
    stages.start("compute normals")
    degenerate, start_normals = _dropped(mesh), mesh.vertex_normals
    defects, valid = mesh.start(boundary=True)
    stages.start("measure noise")
    # the radii increase: the conditions of check_radius (neither below a sliver of an edge nor above the
    # mesh's extent) hold for all of them when they hold for the first and the last
    last = len(radii) - 1
    radii = [_check_radius(radius, mesh) if j in (0, last) else float(radius) for j, radius in enumerate(radii)]
    stages.start("fit normals")
    failed = np.zeros((len(radii), vertices.shape[0]), dtype=bool)
    wraps = np.zeros((len(radii), vertices.shape[0]), dtype=bool)  # the fits reaching round (_wider_reaching)
    # the fits of the radii not fitted on the coarse level (a voxel surface's wider than COARSE_EDGES median edges:
    # _coarse_fits; any other mesh's none), from one walk per vertex (the radii increase, and so does _dense: the
    # radii fitted so are the first ones)
    edge = _mesh_edge(mesh)
    voxel = _coarse_fits(mesh, NORMAL_RADIUS_RATIO * radii[-1], defects.invalid_vertices, stages)
    fine = [NORMAL_RADIUS_RATIO * r for r in radii if not (voxel and NORMAL_RADIUS_RATIO * r > COARSE_EDGES * edge)]
    fits = (
        nested_jet_normals(
            vertices,
            np.where(valid[:, None], start_normals, [0.0, 0.0, 1.0]),
            fine,
            adjacency=_adjacency(topology),
            neighbours=topology.referenced_vertices,
            degree=NORMAL_DEGREE,
            iterations=NORMAL_ITERATIONS,
            settled=NORMAL_SETTLED,
            min_spread=NORMAL_MIN_SPREAD,
        )
        if fine
        else []
    )
    areas = _vertex_areas(mesh) if len(fits) < len(radii) else None  # the coarse level's weights only
    axes = _grid_axes(mesh, stages.voxel) if voxel else None  # (the coarse level along the grid's axes)
    normals = [
        fitted_normals(
            _along(vertices, axes),
            _along(start_normals, axes),
            valid,
            NORMAL_RADIUS_RATIO * radius,
            neighbours=topology.referenced_vertices,
            adjacency=_adjacency(topology),
            areas=areas if j >= len(fits) else None,  # fitted already: no coarse level to look for
            edge=edge,
            failed=failed[j],
            fits=_along(fits[j], axes) if j < len(fits) else None,
            coarse=voxel,
            thin=True,  # a thin part's fits made again over their own side, as estimate's (widen 1)
            widen=1.0,
            reaching=wraps[j],
        )
        for j, radius in enumerate(radii)
    ]
    normals = [rung if axes is None else rung @ axes for rung in normals]
    stages.start("compute face measures")
    facing = _facing_measures(vertices, faces)  # the balls holding a thin part's other side: _reaching
    measures = np.stack([np.column_stack([face_measures(vertices, faces, rung), facing]) for rung in normals])
    kept = [_usable_faces(faces, degenerate, rung) for rung in normals]
    stages.start("sum over balls")
    if all(mask is None if kept[0] is None else mask is not None and np.array_equal(mask, kept[0]) for mask in kept):
        # the same faces at every scale: one walk
        summed = _ball_face_sums_nested(vertices, faces, radii, measures, usable=kept[0])
    else:
        summed = np.stack(
            [
                _ball_face_sums(vertices, faces, radius, values, usable=mask, connected=True)
                for radius, values, mask in zip(radii, measures, kept)
            ]
        )
    stages.start("retrieve curvatures")
    out = []
    voxel_reader = _voxel_reader(mesh, defects, stages)
    for radius, rung, sums, rung_failed, values, mask, wrapped in zip(
        radii, normals, summed, failed, measures, kept, wraps
    ):
        sums, facing_sums = sums[:, :-FACING_COLUMNS], sums[:, -FACING_COLUMNS:]
        k_min, k_max, dir_min, dir_max = curvatures_from_measures(sums, rung)
        parameters = {"radius": radius, "normal_radius": NORMAL_RADIUS_RATIO * radius}
        rung_valid = valid & np.isfinite(k_min) & ~failed_fits_undefined(vertices, faces, radius, rung_failed)
        reached = _reaching(facing_sums, sums[:, 0], rung, radius, k_min, k_max, rung_valid)
        if wrapped.any() and not voxel_reader():  # as estimate's (_curvatures)
            reached |= _wider_reaching(
                vertices, faces, values, mask, radius, rung_valid & wrapped & ~reached, k_min, k_max, rung
            )
        fields = (k_min, k_max, dir_min, dir_max, rung, rung_valid & ~reached)
        out.append(_finished(parameters, fields, defects, np.full(vertices.shape[0], radius), reached))
    return out


def _adaptive(mesh: PreparedMesh, base: float, parameters: dict, defects, valid, stages: Stages):
    """icc with each vertex at its own scale: the rung of a ladder of radii where its estimate is stable.

    The normals are fitted once over ``3 base`` (as at the default radius ``base``); the measures are
    summed over the balls of every rung of :func:`meshcurv.radius.scale_ladder` (``base sqrt(2)^j`` up to
    12 median edge lengths) in one walk, and each vertex takes the sums of the rung that
    :func:`meshcurv.radius.stable_scales` picks (``result.radius``). Measured against the default on the
    families of ``benchmarks/scale.md`` (variant B anchored at the default: geometric mean of the median
    H error 0.57 -> 0.42% on clean, irregular and noisy meshes, 1.3 -> 1.2% on smoothed isosurfaces,
    3.1 -> 2.2% on elongated voxel shapes; 1.4 to 4 times the time).
    """
    vertices, topology = mesh.vertices, mesh.topology
    faces = topology.faces
    stages.start("fit normals")
    wide = _coarse_fits(mesh, NORMAL_RADIUS_RATIO * base, defects.invalid_vertices, stages)
    axes = _grid_axes(mesh, stages.voxel) if wide else None  # (the coarse level along the grid's axes)
    wraps = np.zeros(vertices.shape[0], dtype=bool)  # the fits reaching round (_wider_reaching)
    normals = fitted_normals(
        _along(vertices, axes),
        _along(mesh.vertex_normals, axes),
        valid,
        NORMAL_RADIUS_RATIO * base,
        neighbours=topology.referenced_vertices,
        adjacency=_adjacency(topology),
        areas=_vertex_areas(mesh),
        coarse=wide,
        thin=True,  # a thin part's fits made again over their own side, as estimate's (widen 1)
        widen=1.0,
        reaching=wraps,
    )
    normals = normals if axes is None else normals @ axes
    stages.start("compute face measures")
    measures = np.column_stack([face_measures(vertices, faces, normals), _facing_measures(vertices, faces)])
    stages.start("sum over balls")
    area = 0.5 * float(np.linalg.norm(mesh.cross[~_dropped(mesh)], axis=1).sum())
    radii = scale_ladder(base, median_edge_length(vertices, topology.edges), area)
    usable = _usable_faces(faces, _dropped(mesh), normals)
    summed = _ball_face_sums_nested(vertices, faces, radii, measures, usable=usable)
    stages.start("retrieve curvatures")
    summed, facing_sums = summed[..., :-FACING_COLUMNS], summed[..., -FACING_COLUMNS:]
    rung = stable_scales(*principal_from_measures(summed), topology.neighbour_lists)
    every = np.arange(vertices.shape[0])
    chosen = summed[rung, every]
    k_min, k_max, dir_min, dir_max = curvatures_from_measures(chosen, normals)
    parameters = {**parameters, "scale": "adaptive", "radii": tuple(float(r) for r in radii)}
    valid = valid & np.isfinite(k_min)
    # the rung chosen holding a thin part's other side (_reaching): undefined, not a smaller rung's value
    reached = _reaching(facing_sums[rung, every], chosen[:, 0], normals, radii[rung], k_min, k_max, valid)
    if (
        wraps.any() and not _voxel_reader(mesh, defects, stages)()
    ):  # the rung chosen read over a wider ball (_wider_reaching)
        reached |= _wider_reaching(
            vertices, faces, measures, usable, radii[rung], valid & wraps & ~reached, k_min, k_max, normals
        )
    fields = (k_min, k_max, dir_min, dir_max, normals, valid & ~reached)
    return _finished(parameters, fields, defects, radii[rung], reached)
