"""The curvature estimators of :func:`meshcurv.pointcloud.point_cloud_curvatures`.

Both take trusted arrays (float64 points, unit oriented normals) and return
``k_min, k_max, dir_min, dir_max, normals`` (NaN where undefined).
"""

from __future__ import annotations

import logging
import warnings

import numpy as np

from ._backend import kernel_threads, numba_kernels
from ._pointcloud_normals import NEIGHBOURS, NO_LATTICE, TIE_TOLERANCE, Lattice, _dot
from .errors import InvalidOptionError
from .measures import curvatures_from_measures
from .jets import _fit_jets, jet_curvatures, jet_normals

logger = logging.getLogger(__name__)

#: Degree of the jets of ``method="jets"`` (Cazals and Pouget 2005: error of order ``r^(d-1)``).
JET_DEGREE = 3

#: Fits per point of the jets: the first in the frame of the point's normal, the next in the fitted one's.
JET_ITERATIONS = 2

#: Random triangles per point of ``method="corrected_measures"``.
TRIANGLES = 32

#: A random triangle of ``corrected_measures`` adds nothing when the mean of its corners' normals lies in its plane
#: within this fraction of their lengths' product: its corrected area is round-off, and so is the sign that turns
#: it. On a lattice (a mesh's vertices as a cloud) such triangles are common, and normals equal to round-off turned
#: them apart on the two backends (``benchmarks/fuzz_api.md``, round 11). So does a flat triangle (three points of a
#: lattice's line: the cross product of its edges within this fraction of their lengths' product), whose area is
#: round-off once the cloud is turned, in a direction of its own: its measures of the normals' turning (mu_1, mu_2,
#: not small) came with the sign of that round-off (a voxel sphere turned: 680 of 3,706 estimates 1e-3 of the
#: largest |k| apart, up to 1.3e-2). Euclidean lengths, not L1 ones: the L1 lengths' ratio changes by up to 3
#: times under a rotation, and triangles of a sine between 1e-9 and a few 1e-9 (a voxel line's points with near
#: copies merged at their centroid, 1e-11 of the extent apart) were dropped in one pose and kept in the other,
#: mu_1 up to 0.09 with the sign of that near-zero area (``fuzz_api.py --seed 771 --replay 19``: 25 points' validity).
EDGE_ON = 1e-9

#: Most points of a ball that ``corrected_measures`` draws its triangles from (the nearest ones).
MAX_BALL_POINTS = 96

#: Fewest points of a ball for ``corrected_measures`` (three corners and some choice).
MIN_BALL_POINTS = 6

#: The normals of ``corrected_measures`` (when not given) are those of degree-3 jets over balls of
#: ``s (a + b sqrt(max(nu - 0.005, 0)))`` (``s`` the spacing, ``nu`` the noise level): ``(a, b)``.
NORMAL_RULE = (4.0, 55.0)

#: Fits per point of the normals of ``corrected_measures`` (:func:`fitted_normals`): one, in the frame of
#: the PCA normal. A second fit in the frame of the first one's normal (as ``"jets"`` does) changed no
#: median error of ``benchmarks/pointcloud.py`` by more than 0.02 points (ellipsoid, torus, saddle, noise 0
#: to 0.2 spacings) and cost 7-18% of the fits' time at 1M points (their neighbour search dominates).
NORMAL_ITERATIONS = 1

#: Points of a ball (evenly spread over its distance order) that :func:`flat_balls` checks for a surface ...
SUPPORT_POINTS = 48

#: ... and power iterations for their main direction; a point counts as beside the line through the centre when
#: farther from it than this times the farthest point's distance (94% of a disc's area) ...
SUPPORT_ITERATIONS = 6
BALL_OFFSET = 0.1

#: ... and a ball holds a surface when this many of them (or more) ...
BALL_SUPPORT = 3

#: ... and this share of its points (or more) are beside the line: an elongated
#: ball of a surface (trimmed by :func:`_own_side`, at a rim) has, a line with a few points beside it has not.
BALL_SHARE = 0.25

#: Centres per chunk of the ball searches (bounds memory: chunk x the points of a ball).
CHUNK = 32768

#: Centres per chunk of ``corrected_measures`` on the compiled path and of the checks over balls
#: (:func:`_balls`, :func:`_uniform_balls`): bounds memory, their balls of up to 2 :data:`MAX_BALL_POINTS`
#: points holding some 6 KiB per centre (chunks of :data:`CHUNK` held 0.3 GiB at 32,000 points; these about
#: 0.1 GiB). As many as :data:`meshcurv._backend.SERIAL_ROWS`: the kernels over a chunk's own rows (the inner
#: balls, the curvatures of the measures) run on every core, and the chunks are 4 times fewer than of 4096
#: (1M torus points: the calling thread's CPU 8.17-8.63 -> 7.80-8.13 s, the same results to the bit) ...
MEASURE_CHUNK = 16384

#: ... and triangles per chunk of its NumPy path (some 1 KiB per triangle: a chunk of
#: ``TRIANGLE_CHUNK // TRIANGLES`` centres; all the balls' triangles at once held 1 GiB at 32,000 points,
#: ``benchmarks/memory_pointcloud.md``). Each centre's sums are those of its own triangles, in the same order:
#: the chunks change no number.
TRIANGLE_CHUNK = 65536

#: A jet fit whose ball reaches the other side of the surface is redone over a ball this many times
#: smaller (:func:`one_sided_fits`): sqrt(2) halves the ball's area per step.
SHRINK = 2.0**-0.5

#: An estimate is kept where the same estimator over balls :data:`LARGER` times larger (twice the points)
#: reproduces it (:func:`unsteady`): both principal curvatures within this share of the smaller of the two
#: estimates' largest |k|. A bias that grows as r^2 (a curvature that changes within the ball) differs between
#: the two balls by about itself, and the fuzzer calls a valid H a lie beyond 0.5 of |k|; a fit that follows
#: noise differs from the larger ball's by about its own error.
AGREEMENT = 0.4

#: ... and within this share on a lattice (a voxel surface read as a cloud:
#: :func:`~meshcurv._pointcloud_normals.read_lattice`). A jet fitted to a staircase of steps ``h`` over a ball of
#: radius ``r`` is biased by about ``h / r^2`` (the steps are coherent, no noise that the ball averages out), a bias
#: that falls fast from one ball to the next: the two estimates differ by most of the smaller ball's bias, and
#: bounding the difference bounds that bias below half of |k| (``AGREEMENT`` does not, at the poles of voxel spheres
#: and ellipsoids of 15 voxels and more). Only where the largest |k| falls from the ball to the larger one, as that
#: bias does (a jet's bias from a curvature grows with the ball: small voxel spheres stay measured). Figures:
#: ``benchmarks/pointcloud_diagnostics.md``, "Jets on a staircase".
LATTICE_AGREEMENT = 0.2

#: ... where a change of the curvature by this many radians of normal turning over the ball (``0.05 / r``)
#: counts as none: a flat region's two estimates agree within it.
FLAT_TURN = 0.05

#: A point's estimate is kept where its nearest neighbours' (whose balls hold nearly the same points) reproduce it
#: (:func:`erratic`): the median over them of the largest difference of a principal curvature within this share
#: of the smaller largest |k|.
NEIGHBOUR_AGREEMENT = 0.3

#: On a lattice the jets must agree with the corrected measures over the same balls (:func:`staircase_disagree`)
#: within this share of the smaller largest |k|: with the measures' own error on voxel surfaces added, an agreeing
#: jet stays within half of |k| (``benchmarks/pointcloud_diagnostics.md``, "Jets against the measures on a
#: staircase"; :data:`AGREEMENT` let jets of 1.5 |k| agree with measures of 1.1 |k|).
STAIRCASE_AGREEMENT = 0.3

#: A given radius below this share of the one the noise calls for is unsteady (:func:`small_balls`): the default
#: rule's balls give median errors of 1-6% under noise; half their radius, about four times that, and tails beyond
#: half of |k|.
SMALL_BALL = 0.5

#: The curvatures of the normals' jets (:func:`disagree`) are a reference where the normal turns by at most this
#: many radians over their ball (a unit sphere of 1000 points under noise: balls of 0.5 and more).
JET_TURN = 0.3

#: The ball of the check of :func:`unsteady` is this many times the radius of the estimate.
LARGER = 2.0**0.5

#: Measures whose normal turns by more than this many radians over their ball (``radius |k|``) are checked
#: against jets over the balls of :func:`unsteady` (:func:`turned`) ...
BALL_TURN = 0.3

#: Measures whose normal turns by more than this many radians over their ball (but at most :data:`BALL_TURN`) are
#: checked too, against the same jets, but flagged only where none of them could be fitted on one side of the
#: surface (down to half the radius): a part thinner than the ball, by whose rim the curvature grows a hundredfold
#: within the ball. There a disagreement alone is no sign: under noise the jets over such balls follow the noise.
#: Figures: ``benchmarks/pointcloud.md``, "a thin part read as noise".
THIN_TURN = 0.1

#: ... which must reproduce both principal curvatures within this share of |k| (as :func:`unsteady` compares):
#: both estimators' errors are a few percent where the ball resolves the surface (a unit sphere of 1,000 points
#: under noise of 0.2 spacings keeps 99% of its points; at 0.15, 8%).
TURN_AGREEMENT = 0.2

#: A jet fit that shrank off the other side of a thin part must be reproduced by the jets over balls :data:`SHRINK`
#: times smaller within this share of |k| (:func:`_rim_unsteady`, as :func:`unsteady` compares). Fuzz 350/15
#: (a plate 0.2 thick under noise of 0.1 spacings, radius 0.233): errors up to 0.536 of |k| -> 0.259 with 0.2 or 0.3
#: (:data:`AGREEMENT` 0.4 left 3 points at 0.53); the held-out flat ellipsoid (5,000 points, noise 0.1, jets) keeps
#: 61-62% of its points with 0.3 (66-67% before the check, 58-60% with 0.2), its median and largest H errors unchanged.
RIM_AGREEMENT = 0.3

#: A fit whose ball is one-sided by a rim (an open sheet's edge: its points' centroid lies farther than this share of
#: the ball's reach from the centre across the normal; a half-disc's lies 0.42 of it away, a disc cut 0.3 radii
#: beyond the centre 0.26) must agree, as :func:`unsteady` compares within :data:`RIM_AGREEMENT`, with the fit at
#: its ball's point nearest that centroid (:func:`_rim_balls`), whose ball is balanced: the value at the centre of
#: a one-sided fit is an extrapolation, which under noise follows the noise, and the larger and smaller balls of
#: :func:`unsteady` and :func:`_rim_unsteady`, one-sided alike, extrapolate the same points the same way. Fuzz 483/50
#: (half a cylinder under noise of 0.2 spacings): 19 points within 2.5 spacings of the rim off by up to 1.07 of |k|,
#: both principal curvatures too large by 0.5-0.9 (exact 0 and 1), the smaller ball's by more.
RIM_OFFSET = 0.25

#: The jets of :func:`turned` are fitted over balls turning the normal by at most this many radians (where the
#: check's own would turn more: a unit sphere of 400 points, balls of 0.77).
REFERENCE_TURN = 0.8

#: ... and are not needed where no estimate on the own side of the ball has a largest |k| below this share of the
#: centre's (:func:`_uniform_balls`: a curvature steady over the ball; by a thin plate's rim the whole band is
#: biased alike, so a neighbour within this share is that band: ``benchmarks/pointcloud.md``, Reliability).
UNIFORM_SHARE = 0.7

#: A resolved estimate whose ball turns the normal by more than :data:`UNRESOLVED_TURN` radians and whose own side
#: holds more than :data:`UNRESOLVED_SHARE` of points without a resolved estimate is unsteady
#: (:func:`beside_unresolved`).
UNRESOLVED_TURN = 0.2
UNRESOLVED_SHARE = 0.5

#: A resolved estimate whose ball turns the normal by more than :data:`BLEND_TURN` radians (``radius |k|``) and
#: whose own side's normals are not those of the estimate's shape operator (the :data:`BLEND_QUANTILE` quantile of
#: the differences above :data:`BLEND_RESIDUAL` times the turn out to the farthest of them) is unsteady
#: (:func:`blended`). Seeds 42 and 4242 of ``benchmarks/fuzz_api.py`` (cases 91, 124, 168 and
#: 189, the band by the rim of plates 0.02-0.2 thick, spheres in balls turning by 2 rad): the points off by more
#: than half of |k| turn by 1-4 rad and differ by 0.31-0.85; the valid points of ``benchmarks/pointcloud.py``
#: (both tables) that pass 0.3 turn by 0.2-0.4 rad, and at most 1% of a held-out flat ellipsoid's turn by more
#: than 0.8 (its rim, jets: errors of 12-16% of |k| there).
BLEND_TURN = 0.8
BLEND_QUANTILE = 0.9
BLEND_RESIDUAL = 0.3

#: A jet whose ball turns the normal by more than this many radians on average over the directions (``radius |H|``,
#: the mean of the normal curvature over the directions being H) is unsteady (:func:`wide_jets`): a degree-3 jet's
#: bias grows as the square of the turn. On a unit sphere (400 and 2,000 points, clean or under noise of 0.1-0.2
#: spacings, given radii) the jets' H is 11% too large at ``radius |H|`` 0.9, 19% at 1.2, 30% at 1.57 and 44% at
#: 2.04; seed 142 of ``benchmarks/fuzz_api.py`` (spheres beside flat ellipsoids, balls of a density class or cut to
#: a quarter of the cloud's extent: 1.44 on a unit sphere) left points at 2.13-2.30, off by 0.50-0.54 of |k|. Where
#: one principal curvature dominates (a thin torus's tube under noise, balls turning it by up to 2.4 rad) H takes
#: half of that bias, and ``radius |H|`` stays below 1.3.
JET_MEAN_TURN = 1.6


def one_sided_fits(
    points,
    normals,
    radius,
    centres,
    usable,
    *,
    smallest: float | None,
    degree: int = JET_DEGREE,
    iterations: int = JET_ITERATIONS,
    first: tuple | None = None,
    facing: np.ndarray | None = None,
):
    """Jets over the largest ball, from ``radius`` down to ``smallest``, that holds one side of the surface.

    A ball larger than the thickness of a part (a flat ellipsoid's two faces,
    a thin tube) or than the radius of curvature (a sharp rim) holds points
    of the other side, whose oriented ``normals`` point the other way: a jet
    through both sides is not the surface. Such a fit (more than
    :data:`meshcurv.jets.AWAY_FRACTION` of the ball's points
    facing away, the ``facing`` check of :func:`~meshcurv.jets.fit_jets`)
    is redone over a ball :data:`SHRINK` times smaller, down to ``smallest``.
    Where the surface is thicker than ``radius`` every fit is the one over
    ``radius``. ``smallest=None``: one fit over ``radius``, not checked. ``first``: the fits over ``radius`` at
    ``centres`` (at least) already made, the ``(coefficients, frame, counts)`` of :func:`~meshcurv.jets.fit_jets`.
    ``facing`` (N, 3): the normals of the check (default: ``normals``; a zero row faces away from every centre: a
    point whose side is undecided).

    Returns
    -------
    coefficients : ndarray of shape (N, 6)
        In units of each fit's own radius (NaN where even the smallest ball failed).
    frame : tuple of three ndarrays of shape (N, 3)
    radii : ndarray of shape (N,)
        The radius of each point's fit (NaN where none).
    """
    n = points.shape[0]
    if smallest is None:
        coefficients, frame, _ = first or _fit_jets(
            points, normals, radius, degree=degree, iterations=iterations, centres=centres, neighbours=usable
        )
        return coefficients, frame, np.full(n, float(radius))
    fits: tuple | None = None  # (coefficients, frame, radii), made when a fit leaves a point to a smaller ball
    todo = np.asarray(centres, dtype=np.int64)
    current = float(radius)
    while todo.size:
        own = first is None  # (the fits made here: arrays of this call's own)
        found, local, _ = first or _fit_jets(
            points,
            normals,
            current,
            degree=degree,
            iterations=iterations,
            centres=todo,
            neighbours=usable,
            facing=normals if facing is None else facing,
        )
        first = None
        # (over every row when most are asked: no (M, 6) gather of the fits, 1M points: 0.04-0.08 -> 0.02 CPU s)
        fitted = np.isfinite(found).all(axis=1)[todo] if 2 * todo.size > n else np.isfinite(found[todo]).all(axis=1)
        done = todo[fitted]
        if fits is None and own:
            if done.size == n:  # every point fitted over `radius` (the common case): no copies of the fits
                return found, tuple(local), np.full(n, current)
            # the first fits made here are the fits' own arrays, the rows not fitted NaN (1M points: no (N, 15)
            # NaN arrays and copies of the rows, 0.25 CPU s)
            missed = np.ones(n, dtype=bool)
            missed[done] = False
            found[missed] = np.nan
            for part in local:
                part[missed] = np.nan
            fits = (found, tuple(local), np.full(n, np.nan))
            fits[2][done] = current
        else:
            if fits is None:
                fits = _no_fits(n)
            coefficients, frame, radii = fits
            coefficients[done] = found[done]
            for whole, part in zip(frame, local):
                whole[done] = part[done]
            radii[done] = current
        # (`todo` less `done` in its order, as np.setdiff1d(todo, done, assume_unique=True), without its sort)
        todo = todo[~fitted]
        if current <= smallest:
            break
        current = max(smallest, current * SHRINK)
    return _no_fits(n) if fits is None else fits


def _no_fits(n: int) -> tuple:
    """``(coefficients, frame, radii)`` of :func:`one_sided_fits` without any fit: NaN."""
    return np.full((n, 6), np.nan), tuple(np.full((n, 3), np.nan) for _ in range(3)), np.full(n, np.nan)


def jets(
    points,
    normals,
    radius,
    centres,
    usable,
    *,
    smallest: float | None = None,
    details: dict | None = None,
    facing: np.ndarray | None = None,
    lattice: Lattice = NO_LATTICE,
):
    """Principal curvatures of jets fitted over balls of ``radius`` around ``centres``.

    Where a ball holds the other side of the surface its fit is redone over a
    smaller one, down to ``smallest`` (:func:`one_sided_fits`; default: one
    unchecked fit over ``radius``, as for a radius the user chose).
    Returns ``(k_min, k_max, dir_min, dir_max, normals)`` at every point, NaN
    where the fit failed and at points not in ``centres``; ``normals`` are those
    of the fitted jets (the given ones where the fit failed). ``details``
    receives ``"radii"``: (N,) the radius of each point's fit. ``facing``: the normals of the check of
    :func:`one_sided_fits` (default: ``normals``). ``lattice``: the grid of the cloud's coordinates
    (:func:`~meshcurv._pointcloud_normals.read_lattice`), read by the check of ``details["unsteady"]``.
    """
    logger.debug("point cloud: jet fits")
    facing = normals if facing is None else facing
    first = larger = None
    if details is not None:  # the fits over the check's balls LARGER times larger too, in the same walk
        both: dict = {}
        first = _fit_jets(
            points,
            normals,
            radius,
            degree=JET_DEGREE,
            iterations=JET_ITERATIONS,
            centres=centres,
            neighbours=usable,
            facing=None if smallest is None else facing,
            details=both,
            larger=radius * LARGER,
        )
        larger = both["larger"]
    coefficients, frame, radii = one_sided_fits(
        points, normals, radius, centres, usable, smallest=smallest, first=first, facing=facing
    )
    logger.debug("point cloud: curvatures of the jets")
    if details is not None:
        details["radii"] = radii
    found = _jet_curvatures(coefficients, frame, radii, normals)
    if details is not None:
        # the same fits over balls LARGER times larger, from the same normals: the estimate must not depend on it
        done = np.asarray(centres, dtype=np.int64)
        done = done[np.isfinite(found[0][done])]
        wide_coefficients, wide_frame, wide_radii = one_sided_fits(
            points,
            normals,
            radius * LARGER,
            done,
            usable,
            smallest=None if smallest is None else smallest * LARGER,
            first=larger,
            facing=facing,
        )
        wide_found = _jet_curvatures(wide_coefficients, wide_frame, wide_radii, normals)
        details["unsteady"] = unsteady(found, wide_found, done, radius, _agreement(found, wide_found, done, lattice))
        if smallest is not None:
            details["unsteady"] |= _rim_unsteady(points, normals, found, radii, radius, done, usable)
    return found


def _rim_unsteady(points, normals, found, radii, radius, centres, usable) -> np.ndarray:
    """(N,) bool: the ``centres`` (M,) whose fit shrank below ``radius`` (the ball held the other side of a thin
    part: its rim lies just beyond the fit's ball of ``radii`` (N,)) and whose estimate ``found`` the jets over balls
    :data:`SHRINK` times smaller do not reproduce (as :func:`unsteady` compares). By the rim the curvature grows
    several times within the ball: the fit follows the rim's turn, and a larger ball cannot tell (it holds the other
    side, or the same turn): the band 0.15 from the rim of a plate 0.2 thick under noise (``benchmarks/fuzz_api.py``
    seed 350, case 15: H 1.8 times the exact one, steady over the larger ball)."""
    out = np.zeros(points.shape[0], dtype=bool)
    shrunk = centres[radii[centres] < radius * (1.0 - 1e-9)]
    for size in np.unique(radii[shrunk]):
        group = shrunk[radii[shrunk] == size]
        smaller = size * SHRINK
        coefficients, frame, _ = _fit_jets(
            points, normals, smaller, degree=JET_DEGREE, iterations=JET_ITERATIONS, centres=group, neighbours=usable
        )
        found_smaller = _jet_curvatures(coefficients, frame, np.full(points.shape[0], smaller), normals)
        out |= unsteady(found, found_smaller, group, smaller, RIM_AGREEMENT)
    by_rim, inner = _rim_balls(points, normals, radius, centres, usable)
    if by_rim.any():
        rim, inner = centres[by_rim], inner[by_rim]
        balanced = (np.full(points.shape[0], np.nan), np.full(points.shape[0], np.nan))
        balanced[0][rim], balanced[1][rim] = found[0][inner], found[1][inner]
        out |= unsteady(found, balanced, rim, radius, RIM_AGREEMENT)
    return out


def _rim_balls(points, normals, radius, centres, usable) -> tuple[np.ndarray, np.ndarray]:
    """``(rim, inner)``: (M,) bool, the ``centres`` (M,) whose ball of ``radius`` (its usable points, cut to the
    nearest :data:`MAX_BALL_POINTS` as the fits' are) is one-sided: their centroid lies more than :data:`RIM_OFFSET`
    times the ball's reach from the centre across its normal of ``normals`` (N, 3); and (M,) the index of the ball's
    point nearest that centroid (the centre itself where the ball is not one-sided)."""
    from scipy.spatial import cKDTree

    rim, inner = np.zeros(centres.size, dtype=bool), np.asarray(centres, dtype=np.int64).copy()
    pool = np.flatnonzero(usable)
    if pool.size == 0 or centres.size == 0:
        return rim, inner
    tree = cKDTree(points[pool])
    for start in range(0, centres.size, MEASURE_CHUNK):
        chunk = centres[start : start + MEASURE_CHUNK]
        distance, index = _whole_query(tree, points[chunk], radius, min(MAX_BALL_POINTS, pool.size))
        member = index < pool.size
        theirs = pool[np.where(member, index, 0)]
        reach = np.where(member, distance, 0.0).max(axis=1)
        step = np.where(member[..., None], points[theirs] - points[chunk][:, None, :], 0.0)
        mean = step.sum(axis=1) / np.maximum(member.sum(axis=1), 1)[:, None]
        across = mean - np.einsum("mj,mj->m", mean, normals[chunk])[:, None] * normals[chunk]
        one_sided = np.sqrt(np.einsum("mj,mj->m", across, across)) > RIM_OFFSET * reach
        rim[start : start + chunk.size] = one_sided
        rows = np.flatnonzero(one_sided)  # (their point nearest the centroid: the rim's rows only)
        gap = step[rows] - mean[rows][:, None, :]
        apart = np.where(member[rows], np.einsum("mkj,mkj->mk", gap, gap), np.inf)
        inner[start + rows] = theirs[rows, np.argmin(apart, axis=1)]
    return rim, inner


def _agreement(found, larger, centres, lattice):
    """(M,) the share of |k| within which the jets over balls of two sizes must agree at ``centres`` (M,):
    :data:`LATTICE_AGREEMENT` on a ``lattice`` where the largest |k| falls from the ball (``found``) to the larger
    one (``larger``), the staircase's bias (a curvature's own bias grows with the ball); :data:`AGREEMENT` elsewhere."""
    agreement = np.full(centres.size, AGREEMENT)
    if centres.size == 0 or not lattice.steps.any():
        return agreement
    with np.errstate(invalid="ignore"):
        falls = np.maximum(np.abs(found[0][centres]), np.abs(found[1][centres])) > np.maximum(
            np.abs(larger[0][centres]), np.abs(larger[1][centres])
        )
    agreement[falls] = LATTICE_AGREEMENT
    return agreement


def erratic(k_min, k_max, indices, valid, spacing) -> np.ndarray:
    """(N,) bool: the ``valid`` points whose estimate its nearest neighbours' do not reproduce.

    The balls of a point and of its :data:`~meshcurv._pointcloud_normals.NEIGHBOURS` nearest neighbours
    ``indices`` (N, k) (a spacing or two apart) hold nearly the same points: on a surface the estimator resolves
    their estimates differ by the change of the curvature over a spacing or two. A point whose principal
    curvatures differ from its neighbours' estimates (those that have one, valid or not; none: flagged) by
    more than :data:`NEIGHBOUR_AGREEMENT` times the smaller
    largest |k| (median over the neighbours; at least ``FLAT_TURN / (3 spacing)``) is measured by a fit that
    follows noise, or by balls whose content changes abruptly (a rim sharper than the sampling): NaN.
    """
    n = k_min.shape[0]
    compiled = numba_kernels("pointcloud")
    if compiled is not None:  # the same median, compiled (1M points: about 0.05 CPU s instead of 2.4)
        typical = compiled.neighbour_differences(
            np.ascontiguousarray(k_min, dtype=np.float64),
            np.ascontiguousarray(k_max, dtype=np.float64),
            np.ascontiguousarray(indices, dtype=np.int64),
            np.ascontiguousarray(valid, dtype=bool),
            np.ascontiguousarray(spacing, dtype=np.float64),
            float(FLAT_TURN),
            64 * kernel_threads(),
        )
    else:
        typical = _neighbour_differences(k_min, k_max, indices, valid, spacing)
    out = np.zeros(n, dtype=bool)
    out[valid] = ~(typical[valid] <= NEIGHBOUR_AGREEMENT)  # (no neighbour with an estimate: nothing reproduces it)
    return out


def _neighbour_differences(k_min, k_max, indices, valid, spacing) -> np.ndarray:
    """(N,) the ``typical`` of :func:`erratic` (NaN where no neighbour has an estimate): the NumPy path of
    :func:`meshcurv._kernels.pointcloud.neighbour_differences`."""
    estimated = np.isfinite(k_min) & np.isfinite(k_max)
    safe = np.where(valid[:, None] & estimated[indices], indices, -1)
    # (a point left out of the estimate has spacing 0: its scale is infinite; it has no estimate to keep)
    with np.errstate(invalid="ignore", divide="ignore"):
        own = np.stack([k_min, k_max], axis=1)
        theirs = np.where((safe >= 0)[..., None], own[np.maximum(safe, 0)], np.nan)
        largest = np.minimum(np.abs(own).max(axis=1)[:, None], np.abs(theirs).max(axis=2))
        scale = np.maximum(largest, FLAT_TURN / (3.0 * spacing)[:, None])
        apart = np.abs(theirs - own[:, None, :]).max(axis=2) / scale
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            return np.nanmedian(apart, axis=1)


def unsteady_problem(flagged: np.ndarray, *, beside: bool = False) -> list[str]:
    """The phrase of the call's warning for the ``flagged`` (N,) points of :func:`unsteady`, :func:`erratic` and
    :func:`turned` (``beside``: of :func:`beside_unresolved`); none when none."""
    if not flagged.any():
        return []
    found = (
        f"more than {UNRESOLVED_SHARE:g} of the ball's own side has no resolved estimate and the normal turns by "
        f"more than {UNRESOLVED_TURN:g} rad over it (the band by a rim sharper than the ball, whose curvature the "
        "ball takes in)"
        if beside
        else f"the estimate changed by more than {AGREEMENT:g} of |k| over a ball {LARGER:.3g} times larger (jets: "
        f"{LATTICE_AGREEMENT:g} on a voxel surface read as a cloud where |k| falls with the ball, its staircase's "
        f"bias; there jets also differing from the corrected measures over the same balls by more than "
        f"{STAIRCASE_AGREEMENT:g} of |k|), "
        f"differs from its neighbours' by more than {NEIGHBOUR_AGREEMENT:g} of |k|, or from jets over the same "
        f"balls by more than {TURN_AGREEMENT:g} of |k| where they turn by more than {BALL_TURN:g} rad (a rim or "
        "part sharper than the ball, the other side of a thin part, or noise the fit follows), or no jet fits one "
        f"side of it where they turn by more than {THIN_TURN:g} rad (a part thinner than the ball)"
    )
    return [f"at {int(flagged.sum())} points {found}: NaN"]


def _jet_curvatures(coefficients, frame, radii, normals):
    """``(k_min, k_max, dir_min, dir_max, normals)`` of jets ``coefficients`` (N, 6) in units of their ``radii``
    (N,), fitted in ``frame``; NaN (and the given ``normals``) where a fit failed (:func:`~meshcurv.jets.jet_curvatures`)."""
    return jet_curvatures(coefficients, frame, radii, normals)


def unsteady(found, larger, centres, radius, agreement: float | np.ndarray = AGREEMENT) -> np.ndarray:
    """(N,) bool: the ``centres`` whose estimate ``found`` (``k_min, k_max, ...``) over balls of ``radius`` is
    not reproduced by the estimate ``larger`` over balls :data:`LARGER` times larger: a principal curvature off by
    more than ``agreement`` (a share, or one per centre) times the smaller largest |k| of the two (and at least
    ``FLAT_TURN / radius``), or no estimate there.

    An estimate over a ball is a measurement of the surface when it does not depend on the ball: where the ball
    resolves the surface (radius of curvature, thickness and features larger than the ball, noise averaged out)
    both estimates agree to within their small error. A rim sharper than the ball or a curvature that changes
    several times within it, the other side of a thin part or of a neighbouring one, or noise that a fit
    follows, weigh differently in the two balls.
    """
    n = found[0].shape[0]
    out = np.zeros(n, dtype=bool)
    if centres.size == 0:
        return out
    a_min, a_max, b_min, b_max = found[0][centres], found[1][centres], larger[0][centres], larger[1][centres]
    with np.errstate(invalid="ignore"):  # (the pairs' largest by np.maximum, NaN kept: no (M, 2) stacks to reduce)
        largest = np.minimum(np.maximum(np.abs(a_min), np.abs(a_max)), np.maximum(np.abs(b_min), np.abs(b_max)))
        scale = np.maximum(largest, FLAT_TURN / radius)
        close = np.maximum(np.abs(a_min - b_min), np.abs(a_max - b_max)) <= agreement * scale
    out[centres] = ~close
    return out


def _uniform_balls(points, normals, found, radius, centres, usable) -> np.ndarray:
    """(M,) bool: the ``centres`` (M,) whose ball of ``radius`` holds, on its own side (normals within 90 degrees
    of the centre's), no estimate of ``found`` whose largest |k| is below :data:`UNIFORM_SHARE` of the centre's:
    a curvature steady over the ball, which the measures resolve even where the ball is large against it (the
    tube of a thin torus under noise, whose jets over smaller balls follow the noise)."""
    from scipy.spatial import cKDTree

    pool = np.flatnonzero(usable)
    if pool.size == 0:
        return np.zeros(centres.size, dtype=bool)
    with np.errstate(invalid="ignore"):
        largest = np.maximum(np.abs(found[0]), np.abs(found[1]))
    tree = cKDTree(points[pool])
    out = np.zeros(centres.size, dtype=bool)
    for start in range(0, centres.size, MEASURE_CHUNK):
        chunk = centres[start : start + MEASURE_CHUNK]
        _, index = _whole_query(tree, points[chunk], radius, min(MAX_BALL_POINTS, pool.size))
        member = index < pool.size
        theirs = pool[np.where(member, index, 0)]
        with np.errstate(invalid="ignore"):
            own = member & (np.einsum("mkj,mj->mk", normals[theirs], normals[chunk]) > 0)
            low = own & (largest[theirs] < UNIFORM_SHARE * largest[chunk][:, None])
        out[start : start + chunk.size] = ~low.any(axis=1)
    return out


def beside_unresolved(points, normals, k_min, k_max, radii, resolved, tree) -> np.ndarray:
    """(N,) bool: the ``resolved`` points whose estimate takes in a region the estimator does not resolve.

    A point's estimate over its ball (radius ``radii`` (N,)) is an average over the ball's own side (the points
    whose ``normals`` are within 90 degrees of its own). Where more than :data:`UNRESOLVED_SHARE` of those points
    have no resolved estimate (``resolved`` (N,) False: unsteady, undecided, no one-sided fit) and the normal turns
    by more than :data:`UNRESOLVED_TURN` over the ball (``radius |k|``), the unresolved part weighs on the
    estimate as much as the point's own surroundings: the band by the rim of a plate a few spacings thick, whose
    curvature grows a hundredfold within the ball (seeds 42 and 4242 of ``benchmarks/fuzz_api.py``: k_max twice
    the exact one for both estimators, steady over a larger ball, each neighbour's alike). ``tree``: a
    :class:`scipy.spatial.cKDTree` of ``points``.
    """
    with np.errstate(invalid="ignore"):
        turn = radii * np.maximum(np.abs(k_min), np.abs(k_max))
    return _unresolved_balls(
        points, normals, radii, resolved, resolved & (turn > UNRESOLVED_TURN), tree, UNRESOLVED_SHARE
    )


def _unresolved_balls(points, normals, radii, resolved, candidates, tree, share: float) -> np.ndarray:
    """(N,) bool: the ``candidates`` (N,) bool more than ``share`` of whose ball's own side (the
    :data:`MAX_BALL_POINTS` nearest within ``radii`` (N,) whose ``normals`` are within 90 degrees of the centre's)
    is not ``resolved`` (N,) bool."""
    out = np.zeros(points.shape[0], dtype=bool)
    for chunk, safe, _, member, cosine in _balls(
        points, normals, radii, np.flatnonzero(candidates), tree, MAX_BALL_POINTS
    ):
        own = member & (cosine > 0)
        unresolved = (own & ~resolved[safe]).sum(axis=1)
        out[chunk] = unresolved > share * np.maximum(own.sum(axis=1), 1)
    return out


#: On a staircase (a lattice of three axes), a resolved estimate whose ball's own side holds more than this share of
#: points without a resolved estimate is unsteady (:func:`amid_unresolved`).
LATTICE_UNRESOLVED_SHARE = 0.7


def amid_unresolved(points, normals, radii, resolved, tree, lattice: Lattice) -> np.ndarray:
    """(N,) bool: on a staircase (a ``lattice`` of three axes), the ``resolved`` (N,) points more than
    :data:`LATTICE_UNRESOLVED_SHARE` of whose ball's own side (the points within ``radii`` (N,) whose ``normals``
    are within 90 degrees of the centre's, the :data:`MAX_BALL_POINTS` nearest) have no resolved estimate.

    On a voxel surface the staircase biases neighbouring estimates alike (its steps are coherent, no noise that
    averages out): where the checks left most of a ball unresolved (treads, single steps, facets, estimates that a
    larger ball or the neighbours do not reproduce), the staircase is what the estimator sees there, and the
    estimates that passed are a band of the same region, biased alike (the ring left on the flat faces of voxel
    ellipsoids 10-12 voxels thick, whose normal fits shrink to their half thickness:
    ``tests/test_pointcloud_staircase_regions.py``). The converse of :func:`alone` over the whole ball, on a
    staircase only (elsewhere, under noise, neighbours fail at random). ``tree``: a
    :class:`scipy.spatial.cKDTree` of ``points``.
    """
    if not lattice.steps.all():
        return np.zeros(points.shape[0], dtype=bool)
    return _unresolved_balls(points, normals, radii, resolved, resolved, tree, LATTICE_UNRESOLVED_SHARE)


def amid_unresolved_problem(flagged: np.ndarray) -> list[str]:
    """The phrase of the call's warning for the ``flagged`` (N,) points of :func:`amid_unresolved`; none when none."""
    return _nan_phrase(
        flagged,
        f"more than {LATTICE_UNRESOLVED_SHARE:g} of the ball's own side has no resolved estimate on a voxel "
        "surface read as a cloud (its staircase is what the estimator sees there; the estimates that passed are "
        "biased alike)",
    )


def _balls(points, normals, radii, centres, tree, k):
    """Per chunk of ``centres`` (by radius), ``(chunk, safe, distance, member, cosine)``: (M, k) the indices of the
    ``k`` nearest points within ``radii`` (N,) of each centre (the centre first; 0 where none), their distances,
    which are points, and the cosines of their ``normals`` with the centre's (NaN-free where not members)."""
    n = points.shape[0]
    k = min(k, n)
    for radius in np.unique(radii[centres]):
        group = centres[radii[centres] == radius]
        for start in range(0, group.size, MEASURE_CHUNK):
            chunk = group[start : start + MEASURE_CHUNK]
            distance, index = _whole_query(tree, points[chunk], radius, k)
            member = index < n
            safe = np.where(member, index, 0)
            with np.errstate(invalid="ignore"):
                cosine = np.einsum("mkj,mj->mk", normals[safe], normals[chunk])
            yield chunk, safe, distance, member, cosine


def _whole_query(tree, queries, radius: float, k: int) -> tuple[np.ndarray, np.ndarray]:
    """(M, k) distances and indices of the ``k`` nearest points of the k-d ``tree`` closer than ``radius`` to each
    of ``queries`` (M, 3), padded as :meth:`scipy.spatial.cKDTree.query` pads them (inf, ``tree.n``), less the
    points tied (within :data:`~meshcurv._pointcloud_normals.TIE_TOLERANCE`) with ``radius`` or with the ``k +
    1``-th nearest (unless fewer than :data:`MIN_BALL_POINTS` would be left): the balls of the checks, decided by
    the geometry, not by the order in which the tree met a lattice's points at one distance (see
    :func:`_whole_ties`)."""
    m = queries.shape[0]
    wanted = min(k + 1, tree.n)
    distance, index = tree.query(queries, k=wanted, distance_upper_bound=radius)
    distance, index = np.asarray(distance).reshape(m, -1), np.asarray(index).reshape(m, -1)
    drop = distance >= radius * (1.0 - TIE_TOLERANCE)  # (the padding too)
    if wanted > k:
        tied = distance[:, :k] >= distance[:, k:] * (1.0 - TIE_TOLERANCE)
        enough = (~tied & ~drop[:, :k]).sum(axis=1) >= MIN_BALL_POINTS
        distance, index, drop = distance[:, :k], index[:, :k], drop[:, :k] | (tied & enough[:, None])
    return np.where(drop, np.inf, distance), np.where(drop, tree.n, index)


def blended(points, normals, found, radii, resolved, tree, sheets=None) -> np.ndarray:
    """(N,) bool: the ``resolved`` points whose estimate is a blend of a region where the curvature changes.

    On a surface whose curvature the ball resolves, the normals of the ball's own side (within 90 degrees of the
    centre's ``normals``, of its sheet when ``sheets`` (N,) is given; the :data:`MAX_BALL_POINTS` nearest within
    ``radii`` (N,)) are those of the estimate's shape operator: the tangent part of the normal at an offset ``d``
    is ``k_min (d . e_min) e_min + k_max (d . e_max) e_max`` (exactly so on a sphere and a cylinder; to second
    order elsewhere). Where the ball turns the normal by more than :data:`BLEND_TURN` radians (``radius |k|``) and
    the :data:`BLEND_QUANTILE` quantile of the differences exceeds :data:`BLEND_RESIDUAL` times the turn out to
    the farthest of those points, the curvature changes across the ball by about itself: the estimate averages
    the band by the rim of a thin plate (whose curvature grows a hundredfold within the ball; every estimate of
    the band alike, so neither a larger ball nor the neighbours tell), or a ball larger than a small part. ``found``: ``(k_min, k_max, dir_min,
    dir_max)``; ``tree``: a :class:`scipy.spatial.cKDTree` of ``points``.
    """
    with np.errstate(invalid="ignore"):
        turn = radii * np.maximum(np.abs(found[0]), np.abs(found[1]))
    candidates = np.flatnonzero(resolved & (turn > BLEND_TURN))
    out = np.zeros(points.shape[0], dtype=bool)
    if candidates.size:
        residual, reached = blend_residuals(points, normals, found, radii, candidates, tree, sheets)
        out[candidates] = residual[candidates] > BLEND_RESIDUAL * reached[candidates]  # (NaN: too few, not flagged)
    return out


def blend_residuals(points, normals, found, radii, centres, tree, sheets=None) -> tuple[np.ndarray, np.ndarray]:
    """``(residual, turn)``: (N,) the :data:`BLEND_QUANTILE` quantile over each ball's own side of how far its
    normals are from those the estimate predicts, and the normal's turn over it (NaN outside ``centres`` and at
    balls of fewer than :data:`MIN_BALL_POINTS` points); see :func:`blended`."""
    n = points.shape[0]
    out, turns = np.full(n, np.nan), np.full(n, np.nan)
    k_min, k_max, dir_min, dir_max = found[:4]
    for chunk, safe, distance, member, cosine in _balls(points, normals, radii, centres, tree, MAX_BALL_POINTS + 1):
        own = member & (safe != chunk[:, None]) & (cosine > 0)
        if sheets is not None:
            theirs, mine = sheets[safe], sheets[chunk][:, None]
            own &= (theirs == mine) | (theirs < 0) | (mine < 0)
        offsets = points[safe] - points[chunk][:, None, :]
        # the tangent part of each normal, and the one the estimate's shape operator predicts (exact on a sphere
        # and a cylinder: the tangent parts of normal and offset are proportional there)
        tilt = normals[safe] - cosine[..., None] * normals[chunk][:, None, :]
        along_min = np.einsum("mkj,mj->mk", offsets, dir_min[chunk])
        along_max = np.einsum("mkj,mj->mk", offsets, dir_max[chunk])
        predicted = (k_min[chunk][:, None] * along_min)[..., None] * dir_min[chunk][:, None, :] + (
            k_max[chunk][:, None] * along_max
        )[..., None] * dir_max[chunk][:, None, :]
        residual = np.where(own, np.linalg.norm(tilt - predicted, axis=2), np.nan)
        reach = np.where(own, distance, 0.0).max(axis=1)
        enough = own.sum(axis=1) >= MIN_BALL_POINTS
        if enough.any():
            out[chunk[enough]] = np.nanquantile(residual[enough], BLEND_QUANTILE, axis=1)
            turns[chunk[enough]] = (reach * np.maximum(np.abs(k_min[chunk]), np.abs(k_max[chunk])))[enough]
    return out, turns


def _nan_phrase(flagged: np.ndarray, what: str) -> list[str]:
    """``["at <count> points <what>: NaN"]`` for the ``flagged`` (N,) points of a check; none when none."""
    return [f"at {int(flagged.sum())} points {what}: NaN"] if flagged.any() else []


def blended_problem(flagged: np.ndarray) -> list[str]:
    """The phrase of the call's warning for the ``flagged`` (N,) points of :func:`blended`; none when none."""
    return _nan_phrase(
        flagged,
        f"the ball turns the normal by more than {BLEND_TURN:g} rad and its normals differ from those of the "
        f"estimate by more than {BLEND_RESIDUAL:g} of that turn (the curvature changes across the ball by about "
        "itself: the band by the rim of a thin part, or a ball larger than a small part)",
    )


def wide_jets(k_min, k_max, radii, resolved) -> np.ndarray:
    """(N,) bool: the ``resolved`` jets whose ball of ``radii`` (N,) turns the normal by more than
    :data:`JET_MEAN_TURN` radians on average over the directions (``radius |H|``, from the estimate ``k_min``,
    ``k_max`` (N,)): a ball about as large as the radius of curvature, where the degree-3 jet's bias on H exceeds
    about 0.3 of |k| (a sphere in the ball of a sparser density class, or of a radius cut to the cloud's extent)."""
    with np.errstate(invalid="ignore"):
        turn = radii * np.abs(k_min + k_max) / 2
    return resolved & (turn > JET_MEAN_TURN)  # (NaN: no estimate, not flagged)


def wide_jets_problem(flagged: np.ndarray) -> list[str]:
    """The phrase of the call's warning for the ``flagged`` (N,) points of :func:`wide_jets`; none when none."""
    return _nan_phrase(
        flagged,
        f"the jet's ball turns the normal by more than {JET_MEAN_TURN:g} rad on average (radius |H|: a ball about "
        "as large as the radius of curvature, where a degree-3 jet's H is off by 0.3 of |k| or more)",
    )


def alone(resolved, indices) -> np.ndarray:
    """(N,) bool: the ``resolved`` points none of whose nearest neighbours ``indices`` (N, k) is resolved.

    Their balls hold nearly the same points (a spacing or two apart): where every neighbour's estimate was found
    unsteady, one-sided fits failed or the side is undecided, the estimator does not resolve the region, and the
    one estimate that passed is the luck of the draw (seed 142 case 366 of ``benchmarks/fuzz_api.py``: a point of
    a plate 3.7 spacings thick under noise, its fit shrunk to 3 spacings, H -464 against 116 amid 24 unsteady
    neighbours whose estimates scatter from -250 to 1,560; its ball turns the normal by 0.14 rad, below the checks
    of :func:`beside_unresolved` and :func:`blended`).
    """
    out = np.zeros(resolved.shape[0], dtype=bool)
    # (only where the nearest neighbour is unresolved: at 1M random indices 10 ms of CPU instead of 44)
    candidates = np.flatnonzero(resolved & ~resolved[indices[:, 0]])
    out[candidates] = ~resolved[indices[candidates]].any(axis=1)
    return out


def alone_problem(flagged: np.ndarray) -> list[str]:
    """The phrase of the call's warning for the ``flagged`` (N,) points of :func:`alone`; none when none."""
    return _nan_phrase(
        flagged,
        "none of the nearest neighbours has a resolved estimate (a region the estimator does not resolve; the one "
        "estimate there is the luck of the draw)",
    )


def small_balls(radius: float, spacing: np.ndarray, needed: float) -> tuple[np.ndarray, bool]:
    """``(sparse, noisy)`` of balls of a given ``radius`` at points of local ``spacing`` (M,): (M,) bool, the
    balls too small to hold the :data:`~meshcurv._pointcloud_normals.NEIGHBOURS` nearest points (a disc of
    ``sqrt(10 / pi)`` spacings: the 10 coefficients of a degree-3 jet, triangles of more than a few points),
    whose estimate is undefined; and whether ``radius`` is below :data:`SMALL_BALL` times the radius ``needed``
    by the noise (:func:`meshcurv.radius.cloud_radius`), where the fits follow the noise (unsteady).

    Given radii of 0.4-1.4 spacings left 1-10 valid points off by 50-5000% in balls that happened to hold 6
    points; jets over 3 spacings under noise of 0.1-0.2 spacings (the noise calls for 7-9), 1-8 points in 150.
    """
    sparse = radius < np.sqrt(NEIGHBOURS / np.pi) * spacing
    return sparse, bool(radius < SMALL_BALL * needed)


def small_ball_problem(radius: float, needed: float) -> str:
    """The phrase of the call's warning for a given ``radius`` below :data:`SMALL_BALL` times the one ``needed``."""
    return (
        f"the given radius {radius:.3g} is below {SMALL_BALL:g} times the {needed:.3g} that the noise calls for: "
        "the fits follow the noise, the estimates are unsteady (NaN)"
    )


def disagree(found, jets, centres, radius) -> np.ndarray:
    """(N,) bool: the ``centres`` whose measures ``found`` (``k_min, k_max, ...``) over balls of ``radius`` the
    curvatures ``jets`` (``k_min, k_max, radii``) of their normals' jet fits (:func:`fitted_normals`) do not
    reproduce, as :func:`unsteady` compares. Centres whose jet's normal turns by more than :data:`JET_TURN` over
    its ball (``radius |k|``), or without a jet fit, are not compared: a jet over such a ball is no reference.

    Two estimators of another kind over other balls (an integral of the normals' variation; a polynomial's second
    fundamental form) agree where both resolve the surface. The measures alone drift where the curvature grows
    steeply across the ball (the band by the rim of a plate 0.1-0.2 thick: k_max twice the exact one, with the
    exact normals too, steady over a ball sqrt(2) larger), and follow the noise of normals fitted over balls shrunk
    by a thin part; the jets did neither.
    """
    centres = np.asarray(centres, dtype=np.int64)
    k_min, k_max, radii = jets
    with np.errstate(invalid="ignore"):
        turn = radii[centres] * np.maximum(np.abs(k_min[centres]), np.abs(k_max[centres]))
    compared = centres[turn <= JET_TURN]  # (NaN where no fit: not compared)
    return unsteady(found, (k_min, k_max), compared, radius)


def staircase_disagree(tree, points, normals, found, radius, centres, usable, *, normal_radius, spacing, sheets):
    """(N,) bool: on a lattice, the ``centres`` whose jets ``found`` (``k_min, k_max, ...``) over balls of
    ``radius`` the corrected measures over the same balls do not reproduce within :data:`STAIRCASE_AGREEMENT`, as
    :func:`unsteady` compares; a centre with no measure is flagged. The measures take the normals of jets over
    balls of ``normal_radius`` from the oriented ``normals`` (``None``: the ``normals`` themselves, given).

    A voxel surface read as a cloud is a staircase: the jets fit the positions, and the steps bias neighbouring
    balls alike (a ball on one facet of a diagonal slope reads 0, a ball over a tread's edge up to 1.7 times |k|),
    so that the check over a larger ball and the neighbours' agree with a wrong value. The measures integrate the
    normals' variation, which the steps bias little (on the voxel spheres, ellipsoids and tori of
    ``benchmarks/pointcloud_diagnostics.md``, "Jets against the measures on a staircase"): the converse of
    :func:`disagree`.
    """
    centres = np.asarray(centres, dtype=np.int64)
    compared = centres[np.isfinite(found[0][centres])]
    if compared.size == 0 or not np.any(usable):  # no jet to check, or no point to measure one (all left out)
        flagged = np.zeros(points.shape[0], dtype=bool)
        flagged[compared] = True
        return flagged
    if normal_radius is not None:
        normals = fitted_normals(points, normals, normal_radius, centres, usable, smallest=normal_radius)
    measured = corrected_measures(tree, points, normals, radius, centres, usable, spacing=spacing, sheets=sheets)
    return unsteady(found, measured, compared, radius, STAIRCASE_AGREEMENT)


def fitted_normals(points, normals, radius, centres, usable, *, smallest: float, details: dict | None = None):
    """(N, 3) normals of degree-3 jets over balls of ``radius`` (``normals`` kept where a fit fails).

    Where a ball holds the other side of the surface (a part thinner than the
    ball) the fit is redone over a smaller one, down to ``smallest``
    (:func:`one_sided_fits`); ``details`` receives ``"radii"``, (N,) the
    radius of each point's fit, and ``"jets"``, ``(k_min, k_max)`` (N,) of the
    same jets (a second estimate of the curvatures, see :func:`disagree`).
    """
    logger.debug("point cloud: normal fits")
    coefficients, frame, radii = one_sided_fits(
        points, normals, radius, centres, usable, smallest=smallest, degree=3, iterations=NORMAL_ITERATIONS
    )
    if details is not None:
        details["radii"] = radii
        details["jets"] = (*_jet_curvatures(coefficients, frame, radii, normals)[:2], radii)
    logger.debug("point cloud: measures")
    fitted = jet_normals(coefficients, frame)
    ok = np.isfinite(fitted).all(axis=1)
    return np.where(ok[:, None], fitted, normals)


def _rank_pattern(n_triangles: int) -> np.ndarray:
    """(T, 3) fixed uniform numbers in [0, 1): the same random pattern of ranks for every point."""
    return np.random.default_rng(20230517).random((n_triangles, 3))


def _distinct_ranks(pattern: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """(M, T, 3) three distinct ranks below ``counts`` (>= 3) per triangle, uniform over the triples."""
    c = counts[:, None].astype(float)
    a = np.floor(pattern[None, :, 0] * c).astype(np.int64)
    b = np.floor(pattern[None, :, 1] * (c - 1)).astype(np.int64)
    b += b >= a
    z = np.floor(pattern[None, :, 2] * (c - 2)).astype(np.int64)
    low, high = np.minimum(a, b), np.maximum(a, b)
    z += z >= low
    z += z >= high
    return np.stack([a, b, z], axis=2)


def _triangle_sums(points, normals, index, counts, pattern):
    """(M, 9) summed measures of the triangles of each ball: the NumPy path of the compiled kernel.

    Each triangle's measures as :func:`meshcurv._kernels.icc._triangle_measures` computes them, term by term in
    its order, and summed triangle after triangle as the kernel sums them: the same sums to the bit (the
    closed forms of :func:`meshcurv.measures.face_measures` in another order gave sums an ulp apart, and a
    ball's ``k = H -/+ sqrt(H^2 - K)`` near an umbilic takes the square root of that: 2.6e-9 apart on an
    icosphere).
    """
    m, n_triangles = index.shape[0], pattern.shape[0]
    ranks = _distinct_ranks(pattern, counts)
    triangles = np.take_along_axis(index[:, None, :], ranks.reshape(m, 1, -1), axis=2).reshape(m, n_triangles, 3)
    i, j, k = triangles[..., 0], triangles[..., 1], triangles[..., 2]
    p0, p1, p2 = points[i], points[j], points[k]
    ax, ay, az = p1[..., 0] - p0[..., 0], p1[..., 1] - p0[..., 1], p1[..., 2] - p0[..., 2]
    bx, by, bz = p2[..., 0] - p0[..., 0], p2[..., 1] - p0[..., 1], p2[..., 2] - p0[..., 2]
    u0, u1, u2 = normals[i], normals[j], normals[k]
    u0x, u0y, u0z = u0[..., 0], u0[..., 1], u0[..., 2]
    u1x, u1y, u1z = u1[..., 0], u1[..., 1], u1[..., 2]
    u2x, u2y, u2z = u2[..., 0], u2[..., 1], u2[..., 2]
    sx, sy, sz = u0x + u1x + u2x, u0y + u1y + u2y, u0z + u1z + u2z
    cx, cy, cz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
    # a triangle edge-on to its corners' normals, or flat, adds nothing: its sign would be round-off (EDGE_ON;
    # Euclidean lengths, which no rotation changes)
    tolerance = EDGE_ON * EDGE_ON
    area = cx * cx + cy * cy + cz * cz
    facing = sx * cx + sy * cy + sz * cz
    edge_on = facing * facing <= tolerance * (sx * sx + sy * sy + sz * sz) * area
    edge_on |= area <= tolerance * (ax * ax + ay * ay + az * az) * (bx * bx + by * by + bz * bz)
    mx, my, mz = sx / 3, sy / 3, sz / 3
    # turned so that its normal agrees with the mean of its corners' normals: (i, j, k) -> (i, k, j)
    flip = mx * cx + my * cy + mz * cz < 0
    ax, bx = np.where(flip, bx, ax), np.where(flip, ax, bx)
    ay, by = np.where(flip, by, ay), np.where(flip, ay, by)
    az, bz = np.where(flip, bz, az), np.where(flip, az, bz)
    u1x, u2x = np.where(flip, u2x, u1x), np.where(flip, u1x, u2x)
    u1y, u2y = np.where(flip, u2y, u1y), np.where(flip, u1y, u2y)
    u1z, u2z = np.where(flip, u2z, u1z), np.where(flip, u1z, u2z)
    cx, cy, cz = np.where(flip, -cx, cx), np.where(flip, -cy, cy), np.where(flip, -cz, cz)
    mu0 = 0.5 * (mx * cx + my * cy + mz * cz)
    px, py, pz = u0x - u2x, u0y - u2y, u0z - u2z
    qx, qy, qz = u1x - u0x, u1y - u0y, u1z - u0z
    tx = (py * az - pz * ay) + (qy * bz - qz * by)
    ty = (pz * ax - px * az) + (qz * bx - qx * bz)
    tz = (px * ay - py * ax) + (qx * by - qy * bx)
    mu1 = 0.5 * (mx * tx + my * ty + mz * tz)
    mu2 = 0.5 * (u0x * (u1y * u2z - u1z * u2y) + u0y * (u1z * u2x - u1x * u2z) + u0z * (u1x * u2y - u1y * u2x))
    gx, gy, gz = ay * mz - az * my, az * mx - ax * mz, ax * my - ay * mx
    hx, hy, hz = by * mz - bz * my, bz * mx - bx * mz, bx * my - by * mx
    ex, ey, ez = u2x - u0x, u2y - u0y, u2z - u0z
    measures = np.stack(
        [
            mu0,
            mu1,
            mu2,
            0.5 * (gx * ex - hx * qx),
            0.5 * (gy * ey - hy * qy),
            0.5 * (gz * ez - hz * qz),
            0.25 * ((gx * ey - hx * qy) + (gy * ex - hy * qx)),
            0.25 * ((gx * ez - hx * qz) + (gz * ex - hz * qx)),
            0.25 * ((gy * ez - hy * qz) + (gz * ey - hz * qy)),
        ],
        axis=2,
    )
    measures[edge_on] = 0.0
    summed = np.zeros((m, 9))
    for t in range(n_triangles):  # triangle after triangle, as the kernel adds them
        summed += measures[:, t]
    return summed


def ball_size(radius: float, spacing: float, most: int = MAX_BALL_POINTS) -> int:
    """Neighbours to query for balls of ``radius`` at this spacing: 1.3 times the expected count, at most ``most``.

    A fuller ball is cut to its nearest points (the error did not change
    between 1.2 and 2 times the expected count in ``benchmarks/pointcloud.py``,
    and the query's time grows with it).
    """
    expected = np.pi * (radius / spacing) ** 2 if spacing > 0 else most
    return int(min(most, max(2 * MIN_BALL_POINTS, np.ceil(1.3 * expected))))


def _usable_tree(tree, points, usable):
    """``(tree, pool)``: a k-d tree over the usable points and their indices (``tree`` and None when all are)."""
    if usable.all():
        return tree, None
    from scipy.spatial import cKDTree

    pool = np.flatnonzero(usable)
    return cKDTree(points[pool]), np.append(pool, points.shape[0])


def _ball_indices(search, points, chunk, radius, k):
    """(M, k) the ``k`` nearest usable points within ``radius`` of each centre of ``chunk`` and (M,) their count.

    The search of :func:`_measured_balls` (compiled: the grid search of
    :func:`meshcurv._kernels.pointcloud.measured_balls`): a query of the k-d
    tree of :func:`_usable_tree` (``search``); rows in the order of
    ``(squared distance, index)`` as the kernel's (the tree's own order of
    equal distances is not the index's: a lattice's ties), padded with ``N``.
    """
    tree, pool = search
    n = points.shape[0]
    asked = k
    while True:  # the tree orders equal distances as it meets them: ask past the k-th, then sort as the kernel
        wanted = max(k, min(asked + max(8, asked // 2), tree.n))  # (beyond tree.n: padded with tree.n)
        _, index = tree.query(points[chunk], k=wanted, distance_upper_bound=radius, workers=-1)
        index = index.reshape(chunk.size, -1)
        if pool is not None:
            index = pool[index]
        inside = index < n
        step = points[np.where(inside, index, 0)] - points[chunk][:, None, :]
        squared = step[..., 0] * step[..., 0] + step[..., 1] * step[..., 1] + step[..., 2] * step[..., 2]
        squared = np.where(inside & (squared < radius * radius), squared, np.inf)
        order = np.lexsort((np.where(np.isfinite(squared), index, n), squared), axis=-1)
        index = np.take_along_axis(np.where(np.isfinite(squared), index, n), order, axis=1)
        squared = np.take_along_axis(squared, order, axis=1)
        tied = np.isfinite(squared[:, -1]) & (squared[:, -1] == squared[:, min(k, wanted) - 1])
        if wanted >= tree.n or not tied.any():  # (a tie across the last asked: more may follow)
            break
        asked = 2 * wanted
    index = np.ascontiguousarray(index[:, :k])
    return index, (index < n).sum(axis=1)


def _measured_balls(search, points, normals, chunk, radius, k, wide, k_wide, sheets=None):
    """``(index, counts, wide_index, wide_counts)``: the balls of :func:`corrected_measures` of the centres
    ``chunk`` (M,), (M, k) and (M,) those of ``radius``, (M, k_wide) and (M,) those of ``wide`` (``k_wide`` 0: none).

    Each is searched with one point more than it holds (:func:`_ball_indices` over the k-d tree ``search`` of
    :func:`_usable_tree`), its ties cut whole (:func:`_whole_ties`) and its points facing away or on another of
    the ``sheets`` dropped (:func:`_own_side`). Compiled: :func:`meshcurv._kernels.pointcloud.measured_balls`
    (one search for both radii, each row cut in its thread's buffers: the same arrays to the bit).
    """
    index, counts = _ball_indices(search, points, chunk, radius, k + 1)
    index, counts = _whole_ties(points, normals, chunk, index, counts, radius, k)
    index, counts = _own_side(normals, chunk, index, counts, sheets)
    if k_wide == 0:
        return index, counts, np.full((chunk.size, 0), points.shape[0]), np.zeros(chunk.size, dtype=np.int64)
    wide_index, wide_counts = _ball_indices(search, points, chunk, wide, k_wide + 1)
    wide_index, wide_counts = _whole_ties(points, normals, chunk, wide_index, wide_counts, wide, k_wide)
    wide_index, wide_counts = _own_side(normals, chunk, wide_index, wide_counts, sheets)
    return index, counts, wide_index, wide_counts


#: Two squared distances from a centre within this share of the larger are one distance (twice
#: :data:`~meshcurv._pointcloud_normals.TIE_TOLERANCE`, of the distances): the points of a ball at one distance
#: (a lattice's) are taken or dropped whole at its cuts and ordered among themselves by the geometry
#: (:func:`_whole_ties`), not by the round-off of a pose or by their index.
SQUARED_TIE = 2 * TIE_TOLERANCE

#: Weights of the cosines of :func:`_tie_keys` (their ratios irrational: distinct points rarely share a key).
TIE_WEIGHTS = (0.6180339887498949, 0.41421356237309515, 0.3247179572447460)


def _whole_ties(points, normals, centres, index, counts, radius, k):
    """(M, k) the balls ``index`` (M, K) of the ``centres`` (M,) (rows in the order of ``(squared distance,
    index)``, ``counts`` points first, padded with N; ``K > k``: the next point after the ``k``-th when there is
    one) as the estimate's balls of ``radius`` and at most ``k`` points, and (M,) their counts.

    The triangles of :func:`corrected_measures` and the points that :func:`flat_balls` checks are ranks in the
    ball's distance order. On a lattice (a voxel surface, a mesh's vertices read as a cloud) many points of a
    ball lie at one distance, and round-off (a rotation, a shift: a few units of 1e-16 of the cloud's extent)
    or the index decided their order and which of them a cut kept: a voxel sphere of radius 14 turned by a
    rigid motion moved every estimate, by 0.9% of the largest |k| at the median and 5.4% at most. Here
    distances within :data:`SQUARED_TIE` (squared) are one distance: points tied with ``radius`` go; a row of
    more than ``k`` points loses its points tied with the ``k + 1``-th (unless fewer than
    :data:`MIN_BALL_POINTS` would be left: then its first ``k``); and each run of points tied with the one
    before is ordered by :func:`_tie_keys` (cosines of the offset and the normals, which rigid motions, shifts,
    scaling and re-indexing keep), keys within :data:`SQUARED_TIE` of the one before by index (points that even
    these cannot tell apart, a symmetry of the ball, whose keys round-off orders: the normals of the two backends,
    1e-15 apart, ordered an icosphere's vertices apart, 2e-4 of |k|). Compiled: each row of
    :func:`meshcurv._kernels.pointcloud.measured_balls` (``_whole_row``: the same operations, to the bit).
    """
    n = points.shape[0]
    member = np.arange(index.shape[1])[None, :] < counts[:, None]
    safe = np.where(member, index, centres[:, None])
    step = points[safe] - points[centres][:, None, :]
    squared = step[..., 0] * step[..., 0] + step[..., 1] * step[..., 1] + step[..., 2] * step[..., 2]
    inside = member & (squared < radius * radius * (1.0 - SQUARED_TIE))  # (a prefix: the rows ascend)
    found = inside.sum(axis=1)
    full = np.flatnonzero(found > k)
    if full.size:
        cut = squared[full, k] * (1.0 - SQUARED_TIE)
        keep = (squared[full, :k] < cut[:, None]).sum(axis=1)
        found[full] = np.where(keep >= MIN_BALL_POINTS, keep, k)
    inside = np.arange(index.shape[1])[None, :] < found[:, None]
    # runs of points tied with the one before, sorted by their keys (singletons keep their place)
    starts = np.ones(index.shape, dtype=bool)
    starts[:, 1:] = squared[:, :-1] < squared[:, 1:] * (1.0 - SQUARED_TIE)
    starts |= ~inside
    ends = np.ones(index.shape, dtype=bool)
    ends[:, :-1] = starts[:, 1:]
    tied = inside & ~(starts & ends)
    if tied.any():
        keys = np.zeros(index.shape)
        rows, cols = np.nonzero(tied)
        keys[rows, cols] = _tie_keys(points, normals, index[rows, cols], centres[rows])
        run = np.cumsum(starts, axis=1)
        order = np.lexsort((np.where(inside, index, n), keys, run), axis=-1)
        index, keys = np.take_along_axis(index, order, axis=1), np.take_along_axis(keys, order, axis=1)
        # keys within SQUARED_TIE of the one before (chains: a symmetry of the point and its normals, its keys
        # round-off apart) by their offsets' place against the ball's mean offset (:func:`_tie_turns`), and those
        # within SQUARED_TIE of the one before by index
        with np.errstate(invalid="ignore"):  # (inf - inf: NaN keys, one chain)
            chain = np.ones(index.shape, dtype=bool)
            chain[:, 1:] = starts[:, 1:] | (keys[:, 1:] - keys[:, :-1] > SQUARED_TIE)
        shared = chain.copy()
        shared[:, :-1] &= chain[:, 1:]  # (a chain of one point: nothing to order)
        rows, cols = np.nonzero(inside & ~shared)
        if rows.size:
            # (the ball's mean offset and its mean turn of the normals times the radius, in the order of (squared
            # distance, index): a direction of the ball's own where its points are a symmetry of the lattice)
            turn = normals[safe] - normals[centres][:, None, :]
            turn = np.where(inside[..., None] & np.isfinite(turn), turn, 0.0).sum(axis=1)
            offset = np.where(inside[..., None], step, 0.0).sum(axis=1)
            mean = (offset + radius * turn) / np.maximum(found, 1)[:, None]
            # (a centre without a normal: its ties by index, as its keys)
            mean[~(_dot(normals[centres], normals[centres]) > 0.0)] = 0.0
            turns = np.zeros(index.shape)
            turns[rows, cols] = _tie_turns(points, normals, index[rows, cols], centres[rows], mean[rows], radius)
            order = np.lexsort((np.where(inside, index, n), turns, np.cumsum(chain, axis=1)), axis=-1)
            index, turns = np.take_along_axis(index, order, axis=1), np.take_along_axis(turns, order, axis=1)
            with np.errstate(invalid="ignore"):
                chain[:, 1:] |= turns[:, 1:] - turns[:, :-1] > SQUARED_TIE
        order = np.lexsort((np.where(inside, index, n), np.cumsum(chain, axis=1)), axis=-1)
        index = np.take_along_axis(index, order, axis=1)
    out = np.where(inside, index, n)[:, :k]
    return np.ascontiguousarray(out), found


def _unit_offsets(points, members, centres) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The unit offsets (three (P,) components) from the points ``centres`` (P,) to ``members`` (P,) (0 where they
    coincide): :func:`meshcurv._kernels.pointcloud._unit_offset`'s operations."""
    step = points[members] - points[centres]
    dx, dy, dz = step[:, 0], step[:, 1], step[:, 2]
    length = np.sqrt(dx * dx + dy * dy + dz * dz)
    with np.errstate(invalid="ignore", divide="ignore"):
        safe = np.where(length > 0.0, length, 1.0)
        ux, uy, uz = (np.where(length > 0.0, d / safe, 0.0) for d in (dx, dy, dz))
    return ux, uy, uz


def _tie_keys(points, normals, members, centres) -> np.ndarray:
    """(P,) the keys of :func:`meshcurv._kernels.pointcloud._tie_key` of the points ``members`` (P,) in the balls of
    ``centres`` (P,), the same operations: ``n_c . u + w_1 n_j . u + w_2 n_c . n_j + w_3 n_c . (u x n_j)``
    (:data:`TIE_WEIGHTS`) of the unit offset ``u`` from ``c`` to ``j`` (0 where they coincide), +inf where NaN."""
    ux, uy, uz = _unit_offsets(points, members, centres)
    a, b = normals[centres], normals[members]
    ax, ay, az, bx, by, bz = a[:, 0], a[:, 1], a[:, 2], b[:, 0], b[:, 1], b[:, 2]
    height = ax * ux + ay * uy + az * uz
    slope = bx * ux + by * uy + bz * uz
    cosine = ax * bx + ay * by + az * bz
    twist = ax * (uy * bz - uz * by) + ay * (uz * bx - ux * bz) + az * (ux * by - uy * bx)
    key = height + TIE_WEIGHTS[0] * slope + TIE_WEIGHTS[1] * cosine + TIE_WEIGHTS[2] * twist
    return np.where(np.isnan(key), np.inf, key)


def _tie_turns(points, normals, members, centres, mean, radius) -> np.ndarray:
    """(P,) the keys of :func:`meshcurv._kernels.pointcloud._tie_turn` of the points ``members`` (P,) in the balls of
    ``centres`` (P,) whose balls' directions are ``mean`` (P, 3), the same operations: ``(u . g + w_0 n_c . (u x g)) /
    radius`` (:data:`TIE_WEIGHTS`) of the unit offset ``u`` from ``c`` to ``j`` (0 where they coincide) and ``g``
    the ball's mean offset plus ``radius`` times the mean turn of its normals from the centre's; +inf where NaN.

    Points at one distance whose :func:`_tie_keys` agree are a symmetry of the centre and the two normals: on a
    flat facet of a voxel staircase (every normal the same) every point of the facet at one distance, opposite
    points among them. Their order was their index, which the pose chose (the Morton order): their triangles and
    measures 0.04 of |k| apart (``fuzz_api.py --seed 771 --replay 19``). The ball's mean offset is a direction of
    the ball's own that rigid motions, scaling and re-indexing move with it; it tells them apart unless the ball
    is symmetric about its centre's normal too.
    """
    ux, uy, uz = _unit_offsets(points, members, centres)
    a = normals[centres]
    ax, ay, az, gx, gy, gz = a[:, 0], a[:, 1], a[:, 2], mean[:, 0], mean[:, 1], mean[:, 2]
    along = ux * gx + uy * gy + uz * gz
    twist = ax * (uy * gz - uz * gy) + ay * (uz * gx - ux * gz) + az * (ux * gy - uy * gx)
    key = (along + TIE_WEIGHTS[0] * twist) / radius
    return np.where(np.isnan(key), np.inf, key)


#: A point of a ball faces away from its centre when ``n_j . n_c < -FACING_MARGIN``. Not 0: on a lattice (a gridded
#: scan, a mesh's vertices) points at right angles have ``n_j . n_c`` of round-off, whose sign the two backends'
#: normals (equal to round-off) decide alike only by chance (``benchmarks/fuzz_api.md``, round 11); such points are
#: kept on both.
FACING_MARGIN = 1e-9


def _own_side(normals, centres, index, counts, sheets=None):
    """The balls ``index`` (M, k) (``counts`` points first, padded with N) less their points facing away.

    A point of the ball whose normal is opposite to the centre's
    (``n_j . n_c < -``:data:`FACING_MARGIN`) is on the other side of the surface: the other face
    of a part thinner than the ball, a neighbouring part of the cloud a
    spacing or two away, or the far side of a part smaller than the ball.
    Triangles through it would measure both sides as one surface (two
    spheres 1 spacing apart: H up to 5 times 1/r next to the gap). With
    ``sheets`` (N,) (:func:`meshcurv._pointcloud_normals.oriented_signs`),
    points of another sheet than the centre's go too (-1 matches any). The
    kept points stay in distance order. Returns ``(index, counts)``.
    """
    n = normals.shape[0]
    member = np.arange(index.shape[1])[None, :] < counts[:, None]
    safe = np.where(member, index, 0)
    away = member & (_dot(normals[safe], normals[centres][:, None, :]) < -FACING_MARGIN)  # (the kernel's sum)
    if sheets is not None:
        theirs, own = sheets[safe], sheets[centres][:, None]
        away |= member & (theirs != own) & (theirs >= 0) & (own >= 0)
    if not away.any():
        return index, counts
    order = np.argsort(away | ~member, axis=1, kind="stable")
    index = np.take_along_axis(np.where(away, n, index), order, axis=1)
    return np.ascontiguousarray(index), counts - away.sum(axis=1)


def flat_balls(points, centres, index, counts, rows=None) -> np.ndarray:
    """(M,) bool: the balls ``index`` (M, k) (``counts`` points first, padded with N) of the ``centres`` (M,)
    that hold a surface; (R,) of the balls ``rows`` (R,) only when given.

    See :func:`_flat_balls`; compiled: :func:`meshcurv._kernels.pointcloud.flat_balls` (which reads the rows in
    place).
    """
    compiled = numba_kernels("pointcloud")
    if compiled is None:
        if rows is not None:
            centres, index, counts = centres[rows], index[rows], counts[rows]
        return _flat_balls(points, centres, index, counts)
    return compiled.flat_balls(
        points,
        np.ascontiguousarray(centres),
        np.ascontiguousarray(index),
        np.ascontiguousarray(counts, dtype=np.int64),
        -(-index.shape[1] // SUPPORT_POINTS),
        SUPPORT_ITERATIONS,
        BALL_OFFSET,
        BALL_SHARE,
        BALL_SUPPORT,
        *(() if rows is None else (np.ascontiguousarray(rows, dtype=np.int64),)),
    )


def _flat_balls(points, centres, index, counts) -> np.ndarray:
    """The NumPy path of :func:`flat_balls`.

    A ball holds a surface when at least :data:`BALL_SUPPORT` and
    :data:`BALL_SHARE` of :data:`SUPPORT_POINTS` of its points (every few in distance order) lie farther than
    :data:`BALL_OFFSET` times the farthest one's distance from the line through the centre along their main
    direction (a few power iterations on their covariance): a ball of points on a line and one or two beside it (the end of a scan line,
    a line of points beside a few others) gives triangles of those few points only, and no surface.
    """
    stride = -(-index.shape[1] // SUPPORT_POINTS)  # every stride-th in distance order: the whole ball
    column = np.arange(0, index.shape[1], stride)
    member = column[None, :] < counts[:, None]
    offsets = points[np.where(member, index[:, column], centres[:, None])] - points[centres][:, None, :]
    scale = np.abs(offsets).max(axis=(1, 2))  # each ball in units of its extent: no overflow at 1e75, no underflow
    offsets /= np.where(scale > 0, scale, 1.0)[:, None, None]
    # (the kernel's operations in its order, member by member: the same decisions to the bit)
    squared = _dot(offsets, offsets)
    xx, xy, xz, yy, yz, zz = (np.zeros(index.shape[0]) for _ in range(6))
    for c in range(column.size):
        dx, dy, dz = offsets[:, c, 0], offsets[:, c, 1], offsets[:, c, 2]
        xx, xy, xz, yy, yz, zz = xx + dx * dx, xy + dx * dy, xz + dx * dz, yy + dy * dy, yz + dy * dz, zz + dz * dz
    ux, uy, uz = offsets[np.arange(index.shape[0]), np.argmax(squared, axis=1)].T
    for _ in range(SUPPORT_ITERATIONS):
        vx, vy, vz = xx * ux + xy * uy + xz * uz, xy * ux + yy * uy + yz * uz, xz * ux + yz * uy + zz * uz
        length = np.maximum(np.sqrt(vx * vx + vy * vy + vz * vz), np.finfo(float).tiny)
        ux, uy, uz = vx / length, vy / length, vz / length
    along = offsets[..., 0] * ux[:, None] + offsets[..., 1] * uy[:, None] + offsets[..., 2] * uz[:, None]
    across = squared - along * along
    far = squared.max(axis=1)
    beside = (across > BALL_OFFSET**2 * far[:, None]).sum(axis=1)
    return beside >= np.maximum(BALL_SUPPORT, BALL_SHARE * member.sum(axis=1))


def corrected_measures(
    tree,
    points,
    normals,
    radius,
    centres,
    usable,
    *,
    spacing: float = 0.0,
    n_triangles: int | None = None,
    sheets: np.ndarray | None = None,
    details: dict | None = None,
):
    """Randomized corrected curvature measures over balls of ``radius`` (Lachaud et al. 2023).

    For every centre, ``n_triangles`` triangles with corners drawn at random
    among the (at most :data:`MAX_BALL_POINTS` nearest) usable points of its
    ball, each turned so that its corrected area is positive; the
    interpolated corrected measures of :func:`meshcurv.measures.face_measures`
    of these triangles with the point normals, summed: ``H = mu_1 / (2 mu_0)``,
    ``K = mu_2 / mu_0``, ``k = H -/+ sqrt(max(H^2 - K, 0))``, the directions
    those of ``-sym(mu^{X,Y}) / mu_0`` in the tangent plane of the centre's
    normal. The draws are ranks in the ball's distance order from one fixed
    pattern (points at one distance taken whole and ordered by the geometry:
    :func:`_whole_ties`): the result does not depend on the order of the
    points, and moves with them under rigid motions and scaling. ``details`` receives
    ``"unsteady"`` (:func:`unsteady`: the estimates that the same measures
    over balls :data:`LARGER` times larger do not reproduce).
    """
    n = points.shape[0]
    out = [np.full(n, np.nan), np.full(n, np.nan), np.full((n, 3), np.nan), np.full((n, 3), np.nan)]
    if not usable.any():  # no point may enter a ball (every normal fit failed): nothing to measure
        if details is not None:
            details["unsteady"] = np.zeros(n, dtype=bool)
        return (*out, normals)
    pattern = _rank_pattern(TRIANGLES if n_triangles is None else n_triangles)
    kernels = numba_kernels("pointcloud")
    k = min(ball_size(radius, spacing), n)
    # the check of unsteady: the same measures over balls LARGER times larger, from the same search
    check = details is not None
    wide = radius * LARGER
    # (a ball cut to its nearest points is cut LARGER^2 times wider for the check, else both are the same points)
    k_wide = min(ball_size(wide, spacing, most=round(MAX_BALL_POINTS * LARGER**2)), n)
    # (the check reads the curvatures only: no (N, 3) directions of the larger balls, 48 MB at 1M points)
    larger = [np.full(n, np.nan), np.full(n, np.nan), None, None] if check else []
    if kernels is not None:  # the grid of the compiled ball searches, once for all the chunks
        grid = numba_kernels("neighborhoods").pool_grid(
            points, np.flatnonzero(usable), float(wide if check else radius)
        )
        own_sheets = np.zeros(0, dtype=np.int64) if sheets is None else np.ascontiguousarray(sheets, dtype=np.int64)
    else:
        search = _usable_tree(tree, points, usable)
    size = MEASURE_CHUNK if kernels is not None else max(1, TRIANGLE_CHUNK // pattern.shape[0])
    for start in range(0, centres.size, size):
        chunk = centres[start : start + size]
        logger.debug("point cloud: ball search")
        # one search for both balls (the smaller: the prefix of the larger closer than radius), cut and turned
        if kernels is not None:
            index, counts, wide_index, wide_counts = kernels.measured_balls(
                points,
                normals,
                chunk,
                float(radius),
                k,
                float(wide),
                k_wide if check else 0,
                *grid,
                own_sheets,
                SQUARED_TIE,
                MIN_BALL_POINTS,
                FACING_MARGIN,
                64 * kernel_threads(),
            )
        else:
            index, counts, wide_index, wide_counts = _measured_balls(
                search, points, normals, chunk, radius, k, wide, k_wide if check else 0, sheets
            )
        logger.debug("point cloud: triangle sums")
        done = _measured(out, points, normals, chunk, index, counts, pattern, kernels)
        if check and done.size:
            logger.debug("point cloud: larger balls")
            _measured(larger, points, normals, chunk, wide_index, wide_counts, pattern, kernels, done)
    if details is not None:  # (check)
        done = centres[np.isfinite(out[0][centres])]
        details["unsteady"] = unsteady(out, larger, done, radius) | turned(points, normals, out, radius, done, usable)
    return (*out, normals)


def turned(points, normals, found, radius, centres, usable) -> np.ndarray:
    """(N,) bool: the ``centres`` whose measures ``found`` (``k_min, k_max, ...``) over balls of ``radius`` turn
    the normal by more than :data:`BALL_TURN` over their ball (``radius |k|``) and that jets over the balls of the
    check of :func:`unsteady` (:data:`LARGER` times larger, shrunk to one side of the surface as :func:`jets`
    shrinks them, down to half of ``radius``) do not reproduce within :data:`TURN_AGREEMENT` of |k| (no jet:
    flagged); where they turn by more than :data:`THIN_TURN` but at most :data:`BALL_TURN`, only those where no such
    jet could be fitted (a part thinner than the ball).

    Where the ball is small against the radius of curvature the measures and the jets (an integral of the
    normals' variation; a polynomial's second fundamental form) agree to within their small errors. Where the
    normal turns by a good part of a radian over the ball, the measures also take in what the ball holds beyond
    the surface's own side: the rim of a plate a few spacings thick, whose own side bends a hundredfold within
    the ball (seeds 42 and 4242 of ``benchmarks/fuzz_api.py``: k_max twice the exact one, steady over a ball
    sqrt(2) larger, the normals' jets over larger balls not a reference there).
    """
    with np.errstate(invalid="ignore"):
        turn = radius * np.maximum(np.abs(found[0][centres]), np.abs(found[1][centres]))
    checked = centres[turn > THIN_TURN]  # (NaN: no estimate, nothing to check)
    if checked.size:
        uniform = _uniform_balls(points, normals, found, radius, checked, usable)
        turn = turn[turn > THIN_TURN][~uniform]
        checked = checked[~uniform]
    if checked.size == 0:
        return np.zeros(points.shape[0], dtype=bool)
    # the jets' own ball: the check's (LARGER times larger), or smaller ones (steps of SHRINK, down to half the
    # radius) where the normal would turn by more than REFERENCE_TURN over it (a jet's bias grows as its turn)
    reference = [np.full(points.shape[0], np.nan), np.full(points.shape[0], np.nan)]
    steps = np.clip(np.ceil(np.log(turn * LARGER / REFERENCE_TURN) / -np.log(SHRINK)), 0, 3)
    compared = []
    for step in np.unique(steps):
        group = checked[steps == step]
        ball = radius * LARGER * SHRINK**step
        try:
            found_here = jets(points, normals, ball, group, usable, smallest=min(ball, radius * SHRINK**2))
        except InvalidOptionError:  # balls beyond the work budget (a radius already cut for it): not compared
            continue
        reference[0][group], reference[1][group] = found_here[0][group], found_here[1][group]
        compared.append(group)
    out = unsteady(found, reference, np.concatenate(compared or [checked[:0]]), radius, TURN_AGREEMENT)
    # below BALL_TURN a jet's disagreement may be its noise: only a ball without any one-sided jet counts (THIN_TURN)
    small = checked[turn <= BALL_TURN]
    out[small] &= np.isnan(reference[0][small])
    return out


def _measured(out, points, normals, chunk, index, counts, pattern, kernels, among=None) -> np.ndarray:
    """Write into ``out`` (``k_min, k_max, dir_min, dir_max``; directions None: not written) the measures of the
    balls ``index`` (M, k) of the centres ``chunk`` (M,) (``counts`` points first) that hold a surface, of the
    rows ``among`` only when given; return the rows measured (finite). The compiled kernels read the rows in place (no gathered copies of the
    balls: 0.4-0.5 CPU s at 1M points)."""
    rows = np.flatnonzero(counts >= MIN_BALL_POINTS) if among is None else among[counts[among] >= MIN_BALL_POINTS]
    rows = rows[flat_balls(points, chunk, index, counts, rows)]
    if rows.size == 0:
        return rows
    if kernels is not None:
        summed = kernels.ball_triangle_sums(
            points, normals, index, counts.astype(np.int64, copy=False), pattern, EDGE_ON, rows
        )
    else:
        summed = _triangle_sums(points, normals, index[rows], counts[rows], pattern)
    # rows without area (a ball of collinear points) are NaN and stay so
    k_min, k_max, dir_min, dir_max = curvatures_from_measures(summed, normals[chunk[rows]])
    target = chunk[rows]
    out[0][target] = k_min
    out[1][target] = k_max
    if out[2] is not None:
        out[2][target] = dir_min
        out[3][target] = dir_max
    return rows[np.isfinite(k_min)]
