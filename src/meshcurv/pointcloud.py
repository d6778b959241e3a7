"""Principal curvatures of point clouds, without a mesh.

:func:`point_cloud_curvatures` gives, at every point, the principal curvatures
``k_min <= k_max`` (1/length), their directions, the normal and a ``valid``
mask, in the same :class:`~meshcurv.result.CurvatureResult` as
:func:`meshcurv.principal_curvatures`, with the same sign convention:
curvatures are positive where the surface bends away from the normal (points
sampled on a sphere of radius ``r`` with outward normals give ``+1/r``).

Pipeline (all vectorised, neighbours from :class:`scipy.spatial.cKDTree`
queries in chunks, or, for the balls of the measures with the compiled
backend, from a grid of the ball's radius; no O(N^2) memory):

1. checks: shape, NaN, at least :data:`MIN_POINTS` points, not all on a line;
   duplicate points, and near copies (a point's nearest neighbours closer than
   :data:`COPY_GAP` times the distance to the next one: round-off), are
   computed once and copied; so are copies a registration error apart (merged
   scans, overlapping tiles: a cloud where many points jump from their nearest
   neighbours to the next by :data:`REGISTRATION_JUMP`; see
   :func:`_registration_gap`), each group measured at its centroid, so that
   the spacing is never read between the copies of one point; points whose neighbours are
   all far (outliers) stay out of every neighbourhood and are NaN; the
   distinct points are taken in Morton (Z-curve) order, so that neighbours
   are near in memory (the results do not depend on the input's order);
2. the local spacing ``s_i`` (:func:`meshcurv._pointcloud_normals.local_spacing`,
   the analogue of a mesh's edge length) and its median ``s``;
3. normals: the given ones (made unit), or PCA of the 10 nearest neighbours;
   oriented consistently along a minimum spanning tree of the neighbour graph
   (Hoppe et al. 1992) unless the given ones already are, and, when estimated,
   outward on each part: the sign passes along edges of one sheet, and
   reversed across a gap between two sheets (two parts a spacing or two
   apart, the faces of a thin part), never along other edges
   (:func:`meshcurv._pointcloud_normals.oriented_signs`); then each point's
   side is checked against the generalized winding number of the oriented
   cloud (Barill et al. 2018: 1/2 on a surface whose side agrees with the
   whole cloud's; :func:`meshcurv._pointcloud_normals.winding_sides`): a part
   left inside out is turned, the wall of a cavity (a closed part inside
   another) faces into the cavity, as for meshes; two stacked sheets whose
   normals face each other across a part (the faces of a thin part turned
   together: the winding number between them about -1) are turned
   (:func:`meshcurv._pointcloud_normals.between_sides`); points where two
   sheets closer than the spacing cannot be told apart (and every point of a
   part where they mix over :data:`THIN_PART_SHARE` of it), whose side
   turning does not settle, or, after the estimate, whose normals point the
   same way as a sheet stacked on theirs
   (:func:`meshcurv._pointcloud_normals.two_sheets`: one of the two is inside
   out, and nothing local tells which) are NaN (``invalid_reason``: side
   undecided), and so are the points amid them (a quarter of their 24 nearest
   neighbours, or half of their part: a part thinner than its noise, whose
   faces mix); given normals are re-oriented only where their signs are not
   consistent, and keep their side where it is undecided;
4. the noise level ``nu``: the median distance of the points to degree-2 jets
   fitted over :data:`meshcurv.radius.CLOUD_NOISE_FIT_RADIUS` spacings, in spacings
   (a ball holding the other side of the surface is not fitted: through both
   faces of a thin part a jet would read half its thickness as noise);
5. the radius: ``s (a + b sqrt(max(nu - 0.005, 0)))``, ``(a, b)`` = (3, 11)
   for ``corrected_measures`` and (3, 22) for ``jets``
   (:data:`meshcurv.radius.CLOUD_RADIUS_RULES`, from a sweep of ``benchmarks/pointcloud.py``: three
   spacings on clean samples, about 4.3 and 5.9 under noise of 0.05 and 0.2
   spacings for the measures; jets need larger balls under noise); when the
   density varies by more than a factor 2 across the cloud, each class of
   local spacing (powers of two) gets its own radius, with ``nu`` in its own
   spacings where it is denser than the median (the noise is a length);
6. the estimator (``method``):

   - ``"corrected_measures"`` (default): randomized corrected curvature
     measures (Lachaud, Coeurjolly, Labart, Romon, Thibert 2023): 32 random
     triangles among the points of the ball, their interpolated corrected
     measures with the point normals (:func:`meshcurv.measures.face_measures`)
     summed, ``H = mu_1 / 2 mu_0``, ``K = mu_2 / mu_0``; the normals, when
     not given, are those of degree-3 jets (one fit, in the frame of the PCA
     normal) over ``s (4 + 55 sqrt(max(nu - 0.005, 0)))``, or over the largest smaller ball (down to ``4 s``, steps
     of ``sqrt(2)``) that holds one side of the surface only (no more than
     5% of its points with normals facing away): a part thinner than the ball
     (a flat ellipsoid's two faces, a thin tube) or a rim sharper than it is
     fitted on its own side. The default because its error is the lowest under noise
     (``benchmarks/pointcloud.md``: noise 0.2 spacings on the ellipsoid, H
     1.8% against 7% for jets) and below 1% on clean samples;
   - ``"jets"``: weighted degree-3 jets over the ball, refitted in the frame
     of their own normal (Cazals and Pouget 2005), curvatures from the jet's
     second fundamental form (:func:`meshcurv.jets.shape_operators`);
     a ball that holds the other side of the surface (the default radius or
     a given one) shrinks as the normal fits' do, down to ``3 s``, and is NaN
     (``invalid_reason``: every ball held the other side) below, or where it
     shrank to half the radius the noise calls for or less (the fit follows
     the noise);
     the lowest error on clean samples (ellipsoid H 0.2%) and the fastest.

7. the check: an estimate that the same estimator over balls sqrt(2)
   times larger does not reproduce (a principal curvature off by more than
   0.4 of the smaller |k|), or that its nearest neighbours' estimates do not
   (by more than 0.3 of |k|, median), is NaN (``invalid_reason``: unsteady
   estimate): a rim or part sharper than the ball, the other side of a thin
   part, or noise the fit follows
   (:func:`meshcurv._pointcloud_estimators.unsteady`,
   :func:`meshcurv._pointcloud_estimators.erratic`); so is a measure whose
   ball turns the normal by more than 0.3 rad that jets over the same balls do
   not reproduce, or by more than 0.1 rad where no jet fits one side of the
   surface (a part thinner than the ball, by whose rim the curvature grows a
   hundredfold within it: :func:`meshcurv._pointcloud_estimators.turned`), a
   measure that the
   curvatures of its normals' jets do not reproduce where those jets resolve
   the surface (:func:`meshcurv._pointcloud_estimators.disagree`), and an
   estimate over a given radius below half the one the noise calls for. A
   given radius that cannot hold the 10 nearest points (``sqrt(10 / pi)``
   spacings) leaves the estimate undefined
   (:func:`meshcurv._pointcloud_estimators.small_balls`). An estimate whose
   ball turns the normal by more than 0.8 rad and whose ball's normals its
   own shape operator does not predict is NaN too
   (:func:`meshcurv._pointcloud_estimators.blended`: the band by the rim of a
   thin part, a ball larger than a small part), and so is a jet whose ball
   turns the normal by more than 1.6 rad on average over the directions
   (``radius |H|``: a ball about as large as the radius of curvature, where
   a degree-3 jet's H is off by 0.3 of |k| or more;
   :func:`meshcurv._pointcloud_estimators.wide_jets`), and an estimate none of
   whose 10 nearest neighbours has a resolved one
   (:func:`meshcurv._pointcloud_estimators.alone`). Clean samples keep every
   point (``benchmarks/pointcloud.md``).

References
----------
G. Barill, N. G. Dickson, R. Schmidt, D. I. W. Levin, A. Jacobson (2018).
Fast winding numbers for soups and clouds. ACM Transactions on Graphics
37(4), 43. https://doi.org/10.1145/3197517.3201337

F. Cazals and M. Pouget (2005). Estimating differential quantities using
polynomial fitting of osculating jets. Computer Aided Geometric Design 22(2),
121-146. https://doi.org/10.1016/j.cagd.2004.09.004

H. Hoppe, T. DeRose, T. Duchamp, J. McDonald, W. Stuetzle (1992). Surface
reconstruction from unorganized points. SIGGRAPH '92, 71-78.
https://doi.org/10.1145/133994.134011

J.-O. Lachaud, D. Coeurjolly, C. Labart, P. Romon, B. Thibert (2023).
Lightweight curvature estimation on point clouds with randomized corrected
curvature measures. Computer Graphics Forum 42(5), e14910.
https://doi.org/10.1111/cgf.14910
"""

from __future__ import annotations

import logging
import warnings
from typing import NamedTuple

import numpy as np

from . import _pointcloud_estimators as _estimators
from . import _pointcloud_normals as _normals
from ._adapters import point_array
from ._backend import kernel_threads, numba_kernels
from ._validation import MIN_COORDINATE, as_vertices, check_choice, check_positive_float
from .errors import InvalidMeshError, InvalidOptionError, MeshQualityWarning
from .radius import (
    CLOUD_EXTENT_CAP,
    CLOUD_RADIUS_RULES,
    EXTENT_FACTOR,
    _checked_radii,
    _notes_by_radius,
    _cloud_noise_level,
    _intrinsic_sample,
    cloud_radius,
    noise_rule,
    rigid_extent,
)
from .result import INVALID_REASONS, CurvatureResult

__all__ = ["point_cloud_curvatures", "multiscale_point_cloud_curvatures", "POINT_CLOUD_METHODS", "MIN_POINTS"]

logger = logging.getLogger(__name__)

#: The estimators of :func:`point_cloud_curvatures`; the first is the default.
POINT_CLOUD_METHODS = ("corrected_measures", "jets")

#: Fewest points accepted.
MIN_POINTS = 10

#: A point whose local spacing exceeds this many times the median is an outlier.
OUTLIER_FACTOR = 10.0

#: The density counts as uneven (and each class of spacing gets its own radius) when the 95th
#: percentile of the (neighbour-averaged) local spacing exceeds this many times the 5th.
UNEVEN_DENSITY = 2.0

#: A part of the cloud whose points are this share or more beside a sheet stacked on theirs with normals the same
#: way (:func:`meshcurv._pointcloud_normals.two_sheets`, alike: one of the two is inside out) cannot be told apart
#: from its other face anywhere: every point's side is undecided (a plate 1 x 1 x 0.02 at 400 points: 89%; the
#: clean 3 x 3 x 0.15 ellipsoid at 8,000 points, inward by its rim: 18%).
ALIKE_PART_SHARE = 0.5

#: A part at least :data:`THIN_PART_SHARE` of whose points are undecided (two sheets, alike, amid undecided ones)
#: and whose oriented normals sum to at least this share of its area (``|sum a n| / sum a``, ``a`` the squared local
#: spacing; 0 on a closed part, whichever way it is oriented, 1 on a flat open sheet) is a closed part thinner than
#: the spacing whose two faces were oriented as one sheet: every point's side is undecided. Seed 162 case 305 of
#: ``benchmarks/fuzz_api.py`` (a 1 x 1 x 0.02 disc of 400 points under noise of 0.05 spacings: 33% undecided, 121
#: of its 240 checked valid points inward) and four discs under noise of 0.1 spacings sum to 0.998-1.0 with 33-47%
#: undecided; a clean 3 x 3 x 0.15 ellipsoid of 8,000 points (44% undecided, its rim) to 0.13, a 1 x 1 x 0.2 one
#: to 0.04.
ONE_SHEET_FLUX = 0.5

#: Points whose local spacing is at most this are left out (NaN): the estimators form products of up to four
#: lengths of the order of the spacing (squared areas of triangles; the cubed distances of the winding number,
#: which read 0 below about 1e-103 and gave 0 / 0), which underflow float64's smallest normal number (2.2e-308)
#: below about 1e-77; ten times :data:`meshcurv._validation.MIN_COORDINATE`, so that the points kept have a
#: coordinate above it (the ball checks refuse a cloud without one). A part of a cloud at 1e-100 beside a part
#: at 1 cannot be measured in float64; a cloud all at 1e-200 is refused as for meshes.
MIN_SPACING = 10.0 * MIN_COORDINATE

#: Bits per coordinate of the Morton code that orders the points (3 x 21 bits fill 63 of a uint64).
MORTON_BITS = 21

#: Near copies: a point's nearest neighbours closer than this times the distance to the next one are copies of
#: it (merged scans, overlapping tiles: the same points with round-off differences), merged as duplicates are.
#: Random samples have such a gap at about one point in 10^6 (the chance scales as its square): merging those
#: moves a point by 1e-3 spacings at most.
COPY_GAP = 1e-3

#: A point whose :data:`~meshcurv._pointcloud_normals.NEIGHBOURS` nearest neighbours all lie within this share
#: of the cloud's size-for-its-count (bounding-box diagonal over sqrt(N)) may have more copies than that: its
#: nearest :data:`COPY_NEIGHBOURS` are searched for the gap.
COPY_SUSPECT = 1e-2

#: When near copies are merged, the neighbours of the points kept are those found before (searched again where one
#: of them went) unless more than this share of the points went (then all are searched again).
KEPT_SEARCH_SHARE = 0.1

#: The nearest neighbours of a cloud of this many points or more are searched on a grid (:func:`_knn`) whose
#: reach is this factor times the distance to the next after the nearest ones at this quantile of a sample of
#: the points (a reach of about 1.4 times the median: 0.1% of the rows of a uniform sample left to the k-d tree).
KNN_GRID_POINTS = 65536
KNN_REACH_FACTOR = 1.2
KNN_REACH_SHARE = 0.95
KNN_SAMPLE = 4096

#: Most copies of one point found (see :data:`COPY_SUSPECT`).
COPY_NEIGHBOURS = 64

#: Copies a registration error apart (merged scans, overlapping tiles: each point several times, the copies a
#: few thousandths to a tenth of a spacing apart, far above round-off; :func:`_registration_gap`): a point's
#: nearest neighbours, before a jump of at least this factor to the next distance, are its copies...
REGISTRATION_JUMP = 4.0
#: ...when at least this share of a sample of the points shows such a jump. A random sample of a surface shows
#: it at about 1 / REGISTRATION_JUMP^2 of its points (the squared ratio of the nearest two distances is uniform
#: on a plane: 6.3-7% measured from 400 to 200,000 points), a cloud of copies at most of its points; a cloud
#: of which a part was copied (two overlapping tiles) at about twice the part's share.
REGISTRATION_SHARE = 0.15
#: The points of a cloud of copies closer than this times the 90th percentile of the copies' spread (the
#: largest distance before the jump) are merged, up to :data:`REGISTRATION_CAP` times the median distance
#: beyond the jump (the spacing of the distinct points): what is merged stays well inside one spacing.
REGISTRATION_SPREAD = 2.0
REGISTRATION_CAP = 0.25
#: Points along curves (a line, scan lines, fibres) jump too (on a line, about a third of them by 4): a sample
#: whose groups before the jump hold fewer than this many points, and whose distances grow from the middle of
#: the row to its end by more than this factor (sqrt 2 on a surface, 2 along a curve), is no cloud of copies.
#: (Groups of more copies are copies: a curve's jumps are after its first neighbour or two.)
REGISTRATION_CURVE_GROUP = 8
REGISTRATION_CURVE_GROWTH = 1.7
#: Points of the sample searched for the jump, and the distances looked at from each.
REGISTRATION_SAMPLE = 2048

#: A part of the cloud whose points are this share or more between two sheets closer than the spacing
#: (:func:`meshcurv._pointcloud_normals.two_sheets`) is thinner than the spacing: every point's side is undecided.
THIN_PART_SHARE = 0.25

#: A group of points with a radius of its own (a class of density, a scan line) whose box, grown by the reach of
#: its balls, holds at most this share of the cloud is computed on those points only (no search structure, no
#: output over the whole cloud: at 1M points a group of one point cost about 0.6 CPU s).
LOCAL_SHARE = 0.5

#: A point with at least this share of its :data:`AMID_NEIGHBOURS` nearest neighbours on an undecided side
#: (:func:`_amid_undecided`) is undecided too: a region, not a point or two (seed 4242 case 200 of
#: ``benchmarks/fuzz_api.py``, a plate 0.04 thick under noise of 0.055: its valid points had 0.17-0.62 of their 24
#: nearest undecided, the inward ones 0.25 or more; the clouds of ``benchmarks/pointcloud.py`` have 0-0.2% of
#: their points undecided, apart).
AMID_UNDECIDED = 0.25
AMID_NEIGHBOURS = 24

#: Code of :data:`meshcurv.result.INVALID_REASONS` for points without an estimate.
_UNDEFINED = len(INVALID_REASONS) - 1


def _reason_code(start: str) -> int:
    """The code of the reason that starts with ``start`` (the last one, undefined, if there is none)."""
    return next((code for code, text in enumerate(INVALID_REASONS) if text.startswith(start)), _UNDEFINED)


#: Share of :data:`meshcurv.neighborhoods.MAX_BALL_PAIRS` that the balls of one default fit may take: a default
#: radius whose balls would hold more (noise calls for balls of tens of spacings: a million points under noise
#: of a third of a spacing, or a thin plate whose two faces both fall in each ball) is cut to fit, with a warning.
BALL_PAIRS_SHARE = 0.5

#: Noise level (in spacings of the point's class of density, :func:`_class_noise`, of
#: :func:`meshcurv.radius.cloud_noise_level`) from which a point whose one-sided normal fit (``corrected_measures``)
#: took a ball of at most :data:`NOISY_SHRINK` times the radius asked for (two of the fits' shrinking steps, within
#: :data:`SHRINK_ROUNDING`), or none (then its PCA normal is kept below this level: right at a sharp rim), is NaN:
#: the noise dominates such a fit. The jets' own fits are held to :data:`NOISY_SHRINK` times the radius the noise
#: calls for at any level (below it a given radius is unsteady too, ``_pointcloud_estimators.SMALL_BALL``): the band
#: of a thin part under noise whose balls shrank off its other face (``benchmarks/pointcloud.md``, "a denser class
#: under the cloud's noise").
#: A plate 4 spacings thick under uniform noise of 1 (0.3) spacing measures 0.29 (0.15): before, 0.3% (7%) of
#: its points were valid with H off by 100 times (3 times) its value. The clouds of ``benchmarks/pointcloud.py``
#: under noise of 0.2 spacings measure about 0.08.
NOISY_PCA = 0.1

#: See :data:`NOISY_PCA`.
NOISY_SHRINK = 0.5

#: On a staircase (a voxel surface read as a cloud), under a given radius below the default one, an estimate of
#: ``corrected_measures`` whose normal fit shrank (its ball held the other side) and turns the normal by less than
#: this many radians over the fit's ball (``radius |k|``) is unsteady: the other face of a thin part shrank it, and
#: the normals carry the steps' error of the smaller fits, which the default radius averages out and a smaller one
#: does not. A small part's fits shrink for its far side and turn the normal by about a radian; there the curvature
#: dominates that error (``tests/test_pointcloud_staircase_regions.py``).
STAIRCASE_FIT_TURN = 0.75

#: Relative round-off of a radius shrunk in steps (``SHRINK ** 2`` is ``0.5000000000000001``): a fit two steps down
#: is :data:`NOISY_SHRINK` times the radius asked for.
SHRINK_ROUNDING = 1e-9

#: Code of points whose normal's side could not be decided (between two sheets closer than the spacing).
_UNDECIDED = _reason_code("point cloud: side undecided")

#: Code of points whose every ball held the other side of a thin part.
_TWO_SIDED = _reason_code("point cloud: every ball held")

#: Code of points on a line with no surface around them.
_ON_A_LINE = _reason_code("point cloud: on a line")

#: Code of points whose estimate a larger ball, or their neighbours' estimates, do not reproduce.
_UNSTEADY = _reason_code("point cloud: unsteady estimate")


def point_cloud_curvatures(
    points, faces=None, /, *, normals=None, radius=None, method: str | None = None
) -> CurvatureResult:
    """Principal curvatures, directions and normals at every point of a point cloud.

    Parameters
    ----------
    points : array_like of shape (N, 3)
        Samples of a surface (N >= 10), not all on one line.
    faces : None
        Not accepted: a point cloud has no faces. A second argument (a mesh's
        ``faces``) raises, pointing to :func:`meshcurv.principal_curvatures`.
    normals : array_like of shape (N, 3), optional
        Normals at the points, of any length (not zero) and any signs. Used
        when given: made unit; if their signs are not consistent they are
        oriented along a minimum spanning tree of the neighbour graph, each
        connected part keeping the side most of its given normals point to
        (the two sides of a part thinner than the neighbourhood, whose normals
        point back to back, are not joined, so that both keep their sides).
        The curvature signs follow them. Default: estimated (PCA of the 10
        nearest neighbours), oriented consistently and outward on closed
        shapes (into the cavity on the wall of a cavity: a closed part
        inside another).
    radius : float, optional
        Radius of the Euclidean ball of each estimate, in the units of the
        points. Default: from the data, ``s (3 + 11 sqrt(max(nu - 0.005, 0)))``
        (``jets``: ``s (3 + 22 sqrt(...))``) with ``s`` the median local
        spacing and ``nu`` the noise level in spacings (see the module doc);
        per class of density when it varies by more than a factor 2.
    method : {"corrected_measures", "jets"}, default: "corrected_measures"
        ``"corrected_measures"``: randomized corrected curvature measures
        (Lachaud et al. 2023). ``"jets"``: osculating jets of degree 3
        (Cazals and Pouget 2005).

    Returns
    -------
    CurvatureResult
        ``k_min, k_max, dir_min, dir_max, normals, valid`` per point and
        ``invalid_reason``; ``parameters`` holds ``radius`` (and ``radii`` per
        density class), ``spacing``, ``noise``, ``normal_radius`` (measures
        with estimated normals), ``shrunk`` (the share of points whose jet
        fit, of the normals or of ``"jets"``, took a smaller ball than asked
        for because the ball held the other side of a thin part) and
        ``normals`` (``"given"``, ``"given, reoriented"`` or ``"estimated"``). ``normals`` are those
        the curvatures refer to: the fitted jets' (``"jets"``), or the
        oriented ones used by the measures (``"corrected_measures"``).

    Raises
    ------
    InvalidMeshError
        ``points`` or ``normals`` of the wrong shape, NaN or infinite values,
        fewer than :data:`MIN_POINTS` distinct points, all points on a line,
        zero normals.
    InvalidOptionError
        Unknown ``method``, ``radius`` not a positive number or larger than
        the cloud, ``faces`` given.

    Warns
    -----
    MeshQualityWarning
        Once per call, listing what was found and done: duplicate points
        (computed once, copied), outliers (NaN), very uneven density (one
        radius per class of density), points without an estimate; points
        that look like a mesh's faces (integer rows of three distinct indices).

    Examples
    --------
    >>> import numpy as np
    >>> from meshcurv.pointcloud import point_cloud_curvatures
    >>> rng = np.random.default_rng(0)
    >>> p = rng.normal(size=(5000, 3))
    >>> p = 2.0 * p / np.linalg.norm(p, axis=1, keepdims=True)    # sphere of radius 2
    >>> r = point_cloud_curvatures(p)
    >>> print(f"{np.median(r.mean):.3f}", r.parameters["normals"])
    0.500 estimated
    """
    cloud = _prepared_cloud(points, faces, normals, method)
    if radius is not None:
        radius = _checked_cloud_radius(radius, cloud.points)
    result, problems = _estimated(cloud, radius, reused=False)
    if problems:
        warnings.warn("point cloud: " + "; ".join(problems), MeshQualityWarning, stacklevel=2)
    return result


def multiscale_point_cloud_curvatures(
    points, radii, *, normals=None, method: str | None = None
) -> list[CurvatureResult]:
    """Curvatures of a point cloud at several scales: one :class:`CurvatureResult` per radius.

    Each result equals ``point_cloud_curvatures(points, normals=normals,
    radius=r, method=method)``; the points are checked, their duplicates and
    near copies merged, and their nearest neighbours searched once for all
    radii (the normals, their orientation and the noise level are computed
    again at each radius, as the single call does: the line-scan search of a
    radius depends on it).

    Parameters
    ----------
    points
        As for :func:`point_cloud_curvatures`.
    radii : sequence of float
        The ball radii, in the units of the points (positive, not larger than
        the cloud; any order).
    normals, method
        As for :func:`point_cloud_curvatures`.

    Returns
    -------
    list of CurvatureResult
        One per radius, in the order of ``radii``.

    Raises
    ------
    InvalidMeshError
        As :func:`point_cloud_curvatures`.
    InvalidOptionError
        No radius, a radius that is not a positive finite number or is larger
        than the cloud, an unknown ``method``.

    Warns
    -----
    MeshQualityWarning
        Once per call, as :func:`point_cloud_curvatures` (the notes of each
        radius that differ are named with it).

    Examples
    --------
    >>> import numpy as np
    >>> from meshcurv.pointcloud import multiscale_point_cloud_curvatures
    >>> rng = np.random.default_rng(0)
    >>> p = rng.normal(size=(5000, 3))
    >>> p = 2.0 * p / np.linalg.norm(p, axis=1, keepdims=True)    # sphere of radius 2
    >>> fine, coarse = multiscale_point_cloud_curvatures(p, [0.4, 0.8])
    >>> print(f"{np.median(fine.mean):.2f} {np.median(coarse.mean):.2f}")
    0.50 0.50
    """
    radii = _checked_radii(radii)
    cloud = _prepared_cloud(points, None, normals, method)
    size = rigid_extent(cloud.points)  # (once for every radius: 70 ms of CPU at 1M points)
    radii = [_checked_cloud_radius(radius, cloud.points, name="radii", size=size) for radius in radii]
    results, notes = [], {}
    for radius in radii:
        result, problems = _estimated(cloud, radius)
        results.append(result)
        notes[radius] = "; ".join(problems)
    message = _notes_by_radius(notes)
    if message:
        warnings.warn("point cloud: " + message, MeshQualityWarning, stacklevel=2)
    return results


class _Cloud(NamedTuple):
    """The checked, merged points of a call, before any radius (:func:`_prepared_cloud`)."""

    #: The distinct points (duplicates and near copies merged), in Morton order.
    points: np.ndarray
    #: Their given normals (None: estimated).
    given: np.ndarray | None
    method: str
    #: (N_all,) the row of ``points`` each input point takes its values from.
    take: np.ndarray
    #: ``(tree, distances, indices)`` of ``points``, or None (searched by :func:`_compute`).
    search: tuple | None
    #: What was found and done so far, for the call's warning.
    problems: list


def _prepared_cloud(points, faces, normals, method) -> _Cloud:
    """Check the input, merge duplicates and near copies, search the nearest neighbours: what every radius shares."""
    logger.info("point cloud: checks, duplicates and near copies")
    if faces is not None:
        raise InvalidOptionError(
            "point_cloud_curvatures takes the points only, not a mesh's `faces` (a second argument was given): "
            "for a mesh call meshcurv.principal_curvatures(vertices, faces); for its vertices as a cloud, "
            "point_cloud_curvatures(vertices)"
        )
    method = POINT_CLOUD_METHODS[0] if method is None else check_choice(method, "method", POINT_CLOUD_METHODS)
    points = point_array(points)
    hint = _looks_like_faces(points)
    points = as_vertices(points, name="points")
    given = None if normals is None else _checked_normals(normals, points.shape)
    n_all = points.shape[0]
    if n_all < MIN_POINTS:
        raise InvalidMeshError(f"`points` holds {n_all} points; at least {MIN_POINTS} are needed")
    problems: list[str] = [hint] if hint else []

    # duplicates: computed once on the first of each group of coincident points, copied to the others;
    # the distinct points in Morton order (neighbours near in memory: the searches and fits run from cache)
    order, representative = _spatial_order(points)
    unique = order[representative[order] == order]
    n_exact = n_all - unique.size
    search = None
    registration, centres = 0.0, None
    distinct = points[unique]  # (gathered once: the near copies' search, the kept points' and the cloud's)
    # (from here on centred on one of the distinct points' coordinates: exact far from the origin; the Morton
    # order and the duplicates above read differences and equalities of the given coordinates, exact too)
    anchor = _centre(distinct)
    if unique.size >= MIN_POINTS:
        # near copies (round-off differences, registration errors) are merged into the first of them in the
        # Morton order, each group measured at its centroid: the first's position is the pose's choice (the pose
        # orders the points), and a copy 1e-3 spacings from it moved the balls of its neighbours (fuzz_api 550/60:
        # two copies 2.8e-5 apart, turned: k 1.2e-4 of the largest |k| apart at 46 points); registration errors
        # are averaged out
        copy_of, search, registration = _near_copies(distinct)
        keep = copy_of == np.arange(unique.size)
        if not keep.all():
            group = np.cumsum(keep)[copy_of] - 1
            sizes = np.bincount(group)
            sums = np.stack([np.bincount(group, weights=distinct[:, axis]) for axis in range(3)], axis=1)
            centres = sums / sizes[:, None]
            representative = unique[copy_of][_position(unique, n_all)[representative]]
            unique, distinct = unique[keep], distinct[keep]
            search = None if registration else _kept_search(centres, keep, search[1], search[2], moved=sizes > 1)
    if unique.size < n_all:
        near = n_all - unique.size - n_exact
        found = [f"{n_exact} points coincide with others (duplicates)"] if n_exact else []
        if near and registration:
            found.append(
                f"{near} points are copies of others a registration error apart (within {registration:.2g} of "
                "the spacing of the distinct points: merged scans or overlapping tiles)"
            )
        elif near:
            found.append(
                f"{near} points are near copies of others (closer to one than {COPY_GAP:g} times the distance "
                "to their next neighbour: round-off differences)"
            )
        problems.append(" and ".join(found) + ": merged, each computed once and its values copied")
    if unique.size < MIN_POINTS:
        raise InvalidMeshError(f"`points` holds {unique.size} distinct points; at least {MIN_POINTS} are needed")
    cloud = distinct if centres is None else centres
    _check_spread(cloud, anchor)
    take = _position(unique, n_all)[representative]
    merged = None if given is None else _merged_normals(given, unique, take)
    return _Cloud(cloud, merged, method, take, search, problems)


def _centre(points: np.ndarray) -> np.ndarray:
    """(3,) the point ``points`` (N, 3) are moved by, in place: one of their own coordinates along each axis (the
    lower median: an input value, the same in every order of the points; of the distinct points, so that
    duplicates move nothing); zero where that could overflow.

    Everything after computes in these coordinates, and they are exact for a cloud far from the origin: a
    cloud moved by 2^20 sizes and its input brought back (``moved - shift``, exact) are moved to the same
    points to the last bit (Sterbenz: two coordinates within a factor 2 of each other subtract exactly; near
    the origin both are multiples of the far cloud's last bit), so that they give the same results. Sums in
    absolute coordinates rounded at the far cloud's magnitude (fuzz_api 574/56: the centroid of 5 near copies
    of a point at -2^20 sizes, k by 1.05e-6 of the largest |k|). The median, not a corner of the bounding
    box: a far outlier would round the bulk to its magnitude.
    """
    # (every coordinate within [low, high], of all axes: no difference overflows when that range is finite; two
    # flat reductions, not three strided ones per axis: 1M points 2 ms instead of 38)
    high, low = float(points.max()), float(points.min())
    with np.errstate(over="ignore"):
        if not np.isfinite(high - low):
            return np.zeros(3)  # (a cloud across float64's range: refused or measured as given, as before)
    middle = (points.shape[0] - 1) // 2
    anchor = np.array([np.partition(points[:, axis], middle)[middle] for axis in range(3)])
    points -= anchor
    return anchor


def _merged_normals(given: np.ndarray, unique: np.ndarray, take: np.ndarray) -> np.ndarray:
    """(M, 3) the given unit normals ``given`` (N, 3) of the points merged into each kept point: their mean, each
    first turned to the side of the kept point's own (``given[unique]``), on the side most of them point to (a tie
    keeps the kept point's side).

    The kept point of a group is its first in the Morton order, which the pose chooses: copies whose given normals
    differ (two points of one scan merged as copies of one) took the normals of either (fuzz_api 522/117: three
    spheres in five registered copies, turned: normals 0.0046 apart at 20 points, k by 3.1e-4 of the largest
    |k| at 270). Their mean is the same in every pose and order.
    """
    m = unique.size
    own = given[unique]
    if take.size == m:
        return own
    sides = np.where(np.einsum("ij,ij->i", given, own[take]) < 0.0, -1.0, 1.0)
    sums = np.stack([np.bincount(take, weights=given[:, axis] * sides, minlength=m) for axis in range(3)], axis=1)
    # (each sum holds the kept point's own unit normal and others turned to its side: never zero)
    mean = sums / np.linalg.norm(sums, axis=1, keepdims=True)
    votes = np.bincount(take, weights=sides, minlength=m)
    return mean * np.where(votes < 0.0, -1.0, 1.0)[:, None]


def _checked_cloud_radius(radius, cloud: np.ndarray, *, name: str = "radius", size: float | None = None) -> float:
    """``radius`` a positive number no larger than the cloud's :func:`meshcurv.radius.rigid_extent` (``size``:
    that extent, when known)."""
    if isinstance(radius, str) and radius == "adaptive":
        raise InvalidOptionError(
            f"`{name}` 'adaptive' is for meshes (method 'icc'); a point cloud takes a length (or None: from the data)"
        )
    radius = check_positive_float(radius, name)
    if size is None:
        size = rigid_extent(cloud)
    if radius > size:
        raise InvalidOptionError(
            f"`{name}` {radius:g} is larger than the point cloud itself (bounding-box diagonal {size:g} of the cube "
            f"around its smallest enclosing ball, of radius {size / EXTENT_FACTOR:g}: the same in every pose): every "
            "ball would hold every point; pass a radius of a few point spacings, in the units of the points"
        )
    return radius


def _estimated(cloud: _Cloud, radius: float | None, *, reused: bool = True) -> tuple[CurvatureResult, list[str]]:
    """The estimate at ``radius`` (None: the default) for every input point, and the problems for the warning.

    ``reused``: ``cloud`` serves other radii after this one; else its neighbours are this call's own.
    """
    search = cloud.search
    if search is not None and reused:
        # (the pipeline re-points the neighbours of line points in place: each radius its own copy; a single call
        # skips it: 1M points' (N, 10) indices, 0.18 CPU s of page faults)
        search = (search[0], search[1], search[2].copy())
    k_min, k_max, dir_min, dir_max, out_normals, valid, reason, parameters, found = _compute(
        cloud.points, cloud.given, radius, cloud.method, search
    )
    problems = [*cloud.problems, *found]
    logger.info("point cloud: results")

    # back to all points: each duplicate takes its representative's values
    kernels = numba_kernels("pointcloud_graph")
    if kernels is not None:
        codes = np.asarray(reason, dtype=np.int8)
        k_min, k_max, dir_min, dir_max, out_normals, valid, reason = kernels.gathered_results(
            cloud.take, k_min, k_max, dir_min, dir_max, out_normals, valid, codes, _UNDEFINED
        )
    else:
        k_min, k_max, dir_min, dir_max, out_normals, valid, reason = _gathered_results(
            cloud.take, k_min, k_max, dir_min, dir_max, out_normals, valid, reason
        )
    n_invalid = int((~valid).sum())
    if n_invalid:
        problems.append(f"{n_invalid} points are NaN with valid=False")
    logger.info("point cloud: done")
    result = CurvatureResult._of_arrays(
        k_min=k_min,
        k_max=k_max,
        dir_min=dir_min,
        dir_max=dir_max,
        normals=out_normals,
        valid=valid,
        method=cloud.method,
        parameters=parameters,
        invalid_reason=reason,
    )
    return result, problems


def _gathered_results(take, k_min, k_max, dir_min, dir_max, normals, valid, reason):
    """The fields of the distinct points at the rows ``take`` (M,) (every input point's representative): a row
    is valid when ``valid`` and both curvatures are finite; an invalid row's curvatures and directions are NaN,
    its reason ``reason`` when above 0, else ``_UNDEFINED``. Compiled:
    :func:`meshcurv._kernels.pointcloud_graph.gathered_results`."""
    k_min, k_max, dir_min, dir_max, normals, valid, reason = (
        a[take] for a in (k_min, k_max, dir_min, dir_max, normals, valid, reason)
    )
    valid = valid & np.isfinite(k_min) & np.isfinite(k_max)
    for array in (k_min, k_max, dir_min, dir_max):
        array[~valid] = np.nan
    reason = np.where(valid, 0, np.where(reason > 0, reason, _UNDEFINED)).astype(np.int8)
    return k_min, k_max, dir_min, dir_max, normals, valid, reason


def _looks_like_faces(points) -> str:
    """The warning's phrase when ``points`` look like a mesh's faces: an integer array of rows of three distinct
    indices that use every index from 0 to the largest one, fewer than the rows (a closed mesh has about twice
    as many faces as vertices); "" otherwise. Integer coordinates of a scan or of voxels repeat a value within a
    row at many points."""
    array = np.asarray(points) if isinstance(points, (np.ndarray, list, tuple)) else None
    if array is None or not np.issubdtype(array.dtype, np.integer) or array.ndim != 2 or array.shape[1] != 3:
        return ""
    rows = array.shape[0]
    if rows < MIN_POINTS or array.min() < 0 or array.max() >= rows:
        return ""
    a, b, c = array[:, 0], array[:, 1], array[:, 2]
    if ((a == b) | (b == c) | (a == c)).any() or np.unique(array).size != int(array.max()) + 1:
        return ""
    return (
        f"`points` look like a mesh's faces (integer rows of three distinct indices 0..{int(array.max())}, each "
        "used): they are measured as coordinates; for a mesh call meshcurv.principal_curvatures(vertices, faces)"
    )


def _position(unique: np.ndarray, n: int) -> np.ndarray:
    """(n,) the row of each index of ``unique`` in it (0 elsewhere)."""
    position = np.zeros(n, dtype=np.int64)
    position[unique] = np.arange(unique.size)
    return position


def _near_copies(cloud: np.ndarray):
    """``(copy_of, search, registration)``: (M,) the point each point of ``cloud`` is a copy of (itself when none),
    ``(tree, distances, indices)`` of ``cloud`` (:func:`_kept_search` makes them those of the points kept), and
    the registration error merged, in spacings of the distinct points (0.0 when the cloud is no cloud of copies).

    Point ``j`` is a copy of ``i`` when it is among ``i``'s nearest neighbours before a gap:
    ``d_m <= COPY_GAP d_(m+1)`` for the ``m``-th and next distances (the largest such ``m``), or, in a cloud of
    copies a registration error apart (:func:`_registration_gap`), when it lies within that error. Groups of
    copies are the connected components of these pairs; each becomes its first point (measured at the group's
    centroid: :func:`_prepared_cloud`).
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    m = cloud.shape[0]
    tree = cKDTree(cloud)
    distances, indices = _knn(tree, cloud)
    rows, cols = _copy_pairs(np.arange(m), distances, indices)
    with np.errstate(over="ignore", invalid="ignore"):
        scale = float(np.linalg.norm(cloud.max(axis=0) - cloud.min(axis=0))) / np.sqrt(m)
    gap, spacing = _registration_gap(tree, cloud, distances)
    if gap > 0.0:
        # every pair within the error; a point whose every neighbour is within it may have more copies
        near = distances <= gap
        rows = np.concatenate([rows, np.repeat(np.arange(m), near.sum(axis=1))])
        cols = np.concatenate([cols, indices[near]])
        suspect = np.flatnonzero(near[:, -1])
    else:
        # points whose every neighbour is (nearly) there may have more copies: a wider search for the gap
        suspect = np.flatnonzero((distances[:, -1] < COPY_SUSPECT * scale) & ~np.isin(np.arange(m), rows))
    if suspect.size and distances.shape[1] < m - 1:
        k = min(COPY_NEIGHBOURS, m - 1)
        d, i = tree.query(cloud[suspect], k=k + 1)
        wide_d, wide_i = np.zeros((suspect.size, k)), np.zeros((suspect.size, k), dtype=np.int64)
        _drop_rows(suspect, d, i, k, wide_d, wide_i)
        if gap > 0.0:
            near = wide_d <= gap
            more_rows, more_cols = np.repeat(suspect, near.sum(axis=1)), wide_i[near]
        else:
            more_rows, more_cols = _copy_pairs(suspect, wide_d, wide_i)
        rows, cols = np.concatenate([rows, more_rows]), np.concatenate([cols, more_cols])
    registration = gap / spacing if gap > 0.0 else 0.0
    if rows.size == 0:
        return np.arange(m), (tree, distances, indices), registration
    graph = coo_matrix((np.ones(rows.size, dtype=np.int8), (rows, cols)), shape=(m, m))
    _, labels = connected_components(graph, directed=False)
    first = np.full(int(labels.max()) + 1, m, dtype=np.int64)
    np.minimum.at(first, labels, np.arange(m))
    return first[labels], (tree, distances, indices), registration


def _registration_gap(tree, cloud: np.ndarray, distances: np.ndarray) -> tuple[float, float]:
    """``(gap, spacing)``: the distance within which the points of a cloud of copies a registration error apart
    are copies of one point, and the spacing of its distinct points; ``(0.0, 0.0)`` for any other cloud.
    ``distances``: (M, k) the nearest neighbours' distances of each point of ``cloud`` (M, 3).

    On a sample of :data:`REGISTRATION_SAMPLE` points or more that the pose and the order of the points do not
    choose (:func:`meshcurv.radius._intrinsic_sample`, keyed by the spacing read from ``distances``: 5 registered
    copies of a 4,000-point cloud, turned, read a spacing 4e-4 apart when the sample was spread over the Morton
    order, and curvatures up to 0.016 of the largest apart), the :data:`COPY_NEIGHBOURS` nearest
    distances: the largest ratio of one to the next is the jump from a point's copies to the next point. When
    :data:`REGISTRATION_SHARE` of the sample or more jump by :data:`REGISTRATION_JUMP` or more, the gap is
    :data:`REGISTRATION_SPREAD` times the 90th percentile of the distances before the jump, at most
    :data:`REGISTRATION_CAP` times the median distance after it (the spacing returned); a gap below
    :data:`COPY_GAP` spacings is round-off, left to the merge by that gap. Points along curves are no copies
    (:data:`REGISTRATION_CURVE_GROWTH`).
    """
    m = cloud.shape[0]
    k = min(COPY_NEIGHBOURS, m - 1)
    if k < 4:
        return 0.0, 0.0
    sample = np.flatnonzero(_intrinsic_sample(cloud, _normals.local_spacing(distances), REGISTRATION_SAMPLE))
    d = tree.query(cloud[sample], k=k + 1, workers=-1)[0][:, 1:]
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        ratio = d[:, 1:] / d[:, :-1]
    ratio[~np.isfinite(ratio) | (d[:, :-1] <= MIN_SPACING)] = 1.0
    last = ratio.argmax(axis=1)
    jumped = ratio[np.arange(sample.size), last] >= REGISTRATION_JUMP
    if jumped.mean() < REGISTRATION_SHARE:
        return 0.0, 0.0
    rows = np.flatnonzero(jumped)
    with np.errstate(divide="ignore", invalid="ignore"):
        growth = float(np.median(d[:, -1] / d[:, k // 2 - 1]))
    if np.median(last[rows]) < REGISTRATION_CURVE_GROUP and not growth <= REGISTRATION_CURVE_GROWTH:
        return 0.0, 0.0  # points along curves (a line, scan lines): their gaps are no copies
    spread, beyond = d[rows, last[rows]], d[rows, last[rows] + 1]
    spacing = float(np.median(beyond))
    gap = min(REGISTRATION_SPREAD * float(np.quantile(spread, 0.9)), REGISTRATION_CAP * spacing)
    if not (np.isfinite(gap) and gap > COPY_GAP * spacing and spacing > 0.0):
        return 0.0, 0.0  # (copies within round-off: merged by the gap of COPY_GAP alone)
    return gap, spacing


def _knn(tree, cloud: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`meshcurv._pointcloud_normals.knn` of the distinct points ``cloud`` (M, 3), whose k-d tree is ``tree``.

    With the compiled kernels, on a grid (:func:`meshcurv._kernels.pointcloud.nearest_neighbours`, all cores)
    over a reach that holds the neighbours of :data:`KNN_REACH_SHARE` of a sample of the points (times
    :data:`KNN_REACH_FACTOR`); the rows it does not settle (fewer neighbours within the reach, or two at the
    same distance, whose order is the k-d tree's) are queried from ``tree``. The same arrays to the bit, in
    about a third of the k-d tree's CPU time. Both search one neighbour more: a group tied at the cut is
    taken or dropped whole (:func:`meshcurv._pointcloud_normals.whole_ties`).
    """
    kernels = numba_kernels("pointcloud")
    m = cloud.shape[0]
    k = min(_normals.NEIGHBOURS, m - 1)
    wide = min(k + 1, m - 1)
    if kernels is None or m < KNN_GRID_POINTS:
        return _normals.knn(tree, cloud)
    probe = cloud[np.linspace(0, m - 1, KNN_SAMPLE).astype(np.int64)]
    far = tree.query(probe, k=wide + 2, workers=-1)[0][:, -1]  # (the point itself, its neighbours and the next)
    reach = KNN_REACH_FACTOR * float(np.quantile(far, KNN_REACH_SHARE))
    if not (np.isfinite(reach) and reach > 0):
        return _normals.knn(tree, cloud)
    grid = numba_kernels("neighborhoods").pool_grid(cloud, np.arange(m), reach)
    distances, indices, exact = kernels.nearest_neighbours(cloud, wide, reach, *grid, 64 * kernel_threads())
    again = np.flatnonzero(~exact)
    if again.size:
        d, i = tree.query(cloud[again], k=wide + 1, workers=-1)
        _normals._drop_self(again, d, i, wide, distances, indices)
    return _normals.whole_ties(distances, indices, k)


def _kept_search(
    kept: np.ndarray, keep: np.ndarray, distances: np.ndarray, indices: np.ndarray, moved: np.ndarray | None = None
):
    """``(tree, distances, indices)`` of the points ``kept`` (M, 3), those of ``keep`` of a cloud whose neighbours
    were ``distances, indices`` (overwritten); or None when more than :data:`KEPT_SEARCH_SHARE` of its points went.

    A kept point whose nearest neighbours were all kept, and none of them ``moved`` ((M,) bool: kept points not
    where they were, the centroids of merged copies), has the same nearest neighbours among the kept points
    (:func:`_kept_rows`); the others are searched again.
    """
    from scipy.spatial import cKDTree

    if (~keep).mean() > KEPT_SEARCH_SHARE:
        return None
    tree = cKDTree(kept)
    kernels = numba_kernels("pointcloud")
    # a row with a tied group dropped at its cut (slots holding the point itself) may lose the tie with the point
    # that went: searched again too
    padded = (indices == np.arange(keep.size)[:, None]).any(axis=1)[keep]
    if kernels is not None:  # in place, in one pass (1M points: 0.4 CPU s of (M, k) copies in NumPy)
        m, again = kernels.kept_rows(distances, indices, keep)
        distances, indices, again = distances[:m], indices[:m], np.flatnonzero(again | padded)
    else:
        distances, indices, again = _kept_rows(distances, indices, keep)
        again = np.union1d(again, np.flatnonzero(padded))
    if moved is not None and moved.any():
        again = np.union1d(again, np.flatnonzero(moved | moved[indices].any(axis=1)))
    if again.size:
        k = distances.shape[1]
        wide = min(k + 1, kept.shape[0] - 1)
        d, i = tree.query(kept[again], k=wide + 1, workers=-1)
        found_distances, found_indices = np.zeros((again.size, wide)), np.zeros((again.size, wide), dtype=np.int64)
        _drop_rows(again, d, i, wide, found_distances, found_indices)
        distances[again], indices[again] = _normals.whole_ties(found_distances, found_indices, k, again)
    return tree, distances, indices


def _kept_rows(distances: np.ndarray, indices: np.ndarray, keep: np.ndarray):
    """``(distances, indices, again)``: the rows of the points ``keep`` (N,) of the nearest neighbours
    ``distances, indices`` (N, k), renumbered among the kept points, and the rows that held a point not kept
    (its index there that of the last kept point before it). Compiled:
    :func:`meshcurv._kernels.pointcloud.kept_rows`."""
    position = np.cumsum(keep) - 1
    distances, indices = distances[keep], indices[keep]
    again = np.flatnonzero((~keep[indices]).any(axis=1))
    return distances, position[indices], again


def _drop_rows(centres, d, i, k, distances, indices) -> None:
    """:func:`meshcurv._pointcloud_normals._drop_self` for the points ``centres`` (rows 0.. of the outputs)."""
    if (i[:, 0] == centres).all():  # distinct points: each is its own nearest
        distances[:], indices[:] = d[:, 1:], i[:, 1:]
        return
    own = i == centres[:, None]
    first = np.where(own.any(axis=1), own.argmax(axis=1), 0)
    keep = np.ones(d.shape, dtype=bool)
    keep[np.arange(centres.size), first] = False
    distances[:] = d[keep].reshape(-1, k)
    indices[:] = i[keep].reshape(-1, k)


def _copy_pairs(centres, distances, indices):
    """``(rows, cols)``: each centre and its neighbours before the last gap of :data:`COPY_GAP` in its row."""
    with np.errstate(invalid="ignore"):
        # the distances ascend along a row: a gap anywhere puts its first below COPY_GAP times its last
        maybe = np.flatnonzero(distances[:, 0] <= COPY_GAP * distances[:, -1])
        near = distances[maybe]
        gap = (near[:, :-1] <= COPY_GAP * near[:, 1:]) & (near[:, 1:] > MIN_SPACING)
    if not gap.any():
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    k = distances.shape[1]
    last = np.where(gap.any(axis=1), k - 2 - np.argmax(gap[:, ::-1], axis=1), -1)  # neighbours 0..last are copies
    before = np.arange(k)[None, :] <= last[:, None]
    return np.repeat(centres[maybe], before.sum(axis=1)), indices[maybe][before]


def _checked_normals(normals, shape) -> np.ndarray:
    """The given normals as unit float64 (N, 3) vectors."""
    array = as_vertices(normals, name="normals")
    if array.shape != shape:
        raise InvalidMeshError(f"`normals` must have the shape of `points` {shape}; got {array.shape}")
    length = np.linalg.norm(array, axis=1)
    zero = np.flatnonzero(~(length > 0))
    if zero.size:
        raise InvalidMeshError(f"`normals` has zero length at {zero.size} points (first at index {zero[0]})")
    return array / length[:, None]


def _spatial_order(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(N,) the points' order along a Morton (Z-order) curve and (N,) their representatives.

    The Morton code interleaves the bits of the coordinates quantized to
    :data:`MORTON_BITS` bits on the bounding cube: points close in the order
    are close in space. Coincident points share a code, so duplicates are
    looked for (:func:`_representatives`) only among the runs of equal codes.
    """
    n = points.shape[0]
    low = points.min(axis=0)
    with np.errstate(over="ignore"):
        extent = float((points.max(axis=0) - low).max())
        scale = (2.0**MORTON_BITS - 1) / extent if extent > 0 else 0.0
    if not (np.isfinite(extent) and np.isfinite(scale) and scale > 0):
        # a cloud beyond float64's range or of one point repeated: the input's order, every point compared
        return np.arange(n), _representatives(points)
    kernels = numba_kernels("pointcloud_graph")
    if kernels is not None:  # (the same codes and order: a stable order is unique)
        order, ordered = kernels.stable_order(kernels.morton_codes(points, low, scale, np.uint64(2**MORTON_BITS - 1)))
    else:
        code = _morton_codes(points, low, scale)
        order = np.argsort(code, kind="stable")
        ordered = code[order]
    same = ordered[1:] == ordered[:-1]
    representative = np.arange(n)
    if same.any():
        runs = np.zeros(n, dtype=bool)
        runs[1:] |= same
        runs[:-1] |= same
        subset = np.sort(order[runs])
        representative[subset] = subset[_representatives(points[subset])]
    return order, representative


def _morton_codes(points: np.ndarray, low: np.ndarray, scale: float) -> np.ndarray:
    """(N,) uint64 the Morton codes of ``points`` (N, 3): ``(points - low) * scale`` truncated to integers of
    :data:`MORTON_BITS` bits, their bits interleaved (x lowest). Compiled:
    :func:`meshcurv._kernels.pointcloud_graph.morton_codes`."""
    cells = np.minimum(((points - low) * scale).astype(np.uint64), np.uint64(2**MORTON_BITS - 1))
    code = np.zeros(points.shape[0], dtype=np.uint64)
    for axis in range(3):
        spread = cells[:, axis]
        # spread the 21 bits two apart (bit b goes to bit 3 b)
        for shift, mask in (
            (32, 0x1F00000000FFFF),
            (16, 0x1F0000FF0000FF),
            (8, 0x100F00F00F00F00F),
            (4, 0x10C30C30C30C30C3),
            (2, 0x1249249249249249),
        ):
            spread = (spread | (spread << np.uint64(shift))) & np.uint64(mask)
        code |= spread << np.uint64(axis)
    return code


def _representatives(points: np.ndarray) -> np.ndarray:
    """(N,) the index of the first point with the same coordinates as each point (itself when unique)."""
    order = np.lexsort(points.T[::-1])
    ordered = points[order]
    new = np.ones(points.shape[0], dtype=bool)
    new[1:] = (ordered[1:] != ordered[:-1]).any(axis=1)
    if new.all():
        return np.arange(points.shape[0])
    group = np.cumsum(new) - 1
    first = np.full(group[-1] + 1, points.shape[0], dtype=np.int64)
    np.minimum.at(first, group, order)
    out = np.empty(points.shape[0], dtype=np.int64)
    out[order] = first[group]
    return out


def _check_spread(cloud: np.ndarray, anchor: np.ndarray) -> None:
    """Refuse a cloud whose points all lie on one line (no surface through them), or whose bulk lies below
    the smallest scale the estimators take (a few far outliers pass the check of the largest coordinate).
    ``cloud`` is centred on ``anchor`` (:func:`_centre`): the coordinates checked are the given ones."""
    sample = cloud[np.linspace(0, cloud.shape[0] - 1, min(cloud.shape[0], 100_000)).round().astype(np.int64)]
    bulk = float(np.quantile(np.abs(sample + anchor), 0.9))
    if 0.0 < bulk < MIN_COORDINATE:
        raise InvalidMeshError(
            f"`points`: 90% of the coordinates are below {bulk:.3g} (the few larger ones are outliers); products "
            f"of four lengths (squared areas) would underflow float64 below {MIN_COORDINATE:.0e}: rescale the points"
        )
    centred = sample - sample.mean(axis=0)
    singular = np.linalg.svd(centred, compute_uv=False)
    if singular[1] <= 1e-9 * singular[0]:
        raise InvalidMeshError(
            f"all {cloud.shape[0]} distinct points lie on one line (extent {singular[0]:.3g} along it, "
            f"{singular[1]:.3g} across): no surface to measure"
        )


def _compute(points, given, radius, method, search=None):
    """The pipeline on distinct points. Returns the fields, ``valid``, the reason codes, ``parameters`` and the
    problems. ``search``: ``(tree, distances, indices)`` of ``points`` when already built."""
    from scipy.spatial import cKDTree

    n = points.shape[0]
    problems = []
    logger.info("point cloud: %d points: neighbours", n)
    if search is None:
        tree = cKDTree(points)
        distances, indices = _knn(tree, points)
    else:
        tree, distances, indices = search
    spacing = _normals.local_spacing(distances)
    measurable = spacing > MIN_SPACING
    if not measurable.any():
        raise InvalidMeshError(
            f"`points` are spaced below {MIN_SPACING:.0e} everywhere: products of four such lengths underflow "
            "float64; rescale the points"
        )
    median = float(np.median(spacing[measurable]))
    usable = measurable & (spacing <= OUTLIER_FACTOR * median)
    if not measurable.all():
        problems.append(
            f"{int((~measurable).sum())} points are spaced below {MIN_SPACING:.0e} (products of four such "
            "lengths underflow float64): left out, NaN"
        )
    if not (usable | ~measurable).all():
        problems.append(
            f"{int((~usable & measurable).sum())} points are outliers (their "
            f"{_normals.SPACING_NEIGHBOUR}th neighbour is beyond {OUTLIER_FACTOR:g} times the median "
            "spacing): left out, NaN"
        )
    # neighbourhoods on a line: a surface scanned along lines (its own spacing, normals, neighbours and balls), or
    # a line with no surface around it (NaN)
    lonely, line, line_neighbours, line_spacing, least, line_normals = _normals.scan_lines(
        points, distances, indices, usable, tree, radius
    )
    if lonely.any():
        problems.append(
            f"{int(lonely.sum())} points lie on a line (their nearest neighbours on a line or a curve, fewer than "
            f"{_normals.LINE_SUPPORT} points beside it within their reach, or only points beyond "
            f"{_normals.LINE_BEND:g} times its radius of curvature: a lone ring's far side): no surface there, NaN"
        )
        usable &= ~lonely
    if line.size:  # (in place: the arrays of this call's own search; a 1M-point sample holds a line point or two)
        indices[line] = line_neighbours
        spacing[line] = line_spacing
        median = float(np.median(spacing[usable]))
    if not usable.any():  # every point an outlier or on a line: nothing to measure
        reason = np.where(lonely, _ON_A_LINE, 0).astype(np.int8)
        nothing, nowhere = np.full(n, np.nan), np.full((n, 3), np.nan)
        parameters = {
            "radius": np.nan if radius is None else radius,
            "spacing": median,
            "noise": np.nan,
            "normals": "estimated" if given is None else "given",
        }
        return (
            nothing,
            nothing.copy(),
            nowhere,
            nowhere.copy(),
            nowhere.copy() if given is None else given,
            usable,
            reason,
            parameters,
            problems,
        )
    least_radius = np.zeros(n)
    least_radius[line] = least
    centres = np.flatnonzero(usable)

    logger.info("point cloud: normals")
    if given is None:
        start = _normals.pca_normals(points, indices)
        start[line] = line_normals
        logger.info("point cloud: orientation")
        signs, labels, doubtful, sheets, unsettled = _normals.oriented_signs(
            points, start, indices, usable, spacing, tree
        )
        start = start * signs[:, None]
        # a piece the orientation cut off a larger part (a tread of a voxel staircase), or that the rest wraps and
        # whose side the winding number does not confirm (the inner wall of a voxel torus), has no side of its own
        cut_off = _normals.undecided_fragments(points, start, labels, np.where(usable, spacing**2, 0.0), indices, tree)
        doubtful = doubtful | cut_off
        how = "estimated"
    else:
        doubtful = unsettled = cut_off = np.zeros(n, dtype=bool)
        signs, labels = _normals.orientation_signs(given, indices, usable, given=True, points=points)
        sheets = np.where(np.bincount(labels)[labels] >= _normals.PART_MIN_POINTS, labels, -1)
        # each component keeps the side most of its given normals point to
        majority = np.bincount(labels, weights=signs, minlength=int(labels.max()) + 1)
        signs = signs * np.where(majority[labels] < 0, -1.0, 1.0)
        reoriented = bool((signs < 0).any())
        if reoriented:
            # inconsistent signs: oriented as estimated normals are (one sheet at a time, reversed across a
            # gap between two), each part then on the side most of its given normals point to
            signs, labels, doubtful, sheets, unsettled = _normals.oriented_signs(
                points, given, indices, usable, spacing, tree
            )
            majority = np.bincount(labels, weights=signs, minlength=int(labels.max()) + 1)
            signs = signs * np.where(majority[labels] < 0, -1.0, 1.0)
        start = given * signs[:, None]
        how = "given, reoriented" if reoriented else "given"

    # the normals of the jets' check that refuses balls holding the other side: where given normals were re-oriented,
    # a point whose side the orientation left undecided faces away from every centre (its sign is a coin's toss:
    # turned the same way as a neighbouring part's, it would let that part into the part's balls). (Not for
    # estimated normals: on the noisy saddle of benchmarks/pointcloud.py, 1.7% undecided, it cost the jets 0.028
    # of cover.)
    facing = np.where(doubtful[:, None], 0.0, start) if how == "given, reoriented" else start
    logger.info("point cloud: noise level")
    # (its fits refuse balls holding the other side too: through both faces of a plate thinner than the ball a jet
    # reads half the thickness as noise, and the radius that noise calls for reaches across the whole cloud)
    measured = _cloud_noise_level(points, start, median, centres, usable, facing, problems, local=spacing)
    noise = measured if np.isfinite(measured) else 0.0  # not measured (NaN, a note in problems): a clean sample's rules
    groups = _radius_groups(spacing, indices, usable, median, noise, radius, method, problems, least_radius)
    if radius is None:
        # a quarter of the extent that no rigid motion changes (radius.rigid_extent); the bounding box along the
        # coordinate axes cut three sparse spheres in a row to 1.78 in the axes and 1.89 turned (fuzz_api 512/16)
        largest = CLOUD_EXTENT_CAP * rigid_extent(points[usable])
        if max(r for r, *_ in groups) > largest:
            problems.append(
                f"the cloud is too sparse or too noisy for its size (default radius "
                f"{max(r for r, *_ in groups):.3g} beyond a quarter of its extent): radius cut to "
                f"{largest:.3g}; the curvatures are rough"
            )
            groups = [(min(r, largest), s, m, min(f, largest)) for r, s, m, f in groups]

    k_min, k_max = np.full(n, np.nan), np.full(n, np.nan)
    dir_min, dir_max = np.full((n, 3), np.nan), np.full((n, 3), np.nan)
    out_normals = start.copy()
    logger.info("point cloud: %s over %d radius class(es)", method, len(groups))
    parameters = {"radius": groups[0][0], "spacing": median, "noise": measured, "normals": how}
    shrunk = 0  # points whose jet fit took a smaller ball than asked for (its ball held the other side)
    two_sided = 0  # points whose every ball held the other side (or too few points)
    one_sided = np.ones(n, dtype=bool)  # points with a one-sided jet fit (or given normals)
    two_sided_mask = np.zeros(n, dtype=bool)
    unsteady = np.zeros(n, dtype=bool)  # estimates a larger ball does not reproduce
    balls = np.full(n, np.nan)  # the radius of each point's estimate
    fitted = np.full(n, np.nan)  # ... shrunk as the jets' fits were
    noisy = 0  # points whose fits the noise dominates (see NOISY_PCA)
    mixed = None
    compiled = numba_kernels("pointcloud") is not None
    # (a staircase: every coordinate on a grid, as marching cubes over a mask puts them; not a range image's two)
    lattice = _normals.read_lattice(points, median, usable=usable, neighbours=indices)
    staircase = bool(lattice.steps.all())
    on_lattice = method == "jets" and staircase
    below = 0  # points of a staircase whose normal fits shrank, under a given radius below the default one
    for group_radius, group_spacing, members, floor in groups:
        details: dict[str, np.ndarray] = {}
        seen = _class_noise(noise, median, group_spacing)  # the noise in this class's own spacings
        # the radius of the normal fits (corrected_measures' own; the jets' reference on a staircase)
        normal_rule = max(noise_rule(_estimators.NORMAL_RULE, group_spacing, seen), floor)
        if method == "jets" and radius is None:
            group_radius = _within_budget(points, group_radius, members, "jet fits", problems)
        if method == "corrected_measures" and given is None:
            normal_radius = _within_budget(points, normal_rule, members, "normal fits", problems)
            reach = max(normal_radius, group_radius)
        else:
            reach = group_radius
        if method == "corrected_measures" and given is None and mixed is None:
            # a point whose every normal fit held the other side, and whose nearest neighbours hold
            # it too, keeps a PCA normal that may mix the two sheets: it is left out (NaN, and out of
            # the balls, where its triangles would bend the measures of its neighbours)
            mixed = _normals.facing_away(start, indices, usable)
        # a small group (a few points of a scan line, a class of density in one corner) is computed on the
        # points within reach of it only: the same balls, without a search structure over the whole cloud
        # (its reach: every ball of the group's checks, the steadiness check's LARGER one included; a box of the
        # ball's radius alone held points of a larger ball or not by the pose: fuzz_api 510/42)
        near = _within_reach(points, members, reach * _estimators.LARGER)
        if near is None:
            local = (points, start, usable, members, sheets, one_sided, mixed, facing)
        else:
            local = (
                points[near],
                start[near],
                usable[near],
                np.searchsorted(near, members),
                None if sheets is None else sheets[near],
                one_sided[near],
                None if mixed is None else mixed[near],
                facing[near],
            )
        part_points, part_start, part_usable, part_members, part_sheets, part_one_sided, part_mixed, part_facing = local
        if method == "jets":
            # a ball that holds the other side of a thin or small part shrinks, down to the clean-sample radius
            # (a given radius too: a jet through both sides is not the surface, H doubled on a small sphere)
            smallest = min(group_radius, max(CLOUD_RADIUS_RULES[method][0] * group_spacing, floor))
            found = _estimators.jets(
                part_points,
                part_start,
                group_radius,
                part_members,
                part_usable,
                smallest=smallest,
                details=details,
                facing=part_facing,
                lattice=lattice,
            )
            asked = group_radius
            # a fit over half the radius the noise calls for or less (a ball shrunk off the other side of a thin
            # part) follows the noise, as a given radius below SMALL_BALL of it does: at any level of noise
            needed = cloud_radius(group_spacing, seen, method)
            noisy += _noise_dominated(
                details["radii"], part_members, asked, part_one_sided, needed, undefined=seen >= NOISY_PCA
            )
            if on_lattice:  # a staircase biases neighbouring jets alike: the measures over the same balls must agree
                logger.info("point cloud: jets against the measures on a staircase")
                details["unsteady"] = details["unsteady"] | _estimators.staircase_disagree(
                    tree if near is None else None if compiled else cKDTree(part_points),  # (as corrected_measures)
                    part_points,
                    part_start,
                    found,
                    group_radius,
                    part_members,
                    part_usable & part_one_sided,
                    normal_radius=None if given is not None else normal_rule,
                    spacing=group_spacing,
                    sheets=part_sheets,
                )
        else:
            if given is None:
                asked = normal_radius
                smallest = min(normal_radius, max(_estimators.NORMAL_RULE[0] * group_spacing, floor))
                normals = _estimators.fitted_normals(
                    part_points,
                    part_start,
                    normal_radius,
                    part_members,
                    part_usable,
                    smallest=smallest,
                    details=details,
                )
                parameters["normal_radius"] = normal_radius
                failed = part_members[~np.isfinite(details["radii"][part_members])]
                assert part_mixed is not None  # found above for corrected_measures without given normals
                part_one_sided[failed] = ~part_mixed[failed]
                if seen >= NOISY_PCA:
                    noisy += _noise_dominated(details["radii"], part_members, asked, part_one_sided)
            else:
                normals = part_start
            found = _estimators.corrected_measures(
                tree if near is None else None if compiled else cKDTree(part_points),  # (the NumPy path's search)
                part_points,
                normals,
                group_radius,
                part_members,
                part_usable & part_one_sided,
                spacing=group_spacing,
                sheets=part_sheets,
                details=details,
            )
        if "jets" in details:  # (the measures over estimated normals: their jets' curvatures must agree)
            details["unsteady"] = details["unsteady"] | _estimators.disagree(
                found, details["jets"], part_members, group_radius
            )
        if near is not None:
            one_sided[near] = part_one_sided
        if "radii" in details:
            fitted_radii = details["radii"][part_members]
            fitted_normal_radii = np.where(np.isnan(fitted_radii), 0.0, fitted_radii)  # (no fit: shrank to none)
            shrunk += int((fitted_radii < asked).sum())
            two_sided += int(np.isnan(fitted_radii).sum())
            two_sided_mask[members] = np.isnan(fitted_radii)
        unsteady[members] = details["unsteady"][part_members]
        balls[members] = group_radius
        # the ball each estimate was taken over: the jets' own fits shrink where the ball held the other side
        fitted[members] = fitted_radii if method == "jets" else group_radius
        for whole, part in zip((k_min, k_max, dir_min, dir_max, out_normals), found):
            whole[members] = part[part_members]
        if radius is not None:  # a given radius that the sampling, or the noise, cannot support
            needed = cloud_radius(group_spacing, noise, method)
            sparse, noisy_ball = _estimators.small_balls(radius, spacing[members], needed)
            k_min[members[sparse]] = k_max[members[sparse]] = np.nan
            unsteady[members] |= noisy_ball
            problems.extend([_estimators.small_ball_problem(radius, needed)] if noisy_ball else [])
            if staircase and method == "corrected_measures" and given is None and radius < needed:
                # on a staircase, normals fitted over balls that the other face of a thin part shrank (where they
                # turn the normal by little: not the far side of a small part) carry the steps' error of those
                # smaller balls, which only the default radius averages out
                with np.errstate(invalid="ignore"):
                    turn = fitted_normal_radii * np.maximum(np.abs(k_min[members]), np.abs(k_max[members]))
                held = members[(fitted_normal_radii < normal_radius) & ~(turn >= STAIRCASE_FIT_TURN)]
                unsteady[held] = True
                below += held.size
    if below:
        problems.append(
            f"at {below} points of a voxel surface read as a cloud the normals were fitted over balls shrunk by the "
            f"other side of a thin part (turning the normal by less than {STAIRCASE_FIT_TURN:g} rad), and the given "
            f"radius {radius:g} is below the default one: the staircase's error of those normals dominates the "
            "measures (NaN; the default radius averages it out)"
        )
    if method == "jets" or given is None:
        parameters["shrunk"] = shrunk / max(centres.size, 1)
    if method == "jets" and radius is not None and shrunk:
        problems.append(
            f"at {shrunk} points the ball of the given radius {radius:g} held the other side of a thin "
            "or small part (points facing away): fitted over smaller balls of one side, down to "
            f"{CLOUD_RADIUS_RULES[method][0]:g} spacings (parameters['shrunk'])"
        )
    if two_sided:
        what = (
            "curvatures NaN"
            if method == "jets"
            else "normals from the PCA of 10 neighbours"
            if noise < NOISY_PCA
            else f"NaN (under noise of {noise:.2g} spacings the PCA normals of 10 neighbours are not kept)"
        )
        problems.append(
            f"{two_sided} points have no one-sided jet fit (every ball down to 3-4 spacings held "
            f"points facing the other way: a part thinner than that, or too few points): {what}"
        )
    if noisy:
        problems.append(
            f"{noisy} points under noise of {noise:.2g} spacings have a one-sided fit only over balls "
            f"of at most {NOISY_SHRINK:g} times the radius the noise calls for, or none (a part thinner than "
            "that): NaN"
        )
    valid = usable & np.isfinite(k_min) & np.isfinite(k_max)
    alike = amid = np.zeros(n, dtype=bool)
    if how != "given":
        logger.info("point cloud: stacked sheets")
        # a sheet stacked on another with normals the same way (one of the two is inside out), and two sheets
        # closer than the spacing, whose points mix (the faces of a part thinner than that)
        alike, interleaved = _normals.two_sheets(
            points, out_normals, usable, spacing, tree, noise=noise, lattice=lattice
        )
        # a part whose faces mix over a good share of it, or face the same way over most of it, is thinner than
        # the spacing: its sides are a coin's toss
        count = np.maximum(np.bincount(labels, weights=usable, minlength=int(labels.max()) + 1), 1.0)
        share = np.bincount(labels, weights=interleaved, minlength=count.size) / count
        alike_share = np.bincount(labels, weights=alike, minlength=count.size) / count
        interleaved |= usable & ((share[labels] >= THIN_PART_SHARE) | (alike_share[labels] >= ALIKE_PART_SHARE))
        doubtful = doubtful | alike | interleaved
        # amid undecided sides, a side decided by the same orientation is no better (a plate thinner than its
        # noise, whose faces no neighbourhood tells apart: seed 4242 case 200, 20 of 45 valid points inward)
        amid = _amid_undecided(points, doubtful, usable, indices, tree)
        # ... and so on a part whose points' sides are mostly undecided
        undecided_share = np.bincount(labels, weights=doubtful | amid, minlength=count.size) / count
        whole = undecided_share >= ALIKE_PART_SHARE
        # ... or a good share undecided on a part whose faces were oriented as one sheet (it looks open)
        thin = np.flatnonzero(~whole & (undecided_share >= THIN_PART_SHARE))
        if thin.size:
            whole[thin] = _one_sheet(out_normals, spacing, usable, labels, thin)
        amid |= usable & ~doubtful & whole[labels]
        doubtful |= amid
    reason = np.zeros(n, dtype=np.int8)
    reason[~one_sided | (two_sided_mask & usable)] = _TWO_SIDED
    reason[lonely] = _ON_A_LINE
    valid &= one_sided
    unsteady |= _estimators.erratic(k_min, k_max, indices, valid & ~unsteady, spacing)
    problems.extend(_estimators.unsteady_problem(unsteady & valid))
    reason[unsteady & valid] = _UNSTEADY
    valid &= ~unsteady
    # (an outlier is on no side of a ball: alone, its normal's sign is the convention of a part with no volume, a
    # fixed direction that a rotation of the cloud turns against it: fuzz_api 590/4, ogre's outliers counted on
    # the own side of balls in one pose and not in the other: 5 points' validity)
    sided = np.where(usable[:, None], out_normals, 0.0)
    beside = _estimators.beside_unresolved(points, sided, k_min, k_max, balls, valid & ~doubtful, tree)
    problems.extend(_estimators.unsteady_problem(beside, beside=True))
    reason[beside] = _UNSTEADY
    valid &= ~beside
    # an estimate whose ball's normals its shape operator does not predict: the curvature changes across the ball
    blend = _estimators.blended(
        points, sided, (k_min, k_max, dir_min, dir_max), fitted, valid & ~doubtful, tree, sheets
    )
    problems.extend(_estimators.blended_problem(blend))
    reason[blend] = _UNSTEADY
    valid &= ~blend
    if method == "jets":  # a jet over a ball about as large as the radius of curvature: its bias is about H
        wide = _estimators.wide_jets(k_min, k_max, fitted, valid & ~doubtful)
        problems.extend(_estimators.wide_jets_problem(wide))
        reason[wide] = _UNSTEADY
        valid &= ~wide
    # a voxel surface read as a cloud: a ball on a flat facet of its staircase sees a plane
    tread, found = _normals.lattice_treads(
        points, out_normals, balls, valid & ~doubtful, tree, (k_min, k_max, fitted), lattice
    )
    problems.extend(found)
    reason[tread] = _UNSTEADY
    valid &= ~tread
    # ... and amid a region of the staircase that the checks above left unresolved
    amid_staircase = _estimators.amid_unresolved(points, sided, balls, valid & ~doubtful, tree, lattice)
    problems.extend(_estimators.amid_unresolved_problem(amid_staircase))
    reason[amid_staircase] = _UNSTEADY
    valid &= ~amid_staircase
    # an estimate none of whose nearest neighbours has one: alone in a region the estimator does not resolve
    lone = _estimators.alone(valid & ~doubtful, indices)
    problems.extend(_estimators.alone_problem(lone))
    reason[lone] = _UNSTEADY
    valid &= ~lone
    if doubtful.any():
        found = []
        between = doubtful & ~unsettled & ~alike & ~amid & ~cut_off
        if (cut_off & ~alike & ~amid).any():
            found.append(
                f"{int((cut_off & ~alike & ~amid).sum())} points are on pieces that the orientation cut off a "
                "larger part beside them and whose own shape gives no side (a tread of a voxel staircase, a "
                "patch between creases), or that the rest of the cloud wraps and whose side its winding number "
                "does not confirm (the inner wall of a voxel torus)"
            )
        if between.any():
            found.append(
                f"{int(between.sum())} points lie between two sheets closer than the spacing (two parts "
                "of the cloud, or the faces of a part thinner than that)"
            )
        if (unsettled & ~alike).any():
            found.append(
                f"{int((unsettled & ~alike).sum())} points are on a side the winding number of the cloud "
                "contradicts (a part inside out, or an outward part inside another) and turning them did "
                "not settle it"
            )
        if alike.any():
            found.append(
                f"{int(alike.sum())} points face the same way as a sheet stacked on theirs a few spacings "
                "away (the faces of a thin part, or two parts: one of the two is inside out)"
            )
        if amid.any():
            found.append(
                f"{int(amid.sum())} points have at least {AMID_UNDECIDED:g} of their {AMID_NEIGHBOURS} nearest "
                f"neighbours undecided, or are on a part at least {ALIKE_PART_SHARE:g} of whose points are (a part "
                f"thinner than its noise: its faces mix), or {THIN_PART_SHARE:g} on a part whose normals sum to "
                f"{ONE_SHEET_FLUX:g} of its area or more (a closed part thinner than the spacing, its two faces "
                "oriented as one sheet)"
            )
        problems.append(" and ".join(found) + ": their normals' side is undecided, NaN")
        valid &= ~doubtful
        reason[doubtful] = _UNDECIDED
    if how == "given, reoriented":
        # where the side is undecided (NaN) the user's normal is kept: a consistent orientation that a thin noisy
        # part made look inconsistent stays "given" (seed 42 case 314 of benchmarks/fuzz_api.py: 848 normals of a
        # plate 0.04 thick under noise were turned, every one of them undecided)
        out_normals[doubtful] = given[doubtful]
        turned = int(((signs < 0) & ~doubtful).sum())
        if turned:
            problems.append(
                f"{turned} of the given normals were turned to agree with their neighbours (their signs were not "
                "consistent): parameters['normals'] is 'given, reoriented'"
            )
        else:
            parameters["normals"] = "given"
    if len(groups) > 1:
        parameters["radii"] = tuple(r for r, *_ in groups)
    return k_min, k_max, dir_min, dir_max, out_normals, valid, reason, parameters, problems


def _amid_undecided(points, doubtful, usable, indices, tree) -> np.ndarray:
    """(N,) bool: the ``usable`` points not ``doubtful`` with at least :data:`AMID_UNDECIDED` of their
    :data:`AMID_NEIGHBOURS` nearest usable neighbours ``doubtful`` (searched where one of the nearest ``indices``
    (N, k) is)."""
    out = np.zeros(points.shape[0], dtype=bool)
    near = np.flatnonzero(usable & ~doubtful & (doubtful[indices] & usable[indices]).any(axis=1))
    if near.size == 0:
        return out
    k = min(AMID_NEIGHBOURS + 1, points.shape[0])
    distances, crowd = tree.query(points[near], k=min(k + 1, points.shape[0]), workers=-1)
    # (the point itself first, and in the slots of a lattice's neighbours tied at the cut: the pose ordered them)
    crowd = _normals._whole_rows(distances, crowd, near, k)[:, 1:]
    counted = usable[crowd] & (crowd != near[:, None])
    share = (doubtful[crowd] & counted).sum(axis=1) / np.maximum(counted.sum(axis=1), 1)
    out[near] = share >= AMID_UNDECIDED
    return out


def _one_sheet(normals, spacing, usable, labels, parts) -> np.ndarray:
    """(P,) bool: which of the ``parts`` (P,) (values of ``labels`` (N,)) have usable oriented ``normals`` (N, 3)
    summing to at least :data:`ONE_SHEET_FLUX` of their area (each point's the square of its local ``spacing``)."""
    areas = np.where(usable, spacing * spacing, 0.0)
    weighted = np.where(usable[:, None] & np.isfinite(normals), normals, 0.0) * areas[:, None]
    size = int(labels.max()) + 1
    total = np.bincount(labels, weights=areas, minlength=size)[parts]
    flux = np.stack([np.bincount(labels, weights=weighted[:, j], minlength=size)[parts] for j in range(3)])
    return np.linalg.norm(flux, axis=0) >= ONE_SHEET_FLUX * np.maximum(total, np.finfo(float).tiny)


def _within_reach(points: np.ndarray, members: np.ndarray, reach: float) -> np.ndarray | None:
    """(M,) the sorted indices of the points in the box of ``members`` grown by ``reach`` (every point within
    ``reach`` of one of them), or None when that is more than :data:`LOCAL_SHARE` of the cloud."""
    n = points.shape[0]
    if members.size == 0 or members.size > LOCAL_SHARE * n:
        return None
    own = points[members]
    margin = reach * (1.0 + 1e-9)
    low, high = own.min(axis=0) - margin, own.max(axis=0) + margin
    inside = np.flatnonzero(((points >= low) & (points <= high)).all(axis=1))
    return inside if inside.size <= LOCAL_SHARE * n else None


def _noise_dominated(radii, members, asked, one_sided, needed: float | None = None, *, undefined: bool = True) -> int:
    """Mark in ``one_sided`` the ``members`` whose fit ``radii`` (N,) shrank below ``asked`` to at most
    :data:`NOISY_SHRINK` times ``needed`` (default: ``asked``; within :data:`SHRINK_ROUNDING`), or is NaN when
    ``undefined``; return how many had a (small) fit. (A fit at the radius asked for is the caller's choice: a given
    radius is checked against the noise by :func:`meshcurv._pointcloud_estimators.small_balls`.)"""
    radii = radii[members]
    bound = NOISY_SHRINK * (asked if needed is None else needed) * (1.0 + SHRINK_ROUNDING)
    small = (radii < asked) & (radii <= bound)
    one_sided[members[small | (undefined & np.isnan(radii))]] = False
    return int(small.sum())  # (those without a fit are counted as such)


def _class_noise(noise: float, median: float, spacing: float) -> float:
    """The cloud's ``noise`` (in ``median`` spacings) in spacings of a class of density of ``spacing``: the noise is
    a length, of which a denser class holds more of its own spacings (a sparser one keeps the cloud's level: its
    radius rule was set on it). Figures: ``benchmarks/pointcloud.md``, "a denser class under the cloud's noise"."""
    return noise * max(1.0, median / spacing)


def _within_budget(points, radius, members, what, problems) -> float:
    """``radius``, or less: balls around ``members`` that hold :data:`BALL_PAIRS_SHARE` of
    :data:`meshcurv.neighborhoods.MAX_BALL_PAIRS` (centre, point) pairs at most (the count grows as the square
    of the radius on a surface). A cut is added to ``problems``."""
    from .neighborhoods import MAX_BALL_PAIRS, _estimate_ball_pairs

    if members.size == 0:
        return radius
    mean, _ = _estimate_ball_pairs(points, radius, points[members])
    budget = BALL_PAIRS_SHARE * MAX_BALL_PAIRS
    if mean * members.size <= budget:
        return radius
    cut = float(radius * np.sqrt(budget / (mean * members.size)))
    problems.append(
        f"the default radius of the {what}, {radius:.3g}, would hold about {mean:.3g} points a ball "
        f"({mean * members.size:.3g} in all, hours of work: noise of many spacings, or both faces "
        f"of a thin part in each ball): cut to {cut:.3g}; the curvatures are rougher"
    )
    return cut


def _radius_groups(spacing, indices, usable, median, noise, radius, method, problems, least=None):
    """``[(radius, spacing, centres, floor), ...]``: one radius, or one per class of density when it is uneven.

    ``least`` (N,): the smallest radius of each point's balls (points of scan lines, see
    :func:`meshcurv._pointcloud_normals.scan_lines`; 0 elsewhere): those points get groups of their own, by
    powers of two of ``least``, whose radius and ``floor`` (the smallest radius of their fits) are the largest
    ``least`` of the group or more.
    """
    centres = np.flatnonzero(usable)
    if radius is not None:
        return [(radius, median, centres, 0.0)]
    lines = []
    if least is not None and (least[centres] > 0).any():
        on_line = centres[least[centres] > 0]
        centres = centres[least[centres] == 0]
        level = np.round(np.log2(least[on_line] / median)).astype(np.int64)
        for k in np.unique(level):
            members = on_line[level == k]
            floor = float(least[members].max())
            group_spacing = float(np.median(spacing[members]))
            seen = _class_noise(noise, median, group_spacing)
            lines.append((max(cloud_radius(group_spacing, seen, method), floor), group_spacing, members, floor))
    if centres.size == 0:  # (no usable point: every point an outlier or on a line)
        return lines or [(cloud_radius(median, noise, method), median, centres, 0.0)]
    # the spacing averaged over the neighbours: one class per region, not per random gap
    # (over the usable neighbours of usable points only: a row of outliers alone would have no mean)
    values = np.where(usable, spacing, 0.0)
    kernels = numba_kernels("pointcloud")
    if kernels is not None and indices.shape[1] <= 128:  # (the same numbers, without (M, k) gathers)
        smooth = kernels._neighbour_spacing(values, usable, indices, centres)
    else:
        rows = indices[centres]
        smooth = (values[centres] + values[rows].sum(axis=1)) / (1.0 + np.count_nonzero(usable[rows], axis=1))
    low, high = np.percentile(smooth, [5, 95])
    if high <= UNEVEN_DENSITY * low:
        return [(cloud_radius(median, noise, method), median, centres, 0.0), *lines]
    level = np.round(np.log2(smooth / median)).astype(np.int64)
    groups = []
    for k in np.unique(level):
        members = centres[level == k]
        group_spacing = median * 2.0**k
        groups.append(
            (
                cloud_radius(group_spacing, _class_noise(noise, median, group_spacing), method),
                group_spacing,
                members,
                0.0,
            )
        )
    problems.append(
        f"the density of the points is very uneven (local spacing from {low:.3g} to {high:.3g}, "
        f"5th to 95th percentile): each of {len(groups)} classes of spacing got its own radius"
    )
    return groups + lines
