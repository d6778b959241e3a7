"""Weighted osculating jet fit with normal re-estimation (Cazals and Pouget 2005; Panozzo et al. 2010).

Each vertex's curvatures are those of a weighted least-squares polynomial (a
*jet*) fitted to the height of its neighbours over its tangent plane, with the
vertices of the ball ``B(x_v, r)`` as the points and weights
``(1 - |x_j - x_v|^2 / r^2)^2``. The fits are those of :mod:`meshcurv.jets`
(weights, normal re-estimation and the shape operator of a jet are described
there). The degree is
:data:`~meshcurv.jets.DEGREE` (4) where the ball holds enough points, spread
enough for a well-conditioned fit (:data:`~meshcurv.jets.MIN_SPREAD`, a measure
that no rigid motion, scaling or turn of the tangent frame changes: every pose
of a mesh gets the same degrees, so the same curvatures), else 3, else 2
(Cazals and Pouget: a degree-``d`` jet
gives the curvatures with an error of order ``r^{d-1}`` on a smooth surface,
against ``r`` or ``r^2`` for the quadric, the bias that grows as
``(r k)^2``). The constant term is free (on a noisy mesh the vertex is not on
the surface), and so are the linear terms.

Two fits per vertex (:data:`~meshcurv.jets.ITERATIONS`): the first in the frame
of the area-weighted vertex normal, the second in that of the first fit's normal;
the curvatures are those of the shape operator of the last jet
(:func:`~meshcurv.jets.shape_operators`), solved in the plane of the fitted
normal, which is the normal reported.

The fit uses only vertex positions, not the triangles: it is indifferent to
the quality of the triangulation (irregular meshes), and the ball, unlike a
number of rings, keeps its size in length units across resolutions.

A fit needs at least six points with non-zero weight, spread enough for a
quadric: vertices with fewer (or a degenerate set, for example collinear
points) are NaN with ``valid=False`` (use a larger ``radius``). Boundary vertices are fitted on their one-sided
neighbourhood and kept. The higher terms of a jet are poorly held by the points of a one-sided ball, or of
a ball of few or irregularly placed points, where a noise of a small fraction of an edge length moves them
far: a vertex whose jet departs from a steadier fit on the same ball (a quadric at the boundary,
:data:`STEADY_DEGREE`; inside, the highest degree whose points are spread by :data:`STEADY_MIN_SPREAD`) by
more than :data:`STEADY_AGREEMENT` takes the steadier fit's curvatures, and one whose ball's points are too
little spread for any such fit is NaN with ``valid=False``.

Reach. The default radius is 2.5 mean edge lengths, which on a mesh of long and short edges reaches round a part
curved along the short ones (``torus(10, 3, 30, 30)``: a ball of 4.09 for a tube of radius 3, every vertex valid and
``k_max`` 27% off; issue 29). A default ball whose normals (the fits') turn from its centre's by more than
:data:`meshcurv.radius.BALL_TURN_CAP` with no crease in it (no edge turning the vertex normals by more than
:data:`meshcurv.radius.CREASE_TURN`) is made smaller and fitted again, by a fit whose points are spread by
:data:`ROUND_MIN_SPREAD` (a quadric, mostly); the default fit stays where the smaller ball reproduces it, and a vertex
with no smaller fit is NaN with ``valid=False`` (:func:`_round_balls`).

Noise. A jet of degree 4 amplifies noise far more than a quadric: at 2.5 edge lengths, noise of a tenth of an
edge along the normal gave median H errors of 56-108% of the curvature on the noisy spheres of
``benchmarks/accuracy.py`` (a quadric over the same balls 11-20%). Each vertex's noise level is read as the
default method reads the mesh's (:func:`meshcurv.radius.local_noise`: its distance to a degree-2 jet over two
edge lengths, averaged over two rings), and

- the default radius grows with it (:func:`meshcurv.radius.jet_vertex_radii`:
  ``h (2.5 + 20 sqrt(max(nu_v - 0.005, 0)))``, at most the inverse of the surface's curvedness there, at least
  2.5 h; at the rim the median curvedness inside, as its one-sided fits read noise as curvature;
  ``parameters["scale"] == "noise"``,
  ``result.radius`` per vertex), a grown ball that holds the other side of the surface falling back to 2.5 h;
  a clean mesh keeps 2.5 h;
- at any radius, a vertex whose level, or its mesh's median level, exceeds :data:`NOISE_GATE` has its jet
  checked against a quadric over the same ball, as at the rim (faces detached off the surface by a tenth of an edge make such balls: issue 29, fuzz
  296/1682);
- at the default radius, a crease told from scatter (:func:`_scatter_check`): the residuals of a quadric over
  each noisy ball (:func:`residual_spreads`, compiled) give the noise's spread of its curvatures, held to
  :data:`NOISE_REACH` of its curvature; beyond it, residuals that grow over a wider ball are structure (a crease,
  relief: the fit stays), those that keep their size scatter, fitted over a grown ball within the curvature, else
  NaN with ``valid=False``; a jet that departs from its ball's quadric by more than the quadric's spread takes it,
  on a noisy ball or one by a crack of a soup, whose level may read clean (W20's check of the default radius,
  reverted, read fandisk's creases as noise: ``benchmarks/quadric_noise.md``); on a voxel surface the fits that
  follow the steps are NaN with the reason "voxel staircase" (``meshcurv.defects.STAIRCASE``), also on a voxel
  surface stored as a soup, which the default radius reads as an ordinary mesh: its balls are grown to the voxel
  rule's (:func:`_soup_grid`, :func:`_staircase_radius`; issue 29, fuzz 415/108);
- at a given radius, the noise's reach (:func:`_noise_reach`): the spread of a fit's curvatures under the noise of
  its ball, from the level (as a standard deviation, :data:`NOISE_SIGMA_FACTOR`) and the weighted normal matrix of
  the ball's points (``sigma^2 G^-1 M G^-1``, :func:`_noise_spreads`), against the median curvedness of the
  surface: a jet spread beyond :data:`JET_NOISE_REACH` of it takes a quadric over the same ball, and a vertex
  whose quadric spreads beyond :data:`NOISE_REACH` is NaN with ``valid=False``. A given radius of one or two edge
  lengths holds 6-15 points, which every fit, the quadric too, follows (issue 29: faces detached by 0.08 edge
  lengths, H valid and off a unit sphere's by up to 1.65: fuzz 362/3, 366/5687); the jet and the quadric then
  agree, which the check against each other cannot see. Such balls are NaN with a warning that names them.
  On a mesh welded across cracks, the corners of a crack (faces detached and welded back in part) carry its
  width over ``sqrt(3)`` as their noise (:func:`_crack_sigmas`): on such a soup most points are in place and the
  level reads clean, while a ball of a few points by a crack follows the copies' offsets (fuzz 420/76: H off by
  up to 2.15 of the largest ``|k|``, valid). Not on other meshes: an irregular rim's vertices lie as close (the
  irregular hemisphere at 2.5 edges: 1,343 -> 1,200 valid with them taken for cracks). At the default radius the
  vertices the weld joined across cracks wide for the curvature (:data:`WELDED_GAP`) are a crack's corners too,
  and a ball of scatter over cracks is grown further (:data:`GROWN_REACH`).

``benchmarks/quadric_noise.md`` gives the errors before and after.

References
----------
F. Cazals and M. Pouget (2005). Estimating differential quantities using
polynomial fitting of osculating jets. Computer Aided Geometric Design 22(2),
121-146. https://doi.org/10.1016/j.cagd.2004.09.004

D. Panozzo, E. Puppo, L. Rocca (2010). Efficient multi-scale curvature and
crease estimation. Computer Graphics Forum 29(5) / GraVisMa 2010, 9-16.
https://doi.org/10.1111/j.1467-8659.2010.01797.x
"""

from __future__ import annotations

import dataclasses

import numpy as np

from .._tensors import principal_from_shape_operator
from ..jets import (
    AWAY_FRACTION,
    DEGREE,
    MIN_POINTS,
    MIN_SPREAD,
    PIVOT_FLOOR,
    _binomials,
    _exponents,
    _fit_chunk,
    _fit_jets,
    shape_operators,
)
from ..neighborhoods import _ball_pairs
from .._tensors import tangent_basis
from ..radius import (
    BALL_TURN_CAP,
    CREASE_TURN,
    JET_CURVATURE_CAP,
    _ball_turns,
    _component_radii,
    _edge_turns,
    _jet_vertex_radii,
    _local_noise,
    _resolve_radius,
    _vertex_radii,
    soup_voxel_grid,
    voxel_curvature_radius,
    voxel_rule_radius,
)
from .._prepared import PreparedMesh
from ..defects import REACH, STAIRCASE
from .._backend import kernel_threads, numba_kernels
from ._support import Stages, finish

STAGES = ("compute normals", "fit jets", "retrieve curvatures")

#: A given radius below this many median edge lengths is named in the warning (the registry's
#: ``radius_warning_edges``) (besides the count of balls
#: with too few points): a degree-4 jet needs 15 points, which a ball of one edge length rarely holds.
RADIUS_WARNING_EDGES = 1.0

#: The degree of the steadier fit that the jets of boundary vertices are checked against (inside, the highest
#: degree whose points are spread by :data:`STEADY_MIN_SPREAD`). A jet of degree 4 (or 3) holds its
#: higher terms on few points: on a one-sided ball (a boundary vertex) it extrapolates them to the vertex,
#: and on a ball of few or irregularly placed points they are poorly conditioned; there a noise of a hundredth
#: of an edge length (faces detached and welded across their cracks, a scan) moved the mean curvature by
#: several times the shape's (issue 29). A quadric is stable, but biased on clean meshes: it is taken where
#: the jet departs from it (:data:`STEADY_AGREEMENT`; ``benchmarks/rim_fits.md``, ``benchmarks/noisy_jets.md``).
STEADY_DEGREE = 2

#: The smallest spread (:data:`meshcurv.jets.MIN_SPREAD`) of a vertex's ball for its steadier fit: below it
#: (for every degree) the vertex is NaN with ``valid=False``. A one-sided ball of six points in a sliver (an irregular mesh's
#: rim) holds a spread of a few 1e-7 and amplifies a noise of a thousandth of an edge length into errors of
#: several times the curvature, where the balls of the benchmark meshes hold 1e-5 and more
#: (``benchmarks/rim_fits.md``).
STEADY_MIN_SPREAD = 1e-5

#: A vertex keeps its jet (of degree 4, or 3) while its principal curvatures are within this over the radius
#: of its steadier fit's, and takes the steadier fit's beyond: on clean meshes the two differ by the
#: quadric's bias at the boundary (about ``(r k)^2 / r``) and not at all inside where the jet's points are
#: spread by :data:`STEADY_MIN_SPREAD` (the same fit), under noise by the jet's poorly held terms, several
#: times the curvature. 0.1 and 0.2 kept more of the noisy jets (``benchmarks/rim_fits.md``,
#: ``benchmarks/noisy_jets.md``).
STEADY_AGREEMENT = 0.05

#: A vertex whose noise level (:func:`meshcurv.radius.local_noise`, in edge lengths) exceeds this has its jet
#: checked against a quadric (:data:`STEADY_DEGREE`) over the same ball, as at the rim: the clean meshes of
#: ``benchmarks/accuracy.py`` read at most 0.006 (the fit's bias on the coarsest torus), noise of 0.1 h about 0.02;
#: a degree-4 jet over a ball of 2.5 edge lengths follows such noise (median H error 56-108% on the noisy spheres,
#: a quadric's 11-20%; issue 29, fuzz 296/1682: faces detached by 0.087 edge lengths).
NOISE_GATE = 0.016

#: A vertex at a given radius whose quadric's curvatures spread under the noise of its ball (the root of the
#: expected squared change of its shape operator) by more than this share of its surface's curvature (the median
#: curvedness) is NaN with ``valid=False`` (:func:`_noise_reach`): about a third, so that an error of half the
#: curvature (the fuzzer's tolerance) is some three spreads of the mean curvature away. Looser values left valid
#: wrong numbers: on a sphere with noise of 0.05 edge lengths at a radius of 1.5 (``tests/test_quadric_cracks_W19.py``)
#: 0.4 kept an H off by 0.86, 0.5-0.7 one off by 1.02; fuzz 362/3 at 0.7 two vertices off by 0.55. The cost: on
#: random spheres with a fifth of their faces detached by 0.1 edge lengths, at 2.2 edge lengths
#: (``tests/test_quadric_noise_Q18.py``, four draws) 31-40% of the vertices stay valid (73-83% before, 20 of them
#: off by more than half of H, now none; 0.6: 70-78% and one).
NOISE_REACH = 0.3

#: A jet whose spread under the noise of its ball exceeds this share of the surface's curvature gives way to a
#: quadric over the same ball (:func:`_noise_reach`).
JET_NOISE_REACH = 0.1

#: The smallest spread of a ball's points (:data:`meshcurv.jets.MIN_SPREAD`: ``1 / (sum(w) trace(G^-1))`` in the basis
#: that no turn of the tangent frame changes) for which :func:`_noise_spreads` gives a fit's spread under the noise of
#: its ball (below it: inf, the jet takes a quadric where that one's spread is within :data:`NOISE_REACH`, else NaN):
#: the jets' own floor, below which no jet of that degree is fitted (a jet of degree 4 over such a ball is one of
#: degree 3 or 2). Read on the normal matrix in the monomials' basis, the test (the smallest eigenvalue over the
#: largest above 1e-12) changed with the pose (issue 29, fuzz 804/313).
NOISE_MIN_SPREAD = MIN_SPREAD

#: The noise's standard deviation per unit of noise level (:func:`meshcurv.radius.local_noise`: a mean distance
#: to degree-2 fits over about 13 points, which absorb part of it): on the spheres, tori and ellipsoids with
#: uniform noise of 0.05-0.3 edge lengths along the normal, the standard deviation drawn over the level read
#: (less :data:`meshcurv.radius.NOISE_FLOOR` in quadrature) was 2.0-2.8 (``sqrt(pi / 2) / sqrt(1 - 6 / 13) = 1.7``
#: for a Gaussian noise that the fits absorb as their six terms would on average).
NOISE_SIGMA_FACTOR = 2.5

#: The ball that tells scatter from structure at the default radius is this many times wider
#: (:func:`_scatter_check`): the residuals of a crease grow by as much, those of scatter not at all.
SCATTER_SCALE = 2.0

#: A ball of scatter is grown this much beyond the size at which its fit's spread (falling as ``r^-3``) would meet
#: :data:`NOISE_REACH` (over cracks :data:`GROWN_REACH`; :func:`_scatter_check`).
GROWTH_MARGIN = 1.1

#: A ball of scatter over a soup's cracks at the default radius is grown until its fit's spread would be within this
#: share of its curvature (:func:`_scatter_check`, step 4; with :data:`GROWTH_MARGIN`), below :data:`NOISE_REACH`,
#: which the grown fit is then held to. The spread is honest (the quadrics over fine soups: their H off the truth by
#: half a spread at the standard deviation), but the
#: farthest of 10^5 balls lies 2.2-2.3 spreads out: balls grown to just within :data:`NOISE_REACH` (0.23 with the
#: margin) read H 0.49 and 1.53 for 1, valid (issue 29, fuzz 400/78 and 690/72: ``icosphere(40)`` with every face
#: detached by 0.096 and 0.059 edges, where the wider ball of step 3 read 0.89-1.05, spread 0.05-0.07). Off cracks
#: (a noisy mesh) the balls stay as they were: the noisy saddle of ``accuracy.py --quick`` (0.3 h) read H 14 -> 19%
#: off at the median with 0.15 everywhere. On a staircase :data:`STAIRCASE_PULL` does as much.
GROWN_REACH = 0.15

#: The growth of the residuals of structure over a ball :data:`SCATTER_SCALE` times wider, at the least
#: (:func:`_scatter_check`): the noise left in residuals that grew by ``g`` is their share
#: ``sqrt((G^2 - g^2) / (G^2 - 1))`` (the rest grown by ``G``). A crease centred in the ball grows as the ball
#: (2), a smooth surface's higher terms as its cube; fandisk's clean creases off the centre of their balls grew by
#: 1.44-1.85, scatter by 1 +- 0.15 (20 points), 1.8 where the wider ball reaches the curvature of a noisy torus.
STRUCTURE_GROWTH = SCATTER_SCALE**0.75


#: The residuals of a quadric give a noise (:func:`residual_spreads`) where their degrees of freedom
#: ``sum w - tr(G^-1 M)`` exceed this share of the ball's weight ``sum w``. A ball of six points is fitted exactly: its
#: degrees of freedom are 0, computed as +-1e-15 of ``sum w``, and with the test ``> 0`` the order of the vertices
#: decided whether the ball read no noise (kept its jet) or none at all (grown): on nefertiti 29 balls of six points,
#: 3 vertices' validity and 28 values changed under a permutation (issue 29, fuzz 421/21).
RESIDUAL_DOF_FLOOR = 1e-6


#: A quadric at the default radius on a noisy mesh off cracks (:data:`ROUGH_LEVEL`; over cracks
#: :data:`CRACK_DEPARTURE_SPREADS`) whose principal curvatures depart from those of the quadric over a ball
#: :data:`SCATTER_SCALE` times wider by more than this many of its noise spreads, while its residuals grew less than
#: :data:`STRUCTURE_GROWTH`, follows its scatter (:func:`_scatter_check`, step 5): the spread assumes independent noise,
#: and a staircase's steps (a voxel surface whose faces are detached: issue 29, fuzz 415/108) pull a fit by three
#: times as much (a quadric over 2.4 voxels of ``voxel_sphere(10)`` detached by 0.042 edge lengths: H off by 0.16
#: for spreads of 0.06; off the wider ball's by 2.6-6.7 spreads, where the near fits within a fifth of the
#: curvature depart by 2.1-4.1).
DEPARTURE_SPREADS = 2.0

#: Over a crack (:func:`_cracked_balls`), the departure from the wider ball's quadric, in noise spreads, beyond which a
#: fit follows the steps (:func:`_scatter_check`, step 5): one spread, as a jet departing from its quadric
#: (:func:`_follow_quadrics`), since the steps are not independent noise. At :data:`DEPARTURE_SPREADS` the fits that
#: departed by 1.7-2.0 spreads stayed, 11 of them off by more than half the largest ``|k|`` (up to 0.62) on fuzz
#: 415/108; at 1 spread 5 grown balls' fits (up to 0.52), and 97% of the valid vertices take a grown ball. Half a
#: spread (as on a staircase, :data:`STAIRCASE_DEPARTURE_SPREADS`): at one, a fit 1.06 spreads off stayed on
#: ``icosphere(40)`` with every face detached by 0.059 edges (fuzz 690/72: H 1.39 for 1). With :data:`GROWN_REACH` and
#: :data:`WELDED_GAP`, the tuned soups of ``benchmarks/quadric_soups_Q70.py`` went from 12 valid vertices off by more
#: than half of ``|k|`` (517 by more than 0.35) to none, with 584 more valid.
CRACK_DEPARTURE_SPREADS = 0.5


#: A mesh (a group of components of one scale) whose median noise level (:func:`meshcurv.radius.local_noise`) exceeds
#: this is noisy: its fits that the noise's spread passed are checked against the wider ball's too
#: (:func:`_scatter_check`, step 5, off cracks). Uniform noise of a tenth of an edge length along the normal reads
#: 0.022-0.024 (icospheres of 642 and 2,562 vertices), the real meshes of ``../shared/meshes`` 0.004-0.017
#: (nefertiti 0.0173, rocker-arm 0.0164), which the check cost 1.43x their CPU and changed at a dozen crease
#: vertices (fandisk, rocker-arm), where ``accuracy.py --quick``'s noisy rows took its gains (a noisy sphere's
#: median H error 9.8 -> 9.3%).
ROUGH_LEVEL = 0.02


#: The corners of a crack (:func:`_crack_corners`) have another rim vertex within this many local edge lengths: a
#: face detached by a gap ``g`` (in edge lengths) leaves its corners up to ``2 g`` from its neighbours' (the
#: fuzzer's 0.03-0.1: 0.06-0.2), where the rim vertices of an open surface lie an edge length apart (its default
#: ball over a cylinder's or a saddle's rim: 100 -> 33% valid on the noisy coarse cylinder of ``accuracy.py
#: --quick`` with every rim taken for a crack).
CRACK_WIDTH = 0.5

#: A vertex into which the weld joined the caller's vertices across cracks (``PreparedMesh.crack_gaps``: the
#: largest distance of a copy joined into it) is a crack's corner (:func:`_welded_groups`) where that gap exceeds this
#: share of ``h^2 k`` (``h`` its local edge length, ``k`` its group's median curvedness, :func:`_curvature_scales`):
#: the welded point is one copy's, up to the gap off the surface, with no crack left to show it, and a fit over a
#: ball of a few edges reads an offset ``delta`` as some ``delta / h^2`` of curvature beside the bend ``k`` it
#: measures. On welded soups at the default the largest H error of the valid vertices grew as 2-3 times that ratio
#: (``icosphere(24)`` with half or all of its faces detached by 0.002-0.016 edges: 0.07-0.95 of ``|k|``, 6,120 of
#: 860,976 valid rows off by more than half: ``benchmarks/quadric_soups_Q70.py --set sweep``, none now; fuzz 730/1,
#: ``icosphere(40)`` half detached by 0.031 edges, reads 0.6-1.4: H 0.03 and 1.69 for 1, valid). A weld narrow for
#: the curvature stays on the jets: ``torus(3, 1, 32, 16)`` with 30% of its faces moved by 1e-3 edges
#: (``tests/test_double_sided_welds_D24.py``) reads at most 0.003, and taking every welded vertex for a corner (Q69,
#: reverted) left 272 of its 1,424 vertices valid, all right before (the largest H error 0.16 of ``|k|``).
WELDED_GAP = 0.05


#: On a staircase (a voxel surface at its default radius), the departure from the wider ball's quadric, in noise
#: spreads, beyond which a fit follows the steps (:func:`_scatter_check`, step 5; over cracks
#: :data:`CRACK_DEPARTURE_SPREADS`): the steps are not independent noise, and their pull on a fit is coherent over the
#: ball. At one spread, fits within 0.8-1.0 spreads of the wider ball's stayed, off the exact H by just over half of
#: the largest ``|k|`` (``voxel_sphere(8)``, a 1 x 1 x 2 voxel sphere; issue 29).
STAIRCASE_DEPARTURE_SPREADS = 0.5

#: On a staircase, a ball of scatter is grown as if its fit's spread were this many times larger
#: (:func:`_scatter_check`, step 4): the steps pull a fit further than independent noise of its residuals' size
#: (:data:`DEPARTURE_SPREADS`), and balls sized for that noise alone were left following them (``voxel_sphere(15)``:
#: 24 of 4,229 valid vertices off the exact H by more than half of the largest ``|k|``, saddles on a sphere; median H
#: error 9.6%, now 6.3%). 2 lost a fifth of the anisotropic ellipsoid's valid vertices more (the grown balls reached
#: beyond :data:`STAIRCASE_CURVATURE_CAP`).
STAIRCASE_PULL = 1.5

#: On a staircase, a kept fit whose mean curvature departs from that of a quadric over a ball twice its default
#: radius (in the frame of its normal) by more than this share of its own largest ``|k|`` is NaN with
#: ``valid=False`` (:func:`_staircase_check`): on a smooth surface the two differ by the quadric's bias, a fit that
#: the steps bent departs (a zero fit on a flat terrace of ``voxel_sphere(3)``, saddles on ``voxel_torus()``).
STAIRCASE_AGREEMENT = 0.3

#: On a staircase, a kept fit over a ball wider than this many times the radius of curvature of its own largest
#: ``|k|`` is NaN with ``valid=False`` (:func:`_staircase_check`): the ball reaches round the surface, where a
#: quadric overestimates the curvature (``voxel_torus()``'s tube of 4 voxels: k 0.41-0.44 for 0.25 over balls of 3.0-3.2
#: voxels). :data:`meshcurv.radius.JET_CURVATURE_CAP` holds the curvedness, up to ``sqrt(2)`` times below the largest
#: ``|k|`` on a tube; 1.0 here lost a quarter of the torus' valid vertices, 1.3 kept 2 off.
STAIRCASE_CURVATURE_CAP = 1.2

#: On a staircase, a kept fit whose normal makes with its vertex's normal an angle whose cosine is below this (a right
#: angle) is NaN with ``valid=False`` (:func:`_staircase_check`): its tangent plane stands across the surface (the
#: steps read edge-on), and once its normal faces into the solid the signs of its curvatures are reversed. On
#: ``voxel_torus(12, 4)`` at 1 x 0.5 x 0.5 voxels with every face detached (issue 29), the vertex normals lie within
#: 69 degrees of the surface's and the right fits within 16; at the caps of the tube along the long voxels, fits over
#: the soup's default ball turned 81-98 degrees from their vertex's normal, and the balls grown in their frame
#: (:func:`_scatter_check`) 132-141: H -0.12 for 0.14, valid (31 vertices of the welded soup, 35 given).
STAIRCASE_FACING = 0.0

#: On a voxel soup (:func:`_soup_grid`), a kept fit whose mean curvature departs from the wider quadric's of
#: :func:`_staircase_check` by more than this share of the soup's typical curvature (``1 / R``,
#: :func:`_staircase_radius`) is NaN with ``valid=False`` too: the detached faces' offsets add to the steps, and a
#: fit bent upward by both also reads a larger ``|k|``, which widened the relative test (``voxel_sphere(6)`` with
#: every face detached: 76 of 3,489 valid vertices off its H by more than half of it, now 7 of 3,014, the farthest
#: 0.54 of it, and none off the clean surface's estimate by the fuzzer's bar; 0.15 left none at 0.5 there but lost a
#: fifth of the valid vertices more, 0.25 kept 27; benchmarks/quadric_voxel_soups_V30.py).
SOUP_AGREEMENT = 0.2


#: A voxel soup's typical radius of curvature (:func:`_staircase_radius`) is read from quadrics over balls this many
#: times its noise rule's default radius: twice, as the wider ball of :func:`_staircase_check`, which averages the
#: steps (``voxel_sphere(10)`` with every face detached by 0.042 edges: H within 6% at the median over balls of 6
#: voxels, 38% over 3), while the quadrics over the noise rule's balls read the curvature up to twice too high.
STAIRCASE_PILOT_SCALE = 2.0


#: Noise levels up to this read as a clean mesh in :func:`_noise_sigmas`: twice
#: :data:`meshcurv.radius.NOISE_FLOOR`, as the vertices of a clean irregular mesh read up to 0.006 (a random
#: ellipsoid of 2,562 points, whose degree-4 jets a noise read from the floor alone sent to quadrics 1.2
#: degrees off the normal).
CLEAN_LEVEL = 0.007


def estimate(mesh: PreparedMesh, *, radius, stages: Stages):
    """Weighted jet fits over balls of radius ``radius``. Returns ``(result, problems)``.

    Only referenced vertices enter the balls. A fit whose ball holds the other
    side of the surface (``facing`` of :func:`fit_jets`: a ball across a needle,
    or over a whole small closed part) is NaN with ``valid=False`` and counted
    in the warning. With the default radius, each vertex gets its own
    (:func:`meshcurv.radius.jet_vertex_radii`: its group's, grown with its noise level).
    """
    vertices, topology = mesh.vertices, mesh.topology
    stages.start("compute normals")
    normals = mesh.vertex_normals
    defects, valid = mesh.start(boundary=True, fragments=True)  # its balls are Euclidean: parts alike
    start = np.where(valid[:, None], normals, [0.0, 0.0, 1.0])
    facing = np.where(valid[:, None], normals, np.nan)
    referenced = topology.referenced_vertices
    rim = topology.boundary_vertices
    levels, curvedness = _local_noise(mesh, start, valid)
    scales = _component_radii(mesh)
    noisy = _noisy_balls(levels, scales)
    if radius is None:
        groups = scales
        # the rim capped by the median curvedness inside: its one-sided noise fits read noise as curvature (a noisy
        # saddle's rim 30x its curvedness), and its own cap kept it at 2.5 h (median H error 128-201% under noise
        # of 0.3 h); a detached face's corners are rim too, whose balls of the surface need the cap
        inside = curvedness[~rim & np.isfinite(curvedness)]
        bent = np.where(rim, np.median(inside) if inside.size else np.nan, curvedness)
        radii = _jet_vertex_radii(_vertex_radii(groups, vertices.shape[0]), levels, bent)
        radii = np.where(np.isfinite(radii) & (radii > 0), radii, 1.0)  # coincident points: any unit (all fail)
        # a voxel surface the default radius did not read as one (a soup: issue 29, fuzz 415/108): its staircase
        # needs the voxel rule's ball, and the checks of the voxel default below
        soup_grid = _soup_grid(mesh, defects, valid, stages)
        if soup_grid is not None:
            soup_radius, soup_curvature = _staircase_radius((vertices, start, radii, referenced), soup_grid)
            radii = np.fmax(radii, soup_radius)
        parts: list = [(radii, None)]
    else:
        soup_grid, soup_curvature = None, 0.0
        groups = [(_resolve_radius(radius, mesh), None)]
        radii = _vertex_radii(groups, vertices.shape[0])
        parts = [(group_radius if group_radius > 0 else 1.0, members) for group_radius, members in groups]

    stages.start("fit jets")
    n = vertices.shape[0]
    fields = tuple(np.full((n, width), np.nan) for width in (6, 3, 6))  # six, fitted, coefficients
    away = np.zeros(n)
    sides = (rim, noisy & referenced)
    for unit, members in parts:
        centres = np.flatnonzero(referenced) if np.ndim(unit) else members
        _fit_part((vertices, start, unit, centres), referenced, facing, sides, fields, away)
    round_balls = noisy_levels = np.zeros(n, dtype=bool)
    if radius is None:  # a grown ball that holds the other side: the group's own radius
        base = _vertex_radii(groups, n)
        again = np.flatnonzero(referenced & (away > AWAY_FRACTION) & (radii > base) & np.isfinite(base) & (base > 0))
        if again.size and soup_grid is None:  # (on a soup's staircase the smaller ball follows the steps: NaN)
            radii[again] = base[again]
            _fit_part((vertices, start, radii, again), referenced, facing, sides, fields, away)
        if not stages.voxel_default and soup_grid is None:  # a default ball that reaches round: made smaller
            # (not on a voxel soup's staircase, as not on the voxel default's: the smaller ball follows the steps;
            # its cap, STAIRCASE_CURVATURE_CAP, holds a ball that reaches round)
            with np.errstate(invalid="ignore"):  # its own level: a group's median may be read off its curved parts
                noisy_levels = levels > NOISE_GATE
            ball = (vertices, facing, start, radii, base, referenced, noisy_levels)
            round_balls = _round_balls(ball, topology.edges, sides, fields, away)
    unsure = np.zeros(n, dtype=bool)
    steps = np.zeros(n, dtype=bool)
    # the default radius is grown with the noise (jet_vertex_radii) and checked by the gate. A voxel surface's
    # default (stages.voxel_default) is a staircase under every ball: its steps pull a fit as a crack's do, and
    # the residuals' growth over the wider ball is theirs, not a crease's, so every fit is checked against the wider
    # ball's (step 5 of _scatter_check) and none passes as structure (issue 29: voxel_torus() 1,564 of 2,710 valid
    # vertices off the exact H by more than half of the largest |k| at its voxel default of 1.86 voxels, now 21 of
    # 2,177; voxel_sphere(10) 25 -> 0 of 1,882; the noise gate alone: no valid vertex on the torus); the fits kept
    # there are then checked against a quadric over twice the default ball (_staircase_check: the torus 21 -> 0).
    # So is a voxel soup's (soup_grid: _soup_grid), at the voxel rule's radius (_staircase_radius)
    if stages.voxel_default or soup_grid is not None:
        every = referenced.copy()
        checks = (every, every, every, np.zeros(n, dtype=bool))
        default = radii.copy()  # the wider ball of the check below: twice the default, as step 3's
        unsure = _scatter_check((vertices, radii, referenced, scales), checks, fields, staircase=True)
        typical = soup_curvature if soup_grid is not None and soup_curvature > 0 else None  # 0: none read
        unsure |= _staircase_check((vertices, default, radii, referenced, facing), fields, soup_curvature=typical)
        steps = unsure.copy()  # the fits the steps bent: a limit of the method on this surface, not an undefined fit
    else:
        sigmas = _noise_sigmas(levels, scales, mesh.scale_edge_means)
        if radius is not None:
            curvatures = _curvature_scales(curvedness, scales, vertices, referenced)
            if mesh.n_cracked:  # a soup welded in part (an irregular rim's close vertices are no crack)
                sigmas = np.fmax(sigmas, _crack_sigmas(vertices, rim & referenced, mesh.scale_edge_means))
            unsure = _noise_reach((vertices, start, radii, referenced, facing), sigmas, curvatures, fields)
        else:  # the default radius: scatter told from structure by the residuals at two scales
            corners = _crack_corners(vertices, rim & referenced, mesh.scale_edge_means)
            if mesh.n_cracked:  # the copies the weld joined across cracks wide for the curvature (_welded_groups)
                corners |= _welded_groups(mesh, _curvature_scales(curvedness, scales, vertices, referenced))
            cracked = _cracked_balls(vertices, radii, corners)
            with np.errstate(invalid="ignore"):  # a noisy mesh: its group's median level above ROUGH_LEVEL
                rough = _group_medians(levels, scales, np.isfinite(levels)) > ROUGH_LEVEL
            checks = (sigmas > 0, noisy, cracked, rough)
            soup = cracked if mesh.n_cracked else None  # welded across cracks (an irregular rim's close vertices: no)
            unsure = _scatter_check((vertices, radii, referenced, scales), checks, fields, soup=soup)
    six, fitted, coefficients = fields

    stages.start("retrieve curvatures")
    fitted = np.where(np.isfinite(fitted).all(axis=1, keepdims=True), fitted, normals)
    valid &= np.isfinite(coefficients).all(axis=1)
    k_min, k_max, dir_min, dir_max = principal_from_shape_operator(
        np.where(valid[:, None], six, 0.0), np.where(valid[:, None], fitted, [0.0, 0.0, 1.0])
    )
    failed = ~valid & ~defects.invalid_vertices
    two_sided = int((failed & (away > AWAY_FRACTION)).sum())
    noisy_balls = int((failed & unsure & ~(away > AWAY_FRACTION)).sum())
    reached = failed & round_balls & ~unsure & ~(away > AWAY_FRACTION)
    rough_count = int((reached & noisy_levels).sum())  # a noisy ball reaching round: no smaller one tried
    round_count = int(reached.sum()) - rough_count
    few = int(failed.sum()) - two_sided - noisy_balls - round_count - rough_count
    steps &= failed & ~(away > AWAY_FRACTION)  # on a staircase the unsure balls are its steps' (noisy_balls)
    shown = ", ".join(f"{r:g}" for r, _ in groups) if radius is not None else _shown_radii(radii, referenced)
    extra = (
        (
            f"{few} vertices have fewer than {MIN_POINTS} vertices (or a degenerate set) within "
            f"radius {shown}; pass a larger `radius`"
        )
        if few
        else "",
        (
            f"{two_sided} vertices have a ball of radius {shown} that holds the other side of the surface "
            "(a part thinner than the ball, or a ball over a whole closed part): no height function to fit; "
            "pass a smaller `radius`"
        )
        if two_sided
        else "",
        _unsure_phrase(noisy_balls, shown, given=radius is not None, staircase=bool(steps.any())),
        (
            f"{round_count} vertices have a default ball that reaches round the surface (its normals turn by more "
            f"than {BALL_TURN_CAP:g} rad) and no smaller ball holds a fit: the mesh is too coarse there for this "
            "method (refine it)"
        )
        if round_count
        else "",
        (
            f"{rough_count} vertices have a default ball that reaches round the surface (its normals turn by more "
            f"than {BALL_TURN_CAP:g} rad) where the fits' residuals are above {NOISE_GATE:g} edge lengths: a coarse "
            "mesh there, or a noisy one, whose smaller balls would fit the noise (the residual of a ball that reaches "
            "round does not tell them apart); refine or smooth the mesh, or pass a `radius`"
        )
        if rough_count
        else "",
    )
    normals_out = np.where(valid[:, None], fitted, normals)
    parameters: dict[str, object] = {"radius": groups[0][0]}
    if radius is None:
        used = radii[referenced]
        parameters = {"radius": float(np.median(used)) if used.size else groups[0][0], "scale": "noise"}
    elif len(groups) > 1:
        parameters["radii"] = tuple(r for r, _ in groups)
    result, problems = finish(
        "quadric",
        parameters,
        valid,
        normals_out,
        k_min,
        k_max,
        dir_min,
        dir_max,
        defects,
        extra,
        radius=radii,
    )
    if steps.any() or reached.any():  # their reason: a limit of the method (a defect's code still comes first)
        codes = np.where(steps, STAIRCASE, np.where(reached, REACH, 0)).astype(np.int8)
        result = dataclasses.replace(result, invalid_reason=codes)
    return result, problems


#: A default ball is checked for its reach round the surface (:func:`_round_balls`) where its fit's largest ``|k|``
#: times its radius exceeds this: a ball turning by :data:`meshcurv.radius.BALL_TURN_CAP` spans ``r k`` of 1.2 on a
#: circle, and its fits read the curvature high there (1.27-1.47 times on ``torus(10, 3, 30, 30)``,
#: ``torus(10, 3, 24, 64)`` and ``torus(4, 1, 40, 12)``), or a few percent low (a fit of degree 4 over a clean sphere).
ROUND_CANDIDATE = 0.5

#: A ball that reaches round the surface is made smaller and refitted at most this many times
#: (:func:`_round_balls`): each time to where the normals of a circle through its rim would turn by
#: :data:`ROUND_TURN`, at most :data:`ROUND_SHRINK` of its radius.
ROUND_STEPS = 3

#: ... the margin of each step (:func:`_round_balls`).
ROUND_SHRINK = 0.95

#: A ball that reaches round the surface is made smaller to where the normals of a circle through its rim would turn
#: by this (radians; :func:`_round_balls`; a ball of ``0.83 / k`` with :data:`ROUND_SHRINK`), well within
#: :data:`meshcurv.radius.BALL_TURN_CAP`. A smaller ball holds fewer points, whose fit is a quadric
#: (:data:`ROUND_MIN_SPREAD`), biased as ``(r k)^2``: at 1.0 rad (``r k`` 0.91) it read the tube of
#: ``torus(10, 3, 30, 30)`` 10-13% high, and up to 19% on the jittered ones; at 0.9 rad 8-9% (up to 14%; jitter of a
#: fifth of an edge up to 19%). 0.85 lost a tenth of the jittered torus' valid vertices more (536 -> 483).
ROUND_TURN = 0.9

#: A default fit whose principal curvatures a smaller ball's fit (:func:`_round_balls`, its first step) reproduces
#: within this share of its largest ``|k|`` is kept: its ball turns past the cap where the curvature is high at one
#: side only (the tips of ``ellipsoid((3, 2, 1), 8)``, whose smaller balls, of fewer points, read H 1.9 -> 3.1% off).
ROUND_AGREEMENT = 0.1

#: The fits over a smaller ball (:func:`_round_balls`) are solved at the highest degree whose points are spread by this
#: (:data:`meshcurv.jets.MIN_SPREAD`; below it for every degree the vertex is NaN with ``valid=False``): a fifth of
#: the quadric's spread over the default balls of clean meshes (4.6e-3 to 6.8e-3 on icospheres, tori and ellipsoids,
#: jittered or not; degree 3 holds 5e-4 to 9e-4 there, degree 4 1e-4), so that the smaller balls take quadrics over
#: points spread in both directions. With the spread of the default fits (1e-7, and 1e-5 for the steadier fit) a
#: smaller ball of ``torus(10, 3, 30, 30, jitter=0.1)``, its neighbours along the ring near its rim, kept a fit of
#: degree 3 over points hardly spread across the tube (1e-5 to 1e-4): 71 of 874 valid vertices more than 15% of the
#: largest ``|k|`` off, up to 53% (issue 29); 5e-4 kept a few at 15%.
ROUND_MIN_SPREAD = 1e-3


def _round_balls(ball: tuple, edges: np.ndarray, sides: tuple, fields: tuple, away: np.ndarray) -> np.ndarray:
    """(V,) bool: the vertices whose default ball reaches round the surface and no smaller ball holds a fit (their
    coefficients made NaN); those of them that are ``rough`` (below) are the noisy balls, no smaller one tried.

    ``ball = (vertices, normals, start, radii, base, referenced, rough)``: ``normals`` the vertex normals (NaN rows:
    none), ``radii`` each vertex's default radius (changed in place where a ball is made smaller), ``base`` its
    group's (a ball grown for the noise, :func:`meshcurv.radius.jet_vertex_radii`, is not checked: its radius is capped by the
    curvature already), ``rough`` (V,) bool the vertices whose own noise level is above :data:`NOISE_GATE`;
    ``edges`` (E, 2); ``sides``, ``fields`` and ``away`` as :func:`_fit_part` takes them
    (changed in place). The default radius is :data:`meshcurv.radius.DEFAULT_RADIUS_FACTOR` mean edge lengths,
    which on a mesh of long and short edges (a torus of 30 x 30 quads, its ring's edges four times its tube's) reaches
    round a part curved along the short edges: the ball of ``torus(10, 3, 30, 30)`` (4.09 for a tube of radius 3)
    turns the normals by 1.5 rad, and its fits read the largest curvature 27% high, valid (issue 29). A ball whose
    normals turn from its centre's by more than :data:`meshcurv.radius.BALL_TURN_CAP` with no edge in it turning by
    more than :data:`meshcurv.radius.CREASE_TURN` (:func:`meshcurv.radius._ball_turns`; a crease is the ball's
    reading at any radius) is made smaller, to where a circle through its rim would turn by :data:`ROUND_TURN`, and
    fitted again (:data:`ROUND_STEPS` times at most) at the degrees its points are spread for (:data:`ROUND_MIN_SPREAD`:
    a quadric, mostly); where the first smaller ball reproduces the default fit
    (:data:`ROUND_AGREEMENT`) the default stays. A vertex whose smaller ball holds no fit, or one whose quadric's
    spread under the noise of its residuals exceeds :data:`NOISE_REACH` of its curvature, or that still turns past
    the cap, is NaN with ``valid=False``; so is a noisy one (its own level above :data:`NOISE_GATE`: it needs a wider
    ball, not a smaller one). Checked where the fit's largest ``|k|`` times its radius exceeds
    :data:`ROUND_CANDIDATE`: the fits of such balls read the curvature high (``torus(10, 3, 30, 30)``: 1.27 times)."""
    vertices, normals, start, radii, base, referenced, rough = ball
    six, fitted, coefficients = fields
    out = np.zeros(vertices.shape[0], dtype=bool)
    # the shape operators' Frobenius norm sqrt(k_min^2 + k_max^2) first (no eigenvalues at every vertex of a mesh)
    norms = np.sqrt(np.einsum("ij,ij->i", six[:, :3], six[:, :3]) + 2.0 * np.einsum("ij,ij->i", six[:, 3:], six[:, 3:]))
    with np.errstate(invalid="ignore"):
        bent = radii * norms > ROUND_CANDIDATE
    rows = np.flatnonzero(referenced & np.isfinite(coefficients).all(axis=1) & (radii <= base) & bent)
    if rows.size == 0:
        return out
    k_min, k_max = principal_from_shape_operator(six[rows], fitted[rows])[:2]
    with np.errstate(invalid="ignore"):
        rows = rows[radii[rows] * np.maximum(np.abs(k_min), np.abs(k_max)) > ROUND_CANDIDATE]
    if rows.size == 0:
        return out
    pool = np.flatnonzero(referenced)
    creases = _edge_turns(normals, edges, vertices.shape[0])  # the mesh's own normals: a crease is sharp there
    # the turns read on the fits' normals, which average the noise of the vertex normals (noise of 0.1 edge lengths
    # turned those of the coarse ellipsoid's balls past the cap where the surface's turn by 0.8 rad)
    smooth = np.where(np.isfinite(fitted).all(axis=1, keepdims=True), fitted, normals)
    reach = 2.0 * np.sin(ROUND_TURN / 2.0)  # the chord of a unit circle whose ends' normals turn by ROUND_TURN
    kept_fields = (radii, six, fitted, coefficients, away)  # what a smaller fit overwrites, the default's restored
    default = tuple(field[rows] for field in kept_fields)  # in the order of rows
    checked = rows
    for step in range(ROUND_STEPS + 1):
        turns, bends, sharpest = _ball_turns(vertices, smooth, radii, rows, pool, creases)
        over = (turns > BALL_TURN_CAP) & ~(sharpest > CREASE_TURN)
        rows, bends = rows[over], bends[over]
        noisy = rough[rows]  # a noisy ball needs a wider one, not a smaller one
        out[rows[noisy]] = True
        rows, bends = rows[~noisy], bends[~noisy]
        if rows.size == 0 or step == ROUND_STEPS:
            break
        with np.errstate(divide="ignore"):
            radii[rows] = np.fmin(ROUND_SHRINK * radii[rows], ROUND_SHRINK * reach / bends)
        _fit_part((vertices, start, radii, rows), referenced, normals, sides, fields, away, min_spread=ROUND_MIN_SPREAD)
        if step == 0:  # a default fit that a smaller ball reproduces is the surface's, not its reach's: kept
            at = np.searchsorted(checked, rows)
            same = _agreeing((six[rows], fitted[rows]), (default[1][at], default[2][at]))
            for field, kept in zip(kept_fields, default):
                field[rows[same]] = kept[at[same]]
            rows = rows[~same]  # (their bends are read again at the next step)
        # the smaller ball's quadric, whose spread under the noise of its residuals is held to NOISE_REACH of its
        # curvature (as _scatter_check's step 2): a mesh of noise below the gate may hold no fit over fewer points
        lost = ~np.isfinite(coefficients[rows]).all(axis=1)
        out[rows[lost]] = True
        rows = rows[~lost]
        found, _, spreads = residual_spreads(vertices, pool, radii, fitted, rows)
        with np.errstate(invalid="ignore"):
            lost = ~(spreads <= NOISE_REACH * _curvedness(found, fitted[rows], radii[rows]))
        out[rows[lost]] = True
        rows = rows[~lost]
    out[rows] = True
    coefficients[out] = np.nan
    return out


def _soup_grid(mesh: PreparedMesh, defects, valid: np.ndarray, stages: Stages):
    """The voxel grid (:class:`meshcurv.lattice.VoxelGrid`) of a mesh not measured at the voxel default, or None.

    A voxel surface stored as a triangle soup (faces with corners of their own, moved by a few hundredths of an edge,
    welded in part) is not measured at the voxel default radius (:func:`meshcurv.radius.voxel_surface_radius`): its
    corners read a grid only within a tolerance widened for noise, where the pilot's balls hold pieces of the surface,
    or read none where half of the faces stayed on it. Its grid is read by :func:`meshcurv.radius.soup_voxel_grid`
    (in any pose), without the corners of its cracks (:func:`_crack_corners`) as a second reading; ``valid``: the
    vertices that may centre a ball."""
    if stages.voxel_default:
        return None
    rim = mesh.topology.boundary_vertices & mesh.topology.referenced_vertices
    corners = _crack_corners(mesh.vertices, rim, mesh.scale_edge_means) if mesh.n_cracked else rim
    return soup_voxel_grid(mesh, invalid=defects.invalid_vertices, valid=valid, corners=corners, reading=stages.voxel)


def _staircase_radius(ball: tuple, grid) -> tuple[float, float]:
    """``(radius, curvature)``: the default radius of a voxel soup on ``grid`` (:func:`_soup_grid`), the voxel rule's
    (:func:`meshcurv.radius.voxel_rule_radius`, capped by the extent in the grid's axes), and its typical curvature
    ``1 / R``; 0 for both where no curvature is read.

    ``ball = (vertices, normals, radii, referenced)``: the quadrics over balls :data:`STAIRCASE_PILOT_SCALE` times
    ``radii`` (in the frames of ``normals``) give the typical radius of curvature ``R``
    (:func:`meshcurv.radius.voxel_curvature_radius`), as the voxel default reads it from its pilot. The noise rule's
    radius of such a soup (2.5 edge lengths, grown with the noise of its corners: 3.0 voxels on ``voxel_sphere(10)``
    with every face detached) is a smooth mesh's: the steps bend every fit there (median H error 36%, 1,283 of 11,196
    valid vertices off the clean surface's estimate by more than half its largest ``|k|``: issue 29, fuzz 415/108),
    where the voxel rule gives 4.1 voxels for ``R`` 8.2 (the clean sphere's default 4.2, its median error 7%)."""
    vertices, normals, radii, referenced = ball
    ids = np.flatnonzero(referenced)
    wide = STAIRCASE_PILOT_SCALE * radii
    found = residual_spreads(vertices, ids, wide, normals, ids)[0]
    k_min, k_max = _quadric_curvatures(found, normals[ids], wide[ids])
    curvature_radius = voxel_curvature_radius(np.maximum(np.abs(k_min), np.abs(k_max)), grid)
    if curvature_radius is None:
        return 0.0, 0.0
    return voxel_rule_radius(grid, curvature_radius, vertices[ids])[0], 1.0 / curvature_radius


def _agreeing(smaller: tuple, wider: tuple) -> np.ndarray:
    """(N,) bool: the fits ``(six, normals)`` over smaller balls whose principal curvatures are within
    :data:`ROUND_AGREEMENT` of the largest ``|k|`` of the fits over the wider ones (NaN: not)."""
    near = principal_from_shape_operator(*smaller)[:2]
    far = principal_from_shape_operator(*wider)[:2]
    with np.errstate(invalid="ignore"):
        apart = np.maximum(np.abs(near[0] - far[0]), np.abs(near[1] - far[1]))
        return apart <= ROUND_AGREEMENT * np.maximum(np.abs(far[0]), np.abs(far[1]))


def _unsure_phrase(count: int, shown: str, *, given: bool, staircase: bool) -> str:
    """The warning's phrase for ``count`` vertices whose fits the noise's checks dropped (``shown``: their radii):
    on a voxel surface's default (``staircase``) the fits that followed the voxels' steps."""
    if not count:
        return ""
    if staircase:
        return (
            f"{count} vertices of this voxel surface are NaN (voxel staircase): every fit over their ball, of radius "
            f"{shown}, or over a ball grown within their curvature, follows the voxels' steps"
        )
    advice = "pass a larger `radius` (or none)" if given else "no ball within their curvature averages it"
    return (
        f"{count} vertices have a ball of radius {shown} too small for the noise of their surface: any fit over it "
        f"moves the curvatures by more than {NOISE_REACH:g} of the surface's; {advice}"
    )


def _noisy_balls(levels: np.ndarray, groups: list) -> np.ndarray:
    """(V,) bool: the vertices whose noise level ``levels`` (:func:`meshcurv.radius.local_noise`), or the median
    level of their group of components of one scale (``groups``: :func:`meshcurv.radius.component_radii`),
    exceeds :data:`NOISE_GATE`. A ball of a noisy mesh whose own level reads lower is no less noisy: on fuzz
    296/1682 (faces detached by 0.087 edge lengths, median level 0.023) the vertex whose jet read H 1.58 for 0.99
    read 0.012."""
    with np.errstate(invalid="ignore"):
        return (levels > NOISE_GATE) | (_group_medians(levels, groups, np.isfinite(levels)) > NOISE_GATE)


def _group_medians(values: np.ndarray, groups: list, usable: np.ndarray) -> np.ndarray:
    """(V,) the median of the ``usable`` ``values`` of each vertex's group (``groups``: ``[(radius, members),
    ...]`` of :func:`meshcurv.radius.component_radii`), NaN where its group has none."""
    medians = np.full(values.shape, np.nan)
    for _, members in groups:
        rows = slice(None) if members is None else members
        part = values[rows][usable[rows]]
        if part.size:
            medians[rows] = np.median(part)
    return medians


def _fit_part(
    part: tuple, referenced, facing, sides: tuple, fields: tuple, away: np.ndarray, *, min_spread: float = MIN_SPREAD
) -> None:
    """The jets of ``part = (vertices, start, unit, centres)`` (``unit``: one radius, or (V,) one per vertex;
    ``centres`` None: every vertex) fitted into ``fields = (six, fitted, coefficients)`` and ``away`` (changed in
    place), each made stable (:func:`_steady_fits`): against a quadric at the vertices of ``sides = (rim,
    noisy)``, else against the highest degree spread by :data:`STEADY_MIN_SPREAD`; every degree solved where its
    points are spread by ``min_spread`` (:data:`meshcurv.jets.MIN_SPREAD`; the steadier fits by
    :data:`STEADY_MIN_SPREAD` at least)."""
    vertices, start, unit, centres = part
    six, fitted, coefficients = fields
    per_vertex = np.ndim(unit) > 0
    details: dict = {}
    found, frame, _ = _fit_jets(
        vertices,
        start,
        unit[centres] if per_vertex else unit,
        centres=centres,
        neighbours=referenced,
        facing=facing,
        details=details,
        min_spread=min_spread,
    )
    part_six, part_fitted = shape_operators(found, frame, unit)
    rows = slice(None) if centres is None else centres
    six[rows], fitted[rows], coefficients[rows] = part_six[rows], part_fitted[rows], found[rows]
    away[rows] = np.nan_to_num(details["away"][rows])
    rim, noisy = sides
    for steady_degree, side in ((STEADY_DEGREE, rim | noisy), (DEGREE, referenced & ~rim & ~noisy)):
        rows_fitted = np.flatnonzero(side) if centres is None else centres[side[centres]]
        if rows_fitted.size:
            steady = (vertices, start, unit[rows_fitted] if per_vertex else unit, rows_fitted, steady_degree)
            _steady_fits(steady, referenced, facing, fields, min_spread=max(min_spread, STEADY_MIN_SPREAD))


def _shown_radii(radii: np.ndarray, referenced: np.ndarray) -> str:
    """The default radii of a warning: one, or their range."""
    used = radii[referenced]
    if used.size == 0 or used.min() == used.max():
        return f"{used[0] if used.size else radii[0]:g}"
    return f"{used.min():g} to {used.max():g}"


def _steady_fits(steady: tuple, referenced, facing, fields: tuple, *, min_spread: float = STEADY_MIN_SPREAD) -> None:
    """The fits in ``fields`` (``six, fitted, coefficients``, changed in place) made stable at the vertices
    ``rows`` of ``steady = (vertices, start, unit, rows, degree)`` (``unit``: one radius, or one per row): the fit of at most ``degree`` over the
    same ball whose points are spread by :data:`STEADY_MIN_SPREAD` (:data:`STEADY_DEGREE` at the rim,
    :data:`meshcurv.jets.DEGREE` inside) where the jet differs from it by more than :data:`STEADY_AGREEMENT`
    over the radius ``unit``; NaN where no degree is spread enough (``min_spread``)."""
    vertices, start, unit, rows, degree = steady
    six, fitted, coefficients = fields
    found, frame, _ = _fit_jets(
        vertices,
        start,
        unit,
        degree=degree,
        centres=rows,
        neighbours=referenced,
        facing=facing,
        min_spread=min_spread,
    )
    low_six, low_fitted = shape_operators(found[rows], tuple(axis[rows] for axis in frame), unit)
    spread = np.isfinite(found[rows]).all(axis=1)
    high = np.isfinite(coefficients[rows]).all(axis=1)
    both = spread & high
    apart = np.full(rows.size, np.inf)
    if both.any():
        high_k = principal_from_shape_operator(six[rows][both], fitted[rows][both])[:2]
        low_k = principal_from_shape_operator(low_six[both], low_fitted[both])[:2]
        scale = unit[both] if np.ndim(unit) else unit
        apart[both] = scale * np.maximum(np.abs(high_k[0] - low_k[0]), np.abs(high_k[1] - low_k[1]))
    swap = spread & ~(apart <= STEADY_AGREEMENT)
    six[rows[swap]], fitted[rows[swap]], coefficients[rows[swap]] = low_six[swap], low_fitted[swap], found[rows][swap]
    coefficients[rows[~spread]] = np.nan


def _noise_spreads(ball: tuple, rows: np.ndarray, radii: np.ndarray, sigmas: np.ndarray, degree: int) -> np.ndarray:
    """(len(rows),) how far the noise ``sigmas`` moves the shape operator of a fit of ``degree`` over each ball.

    ``ball = (vertices, normals, referenced)``. The ball of vertex ``rows[i]`` is that of its fit (the
    ``referenced`` vertices within ``radii[i]``, weights ``w = (1 - d^2 / r^2)^2``), in the tangent plane of
    ``normals[rows[i]]``, in units of the radius. Independent noise of standard deviation ``sigmas[j]`` (V,) on
    the heights of the points ``j`` moves the coefficients by the covariance ``G^-1 M G^-1`` (``G``: the
    weighted normal matrix, ``M = sum_j w_j^2 (sigma_j / r)^2 b_j b_j^T``), and the shape operator
    ``[[2 c20, c11], [c11, 2 c02]] / r`` by ``sqrt(4 var c20 + 2 var c11 + 4 var c02) / r`` (the root of its
    expected squared Frobenius norm, which no turn of the tangent frame changes), in units of curvature; inf
    where the ball's points are not spread for a fit of ``degree`` (:data:`NOISE_MIN_SPREAD`: fewer points than
    terms, points along a curve), a measure that no rigid motion, scaling or turn of the frame changes either;
    0 where no point of the ball (of positive weight) has noise.

    The matrices are solved in the basis ``sqrt(C(i + k, i)) u^i v^k`` of :data:`meshcurv.jets.MIN_SPREAD`, on which
    a turn of the frame acts by an orthogonal matrix: their eigenvalues are those of every pose. (The smallest
    eigenvalue of ``G`` in the monomials over its largest, the test until Q71, changed with the frame: 2.4e-12 and
    9.1e-13 for the ball of 15 points of fandisk's vertex 5002 at a radius of 0.198 in two poses, against a floor of
    1e-12: a spread of 0 in one pose, inf in the other, a jet kept in one and a quadric taken in the other, k_max
    0.0726 and 0.0714; issue 29, fuzz 804/313.)"""
    vertices, normals, referenced = ball
    ids = np.flatnonzero(referenced)
    exponents = _exponents(degree)
    second = [int(np.flatnonzero((exponents == pair).all(axis=1))[0]) for pair in ((2, 0), (1, 1), (0, 2))]
    bombieri = np.sqrt(_binomials(degree))  # the basis b_B = S b: G_B = S G S, coefficients c = S c_B
    factor = np.array([4.0, 2.0, 4.0]) * bombieri[second] ** 2
    scaled = bombieri[:, None] * bombieri[None, :]
    t1, t2 = tangent_basis(normals[rows])
    out = np.full(rows.size, np.inf)
    centres = vertices[rows]
    for chunk, i, j in _ball_pairs(vertices[ids], centres, radii):
        local = i - chunk.start
        offsets = (vertices[ids[j]] - centres[i]) / radii[i][:, None]
        weights = np.clip(1.0 - np.einsum("ij,ij->i", offsets, offsets), 0.0, None) ** 2
        size = chunk.stop - chunk.start
        frame = (t1[chunk], t2[chunk], normals[rows][chunk])
        gram = _fit_chunk(offsets, local, size, frame, weights, degree)[0] * scaled
        noise = _fit_chunk(offsets, local, size, frame, (weights * sigmas[ids[j]] / radii[i]) ** 2, degree)[0] * scaled
        values, vectors = np.linalg.eigh(gram)
        with np.errstate(divide="ignore", invalid="ignore"):  # (a singular G: not spread)
            spread = 1.0 / (gram[:, 0, 0] * (1.0 / values).sum(axis=1))
        solid = (values[:, 0] > 0) & (spread >= NOISE_MIN_SPREAD)
        inverse = np.where(solid[:, None], 1.0 / np.where(values > 0, values, 1.0), 0.0)
        # the rows of G_B^-1 = Q diag(1 / l) Q^T for the second-order terms
        rows_inverse = np.einsum("nkm,nm,nlm->nkl", vectors[:, second, :], inverse, vectors)
        covariance = np.einsum("nkl,nlm,nkm->nk", rows_inverse, noise, rows_inverse)
        spread = np.sqrt(np.clip(covariance, 0.0, None) @ factor) / radii[chunk]
        # a ball none of whose weighted points is noisy: the noise moves nothing, however its points are spread
        # (its jet as on a clean mesh; the spread test alone turned such balls to quadrics wherever another
        # vertex of the mesh had noise: test_dirty's torus with a fin, 58 of 668 vertices far from the fin)
        quiet = np.bincount(local, weights=((weights > 0) & (sigmas[ids[j]] > 0)).astype(float), minlength=size) == 0
        out[chunk] = np.where(quiet, 0.0, np.where(solid, spread, np.inf))
    return out


def residual_spreads(vertices, pool, radii, normals, centres) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A quadric fitted over the ball of each centre, the noise of its residuals and how far it moves the fit.

    Parameters
    ----------
    vertices : ndarray of shape (V, 3)
        The points.
    pool : ndarray of shape (P,)
        The ids (int64) of the points that enter the balls.
    radii : ndarray of shape (V,)
        Each vertex's radius.
    normals : ndarray of shape (V, 3)
        Unit normals: each fit's frame (:func:`meshcurv._tensors.tangent_basis`).
    centres : ndarray of shape (M,)
        The vertices fitted.

    Returns
    -------
    coefficients : ndarray of shape (M, 6)
        The quadric ``z = c0 + c1 x + c2 y + c3 x^2 + c4 x y + c5 y^2``, in units of the radius, weights
        ``(1 - d^2 / r^2)^2``.
    sigmas : ndarray of shape (M,)
        The residuals' standard deviation, in length units: ``sum w e^2 / (sum w - tr(G^-1 M))`` (``G = sum w b
        b^T``, ``M = sum w^2 b b^T``: unbiased for independent noise of one standard deviation).
    spreads : ndarray of shape (M,)
        ``sqrt(4 var c3 + 2 var c4 + 4 var c5) / r`` under that noise (``sigma^2 G^-1 M G^-1``), in units of
        curvature: the root of the expected squared change of the shape operator. NaN, NaN and inf where the ball
        holds fewer than six points or a singular normal matrix; NaN and inf (the coefficients kept) where the
        residuals' degrees of freedom ``sum w - tr(G^-1 M)`` do not exceed :data:`RESIDUAL_DOF_FLOOR` of ``sum w``:
        a ball of six points, fitted exactly (its degrees of freedom 0 up to round-off, whose sign the order of the
        sums decided: issue 29, fuzz 421/21).
    """
    kernels = numba_kernels("quadric")
    centres = np.ascontiguousarray(centres, dtype=np.int64)
    if kernels is not None:
        return kernels.residual_spreads(
            np.ascontiguousarray(vertices, dtype=np.float64),
            np.ascontiguousarray(pool, dtype=np.int64),
            np.ascontiguousarray(radii, dtype=np.float64),
            np.ascontiguousarray(normals, dtype=np.float64),
            centres,
            64 * kernel_threads(),
        )
    m = centres.size
    coefficients = np.full((m, 6), np.nan)
    sigmas = np.full(m, np.nan)
    spreads = np.full(m, np.inf)
    if m == 0 or np.size(pool) == 0:
        return coefficients, sigmas, spreads
    t1, t2 = tangent_basis(normals[centres])
    frame = (t1, t2, normals[centres])
    unit = radii[centres]
    for chunk, i, j in _ball_pairs(vertices[pool], vertices[centres], unit):
        size = chunk.stop - chunk.start
        local = i - chunk.start
        offsets = (vertices[pool[j]] - vertices[centres[i]]) / unit[i][:, None]
        weights = 1.0 - (offsets[:, 0] * offsets[:, 0] + offsets[:, 1] * offsets[:, 1] + offsets[:, 2] * offsets[:, 2])
        inside = weights > 0
        offsets, local, weights = offsets[inside], local[inside], weights[inside] ** 2
        x, y, z = (np.einsum("ij,ij->i", offsets, axis[chunk][local]) for axis in frame)
        basis = np.stack([np.ones_like(x), x, y, x * x, x * y, y * y], axis=1)
        terms = np.ascontiguousarray(basis.T)  # (6, N): each term in a row of its own, for the sums
        outer = (terms[:, None, :] * terms[None, :, :]).reshape(36, -1)
        gram = _summed(local, weights * outer, size).reshape(size, 6, 6)
        moments = _summed(local, (weights * weights) * outer, size).reshape(size, 6, 6)
        right = _summed(local, (weights * z) * terms, size)
        count = np.bincount(local, minlength=size)
        total = np.bincount(local, weights=weights, minlength=size)
        diagonal = np.einsum("nii->ni", gram)
        values = np.linalg.eigvalsh(gram)
        solid = (count >= 6) & (values[:, 0] > PIVOT_FLOOR * np.maximum(diagonal.max(axis=1), 1e-300))
        inverse = np.zeros_like(gram)
        inverse[solid] = np.linalg.inv(gram[solid])
        found = np.einsum("nij,nj->ni", inverse, right)
        residuals = z - np.einsum("ij,ij->i", basis, found[local])
        squares = np.bincount(local, weights=weights * residuals * residuals, minlength=size)
        dof = total - np.einsum("nij,nji->n", inverse, moments)
        second = np.einsum("nkr,nrc,nkc->nk", inverse[:, 3:, :], moments, inverse[:, 3:, :]) @ [4.0, 2.0, 4.0]
        usable = solid & (dof > RESIDUAL_DOF_FLOOR * total)  # six points: an exact fit, its dof 0 up to round-off
        sigma2 = np.where(usable, squares, 0.0) / np.where(usable, dof, 1.0)
        coefficients[chunk][solid] = found[solid]
        sigmas[chunk] = np.where(usable, np.sqrt(sigma2) * unit[chunk], np.nan)
        spreads[chunk] = np.where(usable, np.sqrt(np.clip(sigma2 * second, 0.0, None)) / unit[chunk], np.inf)
    return coefficients, sigmas, spreads


def _summed(rows: np.ndarray, values: np.ndarray, size: int) -> np.ndarray:
    """(size, K) the sums of the columns of ``values`` (K, N) by ``rows`` (N,) in their order, as ``np.add.at`` sums
    them (the same numbers), by :func:`numpy.bincount`: ``np.add.at`` took half of the NumPy path's time on soups."""
    return np.stack([np.bincount(rows, weights=row, minlength=size) for row in values], axis=1)


def _scatter_check(
    ball: tuple, checks: tuple, fields: tuple, *, staircase: bool = False, soup: np.ndarray | None = None
) -> np.ndarray:
    """(V,) bool: the vertices at the default radius whose fit the scatter of their ball's points moves beyond
    :data:`NOISE_REACH` of their curvature, at their radius and over a grown ball (their coefficients made NaN).

    ``ball = (vertices, radii, referenced, groups)`` (``radii``: each vertex's default radius, changed in place where
    a grown ball's fit is taken); ``checks = (checked, noisy, cracked, rough)``: the vertices whose ball reads noise
    (:func:`_noise_sigmas` above 0), those above :data:`NOISE_GATE` (:func:`_noisy_balls`), those whose ball holds a
    crack's corner (:func:`_cracked_balls`) and those of a group whose median level exceeds :data:`ROUGH_LEVEL`;
    ``fields = (six, fitted, coefficients)``, changed in place. A crease is told from scatter by its residuals:

    1. at each checked vertex (and each ``soup`` one, whose level may read clean: most points of a soup are in
       place), a quadric over its ball in the frame of its fit (:func:`residual_spreads`, compiled)
       gives its residuals' standard deviation ``s`` and the spread of its curvatures under a noise of that size; at
       the ``noisy`` vertices a jet that departs from it by more than that spread takes it, at the ``soup`` ones it
       takes it whatever (:func:`_follow_quadrics`; elsewhere a clean surface's higher terms make the departure: the
       coarse ellipsoid of ``accuracy.py --quick``, H 1.9 -> 3.1% with the swap everywhere). Over cracks whose level
       read below :data:`NOISE_GATE` the jet of degree 4 followed the copies' offsets while steps 2-5 checked only its
       quadric (fuzz 490/29: ``icosphere(40)`` half detached by 0.049 edges, H 0.18-1.94 for 1 where the ball's
       quadric read 0.74-1.26, 296 of 56,125 valid vertices off by more than half of the largest ``|k|``; none now);
    2. a spread within :data:`NOISE_REACH` of the quadric's curvedness (at least the median curvedness of the fits
       of its group, :func:`_fitted_curvedness`) passes: a crease is a large curvature whose residuals, small beside
       it, read as noise;
    3. beyond it, a quadric over a ball :data:`SCATTER_SCALE` times wider: the residuals of scatter keep their size
       there, those of a crease or relief that the quadric cannot follow grow with the ball. If they grew by ``g``,
       the noise in them is the share ``sqrt((G^2 - g^2) / (G^2 - 1))`` (``G``: :data:`STRUCTURE_GROWTH`, the
       slowest growth of structure) of ``s``, and its spread within the reach passes (W20's check of the spread
       alone, against the noise fits' level, lost fandisk's creases: 80 -> 57% valid);
    4. scatter takes the quadric over a ball grown until its spread (as ``r^-3``) is within the reach (over cracks
       within :data:`GROWN_REACH`), at most :data:`meshcurv.radius.JET_CURVATURE_CAP` over its curvedness, if it is
       steady (its spread within the reach); else it is NaN with ``valid=False``;
    5. at the vertices whose ball holds a crack's corner (``cracked``, :func:`_cracked_balls`: a soup's detached
       faces), a quadric that departs from the wider ball's by more than :data:`CRACK_DEPARTURE_SPREADS` of its
       spreads follows the steps (the spread of independent noise underestimates their pull) whatever its residuals did:
       one that bent to follow a step absorbed its own residuals, and the wider ball's then grew as a crease's would
       (fuzz 415/108: 264 of the 286 vertices left off grew 1.7-3.0 times). It takes the quadric of 4 if steady,
       else it is NaN with ``valid=False``. On a noisy mesh (``rough``: its median level above
       :data:`ROUGH_LEVEL`) off cracks, by more than :data:`DEPARTURE_SPREADS` of its spreads and only while its
       residuals grew less than :data:`STRUCTURE_GROWTH`, and it
       keeps its own fit where the grown one is not steady (fandisk's creases: made NaN, 79.98 -> 76.2-79.1%
       valid). Elsewhere the wider ball is fitted at the rows 2 failed only: at every row it cost nefertiti 1.43x
       its CPU and changed a dozen crease vertices of fandisk and rocker-arm.

    ``soup``: on a mesh welded across cracks (``PreparedMesh.n_cracked``), the ``cracked`` vertices (None elsewhere: an
    irregular rim's close vertices are no crack, and the swap moved the irregular open meshes of ``accuracy.py
    --quick``).

    ``staircase``: a voxel surface at its default radius, every ball over the steps of the voxels (``checks`` all
    set but ``rough``): residuals that grow over the wider ball are the steps' and the ball's reach round the
    surface, not a crease's, so step 3 passes no fit as structure (on ``voxel_torus()`` 103 fits kept so were off
    the exact H by more than half of the largest ``|k|``); step 5 reads a departure beyond
    :data:`STAIRCASE_DEPARTURE_SPREADS` and step 4 grows a ball as for :data:`STAIRCASE_PULL` times its spread (the
    steps' pull is coherent over the ball). :func:`_staircase_check` then checks the fits kept."""
    vertices, radii, referenced, groups = ball
    checked, noisy, cracked, rough = checks
    soup = np.zeros_like(cracked) if soup is None else soup
    six, fitted, coefficients = fields
    frames = fitted.copy()  # the frames of the quadrics (the fits' normals as they were)
    unsure = np.zeros(vertices.shape[0], dtype=bool)
    rows = np.flatnonzero((checked | soup) & referenced & np.isfinite(coefficients).all(axis=1))
    if rows.size == 0:
        return unsure
    pool = np.flatnonzero(referenced)
    floor = _fitted_curvedness(fields, groups, vertices, referenced)
    found, sigmas, spreads = residual_spreads(vertices, pool, radii, frames, rows)
    gated = (noisy | soup)[rows]
    # over a crack the fit kept is the quadric that the steps below hold to the crack: a jet within its spread of it
    # still followed the copies' offsets (H 1.57 for 1 over a quadric of 1.32, spread 0.36; every face of
    # icosphere(24) detached by 0.1 edges)
    held = np.where(soup[rows] & np.isfinite(spreads), 0.0, spreads)
    _follow_quadrics((rows[gated], found[gated], frames[rows[gated]], radii[rows[gated]], held[gated]), fields)
    bent = _curvedness(found, frames[rows], radii[rows])
    loose = ~(spreads <= NOISE_REACH * np.fmax(bent, floor[rows]))
    passed = ~loose  # as the noise's spread alone reads them
    # the wider ball where it can change the outcome: the rows the spread failed, and the balls over cracks (a
    # soup's steps), whose passed fits it checks (step 5); elsewhere a passed fit stays, as it did without step 5
    # (nefertiti 1.43x the CPU with the wider ball at every passed row, and the same results)
    steps = (cracked | rough)[rows]
    wider = loose | steps
    near = (found[steps], frames[rows[steps]], radii[rows[steps]])
    rows, sigmas, spreads_near, bent, passed, steps = (
        rows[wider],
        sigmas[wider],
        spreads[wider],
        bent[wider],
        passed[wider],
        steps[wider],
    )
    over_cracks = cracked[rows]
    if rows.size == 0:
        return unsure
    wide = SCATTER_SCALE * radii[rows]
    found, wide_sigmas, spreads = residual_spreads(vertices, pool, _at(radii, rows, wide), frames, rows)
    with np.errstate(divide="ignore", invalid="ignore"):
        growth = wide_sigmas / sigmas
    # a fit over cracks that departs from the wider ball's by more than its noise follows the steps, whatever its
    # residuals did: the spread of independent noise underestimates their pull, and a fit that bent to follow a
    # step absorbed its own residuals, so that the wider ball's grew as a crease's would (fuzz 415/108: 264 of the
    # 286 vertices left off by more than half the largest |k| grew 1.7-3.0 times, departing by 2.7-7.9 spreads)
    # (on a noisy mesh without cracks, only while its residuals keep their size: a crease's grow)
    following = np.zeros(rows.size, dtype=bool)
    with np.errstate(invalid="ignore"):
        far = (found[steps], frames[rows[steps]], wide[steps])
        reach = np.where(cracked[rows[steps]], CRACK_DEPARTURE_SPREADS, DEPARTURE_SPREADS)
        if staircase:
            reach = np.full(reach.shape, STAIRCASE_DEPARTURE_SPREADS)
        following[steps] = _departure(near, far) > reach * spreads_near[steps]
        following &= over_cracks | (growth < STRUCTURE_GROWTH)
    loose = ~passed | following
    rows, sigmas, spreads_near, growth, passed, over_cracks = (
        rows[loose],
        sigmas[loose],
        spreads_near[loose],
        growth[loose],
        passed[loose],
        over_cracks[loose],
    )
    found, spreads, wide, following, bent = found[loose], spreads[loose], wide[loose], following[loose], bent[loose]
    if rows.size == 0:
        return unsure
    # the noise the two scales leave if the rest grows as STRUCTURE_GROWTH
    share = np.sqrt(np.clip((STRUCTURE_GROWTH**2 - growth * growth) / (STRUCTURE_GROWTH**2 - 1.0), 0.0, 1.0))
    held = NOISE_REACH * np.fmax(bent, floor[rows])
    with np.errstate(invalid="ignore"):
        grew = passed if staircase else passed | (spreads_near * share <= held)
    structure = grew & ~following
    # off cracks, a fit that the spread passed but follows its scatter takes a steady wider ball's, and keeps its own
    # without one (fandisk's creases; NaN gave 76.2-79.1% valid for 79.98)
    spared = (following & grew & ~over_cracks)[~structure]
    rows, found, spreads, wide = rows[~structure], found[~structure], spreads[~structure], wide[~structure]
    if rows.size == 0:
        return unsure
    # scatter: a ball grown until the spread (as r^-3) is within the reach, within the curvature's cap (over a
    # soup's cracks within GROWN_REACH; on a staircase as for STAIRCASE_PULL times the spread)
    held = np.fmax(_curvedness(found, frames[rows], wide), floor[rows])
    target = np.where(over_cracks[~structure] & (not staircase), GROWN_REACH, NOISE_REACH)
    with np.errstate(divide="ignore", invalid="ignore"):
        pull = STAIRCASE_PULL if staircase else 1.0
        grown = wide * np.cbrt(pull * spreads / (target * held)) * GROWTH_MARGIN
        grown = np.fmin(np.fmax(grown, radii[rows]), JET_CURVATURE_CAP / held)
    again = np.isfinite(grown) & (np.abs(grown - wide) > 0.01 * wide)
    if again.any():
        refit = residual_spreads(vertices, pool, _at(radii, rows[again], grown[again]), frames, rows[again])
        found[again], spreads[again], wide[again] = refit[0], refit[2], grown[again]
    bent = _curvedness(found, frames[rows], wide)
    with np.errstate(invalid="ignore"):
        steady = (spreads <= NOISE_REACH * np.fmax(bent, floor[rows])) & (wide * bent <= JET_CURVATURE_CAP * 1.01)
    taken = rows[steady]
    frame = tangent_basis(frames[taken])
    six[taken], fitted[taken] = shape_operators(found[steady], (*frame, frames[taken]), wide[steady])
    coefficients[taken] = found[steady]
    radii[taken] = wide[steady]
    unsure[rows[~steady & ~spared]] = True
    coefficients[unsure] = np.nan
    return unsure


def _staircase_check(ball: tuple, fields: tuple, *, soup_curvature: float | None = None) -> np.ndarray:
    """(V,) bool: the fits kept on a staircase that the steps bent (their coefficients made NaN).

    ``ball = (vertices, default, radii, referenced, facing)``: each vertex's default radius and that of its kept fit
    (:func:`_scatter_check` grows some), ``facing`` the vertex normals (NaN rows: none); ``fields = (six, fitted,
    coefficients)``, changed in place. A fit is unsure where its normal faces away from its vertex's (beyond a right
    angle: :data:`STAIRCASE_FACING`), where its mean curvature departs from that of a quadric over twice its default ball (in the frame of its
    normal, :func:`residual_spreads`) by more than :data:`STAIRCASE_AGREEMENT` of its own largest ``|k|`` (a fit of
    zero is unsure unless the wider quadric is flat too), or where its ball is wider than
    :data:`STAIRCASE_CURVATURE_CAP` times the radius of curvature of that ``|k|``. The wider quadric and the grown balls
    of :func:`_scatter_check` follow the steps too, but not in the same way: where they disagree, neither is the
    surface's (issue 29: off the exact H by more than half of the largest ``|k|``, valid, ``voxel_torus()`` 21 and the
    voxel spheres of radius 3-15 57). On a voxel soup (``soup_curvature``: its typical curvature, ``1 / R`` of
    :func:`_staircase_radius`) the two also agree within :data:`SOUP_AGREEMENT` of it."""
    vertices, default, radii, referenced, facing = ball
    six, fitted, coefficients = fields
    unsure = np.zeros(vertices.shape[0], dtype=bool)
    rows = np.flatnonzero(referenced & np.isfinite(coefficients).all(axis=1))
    if rows.size == 0:
        return unsure
    with np.errstate(invalid="ignore"):  # (NaN: no vertex normal, not checked here)
        turned = np.einsum("ij,ij->i", fitted[rows], facing[rows]) < STAIRCASE_FACING
    unsure[rows[turned]] = True
    coefficients[rows[turned]] = np.nan
    rows = rows[~turned]
    if rows.size == 0:
        return unsure
    k_min, k_max = principal_from_shape_operator(six[rows], fitted[rows])[:2]
    largest = np.maximum(np.abs(k_min), np.abs(k_max))
    wide = 2.0 * default
    found = residual_spreads(vertices, np.flatnonzero(referenced), wide, fitted, rows)[0]
    wide_min, wide_max = _quadric_curvatures(found, fitted[rows], wide[rows])
    with np.errstate(invalid="ignore"):  # NaN: no wider fit, unsure
        apart = np.abs((k_min + k_max) - (wide_min + wide_max)) / 2
        bent = ~(apart <= STAIRCASE_AGREEMENT * largest) | (radii[rows] * largest > STAIRCASE_CURVATURE_CAP)
        if soup_curvature is not None:  # a voxel soup: also within a share of its typical curvature
            bent |= apart > SOUP_AGREEMENT * soup_curvature
    unsure[rows[bent]] = True
    coefficients[rows[bent]] = np.nan
    return unsure


def _quadric_curvatures(coefficients: np.ndarray, normals: np.ndarray, radii: np.ndarray) -> tuple:
    """``(k_min, k_max)``, each (N,), of quadrics fitted in the frames of ``normals`` (:func:`residual_spreads`, in
    units of their ``radii``); NaN where no fit."""
    known = np.isfinite(coefficients).all(axis=1)
    k_min, k_max = np.full(coefficients.shape[0], np.nan), np.full(coefficients.shape[0], np.nan)
    if known.any():
        frame = tangent_basis(normals[known])
        six, tilted = shape_operators(coefficients[known], (*frame, normals[known]), radii[known])
        k_min[known], k_max[known] = principal_from_shape_operator(six, tilted)[:2]
    return k_min, k_max


def _crack_corners(vertices: np.ndarray, rim: np.ndarray, edge_lengths: np.ndarray) -> np.ndarray:
    """(V,) bool: the ``rim`` vertices with another rim vertex within :data:`CRACK_WIDTH` of their local edge length
    (``edge_lengths``, (V,)): the corners of a crack, whose two sides run close (faces detached from their
    neighbours), not those of an open surface's boundary, whose rim vertices are an edge length apart. All False
    on a closed mesh."""
    return np.isfinite(_crack_gaps(vertices, rim, edge_lengths))


def _crack_sigmas(vertices: np.ndarray, rim: np.ndarray, edge_lengths: np.ndarray) -> np.ndarray:
    """(V,) the noise a crack puts on the heights of its corners (:func:`_crack_corners`), 0 elsewhere: the
    crack's width (:func:`_crack_gaps`) over ``sqrt(3)``.

    A face detached by a gap ``g`` in a random direction leaves its corners ``g`` from the corners they were
    (the other side of the crack), which a ball of a given radius holds both of: on a soup whose cracks the weld
    joined in part, most points are in place and the noise level reads clean (:func:`_noise_sigmas`: 0 at most of
    the vertices of ``ellipsoid(subdivisions=24)`` half detached by 0.038 edges), while a ball of 7 to 11 points
    by a crack follows the copies' offsets (a given radius of 1.3 edges: H -5.7 to 8.8 for 0.2, valid; fuzz
    420/76). The offset along the normal of a random direction has the standard deviation ``g / sqrt(3)``, which
    :func:`_noise_reach` then weighs through each ball's normal matrix."""
    return np.nan_to_num(_crack_gaps(vertices, rim, edge_lengths), nan=0.0) / np.sqrt(3.0)


def _crack_gaps(vertices: np.ndarray, rim: np.ndarray, edge_lengths: np.ndarray) -> np.ndarray:
    """(V,) at the corners of a crack (:func:`_crack_corners`) the distance to the nearest other rim vertex, NaN
    elsewhere."""
    out = np.full(vertices.shape[0], np.nan)
    ids = np.flatnonzero(rim)
    if ids.size < 2:
        return out
    from scipy.spatial import cKDTree  # imported on use: scipy.spatial costs import time

    distances = cKDTree(vertices[ids]).query(vertices[ids], k=2)[0][:, 1]  # the nearest other rim vertex
    out[ids] = np.where(distances < CRACK_WIDTH * edge_lengths[ids], distances, np.nan)
    return out


def _welded_groups(mesh: PreparedMesh, curvatures: np.ndarray) -> np.ndarray:
    """(V,) bool: the vertices into which the weld joined the caller's vertices across cracks wider than
    :data:`WELDED_GAP` of ``h^2 k`` (``PreparedMesh.crack_gaps``; ``h`` the local edge length
    ``mesh.scale_edge_means``, ``k`` the (V,) ``curvatures`` of :func:`_curvature_scales`): taken as a crack's
    corners (:func:`_cracked_balls`). All False on a mesh not welded across cracks, and at a weld of coincident copies
    (a seam: no gap)."""
    out = np.zeros(mesh.vertices.shape[0], dtype=bool)
    if mesh.crack_gaps is not None:
        with np.errstate(invalid="ignore"):  # (NaN edge lengths: no corner)
            out |= mesh.crack_gaps > WELDED_GAP * mesh.scale_edge_means**2 * curvatures
    return out


def _cracked_balls(vertices: np.ndarray, radii: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """(V,) bool: the vertices whose ball (``radii``, one per vertex) holds a crack's corner (``corners``,
    :func:`_crack_corners`): where a soup's steps can pull a quadric (:func:`_scatter_check`, step 5)."""
    out = np.zeros(vertices.shape[0], dtype=bool)
    if not corners.any():
        return out
    from scipy.spatial import cKDTree

    finite = np.isfinite(radii)
    reach = float(radii[finite].max()) if finite.any() else 0.0
    distances = cKDTree(vertices[corners]).query(vertices, distance_upper_bound=reach)[0]
    return distances < radii


def _departure(near: tuple, far: tuple) -> np.ndarray:
    """(N,) the largest difference of the principal curvatures of two sets of quadrics ``(coefficients, normals,
    radii)`` (:func:`residual_spreads`); NaN where either has no fit."""
    curvatures = []
    for coefficients, normals, radii in (near, far):
        frame = tangent_basis(normals)
        six, tilted = shape_operators(coefficients, (*frame, normals), radii)
        curvatures.append(principal_from_shape_operator(six, tilted)[:2])
    (a_min, a_max), (b_min, b_max) = curvatures
    return np.maximum(np.abs(a_min - b_min), np.abs(a_max - b_max))


def _follow_quadrics(quadrics: tuple, fields: tuple) -> None:
    """The fits in ``fields = (six, fitted, coefficients)`` (changed in place) replaced by the quadrics of
    ``quadrics = (rows, coefficients, normals, radii, spreads)`` (:func:`residual_spreads`, in the frames of
    ``normals``) where their principal curvatures depart from the quadric's by more than its spread under the noise of
    its residuals: the jet's higher terms then follow the scatter (issue 29, fuzz 395/82: every face of
    ``icosphere(24)`` detached by 0.055 edge lengths, jets off the unit sphere's H by 0.5-0.64 over quadrics off by
    0.16-0.27, spreads 0.15-0.21)."""
    rows, found, normals, radii, spreads = quadrics
    six, fitted, coefficients = fields
    known = np.isfinite(found).all(axis=1) & np.isfinite(spreads)
    rows, found, normals, radii, spreads = rows[known], found[known], normals[known], radii[known], spreads[known]
    if rows.size == 0:
        return
    frame = tangent_basis(normals)
    low_six, low_fitted = shape_operators(found, (*frame, normals), radii)
    high_k = principal_from_shape_operator(six[rows], fitted[rows])[:2]
    low_k = principal_from_shape_operator(low_six, low_fitted)[:2]
    apart = np.maximum(np.abs(high_k[0] - low_k[0]), np.abs(high_k[1] - low_k[1]))
    swap = apart > spreads
    six[rows[swap]], fitted[rows[swap]], coefficients[rows[swap]] = low_six[swap], low_fitted[swap], found[swap]


def _at(radii: np.ndarray, rows: np.ndarray, values: np.ndarray) -> np.ndarray:
    """A copy of ``radii`` with ``values`` at ``rows``."""
    out = radii.copy()
    out[rows] = values
    return out


def _curvedness(coefficients: np.ndarray, normals: np.ndarray, radii: np.ndarray) -> np.ndarray:
    """(N,) ``sqrt((k_min^2 + k_max^2) / 2)`` of quadrics fitted in the frames of ``normals``
    (:func:`residual_spreads`, in units of their ``radii``); NaN where no fit."""
    k_min, k_max = _quadric_curvatures(coefficients, normals, radii)
    return np.sqrt((k_min * k_min + k_max * k_max) / 2)


def _fitted_curvedness(fields: tuple, groups: list, vertices: np.ndarray, referenced: np.ndarray) -> np.ndarray:
    """(V,) the median curvedness ``sqrt((k_min^2 + k_max^2) / 2)`` of the fits in ``fields = (six, fitted,
    coefficients)`` over each group of components (``groups``), at least ``2 / d`` (``d``: the diagonal of the
    bounding box of the referenced vertices, as :func:`_curvature_scales`)."""
    six, fitted, coefficients = fields
    usable = np.isfinite(coefficients).all(axis=1) & referenced
    own = np.full(vertices.shape[0], np.nan)
    if usable.any():
        k_min, k_max = principal_from_shape_operator(six[usable], fitted[usable])[:2]
        own[usable] = np.sqrt((k_min * k_min + k_max * k_max) / 2)
    points = vertices[referenced]
    diagonal = float(np.linalg.norm(points.max(axis=0) - points.min(axis=0))) if points.size else 0.0
    return np.fmax(_group_medians(own, groups, np.isfinite(own)), 2.0 / diagonal if diagonal > 0 else np.inf)


def _noise_sigmas(levels: np.ndarray, groups: list, edge_lengths: np.ndarray) -> np.ndarray:
    """(V,) the standard deviation of the noise on the heights at each vertex, in length units (0: clean).

    Its noise level ``levels`` (:func:`meshcurv.radius.local_noise`, a mean distance in local edge lengths
    ``edge_lengths``), or the median level of its group (``groups``), whichever is larger (as
    :func:`_noisy_balls`), less :data:`CLEAN_LEVEL` (the noise fits' own bias on a clean mesh; in quadrature),
    times :data:`NOISE_SIGMA_FACTOR`. NaN levels take the group's median; 0 where nothing is known."""
    known = np.isfinite(levels)
    medians = np.nan_to_num(_group_medians(levels, groups, known), nan=0.0)
    level = np.fmax(np.where(known, levels, medians), medians)
    sigmas = NOISE_SIGMA_FACTOR * np.sqrt(np.clip(level**2 - CLEAN_LEVEL**2, 0.0, None)) * edge_lengths
    return np.where(np.isfinite(sigmas), sigmas, 0.0)


def _curvature_scales(curvedness: np.ndarray, groups: list, vertices: np.ndarray, referenced) -> np.ndarray:
    """(V,) the curvature that a vertex's estimate is held to: the median curvedness of its group (``groups``;
    :func:`meshcurv.radius.local_noise`), at least ``2 / d`` (``d``: the diagonal of the bounding box of the
    referenced vertices: a sphere's curvedness is ``2.4 / d``; a noisy plane is held to the curvature of its
    extent)."""
    points = vertices[referenced]
    diagonal = float(np.linalg.norm(points.max(axis=0) - points.min(axis=0))) if points.size else 0.0
    floor = 2.0 / diagonal if diagonal > 0 else np.inf
    return np.fmax(_group_medians(curvedness, groups, np.isfinite(curvedness) & referenced), floor)


def _noise_reach(reach: tuple, sigmas: np.ndarray, curvatures: np.ndarray, fields: tuple) -> np.ndarray:
    """(V,) bool: the vertices whose ball cannot hold a fit against its noise (their coefficients made NaN).

    ``reach = (vertices, start, radii, referenced, facing)``; ``fields = (six, fitted, coefficients)``, changed in
    place. At each fitted vertex the spread of its jet's shape operator under the noise of its ball's points
    (``sigmas``, :func:`_noise_sigmas`; :func:`_noise_spreads`, :data:`meshcurv.jets.DEGREE`: a fit of lower degree over
    the same ball spreads less) is held to :data:`JET_NOISE_REACH` of ``curvatures`` (:func:`_curvature_scales`):
    beyond it the vertex takes a quadric's fit over the same ball (:data:`STEADY_DEGREE`) if that one's spread is
    within :data:`NOISE_REACH` of them, else is NaN with ``valid=False``. Called at a given radius only: the
    default one grows with the noise (:func:`meshcurv.radius.jet_vertex_radii`), and on the coarsest clean
    ellipsoid of ``benchmarks/accuracy.py --quick`` (levels of its fits' bias up to 0.02) the swap doubled the
    median H error (1.9% -> 3.6%). A ball of few points (a given radius of an edge length or two)
    lets every fit follow the noise, the quadric as well as the jet, so that the two agree and the check of
    :func:`_steady_fits` passes them (issue 29: faces detached by 0.08 edge lengths, H off by up to 1.65 on a
    unit sphere at a radius of one edge length)."""
    vertices, start, radii, referenced, facing = reach
    six, fitted, coefficients = fields
    unsure = np.zeros(vertices.shape[0], dtype=bool)
    rows = np.flatnonzero(np.isfinite(coefficients).all(axis=1) & referenced)
    if rows.size == 0 or not (sigmas > 0).any():
        return unsure
    unit = radii[rows]
    ball = (vertices, fitted, referenced)
    high = _noise_spreads(ball, rows, unit, sigmas, DEGREE)
    loose = high > JET_NOISE_REACH * curvatures[rows]
    rows, unit = rows[loose], unit[loose]
    if rows.size == 0:
        return unsure
    low = _noise_spreads(ball, rows, unit, sigmas, STEADY_DEGREE)
    steady = low <= NOISE_REACH * curvatures[rows]
    unsure[rows[~steady]] = True
    rows, unit = rows[steady], unit[steady]
    if rows.size:
        found, frame, _ = _fit_jets(
            vertices,
            start,
            unit,
            degree=STEADY_DEGREE,
            centres=rows,
            neighbours=referenced,
            facing=facing,
            min_spread=STEADY_MIN_SPREAD,
        )
        six[rows], fitted[rows] = shape_operators(found[rows], tuple(axis[rows] for axis in frame), unit)
        coefficients[rows] = found[rows]
    coefficients[unsure] = np.nan
    return unsure
