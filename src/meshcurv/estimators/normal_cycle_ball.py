"""The normal-cycle curvature tensor over a Euclidean ball (Cohen-Steiner and Morvan 2003).

The formula of :mod:`meshcurv.estimators.normal_cycle` over the ball
``B = B(x_v, r)`` instead of the barycentric cell:

.. math::

    T(v) = \\frac{1}{|B \\cap S|} \\sum_{e} \\beta(e)\\, |e \\cap B|\\, \\bar e \\bar e^T

``beta(e)`` is the signed dihedral angle of edge ``e`` (positive where the surface
bends away from its normals; :func:`~meshcurv.geometry.edge_dihedral_angles`),
``|e ∩ B|`` the exact length of the edge inside the ball and ``|B ∩ S|`` the
area of the mesh inside the ball, measured on the same edges:
``sum_e |e ∩ B| a(e) / |e|`` with ``a(e)`` a third of the area of each face of
``e`` (:func:`edge_area_densities`; a ball holding whole faces holds their whole
area). Both measures of the ratio then share the ball's cut through the edges:
with each face weighted by its approximate share instead
(:func:`meshcurv.neighborhoods.face_in_ball_ratios`), a ball of one to one and a
half edge lengths cutting a few long edges gave 10% of the vertices of a random
sphere off by more than half the curvature and 1.3% off by half of H (issue 29;
now 1.4% and none at one edge, none from 1.5; the median error of H at 2.5
edges is 0.014 against 0.033). Cohen-Steiner and Morvan
prove that this converges to the integral of the shape operator over the ball
when the mesh is a fine enough, well-shaped sampling, at a rate of the edge
length over the radius: the ball, unlike a fixed number of rings, keeps its
size as the mesh is refined.

Principal curvatures and directions come out as for ``normal_cycle``: the mean
is half the trace of ``T``, the difference and directions come from ``T``
restricted to the tangent plane of the vertex normal (area-weighted face
normals), with the eigenvectors turned by 90 degrees.

Edges on the boundary, non-manifold or inconsistently oriented edges and
edges of zero-area faces have no dihedral angle and add nothing; the area
stops at the boundary as well, so boundary vertices keep a (one-sided) estimate.
The faces of a needle vertex (a vertex flung far away,
:func:`meshcurv.defects.needle_vertices`) and the edges between their corners
add nothing either: the balls around them stop there as at a boundary. A
vertex whose ball holds none of its neighbours (a given radius below its
shortest edge) holds only its own corner, and a ball below one median edge
length (:data:`MIN_RADIUS_SCALES`) a few partial edges: such a vertex is
undefined (NaN, "estimate undefined"), not the cone of the polyhedron at it.

On a voxel surface (marching cubes, vertices on a voxel grid) the ball's
curvature is the small sum of the staircase's dihedral angles, about 90
degrees each and of both signs, which a whole ball balances out. A hole in
the ball (:func:`hole_edges`) takes some of them away at random and the sum
left is noise: such a vertex is undefined (NaN, "estimate undefined"). A voxel
sphere of radius 4 voxels with half of its faces removed had 177 of 421 valid
vertices off by more than half of H at the default radius (119 at 2.5 voxels,
69 at 3.5; spheres of 8 and 12 voxels: half of them), the same mesh with its
vertices moved onto the sphere, same holes and radius, 11 (issue 29). The rims
of voxel surfaces, with nothing beyond them, are not holes and keep their
(one-sided) estimate. A mesh is read as a voxel surface also where only most
of its valid vertices lie on a grid (faces detached off it and welded to each
other: a voxel sphere with half of its faces detached by 0.06 voxels had half
of its valid vertices off by more than half the curvature, fuzz 480/968).

Faces detached by a few hundredths of an edge and welded back across their cracks
(:data:`meshcurv.weld.CRACK_TOLERANCE_RATIO`) are tilted by the cracks' width over their height: on a fine
mesh, whose dihedral angles are as small, each edge reads that tilt as curvature. Where such welds are a
sizeable share of the mesh (:data:`CRACKED_SHARE`), every ball is judged by the standard error of its own
edges' readings (:data:`FEW_ELEMENTS_CRACKED_SPREAD`); at the default radius a ball that fails is grown once
(:data:`CRACK_GROWTH`) and judged again; a grown ball that lost much of its area to cracks left open is undefined
too (:data:`CRACKED_LOST_BIAS`): the weld closes a crack near its tolerance along long edges only, and on a
structured mesh the edges of one length read alike (a uv sphere's diagonals bend nothing), so what the ball kept
need not be a fair sample of its edges (fuzz 602/100: H 0.6 for 1 at every valid vertex). A voxel surface welded
back so, no longer read as one (:func:`._ring_noise.welded_grid`), is undefined: a ball of the default of other
meshes reads the plateaus of its staircase as flat.

Reach. The default radius is 2.5 mean edge lengths, which on a mesh of long and short edges reaches round a part
curved along the short ones (``torus(2, 1, 16, 16)``: a ball of 1.71 for a tube of radius 1), where the ball's
tensor, the mean of the shape operator over the ball, mixes the part's sides (``k`` up to 82% of the largest ``|k|``
off, valid; issue 29). A default ball whose vertex normals turn from its centre's by more than
:data:`meshcurv.radius.BALL_TURN_CAP` with no crease in it is summed again over a smaller ball; its default stays
where the smaller ball reproduces it, and a vertex with no smaller ball within the cap is NaN with ``valid=False``
(reason :data:`meshcurv.defects.REACH`; :func:`_round_balls`). At the voxel default, whose shell of balls
(:data:`VOXEL_SHELL`) reaches round a part thinner than a voxel or two (the rim of ``voxel_ellipsoid((8, 8, 2))``,
read at half its curvature), the vertex normals of the staircase scatter too much for that test: a vertex whose outer
ball's mean normal is short (:data:`VOXEL_REACH_MEAN_NORMAL`) is NaN with the same reason (:func:`_voxel_round_balls`).

Staircase readings. At the voxel default the tensor is read in the tangent plane of the shell's mean normal (the
surface's normals summed over its balls, measured on the edges as the area is: :func:`_shell_normals`), not the
vertex's own, which on a staircase is off the surface's by up to a radian, and it is divided by the surface's area in
the balls, ``pi rho^2`` per ball (exact on a sphere), not the staircase's, which has up to 1.3 times more
(:data:`VOXEL_AREA_INFLATION`, :func:`_voxel_surface_areas`). Without them, the poles of the coarse axis of
``voxel_sphere(3)`` at 0.5 x 0.2 x 0.2 read ``k`` 0.14 and 0.44 for 1/3 (valid) and clean voxel spheres H 7-11% low
(issue 29, N71; ``benchmarks/ncb_thin_rim_N70.py --readings``).

References
----------
D. Cohen-Steiner and J.-M. Morvan (2003). Restricted Delaunay triangulations and
normal cycle. Proc. 19th ACM Symposium on Computational Geometry, 312-321.
https://doi.org/10.1145/777792.777839
"""

from __future__ import annotations

import dataclasses
from typing import NamedTuple

import numpy as np

from .._tensors import outer6, principal_from_shape_operator
from .._geometry import edge_dihedral_angles
from ..neighborhoods import _ball_edge_sums, _candidate_pairs, _gathered, cell_centres, segment_in_ball_lengths
from ..radius import (
    BALL_TURN_CAP,
    CREASE_TURN,
    VoxelReading,
    _ball_turns,
    _component_radii,
    _edge_turns,
    _resolve_radius,
    _vertex_radii,
    _voxel_surface,
)
from .._prepared import PreparedMesh
from ..defects import REACH, STAIRCASE
from ._ring_noise import welded_grid
from ._support import Stages, ball_holds_neighbours, finish

STAGES = ("compute normals", "compute edge tensors", "sum over balls", "retrieve curvatures")

#: A given radius below this many median edge lengths is named in the warning (the registry's
#: ``radius_warning_edges``): on random spheres of 200 to 5,000 vertices (three seeds each), the valid
#: vertices off by more than half the curvature were 0.7% at one length scale, 0.28% at 1.1, 0.06% at 1.25
#: and none from 1.4 (none off by half of H from one; the default is 2.5 mean edges). Before the area was
#: measured on the edges (issue 29): 10% at one edge, 0.15-0.5% at 1.5.
RADIUS_WARNING_EDGES = 1.5

#: A ball whose radius is below this many length scales (the median edge length of the vertex's component,
#: :func:`meshcurv.geometry.vertex_length_scales`) holds a few partial edges and faces, not the surface:
#: its vertex is undefined. On the 2,000-point random unit sphere, the vertices off by more than half of
#: H = 1 were 186 of 767 valid at 0.35 mean edge lengths, 204 of 1,260 at 0.5, 133 of 1,739 at 0.7, 21 of
#: 1,962 at 1 and none from 1.5 (issue 29; fuzz_api seed 51, case 5992: 4 of 6 valid off at 0.07 edges);
#: with the area measured on the edges, none from one. Not higher: the voxel default of a ball of radius
#: 2 voxels is one length scale.
MIN_RADIUS_SCALES = 1.0

#: A default ball is checked for its reach round the surface (:func:`_round_balls`) where its largest ``|k|`` times
#: its radius exceeds this: a ball whose normals turn by :data:`meshcurv.radius.BALL_TURN_CAP` spans ``r k`` of 1.21 on
#: a circle, and the tensor reads a tube's or a sphere's ``k`` whatever the ball. At 0.5 (``quadric``'s rule, whose
#: fits read ``k`` high there) 40,045 of ogre's 62,194 balls were searched (1.6 times its CPU) and 234 made NaN whose
#: H was within 2-7% of ``icc``'s and ``normal_cycle``'s (of the 99th percentile of ``|k|``).
ROUND_CANDIDATE = 1.0

#: A default ball that reaches round the surface is made smaller at most this many times (:func:`_round_balls`), each
#: time to where the normals of a circle through its rim would turn by :data:`ROUND_TURN`, at most
#: :data:`ROUND_SHRINK` of its radius.
ROUND_STEPS = 3

#: ... the margin of each step (:func:`_round_balls`).
ROUND_SHRINK = 0.95

#: A default ball that reaches round the surface is made smaller to where the normals of a circle through its rim
#: would turn by this (radians; :func:`_round_balls`): a ball of ``0.83 / k`` with :data:`ROUND_SHRINK`. The ball's
#: tensor is the mean of the shape operator over the ball, which a ball round a tube mixes from both of its sides:
#: ``torus(2, 1, 16, 16)`` (a ball of 1.71 at its default) read ``k`` up to 82% of the largest ``|k|`` off, 52% over
#: balls of 1.2, 29% over balls of 0.83.
ROUND_TURN = 0.9

#: A default ball's reading that the first smaller ball (:func:`_round_balls`) reproduces within this share of its
#: largest ``|k|`` is kept: the curvature is steady over the ball, whatever its turn (a tube's along the ring:
#: ``torus(10, 1, 40, 12)``, whose default ball of 2.9 turns past the cap, read within 11%).
ROUND_AGREEMENT = 0.1


#: At the voxel default radius (a voxel surface, ``Stages.voxel_default``) the ball sums are taken over these
#: multiples of the radius and added (:func:`_ball_sums`): a shell of balls instead of one. A staircase is flat on
#: its plateaus, so a ball whose rim lies on a plateau (the normals along its rim those of the ball's centre) reads
#: the surface as flat, whatever its curvature: its sum of dihedral angles is the step's convex edges less its
#: concave ones, which nearly cancel (the integrated mean curvature of a patch is the flux of its slope across its
#: rim). Where the steps are widest (the poles and axes of a sphere, its 45-degree diagonals) one radius cuts every
#: step at the same phase: the clean ``voxel_sphere(10)`` at its default (4.225) had 5 valid vertices off the exact
#: H by more than half of 1/R, 105 by more than 0.3 (the poles read H 0.015 for 0.1). Radii spread over a step
#: average the rim's phase out: 0, 0 (benchmarks/ncb_plateaus_M33.py: voxel spheres of 6 to 20 voxels, a torus,
#: an ellipsoid, tuned; other shapes and spacings held out). A sum over each ball (its area grows as its radius
#: squared) gives the outer balls their share of the surface.
VOXEL_SHELL = (0.7, 0.85, 1.0, 1.15, 1.3)

#: ... and the shell is widened (:func:`_voxel_shell`) where its balls' rims would cross fewer than this many terraces
#: of the staircase round a point whose normal is along a grid axis: where the voxel default is capped at half the
#: radius of curvature (a surface of few voxels, anisotropic voxels), the shell of :data:`VOXEL_SHELL` read the
#: coarse axis's poles as flat or as a step (``voxel_sphere(9)`` at 1 x 1 x 2.5: 8 valid vertices at its pole off
#: by more than half of 1/R, H 0.015 for 0.111; ``voxel_torus(14, 5)`` at 1 x 1 x 2.5: 70). Tuned on anisotropic
#: spheres, tori and ellipsoids at 1 x 1 x 1.5, 1 x 1 x 2, 1 x 2 x 2 and 0.5 x 0.2 x 0.2 and M33's isotropic
#: shapes (valid vertices off by more than half the largest ``|k|``: 54 -> 0; 5 at 0.5 terraces, 4 at 0.65, 1 at
#: 0.9); held out at 1 x 1 x 2.5, 1 x 1 x 3, 1 x 1.5 x 2.5 and M33's held-out shapes: 89 -> 0, the valid vertices' ``k`` off by more
#: than half 595 -> 140 (``benchmarks/ncb_plateaus_M33.py --anisotropic``). Wider balls reach further round a
#: part thinner than a voxel: ``voxel_ellipsoid((8, 8, 2))``'s rim (its radius of curvature half a voxel) 1 -> 24
#: (made undefined, :data:`VOXEL_REACH_MEAN_NORMAL`).
VOXEL_SHELL_TERRACES = 1.0

#: At the voxel default a vertex whose outermost shell ball (:data:`VOXEL_SHELL`, :func:`_voxel_shell`) reaches round
#: the surface is undefined (:func:`_voxel_round_balls`): where the mean of the surface's unit normals over the ball
#: (``|sum n dA| / A``) is shorter than this, that of a spherical cap whose normals turn by
#: :data:`meshcurv.radius.BALL_TURN_CAP` (``(1 + cos 1.3) / 2 = 0.63``), and its largest ``|k|`` times the ball's
#: radius exceeds :data:`ROUND_CANDIDATE`. The shell's tensor, the mean of the shape operator over its balls, mixes
#: both sides of a part thinner than the balls: the rim of ``voxel_ellipsoid((8, 8, 2), seed=2)`` (its radius of
#: curvature half a voxel; balls to 2.4 voxels) read ``k_max`` 0.58-0.75 for 1.45-1.71 at 24 valid vertices (issue
#: 29). Not the vertex normals' turn of :func:`_round_balls`: a staircase's vertex normals scatter by up to a radian
#: (the valid vertices of ``voxel_sphere(17)``, whose balls turn by 0.42, turn by up to 1.9), a ball's mean normal by
#: a few hundredths (0.86-0.88 there; a flat staircase 0.85). Tuned on ``benchmarks/ncb_thin_rim_N70.py``'s tuned
#: shapes (valid vertices off by more than half the largest ``|k|``: 126 -> 35, all on the rims 91 -> 0; valid
#: -3.4%), held out on the others (189 -> 90, the rims' 99 -> 0; valid -3.6%, all on thin ellipsoids' rims). The
#: vertex normals' turn over the same balls, the rule of :func:`_round_balls`, refused as many lies for 12% (tuned)
#: and 16% (held out) of the valid vertices.
VOXEL_REACH_MEAN_NORMAL = 0.5 * (1.0 + float(np.cos(BALL_TURN_CAP)))


#: At the voxel default the area that divides a ball's curvature measure is the surface's, not the staircase's
#: (:func:`_voxel_surface_areas`): the mesh's area in the ball over at most this many times ``pi rho^2``. A
#: marching-cubes staircase has more area than the surface it samples (its terraces and risers: a flat staircase's mean
#: normal is 0.85 long, N70), while the curvature measure, the flux of the slope across the ball's rim, is the
#: surface's: ``voxel_sphere(17)`` read H 0.925 of the exact at the median (its balls held 1.06-1.11 times ``pi
#: rho^2``), ``voxel_sphere(10)`` at 1 x 1 x 2 0.893 (1.04-1.22). A sphere holds exactly ``pi rho^2`` in a ball of
#: radius ``rho`` centred on it, a smooth surface ``pi rho^2 (1 + O((rho k)^2))``. A ball holding less (a rim, a
#: hole) keeps its own area; one holding more than this is a ball over more than its sheet (two parts within the
#: ball), whose excess is not the staircase's: it is divided by this much only.
VOXEL_AREA_INFLATION = 1.3


def _voxel_surface_areas(areas: np.ndarray, groups: list, shells: list, n: int) -> np.ndarray:
    """(V,) the ``areas`` of a voxel surface's shells of balls (:func:`_ball_sums`: the mesh's area in each ball,
    added over the shell) read as the surface's: each divided by its ratio to the shell's ``sum pi (s r)^2``, clipped
    to [1, :data:`VOXEL_AREA_INFLATION`]. ``groups``: ``(radius, members)``; ``shells``: the multiples of each group's
    radius (:func:`_voxel_shell`)."""
    disc = np.zeros(n)
    for (group_radius, members), shell in zip(groups, shells):
        rows = slice(None) if members is None else members
        disc[rows] = np.pi * float(sum(s * s for s in shell)) * np.asarray(group_radius, dtype=np.float64) ** 2
    with np.errstate(invalid="ignore", divide="ignore"):
        inflation = np.clip(areas / disc, 1.0, VOXEL_AREA_INFLATION)
    return np.where(np.isfinite(inflation), areas / inflation, areas)


def _shell_normals(normal_sums: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """(V, 3) the unit mean of the surface's normals over each vertex's shell of balls (``normal_sums``, (V, 3):
    :func:`_ball_sums`), the vertex's own unit normal (``normals``) where that sum vanishes.

    The tensor is read in the tangent plane of this normal at the voxel default: a staircase's vertex normals scatter
    by up to a radian round the surface's (``voxel_sphere(3)`` at 0.5 x 0.2 x 0.2: a pole's vertex normals 0.6-1.2 rad
    off its axis), and the tensor restricted to such a plane mixes its normal part into ``k_min`` and ``k_max``
    (``k`` 0.14 and 0.44 for 1/3, valid; issue 29)."""
    lengths = np.linalg.norm(normal_sums, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        unit = normal_sums / lengths[:, None]
    return np.where((lengths > 0)[:, None] & np.isfinite(unit).all(axis=1)[:, None], unit, normals)


def _voxel_shell(radius: float, step: float) -> tuple[float, ...]:
    """The multiples of a voxel default ``radius`` whose balls' sums are added: :data:`VOXEL_SHELL`, widened to the
    terraces of a staircase of largest voxel size ``step`` (:data:`VOXEL_SHELL_TERRACES`).

    Round a point where the surface's normal is along a grid axis (a sphere's pole, a torus's equator along the
    coarse axis of anisotropic voxels) the staircase's terraces are rings about the point, the ``j`` th ring's rim
    about ``sqrt(2 R j h)`` from it on a surface of radius of curvature ``R`` and voxel size ``h`` along the axis:
    balls from ``s0 r`` to ``s1 r`` cross ``n = (s1^2 - s0^2) r^2 / (2 R h)`` terraces. Where ``n`` is below one,
    every ball's rim reads the same terrace's phase, and the shell reads the surface as flat or as a step. The
    voxel default (:func:`meshcurv.radius.voxel_radius`) is ``1.5 sqrt(h R)`` (``n = 1.125`` per unit of ``s1^2 -
    s0^2``: :data:`VOXEL_SHELL` crosses 1.35) or, on a surface of few voxels, ``R / 2``: there ``n = (s1^2 -
    s0^2) r / (4 h)``, and the shell reaches ``s1 = sqrt(s0^2 + 4 n h / r)`` for ``n`` =
    :data:`VOXEL_SHELL_TERRACES` (more where the floor of one voxel holds the radius: ``R`` is then below ``2 r``).
    ``h`` is the largest voxel size: its axis's poles have the widest terraces.
    """
    inner, outer = VOXEL_SHELL[0], VOXEL_SHELL[-1]
    if not (np.isfinite(step) and step > 0 and np.isfinite(radius) and radius > 0):
        return VOXEL_SHELL
    wide = float(np.sqrt(inner * inner + 4.0 * VOXEL_SHELL_TERRACES * step / radius))
    if wide <= outer:
        return VOXEL_SHELL
    return tuple(float(x) for x in np.linspace(inner, wide, len(VOXEL_SHELL)))


def edge_area_densities(topology, face_areas: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """(E,) area per unit length of each edge: a third of the area of each of its faces, over its length.

    Summed over the part of each edge inside a ball (``|e ∩ B|`` times the
    density), the area of the mesh in the ball measured on the edges, as the
    curvature tensor is: an edge wholly inside adds a third of each of its
    faces, so a ball that holds whole faces holds their whole area. Zero on
    edges of zero length (their faces have no area) and for faces of zero
    ``face_areas`` (degenerate faces, needle slivers).
    """
    sides = topology.face_edges
    held = sides >= 0
    thirds = np.broadcast_to((face_areas / 3.0)[:, None], sides.shape)
    shares = np.bincount(sides[held], weights=thirds[held], minlength=lengths.shape[0])
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(lengths > 0, shares / lengths, 0.0)


#: An estimate averaged from elements (``normal_cycle``'s cells, ``normal_cycle_ball``'s edges) whose support kept
#: less than this share of the elements an intact support holds (their effective numbers, :func:`few_elements`) ...
FEW_ELEMENTS_KEPT = 0.5

#: ... is undefined where its standard error, the elements' scatter over the square root of their effective number,
#: exceeds this share of the mesh's curvature (:func:`few_elements`).
FEW_ELEMENTS_SPREAD = 0.2

#: A ball that kept less than this share of the elements of its intact ball (holes or cracks in it) is judged by the
#: scatter of its own readings as well (:func:`few_elements`' ``local_variances``): faces detached by cracks and
#: welded back across them (:data:`meshcurv.weld.CRACK_TOLERANCE_RATIO`) are tilted by the crack's width over their
#: own height, and the edges between them read that tilt (fuzz_api 400/31: -3.2 for H = 1 on icosphere(24),
#: 400/89: 30 to 400 by a uv sphere's poles) where a regular mesh's edges scatter little; half-detached uv spheres
#: (64 x 32) and icosphere(24), default and given balls of 1.5 and 2.9 edges, both windings, seeds 0-1: 2,492 valid
#: vertices off by more than half of H -> 44 (by at most 0.64); with 0.7 instead 246, with 0.5 (the lost balls only)
#: 1,961 (tests/test_ncb_cracks_N21.py).
FEW_ELEMENTS_HOLED = 0.8

#: A ball that lost most of its elements (:data:`FEW_ELEMENTS_KEPT`) and holds fewer than this effective number
#: of them has no scatter to judge: one or two edges' readings are the estimate (a ball of 1.5 edges on a
#: half-detached icosphere(24): one edge left of 48, H -5.8 for 1, their variance 0).
FEW_ELEMENTS_LEAST = 2.0

#: On a mesh welded across cracks (:data:`meshcurv.weld.CRACK_TOLERANCE_RATIO`, ``PreparedMesh.n_cracked``), a
#: ball whose own readings' standard error (the local scatter over the square root of their effective number,
#: :func:`few_elements`) exceeds this share of the mesh's curvature is undefined, whether or not it lost elements
#: and however the mesh's median scatters. A crack weld moves a corner by up to 0.05 of its edges' length, which
#: tilts a well-shaped face by about as many radians and a sliver (a uv sphere's pole: 0.01 wide for 0.1 long) by
#: ten times more; on a fine mesh (icosphere(40): edges of 0.03 on the unit sphere, dihedral angles of 0.03) that
#: tilt is the size of the curvature each edge reads, and the balls' estimates scatter by up to 0.2 of it (the
#: previous bound, :data:`FEW_ELEMENTS_SPREAD`), where the fuzzer's tolerance, half the largest ``|k|``, was 2.5
#: standard errors away: of some 50,000 valid vertices a few were beyond it (fuzz 440/25, 480/2: up to 0.57; measured
#: errors reach 3.7 standard errors). At an eighth the tolerance is four standard errors away. Those faces' scatter is
#: noise, not the structure of a regular mesh, so the mesh's median (:data:`FEW_ELEMENTS_NOISE`) excuses none: a uv
#: sphere's pole ring whose slivers the weld folded read H -1.2 for 1 at 1.07 edges while the mesh's balls scatter
#: alike there (fuzz 500/36: 63 of 4,196 valid vertices off by up to 0.70). Numbers: tests/test_ncb_fine_soups_N25.py.
FEW_ELEMENTS_CRACKED_SPREAD = 0.125

#: ... and at the default radius such a ball is grown this many times (its standard error falling as the radius)
#: and judged again, with the same reference (the scatter and curvature of the first balls): on icosphere(40)
#: half detached by 0.044 edges (three draws), 78-80% of the vertices valid with 8-22 off by more than half of the
#: largest ``|k|`` before, 64-66% and none with the bound alone, 81-82% and none grown twice (1.5 times: 78-80%).
CRACK_GROWTH = 2.0

#: The two rules above hold on a mesh whose vertices welded across cracks (``PreparedMesh.n_cracked``) are at least
#: this share of its vertices: there the mesh's median scatter is the cracks' own. A few welds among wide cracks
#: (the 12 x 8 uv sphere half detached by 0.09 edges: 2 of 338, tests/test_ring_cracks_N19.py) leave the median
#: the mesh's structure, which the rules of :data:`FEW_ELEMENTS_NOISE` read.
CRACKED_SHARE = 0.05

#: ... where their own readings scatter more than this many times the median of the intact balls' (a structured
#: mesh's holed balls scatter as its intact ones: the 12 x 8 uv sphere's vertices of tests/test_ring_cracks_N19.py
#: keep theirs; at 1 the sweep above left 30 off instead of 44, and one more of those vertices undefined).
FEW_ELEMENTS_NOISE = 2.0

#: On a mesh welded across cracks, a ball grown at the default radius (:data:`CRACK_GROWTH`) whose edges with a
#: reading (a dihedral angle) hold the share ``p`` of the area they would hold without open cracks, holes and loose
#: faces is undefined where ``(1 - p) sigma`` exceeds this share of the mesh's curvature, ``sigma`` being the scatter
#: of the edges' readings in the intact balls (:func:`_crack_biased`). The ball's H is the mean of the readings it
#: kept; the edges it lost would have read ``(1 - p)`` of it, and where they are not a fair sample of the ball's edges
#: its H is off by ``(1 - p)`` times the difference of the two groups' means, up to about ``2 sigma``: this bound
#: keeps that bias within half of the curvature (the fuzzer's bar for a lie). The weld across cracks picks its
#: edges by their length (:data:`meshcurv.weld.CRACK_TOLERANCE_RATIO` of the shorter edge): a crack near the
#: tolerance is welded along long edges and left open along short ones, and on a structured mesh the edges of one
#: length read alike. The 64 x 32 uv sphere half detached by 0.048 mean edges: 816 of the 840 edges welded back were
#: its quads' diagonals, which bend nothing (the quads are planar), while its parallels and meridians (H 1.5) stayed
#: open; every valid vertex, each a grown ball, read H 0.42-0.79 for 1 (fuzz 602/100). Half detached by 0.045-0.052 (four draws each): 36-2,702 valid
#: vertices, median H 0.62-0.95, up to 1,232 off by more than a quarter of H; now 2-83, median H 0.90-1.01, none. The
#: balls that pass at the default radius are not judged so: with them the half-detached uv spheres at 0.044 and
#: icosphere(40) lost the valid vertices their tests keep (tests/test_ncb_cracks_N21.py,
#: tests/test_ncb_fine_soups_N25.py), the tilt's noise inflating ``sigma``; at 0.125 icosphere(40)'s grown balls too.
#: Numbers: tests/test_ncb_cracks_C30.py and benchmarks/ncb_crack_bias_C30.py.
CRACKED_LOST_BIAS = 0.25


def few_elements(valid, shares, intact_shares, variances, readings, curvatures, *, local_variances=None) -> np.ndarray:
    """(V,) bool: the ``valid`` vertices whose support lost most of its elements and whose estimate reads too few
    of them to average out their scatter.

    A vertex's H is the weighted mean of its elements' own readings (an edge's dihedral angle over its area; a
    cell, the mean of its edges'), which scatter about it: the tessellation's scatter, small on a regular mesh,
    the size of H itself on a random one (and the curvature's anisotropy: an edge along a cylinder's axis reads
    its curvature, one around it nothing). Averaged over ``N`` elements of equal weight it falls as
    ``1 / sqrt(N)``; with weights ``w``, ``N = (sum w)^2 / sum w^2``. A support that lost most of its elements to
    boundaries, cracks and loose faces reads the few left, and their scatter is its error: faces detached by
    cracks beyond the weld (fuzz ``--wide-cracks``, issue 29) left valid vertices whose region held one cell and
    its fragment (``normal_cycle``, H 3.04 for 1) or whose ball held three or four edges with a dihedral angle
    (``normal_cycle_ball``, H 0.36 for 1), while a regular icosphere's vertex with as little left next to its
    holes reads the sphere. An intact support is not judged: on a structured mesh (a uv sphere's meridians,
    parallels and diagonals) the scatter is large but each whole ring of directions cancels it.

    ``shares``: (V,) ``1 / N`` of each support (or more), ``intact_shares`` the same with every element the support
    would hold without boundaries, holes and defects; ``variances``: (V,) the weighted variance of the readings in
    each intact support (NaN for none), whose median over the valid vertices is their scatter; ``curvatures``: ``(k_min, k_max)``, the estimates, whose larger ``|k|`` at the valid
    vertices that kept their supports gives the mesh's curvature (its median; where none kept theirs, the root
    mean square of the edges' ``readings``, :func:`edge_readings`). Undefined where ``N`` is below
    :data:`FEW_ELEMENTS_KEPT` of the intact one and ``sqrt(variance / N)`` above :data:`FEW_ELEMENTS_SPREAD` times
    that curvature.

    ``local_variances``: (V,) the weighted variance of the readings each support kept (``normal_cycle_ball``'s
    balls; None: not judged). The median scatter of the intact supports misses the few supports where cracks
    welded back tilted faces (their edges read the tilt) or folded them: with it, a support that lost most of its
    elements is judged by the larger of the two scatters, one that kept less than :data:`FEW_ELEMENTS_HOLED` of
    them by its own, one that lost most and kept fewer than :data:`FEW_ELEMENTS_LEAST` is undefined, and where
    no support kept its elements the curvature is the median of the estimates.
    """
    return _few_elements(
        valid, shares, intact_shares, variances, readings, curvatures, local_variances=local_variances
    )[0]


class _Reference(NamedTuple):
    """What :func:`_few_elements` judged its supports against: the median ``variance`` of the intact supports'
    readings and the mesh's curvature ``scale``."""

    variance: float
    scale: float


def _few_elements(
    valid,
    shares,
    intact_shares,
    variances,
    readings,
    curvatures,
    *,
    local_variances=None,
    cracked=False,
    reference=None,
):
    """``(few, reference)``: :func:`few_elements` and the :class:`_Reference` it judged against (None where no
    support was known). ``cracked``: the mesh was welded across cracks (:data:`FEW_ELEMENTS_CRACKED_SPREAD`);
    ``reference``: judge against this one (a second pass over grown balls, whose own medians would be those of the
    noisiest balls alone)."""
    known = valid & np.isfinite(variances)
    if reference is None and not known.any():
        return np.zeros_like(valid), None
    k_min, k_max = curvatures
    with np.errstate(invalid="ignore", over="ignore"):
        lost = ~(FEW_ELEMENTS_KEPT * shares <= intact_shares)
    if reference is None:
        variance = float(np.median(variances[known]))
        # the curvature of the supports that kept their elements; where none did, the edges' readings' root mean
        # square
        kept = valid & ~lost
        largest = np.maximum(np.abs(k_min), np.abs(k_max))
        if kept.any():
            scale = float(np.median(largest[kept]))
        elif local_variances is not None:  # the estimates' median: a few folded edges' readings outweigh a mean square
            scale = float(np.median(largest[valid]))
        else:
            read = readings[np.isfinite(readings)]
            with np.errstate(over="ignore"):
                scale = float(np.sqrt(np.mean(read * read))) if read.size else 0.0
        reference = _Reference(variance, scale)
    variance, scale = reference
    bound = (FEW_ELEMENTS_SPREAD * scale) ** 2
    with np.errstate(invalid="ignore", over="ignore"):
        if local_variances is None:
            return valid & lost & ~(variance * shares <= bound), reference
        holed = ~(FEW_ELEMENTS_HOLED * shares <= intact_shares)
        few = lost & ~(np.fmax(variance, local_variances) * shares <= bound)
        noisy = holed & ~(local_variances <= FEW_ELEMENTS_NOISE * variance)
        few |= noisy & ~(local_variances * shares <= bound)
        if cracked:  # faces welded across cracks scatter as noise, the mesh's median too: every ball by its own
            few |= ~(local_variances * shares <= (FEW_ELEMENTS_CRACKED_SPREAD * scale) ** 2)
        few |= lost & ~(shares * FEW_ELEMENTS_LEAST <= 1.0)
        return valid & few, reference


def few_elements_note(count: int, support: str, elements: str) -> str:
    """The warning's phrase for ``count`` vertices left undefined by :func:`few_elements` ("" for none)."""
    if not count:
        return ""
    return (
        f"{count} vertices are NaN (estimate undefined): their {support} reads too few {elements} (the rest lost to "
        f"boundaries, cracks or loose faces) to average out the scatter of the mesh's {elements}"
    )


def edge_readings(beta: np.ndarray, density: np.ndarray, usable: np.ndarray) -> np.ndarray:
    """(E,) the mean curvature each edge with a dihedral angle reads alone, ``H_e = beta / (2 density)``: the
    normal cycle's H over a support is their mean weighted by the area on each (NaN for the other edges)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(usable & (density > 0), beta / (2.0 * density), np.nan)


#: A boundary edge is the edge of a hole when a vertex of the mesh lies beyond it, farther than this share of the
#: ball's radius from its line, within the ball's radius of its middle (:func:`hole_edges`). A rim cut across a
#: mesh (the hemisphere of ``shapes``) is a row of teeth, each a triangle's height (0.35 of the default radius)
#: beyond the notches between them: at 0.25 the notches counted as holes and the median error of H at the
#: hemisphere's rim went from 7.8% to 1.7%, but that of k_max from 2.3% to 4.3% (``benchmarks/accuracy.py
#: --quick``); at 0.4 and 0.55 no error at the rim grew (a hole of one face has vertices 0.7 and more of the
#: default radius beyond its edges: the holed and detached meshes of issue 29 came out the same from 0.25 to 0.55).
BEYOND_RADII = 0.4

#: Relative margin of :func:`hole_edges`' three tests: far above round-off, far below any measured effect.
LATTICE_TIE = 1e-7


def hole_edges(vertices: np.ndarray, topology, radii: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """(E,) bool: the boundary edges with the surface beyond them, within a ball: the edges of holes, not of rims.

    A boundary edge ``e`` of face ``f`` looks away from ``f``: ``o``, the
    direction in the plane of ``f`` perpendicular to ``e``, from the corner of
    ``f`` opposite ``e`` to ``e``. It is the edge of a hole (or of a crack, or of
    faces detached from their neighbours) when a vertex ``x`` of the mesh lies
    beyond it: within ``rho`` of its middle ``m``, with ``(x - m) . o >
    BEYOND_RADII rho`` and ``|(x - m) . n_f| < (x - m) . o`` (near the plane of
    ``f``, not on another sheet); ``rho`` is the radius of the ball of the
    edge's first end, :data:`BEYOND_RADII` keeps the rim's own vertices out
    where it bends. At the rim of a surface (cylinder, saddle, hemisphere)
    nothing lies beyond. Only the vertices of ``corners`` (V,) bool count.

    A hole takes with it the dihedral angles of all of its edges, which bent
    the surface on both of their sides, while the faces left keep the area of
    one side: summed with that area, a surface full of holes reads as nearly
    flat (issue 29: 394 of 938 valid vertices of an icosphere with half of
    its faces removed off by more than half of H). The area on the edges of
    holes goes with their curvature. A rim keeps it: its edges run along the
    rim, and on a cylinder or a saddle cut along its rulings they bend nothing
    (without their area the median error of H at the cylinder's rim went
    from 0.2% to 4%).
    """
    holes = np.zeros(topology.n_edges, dtype=bool)
    ends = topology.edges
    rho = radii[ends[:, 0]]
    candidates = np.flatnonzero(topology.boundary_edges & np.isfinite(rho) & (rho > 0))
    if candidates.size == 0 or not corners.any():
        return holes
    candidates = candidates[np.argsort(rho[candidates], kind="stable")]  # the pairs' search: ordered by radius
    face = np.max(topology.edge_faces[candidates], axis=1)
    a, b = vertices[ends[candidates, 0]], vertices[ends[candidates, 1]]
    middle = (a + b) / 2
    opposite = vertices[topology.faces[face]].sum(axis=1) - a - b
    along = b - a
    outward = middle - opposite
    with np.errstate(invalid="ignore", divide="ignore"):
        outward -= (np.einsum("ij,ij->i", outward, along) / np.einsum("ij,ij->i", along, along))[:, None] * along
        outward /= np.linalg.norm(outward, axis=1)[:, None]
        normal = np.cross(along, outward)
        normal /= np.linalg.norm(normal, axis=1)[:, None]
    points = np.flatnonzero(corners)
    reach = np.full(points.size, np.finfo(float).tiny)  # points: no reach of their own
    beyond = np.zeros(candidates.size, dtype=bool)
    for chunk, i, c in _candidate_pairs(middle, vertices[points], reach, rho[candidates]):
        rows = chunk.start + i
        offsets = vertices[points[c]] - middle[rows]
        out = np.einsum("ij,ij->i", offsets, outward[rows])
        # each test off its bound by LATTICE_TIE: on a voxel surface distances and angles of 45 degrees fall on
        # the bounds exactly, and round-off (of a scaled copy) decided them
        hit = (
            (np.einsum("ij,ij->i", offsets, offsets) <= rho[candidates[rows]] ** 2 * (1 + 2 * LATTICE_TIE))
            & (out > BEYOND_RADII * rho[candidates[rows]] * (1 + LATTICE_TIE))
            & (np.abs(np.einsum("ij,ij->i", offsets, normal[rows])) < out * (1 - LATTICE_TIE))
        )
        beyond[rows[hit]] = True
    holes[candidates] = beyond
    return holes


def estimate(mesh: PreparedMesh, *, radius, stages: Stages):
    """Normal-cycle tensor over balls of radius ``radius``. Returns ``(result, problems)``."""
    vertices, topology = mesh.vertices, mesh.topology
    stages.start("compute normals")
    if radius is None:  # each group of components of one scale at its own default
        groups = _component_radii(mesh)
    else:
        groups = [(_resolve_radius(radius, mesh), None)]
    cross, degenerate, normals = mesh.cross, mesh.degenerate, mesh.vertex_normals
    defects, valid = mesh.start(boundary=True)
    sound = valid.copy()  # the vertices free of defects, before the balls' checks

    stages.start("compute edge tensors")
    double_areas = np.linalg.norm(cross, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        unit_normals = cross / double_areas[:, None]
    usable = topology.interior_edges & ~degenerate[np.maximum(topology.edge_faces, 0)].any(axis=1)
    # a needle's slivers (and the edges between its corners) add nothing: they would outweigh the balls around it
    needle_edges, needle_faces = defects.needle_cells(topology.edges), defects.needle_cells(topology.faces)
    if needle_edges is not None:
        usable &= ~needle_edges
    kept_faces = ~degenerate if needle_faces is None else ~degenerate & ~needle_faces
    beta, lengths, unit = edge_dihedral_angles(vertices, topology, unit_normals, usable)
    intact = edge_area_densities(topology, np.where(kept_faces, double_areas / 2, 0.0), lengths)
    radii = _vertex_radii(groups, vertices.shape[0])

    stages.start("sum over balls")
    # on a mesh with boundaries the sums carry the scatter of the edges' own estimates too (FEW_ELEMENTS_SPREAD)
    scattered = bool(topology.boundary_edges.any())
    terms = (beta, unit, lengths, intact, usable)
    # at the voxel default a shell of balls (VOXEL_SHELL): one ball's rim on a plateau reads the staircase as flat
    shells: list[tuple[float, ...]] = [(1.0,)] * len(groups)
    if stages.voxel_default:
        grid = stages.voxel.mesh_grid(mesh)
        step = float(np.max(grid.spacing)) if grid is not None else np.nan
        shells = [_voxel_shell(float(np.max(r)), step) for r, _ in groups]
    # at the voxel default the shell's own normals too: a staircase's vertex normal is off by up to a radian
    area_normals = np.where(kept_faces[:, None], cross / 2.0, 0.0) if stages.voxel_default else None
    measures, areas, spread_sums, holes, readings, summed, normal_sums = _ball_sums(
        vertices, topology, groups, radii, terms, scattered, shells, area_normals
    )

    stages.start("retrieve curvatures")
    valid &= areas > 0
    # a ball that holds none of the vertex's neighbours holds only its own corner: the polyhedron's cone at
    # the vertex, not the surface (a given radius far below the edges; issue 29): undefined
    valid &= ball_holds_neighbours(vertices, topology.edges, radii) & (radii >= MIN_RADIUS_SCALES * mesh.length_scales)
    outer = [(max(shell) * np.asarray(r, dtype=np.float64), m) for (r, m), shell in zip(groups, shells)]  # its reach
    holed = _voxel_holed_balls(mesh, holes, outer, valid, stages.voxel) & valid
    valid &= ~holed
    read_areas = areas
    # at the voxel default: the shell's mean normal and the surface's area, not the staircase's
    if normal_sums is not None:
        normals = _shell_normals(normal_sums, normals)
        read_areas = _voxel_surface_areas(areas, groups, shells, vertices.shape[0])
    k_min, k_max, dir_min, dir_max = _principal(measures, read_areas, normals, valid)
    reached = np.zeros_like(valid)
    if radius is None and not stages.voxel_default:  # a default ball that reaches round the surface: made smaller
        sums = (measures, areas, spread_sums)
        reached = _round_balls(mesh, (radii, valid), summed, sums, (k_min, k_max, dir_min, dir_max))
        valid &= ~reached
    elif stages.voxel_default:  # a shell that reaches round a part thinner than its balls (a thin rim): undefined
        factors = np.ones_like(radii)
        for (_, members), shell in zip(groups, shells):
            factors[slice(None) if members is None else members] = max(shell)
        faces = (area_normals, intact, lengths)
        reached = _voxel_round_balls(mesh, factors * radii, valid, (k_min, k_max), faces)
        valid &= ~reached
    few, biased = np.zeros_like(valid), np.zeros_like(valid)
    on_voxels = _voxel_surface(mesh, defects.invalid_vertices, valid=valid, reading=stages.voxel)
    if scattered and not on_voxels:
        cracked = mesh.n_cracked >= CRACKED_SHARE * vertices.shape[0]
        few, reference = _few_edges(valid, areas, spread_sums, readings, (k_min, k_max), cracked=cracked)
        if cracked and radius is None and few.any():  # the default's balls over welded cracks: grown once
            grown = few
            radii = np.where(grown, CRACK_GROWTH * radii, radii)
            wide = [(CRACK_GROWTH * r, grown if m is None else grown & _member_mask(m, grown.size)) for r, m in groups]
            sums = _ball_sums(vertices, topology, wide, radii, terms, scattered)
            curvatures = _principal(sums[0], sums[1], normals, grown)
            again, _ = _few_edges(grown, sums[1], sums[2], sums[4], curvatures[:2], cracked=True, reference=reference)
            # a grown ball that lost much of its area to open cracks: what it kept need not be a fair sample
            biased = _crack_biased(grown & ~again, sums[2], reference)
            kept = grown & ~again & ~biased
            for old, new in zip((k_min, k_max, dir_min, dir_max), curvatures):
                old[kept] = new[kept]
            few &= ~kept
        valid &= ~few
    # a voxel surface welded across cracks, no longer read as one, has the default of other meshes, whose balls
    # read a plateau of its staircase as flat with no scatter (fuzz 500/28: H 0 for 0.1, valid); so has one read as
    # a voxel surface only by its vertices on the grid's planes (its holes' rule), whose default radius is not the
    # voxel default (no grid read for it) and is one ball, no shell (fuzz 647/28: voxel_sphere(10) a fifth detached
    # by 0.045 edges, balls of 2.41 for the voxel default's 4.23: 12 of 97 valid vertices off by more than half of
    # H, 8 of them H 0 for 0.1 at a pole)
    staircase = np.zeros_like(valid)
    plain_default = radius is None  # (the voxel default is handed to the estimator as a radius)
    if (not on_voxels or plain_default) and valid.any() and welded_grid(mesh, sound) is not None:
        staircase, valid = valid, np.zeros_like(valid)
    parameters: dict[str, object] = {"radius": groups[0][0]}
    if len(groups) > 1:
        parameters["radii"] = tuple(r for r, _ in groups)
    note = (
        f"{int(holed.sum())} vertices of this voxel surface are NaN (estimate undefined): their ball holds a hole, "
        f"and the staircase's dihedral angles left in it do not average out"
        if holed.any()
        else ""
    )
    curvatures = (k_min, k_max, dir_min, dir_max)
    extra = (
        note,
        few_elements_note(int((few & ~biased).sum()), "ball", "edges"),
        _crack_bias_note(int((few & biased).sum())),
        _staircase_note(int(staircase.sum())),
        _reach_note(int((reached & ~staircase).sum()), voxel=stages.voxel_default),
    )
    result, problems = finish(
        "normal_cycle_ball", parameters, valid, normals, *curvatures, defects, extra=extra, radius=radii
    )
    if staircase.any() or reached.any():  # the reason: a limit of the method (a defect's code comes first)
        codes = np.where(staircase, STAIRCASE, np.where(reached, REACH, 0)).astype(np.int8)
        result = dataclasses.replace(result, invalid_reason=codes)
    return result, problems


def _round_balls(mesh: PreparedMesh, balls: tuple, edges: tuple, sums: tuple, curvatures: tuple) -> np.ndarray:
    """(V,) bool: the vertices whose default ball reaches round the surface and no smaller ball holds the surface.

    ``balls = (radii, valid)``: each vertex's default radius (changed in place where a ball is made smaller) and the
    vertices estimated; ``edges = (edge_values, measured)``, what :func:`_ball_sums` summed; ``sums = (measures,
    areas, spread_sums)`` of the balls and ``curvatures = (k_min, k_max, dir_min, dir_max)`` (changed in place at
    the balls made smaller). A ball of the default radius (2.5 mean edge lengths) reaches round a part curved along
    its short edges: on ``torus(2, 1, 16, 16)`` a ball of 1.71 for a tube of radius 1, whose tensor, the mean of the
    shape operator over the ball, mixes the tube's outer and inner sides (``k_min`` up to 82% of the largest ``|k|``
    off, valid; issue 29). A ball whose vertex normals turn from its centre's by more than
    :data:`meshcurv.radius.BALL_TURN_CAP` with no edge in it turning by more than
    :data:`meshcurv.radius.CREASE_TURN` (a crease is the ball's reading at any radius) is made smaller, to where a
    circle through its rim would turn by :data:`ROUND_TURN`, and summed again (:data:`ROUND_STEPS` times at most); a
    vertex whose smaller ball holds none of its neighbours, or is below :data:`MIN_RADIUS_SCALES` length scales, or
    that still turns past the cap, is returned (NaN with ``valid=False``, the reason
    :data:`meshcurv.defects.REACH`). Checked where the largest ``|k|`` times the radius exceeds
    :data:`ROUND_CANDIDATE`."""
    radii, valid = balls
    measures, areas, spread_sums = sums
    vertices, topology, normals = mesh.vertices, mesh.topology, mesh.vertex_normals
    out = np.zeros(vertices.shape[0], dtype=bool)
    with np.errstate(invalid="ignore"):
        bent = radii * np.fmax(np.abs(curvatures[0]), np.abs(curvatures[1])) > ROUND_CANDIDATE
    rows = np.flatnonzero(valid & bent)
    if rows.size == 0:
        return out
    pool = np.flatnonzero(topology.referenced_vertices)
    creases = _edge_turns(normals, topology.edges, vertices.shape[0])
    reach = 2.0 * np.sin(ROUND_TURN / 2.0)  # the chord of a unit circle whose ends' normals turn by ROUND_TURN
    values, measured = edges  # the holes read within the default
    ends, values = np.ascontiguousarray(topology.edges[measured], dtype=np.int64), values[measured]
    for step in range(ROUND_STEPS + 1):
        turns, bends, sharpest = _ball_turns(vertices, normals, radii, rows, pool, creases)
        over = (turns > BALL_TURN_CAP) & ~(sharpest > CREASE_TURN)
        rows, bends = rows[over], bends[over]
        if rows.size == 0 or step == ROUND_STEPS:
            break
        if step == 0:  # the default's balls and readings, kept where a smaller ball reproduces them
            first = rows
            default = [field[rows].copy() for field in (radii, *sums, *curvatures)]
        with np.errstate(divide="ignore"):
            smaller_radii = np.fmin(ROUND_SHRINK * radii[rows], ROUND_SHRINK * reach / bends)
        # no smaller than the balls of the surface (MIN_RADIUS_SCALES): a ball there that turns within the cap holds
        smallest = MIN_RADIUS_SCALES * mesh.length_scales[rows]
        radii[rows] = np.fmin(radii[rows], np.fmax(smaller_radii, smallest))
        smaller = _centre_edge_sums(vertices, ends, rows, radii[rows], values)
        measures[rows], areas[rows], spread_sums[rows] = smaller[:, :6], smaller[:, 6], smaller[:, 7:]
        held = ball_holds_neighbours(vertices, topology.edges, radii)[rows] & (areas[rows] > 0)
        held &= radii[rows] >= MIN_RADIUS_SCALES * mesh.length_scales[rows]
        out[rows[~held]] = True
        rows = rows[held]
        again = np.zeros(vertices.shape[0], dtype=bool)
        again[rows] = True
        for old, new in zip(curvatures, _principal(measures, areas, normals, again)):
            old[rows] = new[rows]
        if step == 0:  # a default reading that a smaller ball reproduces is the surface's, not its reach's: kept
            at = np.searchsorted(first, rows)
            k_min, k_max = default[4][at], default[5][at]
            with np.errstate(invalid="ignore"):
                apart = np.fmax(np.abs(curvatures[0][rows] - k_min), np.abs(curvatures[1][rows] - k_max))
                same = apart <= ROUND_AGREEMENT * np.fmax(np.abs(k_min), np.abs(k_max))
            for field, kept in zip((radii, *sums, *curvatures), default):
                field[rows[same]] = kept[at[same]]
            rows = rows[~same]
    out[rows] = True
    return out


def _voxel_round_balls(mesh: PreparedMesh, radii: np.ndarray, valid: np.ndarray, curvatures: tuple, faces: tuple):
    """(V,) bool: the ``valid`` vertices of a voxel surface at its default whose outermost shell ball (``radii``, (V,))
    reaches round the surface (:data:`VOXEL_REACH_MEAN_NORMAL`): NaN with ``valid=False``, the reason
    :data:`meshcurv.defects.REACH`.

    ``curvatures = (k_min, k_max)`` of the shells; ``faces = (area_normals, intact, lengths)``: each face's area times
    its unit normal (0 for a degenerate face or a needle's sliver), (F, 3), and the edges' area densities
    (:func:`edge_area_densities`) and lengths. The ball's sum of the normals is measured on the edges as its area is
    (a third of each face of an edge, per unit length, times ``|e ∩ B|``): ``edge_area_densities`` of each of the
    three components. Checked where the largest ``|k|`` times the radius exceeds :data:`ROUND_CANDIDATE`."""
    out = np.zeros_like(valid)
    with np.errstate(invalid="ignore"):
        bent = radii * np.fmax(np.abs(curvatures[0]), np.abs(curvatures[1])) > ROUND_CANDIDATE
    rows = np.flatnonzero(valid & bent)
    area_normals, intact, lengths = faces
    topology = mesh.topology
    measured = intact > 0
    if rows.size == 0 or not measured.any():
        return out
    columns = [edge_area_densities(topology, area_normals[:, axis], lengths) for axis in range(3)]
    values = np.column_stack([*columns, intact])[measured]
    ends = np.ascontiguousarray(topology.edges[measured], dtype=np.int64)
    sums = _centre_edge_sums(mesh.vertices, ends, rows, radii[rows], values)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean_normal = np.linalg.norm(sums[:, :3], axis=1) / sums[:, 3]
    out[rows[mean_normal < VOXEL_REACH_MEAN_NORMAL]] = True
    return out


def _reach_note(count: int, *, voxel: bool = False) -> str:
    """The warning's phrase for ``count`` vertices whose default ball reaches round the surface (:func:`_round_balls`;
    ``voxel``: the shell of a voxel surface's default, :func:`_voxel_round_balls`)."""
    if not count:
        return ""
    if voxel:
        return (
            f"{count} vertices of this voxel surface have a default shell of balls that reaches round a part thinner "
            f"than it (the mean of the normals over its outer ball is shorter than {VOXEL_REACH_MEAN_NORMAL:.2f}, "
            f"a cap turning by {BALL_TURN_CAP:g} rad): the voxels are too coarse there for this method"
        )
    return (
        f"{count} vertices have a default ball that reaches round the surface (its normals turn by more than "
        f"{BALL_TURN_CAP:g} rad) and no smaller ball holds the surface: the mesh is too coarse there for this method "
        "(refine it)"
    )


def _ball_sums(vertices, topology, groups, radii, terms, scattered, shells=None, area_normals=None):
    """``(measures, areas, spread_sums, holes, readings, (edge_values, measured), normal_sums)`` of the balls of ``groups``
    (``(radius, members)``; a radius may be one per vertex): the tensor's six columns, the area and the scatter's
    columns (:func:`_edge_spread_columns`, none without ``scattered``), each vertex's sums over its ball, with the
    edges of holes (:func:`hole_edges`, read within ``radii``, (V,)) taking neither curvature nor area; last, what
    was summed (:func:`_edge_values`: :func:`_round_balls` sums it again over smaller balls). ``terms``: ``(beta,
    unit, lengths, intact, usable)`` of the edges, ``intact`` their area densities with the holes'. ``shells``: per group,
    the multiples of its radius whose balls' sums are added (:func:`_voxel_shell`; None: one ball each).
    ``area_normals``: (F, 3) each face's area times its unit normal (0 for the faces left out); with it, each ball's
    sum of the normals over its area (``normal_sums``, (V, 3); else None), measured on the edges as the area is (the
    holes' edges add none), in the same pass."""
    edge_values, measured, holes, readings = _edge_values(vertices, topology, radii, terms, scattered)
    width = edge_values.shape[1]
    values = edge_values
    if area_normals is not None:
        lengths = terms[2]
        columns = [edge_area_densities(topology, area_normals[:, axis], lengths) for axis in range(3)]
        values = np.column_stack([edge_values, np.where(holes[:, None], 0.0, np.column_stack(columns))])
    measures = np.zeros((vertices.shape[0], values.shape[1]))
    for (group_radius, members), shell in zip(groups, shells or [(1.0,)] * len(groups)):
        rows = slice(None) if members is None else members
        for factor in shell:
            ball = group_radius if factor == 1.0 else factor * np.asarray(group_radius, dtype=np.float64)
            measures[rows] += _ball_edge_sums(vertices, topology.edges, ball, values, usable=measured)[rows]
    normal_sums = measures[:, width:] if area_normals is not None else None
    sums = (measures[:, :6], measures[:, 6], measures[:, 7:width], holes, readings, (edge_values, measured))
    return (*sums, normal_sums)


def _edge_values(vertices, topology, radii, terms, scattered):
    """``(edge_values, measured, holes, readings)``: what :func:`_ball_sums` sums over the balls, (E, 7 + s) (the
    tensor's six columns, the area density and the scatter's columns), the edges that enter the sums, the edges of
    holes (read within ``radii``) and the edges' readings (:func:`edge_readings`)."""
    beta, unit, lengths, intact, usable = terms
    holes = hole_edges(vertices, topology, radii, topology.edge_vertices(usable | (intact > 0)))
    density = np.where(holes, 0.0, intact)
    readings = edge_readings(beta, density, usable)
    spread = _edge_spread_columns(density, intact, lengths, readings) if scattered else np.zeros((beta.shape[0], 0))
    # the tensor and the area on the same support, the edges inside the ball: one sum
    edge_values = np.column_stack([outer6(unit, beta), density, spread])
    measured = usable | (density > 0) | (scattered & (intact > 0))  # the edges of holes add zeros to the first 7
    return edge_values, measured, holes, readings


def _centre_edge_sums(vertices, edges, centres, radii, values) -> np.ndarray:
    """(M, k) ``sum_e |e ∩ B(x_c, r_c)| * values[e]`` over the ``edges`` (E, 2) at the ``centres`` (M,), each with its
    own radius ``radii`` (M,): :func:`meshcurv.neighborhoods.ball_edge_sums` at a few vertices, with the same exact
    lengths, on both backends alike (the balls made smaller by :func:`_round_balls`)."""
    out = np.zeros((centres.size, values.shape[1]))
    if centres.size == 0 or edges.shape[0] == 0:
        return out
    order = np.argsort(radii, kind="stable")  # each chunk searched with its largest radius
    points, unit = vertices[centres[order]], radii[order]
    middles, reach = cell_centres(vertices, edges)
    for chunk, i, c in _candidate_pairs(points, middles, reach, unit):
        inside = segment_in_ball_lengths(vertices[edges[c, 0]], vertices[edges[c, 1]], points[chunk][i], unit[chunk][i])
        out[order[chunk]] = _gathered(i, c, inside, chunk, values)
    return out


def _member_mask(members, n: int) -> np.ndarray:
    """(n,) bool of a group's ``members`` (a mask or indices)."""
    mask = np.zeros(n, dtype=bool)
    mask[members] = True
    return mask


def _principal(measures, areas, normals, valid):
    """``(k_min, k_max, dir_min, dir_max)`` of the ball sums ``measures`` (V, 6) over ``areas`` at the ``valid``
    vertices (the others: whatever the zero tensor gives, made NaN by :func:`finish`)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        tensors = measures / areas[:, None]
    return principal_from_shape_operator(
        np.where(valid[:, None], tensors, 0.0),
        np.where(valid[:, None], normals, [0.0, 0.0, 1.0]),
        rotate=True,
        mean_from_trace=True,
    )


def _edge_spread_columns(density: np.ndarray, intact: np.ndarray, lengths: np.ndarray, readings: np.ndarray):
    """(E, 6) per unit length, for :func:`_few_edges`: ``density * a`` (``a = density * length``, the edge's area:
    summed over a ball, at least the sum of the squared weights ``(density |e ∩ B|)^2``); the area and that column
    again with the holes' area (``intact``); with it, on the edges with a reading (``readings``,
    :func:`edge_readings`, NaN for none), the area, ``H_e`` and ``H_e^2`` times it: their weighted variance in an
    intact ball."""
    read = np.isfinite(readings)
    held = np.where(read, readings, 0.0)
    whole = intact * read
    kept = density * read
    return np.column_stack(
        [
            density * density * lengths,
            intact,
            intact * intact * lengths,
            whole,
            whole * held,
            whole * held * held,
            kept,
            kept * held,
            kept * held * held,
        ]
    )


def _few_edges(valid, areas, spread_sums, readings, curvatures, **options):
    """``(few, reference)``: (V,) bool, the ``valid`` vertices whose ball reads too few edges to average out their
    scatter (:func:`_few_elements`, the edges being the elements: each reads ``H_e = beta / (2 density)`` with
    weight ``density |e ∩ B|``, the ball's H their weighted mean), and the scatter and curvature they were judged
    against. ``spread_sums``: the ball sums of :func:`_edge_spread_columns`; ``readings``: the edges'
    (:func:`edge_readings`); ``curvatures``: ``(k_min, k_max)``; ``options``: ``cracked`` and ``reference`` of
    :func:`_few_elements`."""
    squared, whole, whole_squared, read, first, second, kept, kept_first, kept_second = spread_sums.T
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        shares = squared / (areas * areas)  # 1 / N (at least)
        intact_shares = whole_squared / (whole * whole)
        variances = second / read - (first / read) ** 2
        local = kept_second / kept - (kept_first / kept) ** 2
    return _few_elements(
        valid, shares, intact_shares, variances, readings, curvatures, local_variances=local, **options
    )


def _crack_biased(valid, spread_sums, reference) -> np.ndarray:
    """(V,) bool: the ``valid`` vertices of a mesh welded across cracks whose ball lost too much of its area to
    edges with no reading (open cracks, holes, loose faces) for what it kept to stand for the surface
    (:data:`CRACKED_LOST_BIAS`). ``spread_sums``: the ball sums of :func:`_edge_spread_columns`; ``reference``: the
    mesh's scatter and curvature (:class:`_Reference`; None: nothing judged)."""
    if reference is None:
        return np.zeros_like(valid)
    intact, kept = spread_sums[:, 1], spread_sums[:, 6]
    with np.errstate(invalid="ignore", divide="ignore"):
        lost = 1.0 - kept / intact
        return valid & ~(lost * np.sqrt(reference.variance) <= CRACKED_LOST_BIAS * reference.scale)


def _crack_bias_note(count: int) -> str:
    """The warning's phrase for ``count`` vertices left undefined by :func:`_crack_biased` ("" for none)."""
    if not count:
        return ""
    return (
        f"{count} vertices are NaN (estimate undefined): their ball lost too much of its area to open cracks "
        "between detached faces for the edges left to stand for the surface"
    )


def _staircase_note(count: int) -> str:
    """The warning's phrase for ``count`` vertices of a welded voxel surface (:func:`._ring_noise.welded_grid`)."""
    if not count:
        return ""
    return (
        f"{count} vertices of this voxel surface are NaN (voxel staircase): it was welded across cracks between "
        "detached faces, and its faces away from the cracks lie on a voxel grid, whose steps a ball of a few edges "
        "reads as flat or as curvature"
    )


def _voxel_holed_balls(
    mesh: PreparedMesh, holes: np.ndarray, groups: list, valid: np.ndarray, reading: VoxelReading
) -> np.ndarray:
    """(V,) bool: on a voxel surface, the vertices whose ball holds a part of an edge of a hole (``holes``, (E,)
    bool, :func:`hole_edges`); all False on other meshes (the module's Notes). A voxel surface: the mesh, or the
    faces around its vertices free of defects and boundaries, or most of the ``valid`` vertices, on a grid
    (:func:`meshcurv.radius._voxel_surface_grid`, the mesh's grid kept by ``reading``)."""
    vertices, edges = mesh.vertices, mesh.topology.edges
    holed = np.zeros(vertices.shape[0], dtype=bool)
    if not holes.any():
        return holed
    if not _voxel_surface(mesh, mesh.defects().invalid_vertices, valid=valid, reading=reading):
        return holed
    ones = np.ones((edges.shape[0], 1))
    for group_radius, members in groups:
        rows = slice(None) if members is None else members
        holed[rows] = _ball_edge_sums(vertices, edges, group_radius, ones, usable=holes)[rows, 0] > 0
    return holed
