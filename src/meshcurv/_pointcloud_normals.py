"""Neighbours, spacing, normals and their orientation for point clouds (:mod:`meshcurv.pointcloud`).

Normals are estimated by principal component analysis of the k nearest
neighbours (the eigenvector of the smallest eigenvalue of their covariance)
and oriented consistently by propagation along a minimum spanning tree of the
k-nearest-neighbour graph weighted by ``1 - |n_i . n_j|`` (Hoppe et al. 1992):
the tree follows the pairs of most parallel normals, where the relative sign
is least ambiguous. The sign of every point relative to its tree's root is the
product of the signs ``sign(n_i . n_parent(i))`` along its path to the root,
computed by pointer jumping (``log2(depth)`` vectorised passes over the
points, no loop over them); with the compiled backend, Kruskal's algorithm
over the edges in order of weight with a union-find that keeps each point's
flip relative to its root gives the same signs in one pass
(:func:`meshcurv._kernels.pointcloud.spanning_signs`). Estimated normals are
oriented by :func:`oriented_signs`, which passes the sign only along edges of one
sheet, and reversed across a gap between two sheets. Each part is then
turned outward: by the divergence theorem ``sum_i a_i n_i . (p_i - c) = 3 V > 0``
for the outward normals of a closed surface (``a_i`` the area of a point, the
square of its local spacing; ``c`` any point); on an open surface the sum
picks one side. Last, the side of every point is checked against the
generalized winding number of the oriented cloud (Barill et al. 2018,
:func:`winding_sides`): ``1/2`` on a surface whose side agrees with the whole
cloud's; a part still inside out (the orientation crossed a gap of a spacing
or two by edges near both tangent planes), a face of a thin part turned with
the other, or an outward part inside another (a cavity's wall, whose normals
point into the cavity as for meshes) is turned, and what that does not
settle is undecided.

References
----------
G. Barill, N. G. Dickson, R. Schmidt, D. I. W. Levin, A. Jacobson (2018).
Fast winding numbers for soups and clouds. ACM Transactions on Graphics
37(4), 43. https://doi.org/10.1145/3197517.3201337

H. Hoppe, T. DeRose, T. Duchamp, J. McDonald, W. Stuetzle (1992). Surface
reconstruction from unorganized points. SIGGRAPH '92, 71-78.
https://doi.org/10.1145/133994.134011
"""

from __future__ import annotations

import math

import numpy as np

from ._backend import numba_kernels

# the lattice reader, shared with the meshes' voxel reading, lives in meshcurv.lattice (imported from here too)
from .lattice import LATTICE_TOLERANCE, NO_LATTICE, Lattice, _spread
from .lattice import read_lattice as read_lattice

#: Neighbours (the point itself not counted) of the k-nearest-neighbour query that
#: gives the spacing, the PCA normals and the orientation graph.
NEIGHBOURS = 10

#: Two distances from a point within this share of the larger are one distance (:func:`whole_ties`): the
#: neighbours at the cut of a k-nearest-neighbour query are taken or dropped as a whole group, whatever round-off
#: a rigid motion or a scaling of the cloud gives them (a few units of 1e-16 times the cloud's extent over the
#: spacing: about 1e-13 at 1M points, 1e-10 moved 1,000 extents away). Distances this close are one distance to
#: the estimates too: the geometry decides the neighbours, not the pose, the input's order or the search's.
TIE_TOLERANCE = 1e-9

#: ... unless fewer than this many neighbours would be left (no plane through them): the query's cut is kept
#: there. Such a point's nearest are all at one distance, a ring about it (the pole of a grid of latitude and
#: longitude, the apex of a cone of revolution), any three of which span the ring's plane.
TIE_LEAST = 3

#: The local spacing is measured at this neighbour (see :func:`local_spacing`).
SPACING_NEIGHBOUR = 8

#: Neighbours per point in the graph of the orientation (the nearest of the query's).
GRAPH_NEIGHBOURS = 6

#: With given normals, an edge of the orientation graph is steep when an end lies beyond this slope
#: (15 degrees) of the other's tangent plane (see :func:`orientation_signs`).
TANGENT_SLOPE = 0.25

#: A point keeps its steep edges (except back-to-back ones) when fewer than this many of its edges are flat.
MIN_FLAT_EDGES = 3

#: Estimated normals: an edge of the orientation graph jumps between two sheets (two parts of the cloud,
#: the faces of a thin part) when an end lies beyond this slope (about 22 degrees) of the other's tangent
#: plane; the orientation is not passed across it (see :func:`oriented_signs`). Measured on 20,000
#: samples of an ellipsoid and a torus under noise of 0.2 spacings: no such edge cuts a part of 32 points
#: or more off the surface; between two spheres 1 spacing apart every edge across the gap is steeper.
SHEET_SLOPE = 0.4

#: An edge between two sheets (see :func:`oriented_signs`): normals within this cosine of (anti-)parallel ...
FACING_COSINE = 0.5

#: ... and each end at least this many spacings off the other's tangent plane (noise of 0.2 spacings moves
#: two points by 0.4 spacings at most along the normal).
STACKED_OFFSET = 0.75

#: A flat edge whose normals are this close to (anti-)parallel and left opposite by the orientation marks
#: its ends as undecided (two sheets closer than the spacing).
PARALLEL_COSINE = 0.9

#: A flat edge steeper than this must close a triangle of flat edges to join two points in one sheet.
TRUSTED_SLOPE = 0.2

#: An edge of the orientation graph whose normals' cosine is at most this in magnitude passes no sign: at right
#: angles ``sign(n_i . n_j)`` is the sign of round-off, which a motion of the cloud decides (ogre's vertices as a
#: cloud, shifted by 1024 sizes: a point joined to its part only by two flat edges across a right-angled crease,
#: cosine -0.0 in one pose and -2.4e-16 in the other, was turned; the winding numbers around it moved by 0.15, the
#: noise level by 0.14%, and 49 points changed validity: fuzz_api 540/33). The normals of a cloud shifted by 2^20
#: sizes carry errors of about 1e-7 (its coordinates rounded to 2^-32 of its size, a millionth of it apart).
SIGN_COSINE = 1e-4

#: The orientation takes its edges in the order of their slopes rounded to this: equal ones are taken in the order
#: of the edges. Both backends' normals agree to round-off, not bit for bit, and on a lattice many edges tie
#: exactly: without it a tie decided by round-off turned a few points on one backend (``benchmarks/fuzz_api.md``,
#: round 15, seed 256 case 104).
TIE_RESOLUTION = 1e-9

#: A part of the flat graph of at least this many points is oriented on its own (see :func:`oriented_signs`).
PART_MIN_POINTS = 32

#: A part of less than this share of the area of a part beside it ...
FRAGMENT_SHARE = 0.25
#: ... whose flux about its centroid is at most this share of its absolute flux has no side of its own
#: (:func:`undecided_fragments`).
FRAGMENT_FLUX = 0.5

#: A part beside another (after :func:`winding_sides`) whose side the rest of the cloud settles: the mean winding number
#: of the rest at its points at least this far from 0 (it wraps the part: a piece of a larger closed surface, as
#: on a closed surface about a hole in it, 1/2) ...
FRAGMENT_WRAPPED = 0.25
#: ... must come this much closer to 1/2 in the mean (the whole cloud's winding number at the part's points) on the
#: part's side than turned, or its side is undecided (:func:`unconfirmed_parts`) ...
FRAGMENT_MARGIN = 0.1
#: ... evaluated at this many points of each part at least (all when fewer), besides the evenly spaced ones.
FRAGMENT_QUERIES = 16

#: Rounds of attaching small parts to their neighbours (each round reaches one part further).
SMALL_PART_ROUNDS = 8

#: Points per chunk of the neighbour query and the PCA (bounds memory: about 100 MB).
CHUNK = 131072

#: Points per chunk of :func:`lattice_treads` (bounds memory: its :data:`STEP_NEIGHBOURS` nearest neighbours
#: and their heights, some 2.5 KiB per point; chunks of :data:`CHUNK` held 0.3 GiB at 100,000 points).
TREAD_CHUNK = 8192

#: A point's nearest neighbours lie on a line when their spread across their main direction (the square root
#: of the second eigenvalue of their covariance) is below this share of the spread along it (see
#: :func:`scan_lines`); a random sample of a surface has no such neighbourhood.
LINE_SPREAD = 0.1

#: ... then its this many nearest neighbours are searched for support beyond the line ...
LINE_NEIGHBOURS = 64

#: ... the points no farther along the line than its nearest neighbours reach (``w``) and farther than this times
#: ``w`` from the line ...
LINE_OFFSET = 0.5

#: ... and no farther than this times ``w`` (lines up to about 25 times sparser across than along) ...
LINE_FAR = 5.0

#: ... at least this many of them: a surface sampled along lines (scan lines), measured over balls that reach
#: the neighbouring lines; fewer: the point is on a line, and has no surface to measure.
LINE_SUPPORT = 4

#: A point of a scan line is measured over balls of at least this many times the distance to the neighbouring
#: lines (three lines or more in each ball).
LINE_REACH = 2.0

#: A point whose nearest neighbours spread across their main direction by up to this share of their spread along
#: it (see :data:`LINE_SPREAD`) is checked for a curve: a lone ring of 30 to 70 points measures 0.30 to 0.13 (its
#: neighbours span 70 to 150 degrees of it), a random sample of a surface 0.16 at the least, 0.70 typically ...
CURVE_CANDIDATE = 0.35

#: ... and its neighbours lie on a curve through it when their offsets across the main direction, less the best
#: ``b t + c t^2`` (``t`` along it), spread by less than :data:`LINE_SPREAD` of their spread along it
#: (:func:`curve_fits`): rings of 30, 50 and 200 points measure 0.034, 0.007 and 1e-4, random samples of a plane or a
#: sphere (noisy or not) 0.17 at the least, 0.70 typically. Such a point is on a line (the scan line of a
#: surface, or no surface) when the points beside its curve are not on it (see :func:`scan_lines`).
CURVE_SPREAD = 0.1

#: A line whose support beyond it (see :func:`scan_lines`) is farther than this many times its radius of
#: curvature is not the scan line of a surface: a lone ring's only support is its own far side, a diameter
#: (twice its radius) away, and no surface through the two is measured by them (a surface between two lines
#: has no curvature across them to measure: three lines are needed, and a line that curves within the gap to
#: the next does not sample the surface between). Lines of a scanned sphere measure 0.56 at the most (rings of
#: latitude 0.2 apart, radius 0.36), concentric rings one gap apart 1 (the innermost).
LINE_BEND = 1.5

#: The winding number (see :func:`winding_sides`) is evaluated at this many points at most (all when fewer) ...
WINDING_QUERIES = 8192

#: ... as a sum over this many source points at most beyond each point's :data:`WINDING_NEAR` nearest (each
#: source weighted by the share of the points it stands for) ...
WINDING_SOURCES = 4096

#: ... and over all of these nearest neighbours: two sheets a spacing or two apart (where the sampled sum is
#: noisiest) are summed exactly up to about 4 spacings. Measured: 1M points, 4096 sources, two sheets 1 spacing
#: apart: a standard deviation of about 0.1 from the sampling.
WINDING_NEAR = 48

#: A point's side is wrong when the winding number at it is farther than this from 1/2 (about -1/2: a part
#: inside out; about 3/2: an outward part inside another, a cavity).
WINDING_WRONG = 0.75

#: Evaluations of the winding number at most (each but the last followed by turning the wrong points).
WINDING_ROUNDS = 3

#: A neighbour is on a sheet stacked on a point's (see :func:`stacked_alike`) when each lies at least this many
#: spacings off the other's tangent plane ...
STACKED_ALIKE_OFFSET = 0.45

#: ... or, with the noise level ``nu`` measured (in spacings, :func:`meshcurv.radius.cloud_noise_level`), at least
#: :data:`ALIKE_NOISE` ``nu`` and :data:`ALIKE_MIN_OFFSET` spacings when that is less: two points of one sheet under
#: uniform noise of ``a`` spacings (``nu`` about ``a / 2``, less where the fit absorbs some) differ by at most
#: ``2 a`` along the normal (4 ``nu``: 599 false pairs on a torus under noise of 0.2 spacings; 6 leaves a margin),
#: while the two faces of a plate thinner than :data:`STACKED_ALIKE_OFFSET` (0.44 spacings: 1 x 1 x 0.02 at 400
#: points under noise of 0.05 spacings, a face left inward, valid) are stacked by their thickness ...
ALIKE_NOISE = 6.0
ALIKE_MIN_OFFSET = 0.15

#: ... plus this many times its distance times the tilt of the point's normal (normals tilted by noise lift far
#: neighbours off a tangent plane) ...
STACKED_ALIKE_TILT = 2.0

#: ... and a point with this many such neighbours oriented alike has a sheet inside out beside it ...
STACKED_ALIKE_MIN = 2

#: ... farther apart too, on a lattice (a voxel surface read as a cloud: the vertices of marching cubes, each on an
#: edge of the voxels, their coordinates on a grid of ``h`` along each axis, :func:`read_lattice`), than this many
#: times ``max_k |n_k| h_k`` (``n`` the point's normal): a vertex lies up to ``h_k`` off the surface along its
#: edge, and the two points of a pair on one staircase up to twice that along the normal (its steps are stacked
#: sheets side by side). Only on a lattice whose largest ``h`` is at most :data:`LATTICE_RESOLVED` spacings:
#: coarser steps are steeper than the orientation's flat edges, and patches of such a staircase are turned inside
#: out (``benchmarks/pointcloud_diagnostics.md``).
STACKED_ALIKE_LATTICE = 2.0
LATTICE_RESOLVED = 1.0

#: On a lattice, a point is on a flat tread of the staircase (see :func:`lattice_treads`) when at least this share
#: of its :data:`TREAD_NEIGHBOURS` nearest neighbours within its ball lie on its plane of the grid. The share ``s``
#: is the step over the rise of the surface across the ball (a tread is the disc within one step ``h`` of the top,
#: radius ``sqrt(2 h / k)``, in a ball of radius ``r``: ``s = h / (k r^2 / 2)``): the ball sees fewer than ``1 / s``
#: steps, and only the points off the tread say that the surface curves: the jets' error grows with ``s``, and this
#: share is where it stays below half of |k| with a margin over voxel spheres, ellipsoids and tori of 6-40 voxels
#: (``benchmarks/pointcloud_diagnostics.md``, "Jets on a staircase").
TREAD_SHARE = 0.75
TREAD_NEIGHBOURS = 48

#: On a lattice, a ball whose points (its :data:`STEP_NEIGHBOURS` nearest, the most that the measures draw from) lie
#: on at most this many planes of the grid along the axis most along the normal sees one step of the staircase at
#: most (a tread, its riser and the next tread: the grid of half voxels of marching cubes over a mask): the curvature
#: it reads is the step's, whatever the surface's (at the rims of the wide treads of a flat face, 1.6-2 times its
#: |k|); its estimate is NaN (see :func:`lattice_treads`; ``benchmarks/pointcloud_diagnostics.md``, "One step").
STEP_PLANES = 3
STEP_NEIGHBOURS = 96

#: On a lattice, an estimate whose surface rises over its ball by less than this share of the staircase's own
#: relief along the normal (``max(|k|) r^2 / 2 < FACET_SAGITTA * max_k |n_k| h_k``, ``h`` the grid's steps) sees
#: no curvature the grid resolves (see :func:`lattice_treads`): a ball on one facet of the staircase (a plane of
#: the grid of any slope: the tread of an axis, the digital planes of slopes such as (1, 1, 1) and (2, 1, 1) of
#: the voxels). Jets over such balls read exactly 0 (a sagitta of round-off); estimates that resolve the
#: surface read a tenth or more of the relief (``benchmarks/pointcloud_diagnostics.md``, "Facets of a staircase").
FACET_SAGITTA = 0.1

#: The winding number between two stacked sheets (see :func:`between_sides`) below which the part between them
#: is inside out (-1; 1 inside a part, 0 in a gap between two).
BETWEEN_WRONG = -0.5

#: Two sheets closer than :data:`STACKED_OFFSET` (see :func:`two_sheets`): the heights of a point's neighbours
#: among this many nearest ...
INTERLEAVED_NEIGHBOURS = 24

#: ... within this many spacings of it along their plane ...
INTERLEAVED_REACH = 1.5

#: ... fall into two groups of at least this many points ...
INTERLEAVED_GROUP = 3

#: ... apart by at least this many spacings ...
INTERLEAVED_GAP = 0.3

#: ... (or apart by this many times the spread of each group: two clean sheets closer than that) ...
INTERLEAVED_SPREAD = 3.0

#: ... (but at least this many spacings: on a clean sheet every gap is a fraction of the curvature's height) ...
INTERLEAVED_MIN_GAP = 0.1

#: ... at this share of the point's nearest neighbours (itself counted) at least.
INTERLEAVED_SHARE = 0.25

#: :func:`two_sheets` runs at every point when this share of its sample has two sheets (a thin part of a cloud
#: of 1M points is seen from about 5000 points).
INTERLEAVED_SAMPLE = 0.005

#: Query points per chunk of the NumPy far sum (bounds memory: a few (chunk, sources) arrays).
WINDING_CHUNK = 256


def knn(tree, points: np.ndarray, k: int = NEIGHBOURS) -> tuple[np.ndarray, np.ndarray]:
    """(N, k) distances and indices of the ``k`` nearest other points of each point (chunked, all cores), the
    neighbours tied at the cut taken or dropped together (:func:`whole_ties`).

    The point itself is dropped from its row (when duplicates make it not the
    first, the first column is dropped instead: a duplicate at distance 0 is
    then also a neighbour at distance 0, which is what counts).
    """
    n = points.shape[0]
    k = min(k, n - 1)
    wide = min(k + 1, n - 1)  # (the next one too: is the cut through a tie?)
    distances = np.zeros((n, wide))
    indices = np.zeros((n, wide), dtype=np.int64)
    for start in range(0, n, CHUNK):
        rows = np.arange(start, min(n, start + CHUNK))
        d, i = tree.query(points[rows], k=wide + 1, workers=-1)
        _drop_self(rows, d, i, wide, distances, indices)
    return whole_ties(distances, indices, k)


def whole_ties(distances: np.ndarray, indices: np.ndarray, k: int, centres=None) -> tuple[np.ndarray, np.ndarray]:
    """(N, k) the nearest neighbours ``distances, indices`` (N, k + 1) (the ``k`` nearest and the next) cut to
    ``k``, the neighbours tied with the next dropped: a row's neighbours are decided by the geometry alone.

    A query cuts a group of neighbours at one distance (within :data:`TIE_TOLERANCE`) by the order in which
    the search met them: the input's order, the tree's, the grid's, which a rigid motion changes by round-off
    (fandisk's vertices: 43 points with their 10th and 11th neighbours at one distance; turned, 16 of them got
    another set of neighbours, and other normals, ``tests/test_knn_ties_K24.py``). A group tied with the
    first neighbour beyond the cut is dropped whole; its slots hold the point itself, at the group's distance
    (the distances along the row are those of any cut: the spacing read from them is unchanged; the graph of
    the orientation leaves such slots out, the PCA counts the point once more). Rows with no tie at the cut
    are the query's ``k`` nearest, and so are those where fewer than :data:`TIE_LEAST` would be left. ``k + 1``
    columns or fewer than ``k``: returned as they are (a cloud of
    ``k + 1`` points or fewer, every other point a neighbour). ``centres``: (N,) the point of each row (by
    default row ``i`` is point ``i``).
    """
    if distances.shape[1] != k + 1:
        return distances[:, :k], indices[:, :k]
    compiled = numba_kernels("pointcloud")
    if compiled is not None and k >= 1:  # (in one pass on every core: 1M points' (N, k) copies, 0.36 CPU s serial)
        return compiled.cut_neighbours(
            np.ascontiguousarray(distances, dtype=np.float64),
            np.ascontiguousarray(indices, dtype=np.int64),
            k,
            np.zeros(0, dtype=np.int64) if centres is None else np.ascontiguousarray(centres, dtype=np.int64),
            TIE_TOLERANCE,
            TIE_LEAST,
        )
    return _cut_neighbours(distances, indices, k, centres)


def _cut_neighbours(distances: np.ndarray, indices: np.ndarray, k: int, centres=None) -> tuple[np.ndarray, np.ndarray]:
    """The NumPy path of :func:`whole_ties` (``k + 1`` columns). Compiled:
    :func:`meshcurv._kernels.pointcloud.cut_neighbours` (the same comparisons: the same arrays to the bit)."""
    cut = distances[:, k]
    with np.errstate(invalid="ignore"):
        rows = np.flatnonzero(distances[:, k - 1] >= cut * (1.0 - TIE_TOLERANCE))
        tied = distances[rows, :k] >= cut[rows, None] * (1.0 - TIE_TOLERANCE)  # a suffix of each row: rows ascend
    left = k - tied.sum(axis=1) >= min(TIE_LEAST, k)
    rows, tied = rows[left], tied[left]
    distances, indices = distances[:, :k].copy(), indices[:, :k].copy()
    if rows.size:
        own = rows if centres is None else centres[rows]
        indices[rows] = np.where(tied, own[:, None], indices[rows])
        distances[rows] = np.where(tied, cut[rows, None], distances[rows])
    return distances, indices


def _drop_self(rows, d, i, k, distances, indices) -> None:
    """Write the (M, k + 1) neighbours ``d, i`` of the points ``rows``, less each point itself, into the outputs."""
    if (i[:, 0] == rows).all():  # distinct points: each is its own nearest
        distances[rows], indices[rows] = d[:, 1:], i[:, 1:]
        return
    own = i == rows[:, None]
    first = np.where(own.any(axis=1), own.argmax(axis=1), 0)
    keep = np.ones(d.shape, dtype=bool)
    keep[np.arange(rows.size), first] = False
    distances[rows] = d[keep].reshape(-1, k)
    indices[rows] = i[keep].reshape(-1, k)


def curve_fits(points: np.ndarray, indices: np.ndarray, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(spread, curvature)``: (M,) how far the points ``rows`` and their neighbours ``indices[rows]`` lie from a
    curve through each point, and (M,) that curve's curvature.

    In the frame of the main direction ``e`` of each group (its covariance's
    largest eigenvector), the offsets ``d`` from the point have ``t = d . e``
    along and ``a = d - t e`` across; ``a`` is fitted by ``b t + c t^2``
    (``b, c`` vectors, least squares). ``spread``: the root mean square of the
    residuals over that of ``t`` (0 on a smooth curve, about 0.7 on a
    random sample of a surface); ``curvature``: ``2 |c|`` over ``1 + |b|^2``
    to the power 3/2 (the curvature of the fitted curve at the point).
    """
    spread, curvature = np.ones(rows.size), np.zeros(rows.size)
    for start in range(0, rows.size, CHUNK // 4):
        part = rows[start : start + CHUNK // 4]
        offsets = points[indices[part]] - points[part][:, None, :]
        scale = np.maximum(np.abs(offsets).max(axis=(1, 2)), np.finfo(float).tiny)  # each group in its own units
        offsets = offsets / scale[:, None, None]
        centred = offsets - offsets.mean(axis=1, keepdims=True)
        _, vectors = np.linalg.eigh(np.einsum("mki,mkj->mij", centred, centred))
        main = vectors[:, :, 2]
        along = np.einsum("mkj,mj->mk", offsets, main)
        across = offsets - along[..., None] * main[:, None, :]
        basis = np.stack([along, along * along], axis=2)  # (M, k, 2)
        gram = np.einsum("mki,mkj->mij", basis, basis)
        determinant = gram[:, 0, 0] * gram[:, 1, 1] - gram[:, 0, 1] ** 2
        fitted = determinant > 1e-12 * np.maximum(gram[:, 0, 0] * gram[:, 1, 1], np.finfo(float).tiny)
        inverse = (
            np.stack(
                [np.stack([gram[:, 1, 1], -gram[:, 0, 1]], axis=1), np.stack([-gram[:, 1, 0], gram[:, 0, 0]], axis=1)],
                axis=1,
            )
            / np.where(fitted, determinant, 1.0)[:, None, None]
        )
        coefficients = np.einsum("mij,mkj,mkl->mil", inverse, basis, across)  # (M, 2, 3): b and c
        residual = across - np.einsum("mki,mil->mkl", basis, coefficients)
        length = np.sqrt((along * along).mean(axis=1))
        ratio = np.sqrt((residual * residual).sum(axis=2).mean(axis=1)) / np.maximum(length, np.finfo(float).tiny)
        slope = (coefficients[:, 0, :] ** 2).sum(axis=1)
        bend = 2.0 * np.linalg.norm(coefficients[:, 1, :], axis=1) / (1.0 + slope) ** 1.5 / scale
        spread[start : start + part.size] = np.where(fitted & (length > 0), ratio, 1.0)
        curvature[start : start + part.size] = np.where(fitted, bend, 0.0)
    return spread, curvature


def line_spread(points: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """(N,) the spread of each point and its neighbours ``indices`` (N, k) across their main direction, over the
    spread along it: ``sqrt(lambda_2 / lambda_1)`` of their covariance (0 on a line, 1 when isotropic).

    The eigenvalues in closed form (Smith 1961): compiled
    (:func:`meshcurv._kernels.pointcloud.line_spread`), or with arrays in chunks of :data:`CHUNK` points.
    """
    compiled = numba_kernels("pointcloud")
    if compiled is not None:
        return compiled.line_spread(points, np.ascontiguousarray(indices))
    return _line_spread_numpy(points, indices)


#: The C library's ``acos`` and ``cos``, elementwise: those the kernel calls. NumPy's own (its SIMD loops: SVML on
#: AVX-512 machines) differ from them in the last bit, and the two backends' normals with them (366 of 34,572
#: components one ulp apart on a thin pair of sheets, where ties of the orientation's weights may turn).
_ACOS, _COS = np.frompyfunc(math.acos, 1, 1), np.frompyfunc(math.cos, 1, 1)


def _libm(function, values: np.ndarray) -> np.ndarray:
    """``function`` (:data:`_ACOS`, :data:`_COS`) of each of ``values`` (M,) float64, NaN kept (a NaN input)."""
    return function(values).astype(np.float64)


def _line_spread_numpy(points: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """The NumPy path of :func:`line_spread`: the kernel's operations in its order (the same ratios to the bit:
    they are compared with :data:`LINE_SPREAD` and :data:`CURVE_CANDIDATE`)."""
    n, k = indices.shape
    ratio = np.ones(n)
    for start in range(0, n, CHUNK):
        stop = min(n, start + CHUNK)
        xx, xy, xz, yy, yz, zz = _covariances(points, indices, start, stop, k)
        mean = (xx + yy + zz) / 3
        sxx, syy, szz = xx - mean, yy - mean, zz - mean
        spread = np.sqrt((sxx * sxx + syy * syy + szz * szz + 2 * (xy * xy + xz * xz + yz * yz)) / 6)
        scale = np.where(spread > 0, spread, 1.0)
        bxx, byy, bzz, bxy, bxz, byz = sxx / scale, syy / scale, szz / scale, xy / scale, xz / scale, yz / scale
        half = 0.5 * (bxx * (byy * bzz - byz * byz) - bxy * (bxy * bzz - byz * bxz) + bxz * (bxy * byz - byy * bxz))
        with np.errstate(invalid="ignore", divide="ignore"):
            angle = _libm(_ACOS, np.minimum(1.0, np.maximum(-1.0, half))) / 3
            largest = mean + 2 * spread * _libm(_COS, angle)
            smallest = mean + 2 * spread * _libm(_COS, angle + 2 * np.pi / 3)
            second = np.maximum(3 * mean - largest - smallest, 0.0)
            ratio[start:stop] = np.where(largest > 0, np.sqrt(second / np.where(largest > 0, largest, 1.0)), 1.0)
    return ratio


def scan_lines(
    points: np.ndarray,
    distances: np.ndarray,
    indices: np.ndarray,
    usable: np.ndarray,
    tree,
    radius: float | None = None,
):
    """The points whose nearest neighbours lie on a line: on a surface sampled along lines, or on a line alone.

    A surface scanned along lines (LiDAR, profilometers) is sampled densely
    along each line and sparsely across: the nearest neighbours of a point
    all lie on its own line (their spread across it below
    :data:`LINE_SPREAD` of their spread along it, :func:`line_spread`), and the
    spacing, the PCA normal and the graph of the orientation made of them
    describe a line, not the surface. The :data:`LINE_NEIGHBOURS` nearest
    points of such a point are searched for support beyond the line: points
    within the reach ``w`` of its nearest neighbours along the line,
    farther than :data:`LINE_OFFSET` ``w`` from it and no farther than
    :data:`LINE_FAR` ``w`` (within ``radius`` when given). With :data:`LINE_SUPPORT` of them or more the point is on a
    scan line: its spacing is the side of the area per point of the larger
    neighbourhood (``d_k sqrt(pi / k)``), its normal the least-variance
    direction of the point, its nearest neighbours and its support, its
    neighbours half on its line and half beyond (alternately, each in
    distance order), and its balls reach :data:`LINE_REACH` times the
    distance to the neighbouring lines. With fewer the point is on a line
    (a wire, a line of points beside a few others): no surface to measure.

    Parameters
    ----------
    points : ndarray of shape (N, 3)
    distances, indices : ndarray of shape (N, k)
        The nearest neighbours of each point (:func:`knn`).
    usable : ndarray of shape (N,), bool
        The points that count (the others are never searched, nor support).
    tree : scipy.spatial.cKDTree
        The points' tree.
    radius : float, optional
        The radius the user gave: the support must lie within it.

    Returns
    -------
    lonely : ndarray of shape (N,), bool
        Points on a line without a surface around them.
    rows : ndarray of shape (M,), int
        Points on scan lines; for each of them:
    neighbours : ndarray of shape (M, k), int
        New rows of ``indices``.
    spacing : ndarray of shape (M,)
        The local spacing.
    least : ndarray of shape (M,)
        The smallest radius of their balls.
    normals : ndarray of shape (M, 3)
        Unit normals (unoriented).
    """
    n, k = indices.shape
    lonely = np.zeros(n, dtype=bool)
    spread = line_spread(points, indices)
    line = np.flatnonzero(usable & (spread < LINE_SPREAD))
    empty = np.zeros(0, dtype=np.int64)
    if n <= k + 1:
        return lonely, empty, np.zeros((0, k), dtype=np.int64), np.zeros(0), np.zeros(0), np.zeros((0, 3))
    # neighbourhoods on a curve that bends within them (a lone ring of 30 to 70 points): on a line too, but the
    # curve comes back beside its straight line, and only points off the curve itself support a surface
    candidates = np.flatnonzero(usable & (spread >= LINE_SPREAD) & (spread < CURVE_CANDIDATE))
    curve = candidates[curve_fits(points, indices, candidates)[0] < CURVE_SPREAD] if candidates.size else empty
    if line.size == 0 and curve.size == 0:
        return lonely, empty, np.zeros((0, k), dtype=np.int64), np.zeros(0), np.zeros(0), np.zeros((0, 3))
    if curve.size:
        own = _curve_labels(indices, line, curve)
        for start in range(0, curve.size, CHUNK // 4):
            rows = curve[start : start + CHUNK // 4]
            far, near, support, across = _line_support(points, distances, indices, usable, tree, rows, radius)
            support &= own[near] != own[rows][:, None]
            held = _surface_beside(support, across, curve_fits(points, indices, rows)[1])
            lonely[rows[~held]] = True  # (held: points beside a bent scan line, measured as any other)
    found = []
    wide = min(LINE_NEIGHBOURS, n - 1)
    for start in range(0, line.size, CHUNK // 4):
        rows = line[start : start + CHUNK // 4]
        far, near, support, across = _line_support(points, distances, indices, usable, tree, rows, radius)
        held = _surface_beside(support, across, curve_fits(points, indices, rows)[1])
        lonely[rows[~held]] = True
        rows, far, near, support, across = rows[held], far[held], near[held], support[held], across[held]
        if rows.size == 0:
            continue
        # alternately the nearest on the line and the nearest beyond it
        rank = np.cumsum(support, axis=1) * support + np.cumsum(~support, axis=1) * ~support
        order = np.argsort(2 * rank + ~support, axis=1, kind="stable")[:, :k]
        neighbours = np.take_along_axis(near, order, axis=1)
        spacing = far[:, -1] * np.sqrt(np.pi / wide)
        gap = np.nanmedian(np.where(support, across, np.nan), axis=1)
        members = np.concatenate([rows[:, None], indices[rows], np.where(support, near, rows[:, None])], axis=1)
        group = points[members] - points[rows][:, None, :]
        group = group - group.mean(axis=1, keepdims=True)
        _, vectors = np.linalg.eigh(np.einsum("mki,mkj->mij", group, group))
        found.append((rows, neighbours, spacing, LINE_REACH * gap, vectors[:, :, 0]))
    if not found:
        return lonely, empty, np.zeros((0, k), dtype=np.int64), np.zeros(0), np.zeros(0), np.zeros((0, 3))
    rows, neighbours, spacing, least, normals = (np.concatenate(parts) for parts in zip(*found))
    return lonely, rows, neighbours, spacing, least, normals


def _line_support(points, distances, indices, usable, tree, rows, radius):
    """``(far, near, support, across)`` of the line points ``rows`` (M,) (see :func:`scan_lines`): the distances
    and indices (M, w) of their :data:`LINE_NEIGHBOURS` nearest, which of them support a surface beside the
    line, and their distances from the line."""
    wide = min(LINE_NEIGHBOURS, points.shape[0] - 1)
    far, near = tree.query(points[rows], k=wide + 1, workers=-1)
    far, near = far[:, 1:], near[:, 1:]  # (distinct points: each is its own nearest)
    reach = distances[rows, -1]
    direction = points[indices[rows, -1]] - points[rows]
    direction /= np.maximum(np.linalg.norm(direction, axis=1), reach * 1e-12)[:, None]
    offsets = points[near] - points[rows][:, None, :]
    along = np.einsum("mkj,mj->mk", offsets, direction)
    across = np.sqrt(np.maximum(np.einsum("mkj,mkj->mk", offsets, offsets) - along * along, 0.0))
    support = (
        usable[near]
        & (np.abs(along) <= reach[:, None])
        & (across > LINE_OFFSET * reach[:, None])
        & (across <= LINE_FAR * reach[:, None])
        & (near != rows[:, None])
    )
    if radius is not None:
        support &= far < radius
    return far, near, support, across


def _surface_beside(support, across, curvature) -> np.ndarray:
    """(M,) bool: lines with :data:`LINE_SUPPORT` points of ``support`` (M, w) or more, whose median distance
    ``across`` (M, w) from the line is at most :data:`LINE_BEND` over the line's ``curvature`` (M,)."""
    held = support.sum(axis=1) >= LINE_SUPPORT
    gap = np.zeros(held.size)
    if held.any():  # (the rows with support only: no median of nothing)
        gap[held] = np.nanmedian(np.where(support[held], across[held], np.nan), axis=1)
    return held & ~(gap * curvature > LINE_BEND)


def _curve_labels(indices, line, curve) -> np.ndarray:
    """(N,) the connected part of each point of ``line`` and ``curve`` along the edges of ``indices`` (N, k) between
    two of them (the curve a point lies on, and its continuation); -1 elsewhere."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    n = indices.shape[0]
    member = np.zeros(n, dtype=bool)
    member[line] = member[curve] = True
    # the rows of the members only (the same edges: 1M points, a few of them members, 0.2 -> 0.01 CPU s)
    ends = np.flatnonzero(member)
    rows = np.repeat(ends, indices.shape[1])
    cols = indices[ends].ravel()
    keep = member[cols]
    graph = coo_matrix((np.ones(int(keep.sum()), dtype=np.int8), (rows[keep], cols[keep])), shape=(n, n))
    _, labels = connected_components(graph, directed=False)
    return np.where(member, labels, -1)


def local_spacing(distances: np.ndarray) -> np.ndarray:
    """(N,) the side of the square of surface each point stands for: ``d_k sqrt(pi / k)``.

    ``d_k`` is the distance to the :data:`SPACING_NEIGHBOUR`-th neighbour: ``k``
    points in a disc of radius ``d_k`` give ``pi d_k^2 / k`` of area per point.
    On a square grid of step ``h`` it is about ``h``; it plays the part of the
    mean edge length of a mesh.
    """
    k = min(SPACING_NEIGHBOUR, distances.shape[1])
    return distances[:, k - 1] * np.sqrt(np.pi / k)


#: PCA normals are signed to face this direction (generic: no lattice normal is at right angles to it), on both
#: backends alike. An eigenvector's sign is its solver's choice (the kernel's closed form and ``eigh`` differ), and
#: the orientation's decisions on a noisy cloud depend on its input signs (``benchmarks/pointcloud.md``).
PCA_SIGN = np.array([1.0, np.sqrt(2.0), np.sqrt(3.0)]) / np.sqrt(6.0)

#: A part whose flux about its centroid is at most this share of its area-weighted size has no volume (a flat
#: part: the flux is round-off, of either sign on the two backends): its side is :data:`PCA_SIGN`'s
#: (:func:`outward_signs`).
FLAT_FLUX = 1e-9


#: ``A - lambda I`` has rank 1 (a collinear neighbourhood) where its rows' largest squared cross product is at most
#: this times its longest row's squared length, squared (:data:`meshcurv._kernels.pointcloud.RANK_ONE`, the same).
RANK_ONE = 1e-24


def pca_normals(points: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """(N, 3) unit normals (unoriented: signed to face :data:`PCA_SIGN`): the least-variance direction of each point
    and its neighbours.

    The compiled kernel (:func:`meshcurv._kernels.pointcloud.pca_normals`, a
    closed form) when the numba backend is in use, else the same closed form
    with arrays (:func:`_pca_normals_numpy`), its operations in the kernel's
    order: the two agree to the last bits.
    """
    kernels = numba_kernels("pointcloud")
    if kernels is not None:
        normals = kernels.pca_normals(points, np.ascontiguousarray(indices))
    else:
        normals = _pca_normals_numpy(points, indices)
    return normals * np.where(normals @ PCA_SIGN < 0, -1.0, 1.0)[:, None]


def _pca_normals_numpy(points: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """The NumPy path of :func:`pca_normals`: the kernel's closed form, its operations in its order.

    The same formula as :func:`meshcurv._kernels.pointcloud.pca_normals` (the covariance summed neighbour by
    neighbour, the smallest eigenvalue by Smith's trigonometric root, the longest cross product of two rows of
    ``A - lambda I``), each product and sum as the kernel takes them, so that the two backends' normals agree
    to the last bits (``numpy.linalg.eigh`` gave vectors 6e-12 apart at the rim of a thin part, which tipped
    the orientation's tied weights, ``tests/test_pointcloud_parity_P20.py``). Vectorised over chunks of
    :data:`CHUNK` points, a loop over the ``k`` neighbours.
    """
    n, k = indices.shape
    normals = np.zeros((n, 3))
    for start in range(0, n, CHUNK):
        stop = min(n, start + CHUNK)
        normals[start:stop] = _closed_form_normals(points, indices, start, stop, k)
    return normals


def _closed_form_normals(points: np.ndarray, indices: np.ndarray, start: int, stop: int, k: int) -> np.ndarray:
    """(M, 3) :func:`_pca_normals_numpy` of the points ``start:stop``."""
    xx, xy, xz, yy, yz, zz = _covariances(points, indices, start, stop, k)
    trace = xx + yy + zz
    positive = trace > 0
    divisor = np.where(positive, trace, 1.0)  # (x / 1.0 is x: the kernel's "if trace > 0")
    xx, xy, xz, yy, yz, zz = xx / divisor, xy / divisor, xz / divisor, yy / divisor, yz / divisor, zz / divisor
    off = xy * xy + xz * xz + yz * yz
    mean = (xx + yy + zz) / 3
    spread = np.sqrt(((xx - mean) ** 2 + (yy - mean) ** 2 + (zz - mean) ** 2 + 2 * off) / 6)
    spread_ok = spread > 0
    divisor = np.where(spread_ok, spread, 1.0)
    bxx, byy, bzz = (xx - mean) / divisor, (yy - mean) / divisor, (zz - mean) / divisor
    bxy, bxz, byz = xy / divisor, xz / divisor, yz / divisor
    half = 0.5 * (bxx * (byy * bzz - byz * byz) - bxy * (bxy * bzz - byz * bxz) + bxz * (bxy * byz - byy * bxz))
    with np.errstate(invalid="ignore"):
        angle = _libm(_ACOS, np.minimum(1.0, np.maximum(-1.0, half))) / 3
    smallest = mean + 2 * spread * _libm(_COS, angle + 2 * np.pi / 3)
    r0 = np.stack([xx - smallest, xy, xz], axis=1)
    r1 = np.stack([xy, yy - smallest, yz], axis=1)
    r2 = np.stack([xz, yz, zz - smallest], axis=1)
    a, b, e = _cross(r0, r1), _cross(r0, r2), _cross(r1, r2)
    la, lb, le = _squared(a), _squared(b), _squared(e)
    pick_b = (lb > la) & (lb >= le)
    pick_e = ~pick_b & (le > la)
    best = np.where(pick_b[:, None], b, np.where(pick_e[:, None], e, a))
    longest = np.where(pick_b, lb, np.where(pick_e, le, la))
    s0, s1, s2 = _squared(r0), _squared(r1), _squared(r2)
    row_1 = (s1 > s0) & (s1 >= s2)
    row_2 = ~row_1 & (s2 > s0)
    row = np.where(row_1[:, None], r1, np.where(row_2[:, None], r2, r0))
    row_length = np.where(row_1, s1, np.where(row_2, s2, s0))
    out = np.zeros((stop - start, 3))
    out[:, 2] = 1.0  # isotropic, a single repeated point or a zero matrix: every direction is as good
    rank_two = spread_ok & (longest > RANK_ONE * row_length * row_length)
    length = np.sqrt(np.where(rank_two, longest, 1.0))
    out[rank_two] = best[rank_two] / length[rank_two, None]
    # rank 1 (a collinear neighbourhood): a direction orthogonal to the longest row (the frame of the line)
    line = spread_ok & ~rank_two & (row_length > 0)
    if line.any():
        root = np.sqrt(row_length[line])
        out[line] = _first_tangent(row[line] / root[:, None])
    return out


def _covariances(points: np.ndarray, indices: np.ndarray, start: int, stop: int, k: int):
    """``xx, xy, xz, yy, yz, zz`` (M,) each: the (unnormalised) covariance of the points ``start:stop`` with their
    ``k`` neighbours ``indices``, summed neighbour by neighbour as :func:`meshcurv._kernels.pointcloud._covariance`
    sums them (to the bit; ``numpy.sum`` adds pairwise, ``einsum`` in its own order)."""
    own = points[start:stop]
    near = indices[start:stop]
    cx, cy, cz = own[:, 0].copy(), own[:, 1].copy(), own[:, 2].copy()
    for j in range(k):
        q = points[near[:, j]]
        cx += q[:, 0]
        cy += q[:, 1]
        cz += q[:, 2]
    cx, cy, cz = cx / (k + 1), cy / (k + 1), cz / (k + 1)
    dx, dy, dz = own[:, 0] - cx, own[:, 1] - cy, own[:, 2] - cz
    xx, xy, xz, yy, yz, zz = dx * dx, dx * dy, dx * dz, dy * dy, dy * dz, dz * dz
    for j in range(k):
        q = points[near[:, j]]
        dx, dy, dz = q[:, 0] - cx, q[:, 1] - cy, q[:, 2] - cz
        xx, xy, xz, yy, yz, zz = xx + dx * dx, xy + dx * dy, xz + dx * dz, yy + dy * dy, yz + dy * dz, zz + dz * dz
    return xx, xy, xz, yy, yz, zz


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(M, 3) the cross products of the rows of ``a`` and ``b`` (M, 3), each term as the kernels take it."""
    return np.stack(
        [
            a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1],
            a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2],
            a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0],
        ],
        axis=1,
    )


def _squared(a: np.ndarray) -> np.ndarray:
    """(M,) the squared lengths of the rows of ``a`` (M, 3), added left to right."""
    return a[:, 0] * a[:, 0] + a[:, 1] * a[:, 1] + a[:, 2] * a[:, 2]


def _first_tangent(unit: np.ndarray) -> np.ndarray:
    """(M, 3) the first tangent of the kernels' frame of the unit vectors ``unit`` (M, 3): ``cross(n, e)``
    for the axis ``e`` least aligned with ``n`` (:func:`meshcurv._kernels._common._tangent_frame`)."""
    nx, ny, nz = unit[:, 0], unit[:, 1], unit[:, 2]
    ax, ay, az = np.abs(nx), np.abs(ny), np.abs(nz)
    first = (ax <= ay) & (ax <= az)
    second = ~first & (ay <= az)
    zero = np.zeros(unit.shape[0])
    tangent = np.where(
        first[:, None],
        np.stack([zero, nz, -ny], axis=1),
        np.where(second[:, None], np.stack([-nz, zero, nx], axis=1), np.stack([ny, -nx, zero], axis=1)),
    )
    return tangent / np.sqrt(_squared(tangent))[:, None]


def orientation_signs(
    normals: np.ndarray,
    indices: np.ndarray,
    usable: np.ndarray,
    *,
    given: bool = False,
    points: np.ndarray | None = None,
):
    """Signs (+1/-1) that orient ``normals`` consistently, and the component label of each point.

    Parameters
    ----------
    normals : ndarray of shape (N, 3)
        Unit normals, any signs.
    indices : ndarray of shape (N, k)
        The nearest neighbours of each point (:func:`knn`); the first
        :data:`GRAPH_NEIGHBOURS` are the graph's edges.
    usable : ndarray of shape (N,), bool
        Points that enter the graph (outliers do not; each is its own component).
    given : bool, default: False
        The signs carry information (normals given by the user): the edges
        are weighted ``1 - n_i . n_j`` instead of ``1 - |n_i . n_j|``, so that
        the tree follows agreeing pairs and crosses to an opposite normal only
        where no agreeing path exists. Consistent normals on the two sides of
        a part thinner than the spacing (whose nearest neighbours face the
        other way) then stay as they are; with ``1 - |n_i . n_j|`` the tree
        would take those anti-parallel pairs as well and flip one side.
    points : ndarray of shape (N, 3), optional
        The positions (given normals): an edge is steep where an end lies
        beyond :data:`TANGENT_SLOPE` of the other's tangent plane
        (``|n . d| > 0.25 |d|``). A steep edge is dropped where its point has
        :data:`MIN_FLAT_EDGES` flat ones, and always when its normals are
        opposite and both point away from the other point (back to back: the
        two sides of a part thinner than the neighbourhood, whose consistent
        normals must not be "corrected" into one direction). A point that
        noise lifted off its neighbours' planes keeps its other steep edges.
        When the given normals are not consistent on that graph, they still
        are (signs all +1, a user's orientation is kept) when every edge of
        the graph between opposite normals runs between two stacked sheets:
        both normals point to the other end (face to face: the inward faces
        of a thin part, two outward parts across a gap) or both away from it
        (back to back), and no point has edges of both kinds. A normal flipped
        within one sheet has opposite edges whose two ends point the same way
        (across the chord of a curved sheet), or, under noise, both kinds
        (it lies above some neighbours and below others). This settles a part
        thinner than the spacing, or a rim sharper than it, whose two faces
        join by opposite edges only.

    Returns
    -------
    signs : ndarray of shape (N,)
        ``signs[i] * normals[i]`` is consistent with the root of its component,
        whose sign is +1.
    labels : ndarray of shape (N,), int
        Connected component of the k-nearest-neighbour graph.
    """
    indices = indices[:, :GRAPH_NEIGHBOURS]
    n = indices.shape[0]
    rows, cols, keep = _graph_edges(indices, usable)
    if points is None:
        compiled = numba_kernels("pointcloud")
        if compiled is not None:  # every kept edge's cosine without (E, 3) gathers
            cosine = compiled.edge_cosines(normals, np.ascontiguousarray(indices)).ravel()[keep]
        else:  # (the kernel's products, left to right: the same weights to the bit)
            cosine = _dot(normals[rows], normals[cols])
        # weight 1 - |cos| (1 - cos for given signs), plus a floor so that parallel pairs stay edges of the sparse graph
        weights = (1.0 - cosine if given else 1.0 - np.abs(cosine)) + 1e-6
        return _spanning_forest(n, rows, cols, cosine < 0, weights)
    offsets = points[cols] - points[rows]
    cosine = np.einsum("ij,ij->i", normals[rows], normals[cols])
    ahead = np.einsum("ij,ij->i", offsets, normals[rows])
    behind = np.einsum("ij,ij->i", offsets, normals[cols])
    flat = np.maximum(np.abs(ahead), np.abs(behind)) <= TANGENT_SLOPE * np.linalg.norm(offsets, axis=1)
    # a steep edge is dropped only where its point keeps enough flat ones: a point that noise
    # lifted off its neighbours' planes stays joined to them
    enough = np.bincount(rows, weights=flat, minlength=n) >= MIN_FLAT_EDGES
    # opposite normals that both point away from the other point: the two sides of a thin part
    back_to_back = (ahead < 0) & (behind > 0) & (cosine < 0)
    kept = flat | (~enough[rows] & ~back_to_back)
    weights = (1.0 - cosine if given else 1.0 - np.abs(cosine)) + 1e-6
    signs, labels = _spanning_forest(n, rows[kept], cols[kept], cosine[kept] < 0, weights[kept])
    if not given or (signs > 0).all():
        return signs, labels
    # opposite normals that both point to the other point: the inward faces of a thin part, two outward parts
    face_to_face = (ahead > 0) & (behind < 0) & (cosine < 0)
    if (((cosine < 0) & ~back_to_back & ~face_to_face).any()) or _both_ways(n, rows, cols, back_to_back, face_to_face):
        return signs, labels
    # every opposite pair lies across two stacked sheets, each point's one way: the normals are consistent
    apart = cosine >= 0
    _, labels = _spanning_forest(n, rows[apart], cols[apart], np.zeros(int(apart.sum()), dtype=bool), weights[apart])
    return np.ones(n), labels


def _both_ways(n: int, rows: np.ndarray, cols: np.ndarray, one: np.ndarray, other: np.ndarray) -> bool:
    """Whether a point is an end of an edge ``(rows, cols)`` of ``one`` (E,) bool and of one of ``other``."""
    ends = np.concatenate([rows, cols])
    on_one = np.bincount(ends, weights=np.concatenate([one, one]), minlength=n) > 0
    on_other = np.bincount(ends, weights=np.concatenate([other, other]), minlength=n) > 0
    return bool((on_one & on_other).any())


def _smallest_part(labels: np.ndarray, usable: np.ndarray) -> int:
    """Points of the smallest component ``labels`` (N,) of the ``usable`` points (N,) (0 when none is usable)."""
    sizes = np.bincount(labels[usable])
    sizes = sizes[sizes > 0]
    return int(sizes.min()) if sizes.size else 0


def _graph_edges(indices: np.ndarray, usable: np.ndarray):
    """``(rows, cols, keep)``: the edges of the graph ``indices`` (N, k) between usable points, and (N k,) which."""
    n, k = indices.shape
    rows = np.repeat(np.arange(n), k)
    cols = indices.ravel()
    keep = usable[rows] & usable[cols] & (rows != cols)
    return rows[keep], cols[keep], keep


def _tie_order(values: np.ndarray) -> np.ndarray:
    """(E,) the order of ``values`` (E,) rounded to :data:`TIE_RESOLUTION`, equal ones (and NaN, last) in their order."""
    with np.errstate(over="ignore", invalid="ignore"):
        key = np.rint(np.nan_to_num(values, nan=np.inf, posinf=np.inf) / TIE_RESOLUTION)
    return np.argsort(key, kind="stable")


def _forest_order(weights: np.ndarray) -> np.ndarray:
    """(E,) the order in which the orientation's forest takes the edges of ``weights`` (E,): by their weights
    rounded to :data:`TIE_RESOLUTION`, equal ones in the order of the edges (a stable sort: the order is unique).

    A strict order makes the minimum spanning forest unique, so that both backends grow the same one (the
    sorts of NumPy and scipy order equal weights each their own way, and a symmetric cloud's edges tie by the
    thousand: two copies of a thin ellipsoid side by side were oriented differently at 68 points,
    ``benchmarks/fuzz_api.md``, round 21, seed 387 case 882). The rounded weights, integers below 2^32 (the
    weights are below 4.3), are sorted by the radix sort of
    :func:`meshcurv._kernels.pointcloud_graph.stable_order` when compiled (1M points, 6M edges: 0.33-0.42 CPU
    s, where ``numpy.argsort`` of the weights took 0.58-0.60), by :func:`numpy.argsort` else; weights that do
    not fit an unsigned 64-bit integer so (NaN, negative or huge) by :func:`numpy.lexsort`.
    """
    key = np.multiply(weights, 1.0 / TIE_RESOLUTION)
    np.rint(key, out=key)
    if key.size and not (key.min() >= 0.0 and key.max() < 2.0**63):  # (NaN fails both)
        return np.lexsort((np.arange(key.size), np.nan_to_num(key, nan=np.inf)))
    code = key.astype(np.uint64)
    forest = numba_kernels("pointcloud_graph")
    if forest is not None:
        return forest.stable_order(code)[0]
    return np.argsort(code, kind="stable")


def _first_point_parts(signs: np.ndarray, roots: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(signs, labels)`` of the compiled forest (``roots`` (N,) of its union-find) as the NumPy path gives them:
    the components numbered in the order of their first point, whose sign is +1
    (:func:`meshcurv._kernels.pointcloud_graph.first_point_parts`; the compiled path only)."""
    return numba_kernels("pointcloud_graph").first_point_parts(signs, np.ascontiguousarray(roots, dtype=np.int64))


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(...) the dot products of the vectors of ``a`` and ``b`` (..., 3) (broadcast), added left to right as the compiled kernels
    add them (:func:`numpy.einsum` adds them in another order: the weights of the orientation's edges, whose ties
    decide its forest, would differ in their last bits between the backends)."""
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1] + a[..., 2] * b[..., 2]


def _spanning_forest(n: int, rows: np.ndarray, cols: np.ndarray, opposite: np.ndarray, weights: np.ndarray):
    """``(signs, labels)``: signs propagated along the minimum spanning forest of the edges ``(rows, cols)``.

    ``opposite`` (E,) bool: the ends of the edge take opposite signs (their
    normals point apart); ``weights`` (E,) > 0. Each component's root gets
    +1; ``labels`` numbers the components of the ``n`` nodes from 0.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import breadth_first_order, connected_components, minimum_spanning_tree

    order = _forest_order(weights)
    compiled = numba_kernels("pointcloud")
    if compiled is not None:
        signs, roots = compiled.spanning_signs(n, rows, cols, np.asarray(opposite).astype(np.int8), order)
        return _first_point_parts(signs, roots)
    # the edges weighed by their rank in ``order``: distinct weights, whose minimum spanning forest is the one
    # Kruskal's algorithm grows taking the edges in ``order`` (the compiled path's)
    ranks = np.zeros(order.size)
    ranks[order] = np.arange(1, order.size + 1)
    graph = coo_matrix((ranks, (rows, cols)), shape=(n + 1, n + 1)).tocsr()
    # both searches treat the graph as undirected: (i, j) is an edge when either is among the other's neighbours
    n_components, labels = connected_components(graph[:n, :n], directed=False)
    # one virtual node n joined to the first point of each component: one tree for every component
    roots = np.zeros(n_components, dtype=np.int64)
    roots[labels[::-1]] = np.arange(n)[::-1]
    hub = coo_matrix((np.full(n_components, 1e-9), (np.full(n_components, n), roots)), shape=(n + 1, n + 1))
    tree = minimum_spanning_tree(graph + hub + hub.T)
    _, parent = breadth_first_order(tree, n, directed=False, return_predecessors=True)
    parent = parent[:n].astype(np.int64)
    parent[(parent == n) | (parent < 0)] = -1  # the roots (children of the hub) and the hub
    # relative sign of each point to its parent, then products along the paths by pointer jumping
    has_parent = parent >= 0
    signs = np.ones(n)
    anchor = np.where(has_parent, parent, np.arange(n))
    # the relation of each tree edge, looked up in a matrix of the edges in both directions
    relation = np.where(opposite, -1.0, 1.0)
    lookup = coo_matrix(
        (np.concatenate([relation, relation]), (np.concatenate([rows, cols]), np.concatenate([cols, rows]))),
        shape=(n, n),
    ).tocsr()
    child = np.flatnonzero(has_parent)
    if child.size:  # no edge at all (every point unusable, e.g. on a line): every point its own root
        signs[child] = np.sign(np.asarray(lookup[child, parent[child]]).reshape(-1))
    signs[signs == 0] = 1.0
    while True:
        moved = anchor[anchor] != anchor
        if not moved.any():
            break
        signs = signs * signs[anchor]
        anchor = anchor[anchor]
    # the last pass multiplies by the sign of each path's first step at the root (+1): nothing lost
    signs = signs * signs[anchor]
    return signs, labels


def _part_centroids(points: np.ndarray, labels: np.ndarray, n_labels: int) -> np.ndarray:
    """(n_labels, 3) the centroid of each part's points (0 for a part of none)."""
    counts = np.bincount(labels, minlength=n_labels).astype(float)
    sums = np.stack([np.bincount(labels, weights=points[:, j], minlength=n_labels) for j in range(3)], axis=1)
    return sums / np.maximum(counts, 1.0)[:, None]


def outward_signs(points: np.ndarray, normals: np.ndarray, labels: np.ndarray, areas: np.ndarray) -> np.ndarray:
    """(N,) +1 or -1 per point: -1 on the components whose normals point inward.

    ``sum_i areas_i n_i . (p_i - c)`` over a component (``c`` its centroid) is
    three times the enclosed volume for outward normals (divergence theorem).
    A component with no volume (that sum at most :data:`FLAT_FLUX` times
    ``sum_i areas_i |p_i - c|``: a flat part, whose sum is round-off) has no
    outside: its normals face :data:`PCA_SIGN`, on both backends alike.
    """
    n_labels = int(labels.max()) + 1 if labels.size else 0
    centroid = _part_centroids(points, labels, n_labels)
    offsets = points - centroid[labels]
    flux = np.bincount(labels, weights=areas * np.einsum("ij,ij->i", normals, offsets), minlength=n_labels)
    size = np.bincount(labels, weights=areas * np.linalg.norm(offsets, axis=1), minlength=n_labels)
    facing = np.bincount(labels, weights=areas * (normals @ PCA_SIGN), minlength=n_labels)
    flat = np.abs(flux) <= FLAT_FLUX * size
    return np.where(np.where(flat, facing, flux)[labels] < 0, -1.0, 1.0)


def undecided_fragments(
    points: np.ndarray, normals: np.ndarray, labels: np.ndarray, areas: np.ndarray, indices: np.ndarray, tree=None
) -> np.ndarray:
    """(N,) bool: the points of fragments of a larger part whose outward side nothing decides.

    A part that the orientation's graph cut off from a larger part beside it (a neighbour of one of its points
    on a part at least 1 / :data:`FRAGMENT_SHARE` times its area), not closed as far as its flux tells
    (``|sum a_i n_i . (p_i - c)|`` below :data:`FRAGMENT_FLUX` times ``sum a_i |n_i . (p_i - c)|``, ``c`` its
    centroid: 1 on a sphere), took its side in :func:`outward_signs` from its own shape, which on a piece of a
    saddle or of a flat tread says nothing, and the winding number does not correct it (a patch adds little to
    the winding number at its own points). Such a piece: treads of a voxel staircase cut off from the rest by
    their risers (``benchmarks/fuzz_api.py --point-clouds``, voxel surfaces). So are the parts that the rest of
    the cloud wraps and whose side its winding number does not confirm (:func:`unconfirmed_parts`).

    Parameters
    ----------
    points, normals : ndarray of shape (N, 3)
        The points and their oriented normals.
    labels : ndarray of shape (N,), int
        The part of each point (:func:`oriented_signs`).
    areas : ndarray of shape (N,)
        Each point's area (0 for the points that do not count).
    indices : ndarray of shape (N, k)
        The nearest neighbours of each point.
    tree : scipy.spatial.cKDTree, optional
        The points' tree (default: built when needed).
    """
    n_labels = int(labels.max()) + 1 if labels.size else 0
    if n_labels < 2:
        return np.zeros(labels.shape[0], dtype=bool)
    centroid = _part_centroids(points, labels, n_labels)
    height = np.einsum("ij,ij->i", normals, points - centroid[labels]) * areas
    flux = np.abs(np.bincount(labels, weights=height, minlength=n_labels))
    spread = np.bincount(labels, weights=np.abs(height), minlength=n_labels)
    area = np.bincount(labels, weights=areas, minlength=n_labels)
    beside = np.zeros(n_labels, dtype=bool)  # a neighbour of one of its points on a part that much larger
    beside[labels[(area[labels[indices]] * FRAGMENT_SHARE > area[labels][:, None]).any(axis=1)]] = True
    return ((flux <= FRAGMENT_FLUX * spread) & beside & (area > 0))[labels] | unconfirmed_parts(
        points, normals, labels, areas, indices, tree
    )


def unconfirmed_parts(
    points: np.ndarray, normals: np.ndarray, labels: np.ndarray, areas: np.ndarray, indices: np.ndarray, tree=None
) -> np.ndarray:
    """(N,) bool: the points of parts beside another that the rest of the cloud wraps and whose side it does not
    confirm.

    A part's side comes from its own shape (:func:`outward_signs`), right on a closed part. On a piece of a larger
    closed surface that the orientation's graph cut off the rest (a voxel staircase's steps carry no sign), the
    flux about the piece's centroid can be as clear as a closed part's and wrong: the inner wall of a torus, a band
    about the hole, has its centroid in the hole, and its normals, pointing into the hole, give a negative flux:
    turned, the whole band is inside out (``benchmarks/fuzz_api.py --point-clouds``, voxel clouds). The winding
    number of the whole cloud at the points of a part beside another (a neighbour of one of its points, of
    ``indices``, on another part) is the sum of the part's own, ``o``,
    and the rest's, ``r``: ``r + o`` as it is, ``r - o`` turned, ``1/2`` on a consistent closed cloud. Where the
    rest wraps the part (mean ``|r|`` at least :data:`FRAGMENT_WRAPPED`), its side is confirmed only when ``r + o``
    is closer to 1/2 in the mean than ``r - o`` by :data:`FRAGMENT_MARGIN` (the band: ``o`` near 0 at its own
    points, ``r`` near 1/2 about the hole: either side fits, and the side is undecided). A closed part has ``o``
    1/2 (or -1/2 as a cavity's wall): confirmed; a part alone (``r`` 0) keeps its side, and so does a part
    beside no other (two flat plates several spacings apart: the other adds up to 1/2 near a wide one, as the rest
    of a closed surface about a hole does). The arguments are those of :func:`undecided_fragments` (the tree built
    here when a part is beside another and none is given).
    """
    n = points.shape[0]
    unsure = np.zeros(n, dtype=bool)
    usable = areas > 0
    candidates = np.flatnonzero(usable)
    # the parts beside another: a usable neighbour of one of their usable points on another part
    beside = np.zeros(int(labels.max()) + 1 if labels.size else 0, dtype=bool)
    near = indices[candidates]
    beside[labels[candidates[((labels[near] != labels[candidates][:, None]) & usable[near]).any(axis=1)]]] = True
    if not beside.any():
        return unsure
    if tree is None:
        from scipy.spatial import cKDTree

        tree = cKDTree(points)
    local = np.sqrt(areas)  # (each point's spacing)
    queries = _part_queries(candidates[beside[labels[candidates]]], labels, points, local)
    sources = _spread(candidates, WINDING_SOURCES, points, local)
    total, own = _winding(points, normals, areas, usable, tree, points[queries], queries, sources, labels)
    part = labels[queries]
    count = np.maximum(np.bincount(part, minlength=beside.size), 1)
    own = np.bincount(part, weights=own, minlength=count.size) / count
    rest = np.bincount(part, weights=total, minlength=count.size) / count - own
    away = rest - 0.5
    confirmed = np.abs(away - own) - np.abs(away + own) >= FRAGMENT_MARGIN
    unsure[candidates] = (beside & (np.abs(rest) >= FRAGMENT_WRAPPED) & ~confirmed)[labels[candidates]]
    return unsure


def _part_queries(candidates: np.ndarray, labels: np.ndarray, points: np.ndarray, local: np.ndarray) -> np.ndarray:
    """(M,) sorted: :data:`WINDING_QUERIES` of the ``candidates`` or more (:func:`meshcurv.lattice._spread` of
    ``points`` (N, 3) and their spacings ``local`` (N,)), and of each part's (``labels``) candidates
    :data:`FRAGMENT_QUERIES` at least (all when fewer), evenly spaced in their order."""
    part = labels[candidates]
    order = np.argsort(part, kind="stable")
    sizes = np.bincount(part)
    first = np.cumsum(sizes) - sizes
    rank = np.empty(candidates.size, dtype=np.int64)
    rank[order] = np.arange(candidates.size) - first[part[order]]
    size = sizes[part]
    most = np.minimum(size, FRAGMENT_QUERIES)
    picked = (rank + 1) * most // size > rank * most // size  # ``most`` of each part's ``size``, evenly
    return np.union1d(_spread(candidates, WINDING_QUERIES, points, local), candidates[picked])


def oriented_signs(
    points: np.ndarray, normals: np.ndarray, indices: np.ndarray, usable: np.ndarray, spacing: np.ndarray, tree=None
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Signs that orient estimated (unsigned) ``normals`` consistently, and outward on each part.

    The orientation is propagated (:func:`_spanning_forest`) along two kinds
    of edges of the graph:

    - *flat* edges, whose ends both lie within :data:`SHEET_SLOPE` of the
      other's tangent plane (``|n . d| <= 0.4 |d|`` at both ends): one sheet,
      the normals keep their relative sign (``sign(n_i . n_j)``);
    - *stacked* edges, between two (near) parallel sheets: ``|n_i . n_j| >=``
      :data:`FACING_COSINE`, each end at least :data:`STACKED_OFFSET` spacings
      off the other's tangent plane, on the sides that parallel planes give
      (``(n_i . d)(n_j . d)(n_i . n_j) > 0``). They cross a gap between two
      parts of the cloud (facing each other) or the inside of a thin part
      (back to back): either way outward normals point apart, so the sign
      passes *reversed*. These are taken after every flat edge: they join
      sheets that no flat path joins.

    Other edges (off one sheet, not across two: a crease, noise) carry no
    sign. A flat edge steeper than :data:`TRUSTED_SLOPE` must close a
    triangle of flat edges (:func:`_supported`). Without this a tree through a gap a spacing or two wide passes the
    sign as if the two sheets were one surface and turns one part inside out
    (two spheres 1 spacing apart: one at ``H = -1/r``); the faces of a thin
    part are joined the same way.

    Components of fewer than :data:`PART_MIN_POINTS` points (noise lifts
    single points off their neighbours' planes) take the side of the part
    they are joined to by their flattest other edge (rounds of this until
    none is left). A small component joined so to two different large parts
    stands between two sheets: its side is undecided (``doubtful``), as are
    both ends of a flat edge of (near) parallel normals that the orientation
    leaves opposite (two sheets closer than the spacing, as at the rim of a
    part thinner than that: they cannot be told apart there). Each part is
    then turned outward by the sign of ``sum_i a_i n_i . (p_i - c)``
    (:func:`outward_signs`: three times its volume on a closed part), and,
    given the points' ``tree``, each point's side checked against the
    winding number of the cloud (:func:`winding_sides`); the flat edges left
    opposite are looked for after that.

    Parameters
    ----------
    points : ndarray of shape (N, 3)
    normals, indices, usable
        As for :func:`orientation_signs` (each outlier is its own part).
    spacing : ndarray of shape (N,)
        The local spacing (:func:`local_spacing`).
    tree : scipy.spatial.cKDTree, optional
        The points' tree: the sides are checked against the winding number
        (:func:`winding_sides`). Default: not checked.

    Returns
    -------
    signs : ndarray of shape (N,)
        ``signs[i] * normals[i]`` is consistent within each part and outward
        (into the cavity on a cavity's wall, when ``tree`` is given).
    labels : ndarray of shape (N,), int
        The part of each point.
    doubtful : ndarray of shape (N,), bool
        Points whose side could not be decided.
    sheets : ndarray of shape (N,), int
        The sheet of each point: the components of the flat edges (-1 for
        components of fewer than :data:`PART_MIN_POINTS` points: noise).
    unsettled : ndarray of shape (N,), bool
        The doubtful points whose side the winding number contradicts
        (:func:`winding_sides`).
    """
    n = points.shape[0]
    graph = _graph_cut(points, indices)
    compiled = numba_kernels("pointcloud")
    if compiled is not None:  # the edges and their products in one pass on every core, without (E, 3) gathers
        rows, cols, kept, ahead, behind, cosine, slope = compiled.graph_edges(points, normals, graph, usable)
    else:
        rows, cols, kept, ahead, behind, cosine, slope = _graph_geometry(points, normals, graph, usable)
    # (NaN, a zero offset, is not flat; nor is an edge at right angles: it passes no sign, SIGN_COSINE)
    signed = (cosine > SIGN_COSINE) | (cosine < -SIGN_COSINE)  # (|cos| > SIGN_COSINE without an (E,) temporary)
    flat = (slope <= SHEET_SLOPE) & signed
    flat = _supported(flat, slope, rows, cols, kept, graph)
    forest = numba_kernels("pointcloud_graph")
    if forest is None:
        sheets = _sheets(n, rows[flat], cols[flat])
    # flat edges first, by 1 - |cos| and their slope (a tree of one sheet is grown before edges that leave it a
    # little); stacked edges after them all: they only join sheets that no flat path joins (taken first, an
    # accidental stacked edge inside a sphere of 1000 points turned half of it)
    if compiled is not None:
        stacked, weights, opposite = compiled.edge_weights(
            flat, ahead, behind, cosine, slope, spacing, rows, cols, STACKED_OFFSET, FACING_COSINE
        )
    else:
        stacked, weights, opposite = _edge_weights(flat, ahead, behind, cosine, slope, spacing, rows, cols)
    used = flat | stacked
    separated = False
    if forest is not None:
        # the sheets read off the forest's union-find once its flat edges are taken, where the flat edges come
        # first in the order (a flat edge weighs 1 - |cos| + a slope of at most SHEET_SLOPE, below 3; a stacked
        # one 3 or more, its |cos| clipped to 1); else, as a guard, the NumPy forest
        # (each edge taken both ways once: the later way is one Kruskal skips; 1M torus points: 5.9M -> 3.5M edges)
        # (the single edges' positions, their count of flat ones and the order's keys in one pass on every core)
        single, code, n_flat, fits = forest._single_edge_keys(graph, kept, used, flat, weights, 1.0 / TIE_RESOLUTION)
        # `order` over the single edges, as edges of the graph (the sort carries them: no gather after it)
        taken = forest.stable_order(code, single)[0] if fits else single[_forest_order(weights[single])]
        separated = (n_flat == 0 or weights[taken[n_flat - 1]] < 3.0) and (
            n_flat == taken.size or weights[taken[n_flat]] >= 3.0
        )
    if separated:
        # the kernel gathers the edges in their order itself
        signs, roots, sheets = forest.spanning_sheets(
            n, rows, cols, opposite.view(np.int8), taken, n_flat, PART_MIN_POINTS
        )
        signs, labels = _first_point_parts(signs, roots)
    else:
        if forest is not None:
            sheets = _sheets(n, rows[flat], cols[flat])
        signs, labels = _spanning_forest(n, rows[used], cols[used], opposite[used], weights[used])
    other = np.flatnonzero(~used & signed)
    sizes = np.bincount(labels)
    part = np.where((sizes >= PART_MIN_POINTS)[labels] & usable, labels, -1)
    doubtful = np.zeros(n, dtype=bool)
    # the other edges in both directions, the flattest first
    other = other[_tie_order(slope[other])]  # (slopes equal to round-off: in the order of the edges)
    a = np.stack([rows[other], cols[other]], axis=1).ravel()
    b = np.stack([cols[other], rows[other]], axis=1).ravel()
    c = np.repeat(cosine[other], 2)
    steep = np.repeat(slope[other], 2)
    for _ in range(SMALL_PART_ROUNDS):
        joins = (part[a] < 0) & (part[b] >= 0)  # from a point of a small, unattached component to an attached one
        if not joins.any():
            break
        ja, jb, jc = a[joins], b[joins], c[joins]
        small = labels[ja]
        pairs = np.unique(np.stack([small, part[jb]], axis=1), axis=0)
        between = np.bincount(pairs[:, 0], minlength=sizes.size) > 1  # joined to two large parts
        unique_small, first = np.unique(small, return_index=True)  # its flattest edge gives its side and its part
        sides = np.where(signs[ja] * signs[jb] * jc < 0, -1.0, 1.0)
        flip = np.ones(sizes.size)
        flip[small[first]] = sides[first]
        # ... unless an edge as flat (equal to round-off) gives the other side: which is first is the order of the
        # edges, the pose's (fuzz_api 590/4: ogre's mirror-symmetric pair of edges, slopes equal in one pose and
        # 3e-13 apart turned, three points turned over with it)
        head = first[np.searchsorted(unique_small, small)]
        js = steep[joins]
        torn = (np.abs(js - js[head]) <= TIE_RESOLUTION) & (sides != sides[head])
        between[small[torn]] = True
        target = np.full(sizes.size, -1)
        target[small[first]] = part[jb[first]]
        taken = target[labels] >= 0
        signs = np.where(taken, signs * flip[labels], signs)
        doubtful |= taken & between[labels]
        part = np.where(taken, target[labels], part)
    part = np.where(part >= 0, part, sizes.size + labels)  # the small components left alone are their own parts
    labels = np.unique(part, return_inverse=True)[1].reshape(-1)
    signs = signs * outward_signs(points, normals * signs[:, None], labels, np.where(usable, spacing**2, 0.0))
    unsettled = np.zeros(n, dtype=bool)
    if tree is not None:
        flips, unsettled = winding_sides(points, normals * signs[:, None], usable, spacing, tree, indices)
        signs = signs * flips
        signs = signs * between_sides(points, normals * signs[:, None], usable, spacing, tree, indices)
    # flat edges of (near) parallel normals left opposite: two sheets closer than the spacing
    if forest is not None:
        doubtful = forest.torn_ends(flat, cosine, signs, rows, cols, PARALLEL_COSINE, doubtful)
    else:
        torn = flat & (np.abs(cosine) >= PARALLEL_COSINE) & (signs[rows] * signs[cols] * cosine < 0)
        doubtful[rows[torn]] = True
        doubtful[cols[torn]] = True
    undecided = doubtful | unsettled
    signs = _settled_sides(normals, signs, doubtful & ~unsettled, indices, usable, undecided=undecided)
    return signs, labels, undecided, sheets, unsettled


def _settled_sides(normals, signs, settle, indices, usable, undecided=None):
    """``signs`` (N,) with each of the ``settle`` (N,) bool points on the side of the sum of its decided usable
    neighbours' oriented normals (``indices`` (N, k)); where they sum to none across it (the cosine of the sum and
    its normal within :data:`SIGN_COSINE` of 0, as an edge at right angles passes no sign), as it was. A neighbour
    is decided unless ``undecided`` (N,) bool (default: ``settle``): the unsettled points (the winding number
    contradicts their side) are not settled here, and do not vote either (R30, session 64: their signs are as
    undecided as the others').

    The orientation leaves an undecided point the sign of whichever edge reached it, and on a lattice edges tie:
    the pose's order chose (fuzz_api 522/23: two such points of a voxel torus in opposite signs in two poses; the
    noise level's fits, which refuse balls holding the other side by the normals, then read 0.05843 and 0.05851,
    and the default radius moved with it). Their neighbours' normals turn with the pose. (A normal at right angles
    to the sum was turned by the sign of round-off: fuzz_api 660/28, three points of ogre's cloud at cosines of
    -7e-16 and 3e-12 in two poses; the fits' check of the side of their neighbours then moved 5 points' reasons.)
    """
    rows = np.flatnonzero(settle)
    if rows.size == 0:
        return signs
    near = indices[rows]
    undecided = settle if undecided is None else undecided
    decided = (usable[near] & ~undecided[near] & (near != rows[:, None]))[:, :, None]
    oriented = normals[near] * signs[near][:, :, None]
    summed = (oriented * decided).sum(axis=1)
    own = normals[rows] * signs[rows, None]
    side = np.einsum("mj,mj->m", summed, own)
    scale = np.sqrt(np.einsum("mj,mj->m", summed, summed) * np.einsum("mj,mj->m", own, own))
    signs = signs.copy()
    signs[rows[side < -SIGN_COSINE * scale]] *= -1
    return signs


def _graph_cut(points: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """The graph of the orientation: the first :data:`GRAPH_NEIGHBOURS` columns of the nearest neighbours
    ``indices`` (N, k), and in a row whose neighbours tie across that cut (within :data:`TIE_TOLERANCE`) the whole
    tied group (columns up to ``k``; the slots after it hold the point itself: no edge). On a lattice a ring of
    neighbours at one distance crosses the cut, and the search's order, which a rigid motion changes by round-off,
    chose the edges: a voxel torus (12, 5) turned had two points joined by a stacked edge only and turned inside out
    (the noise level's fits then refused their balls, and the default radius moved). A view of ``indices`` where
    no row has such a tie; else as wide as the widest group needs."""
    k = GRAPH_NEIGHBOURS
    if indices.shape[1] <= k:
        return indices
    own = np.arange(indices.shape[0])
    cut = np.linalg.norm(points[indices[:, k]] - points, axis=1)
    # (a slot beyond the cut holding the point itself: a group tied farther out was dropped, none crosses this cut)
    cut[indices[:, k] == own] = np.inf
    last = np.linalg.norm(points[indices[:, k - 1]] - points, axis=1)
    rows = np.flatnonzero(last >= cut * (1.0 - TIE_TOLERANCE))
    if rows.size == 0:
        return indices[:, :k]  # (a view: the kernels read it in place)
    wide = indices[rows, k:]
    distances = np.linalg.norm(points[wide] - points[rows, None, :], axis=2)
    # the group: the columns from k on at the distance of column k - 1 (the point itself ends it)
    tied = (distances <= last[rows, None] * (1.0 + TIE_TOLERANCE)) & (wide != rows[:, None])
    tied = np.cumprod(tied, axis=1).astype(bool)
    width = k + int(tied.sum(axis=1).max())
    if width == k:
        return indices[:, :k]
    graph = np.repeat(own[:, None], width, axis=1)
    graph[:, :k] = indices[:, :k]
    graph[rows, k:] = np.where(tied, wide, rows[:, None])[:, : width - k]
    return graph


def _graph_geometry(points, normals, indices, usable):
    """``(rows, cols, kept, ahead, behind, cosine, slope)``: the edges of the graph ``indices`` (N, k) between
    usable points (:func:`_graph_edges`) and (E,) ``n_i . d``, ``n_j . d``, ``n_i . n_j`` and
    ``max(|n_i . d|, |n_j . d|) / |d|`` of ``d = p_j - p_i`` (NaN where ``d`` is 0). Compiled:
    :func:`meshcurv._kernels.pointcloud.graph_edges`."""
    rows, cols, kept = _graph_edges(indices, usable)
    offsets = points[cols] - points[rows]
    # (the kernel's operations in its order: the same weights, to the bit)
    length = np.sqrt(_dot(offsets, offsets))
    ahead = _dot(offsets, normals[rows])
    behind = _dot(offsets, normals[cols])
    cosine = _dot(normals[rows], normals[cols])
    with np.errstate(invalid="ignore", divide="ignore"):
        slope = np.maximum(np.abs(ahead), np.abs(behind)) / length
    return rows, cols, kept, ahead, behind, cosine, slope


def _edge_weights(flat, ahead, behind, cosine, slope, spacing, rows, cols):
    """(E,) ``stacked``, ``weights`` and ``opposite`` of the edges of :func:`oriented_signs` (see there).
    Compiled: :func:`meshcurv._kernels.pointcloud.edge_weights`."""
    reach = STACKED_OFFSET * 0.5 * (spacing[rows] + spacing[cols])
    stacked = (
        ~flat
        & (np.abs(cosine) >= FACING_COSINE)
        & (np.minimum(np.abs(ahead), np.abs(behind)) >= reach)
        & (ahead * behind * cosine > 0)
    )
    weights = np.where(
        stacked, 3.0 + (1.0 - np.minimum(np.abs(cosine), 1.0)), 1.0 - np.abs(cosine) + np.nan_to_num(slope) + 1e-6
    )
    return stacked, weights, (cosine < 0) ^ stacked


def _supported(flat, slope, rows, cols, kept, indices):
    """``flat`` less the edges above :data:`TRUSTED_SLOPE` that close no triangle of flat edges.

    Two sheets a spacing apart are joined by a few edges that happen to lie
    near both tangent planes (slopes up to 0.4, at 1000 points a sphere); an
    edge of one sheet has a common neighbour with flat edges to both its ends.
    """
    check = np.flatnonzero(flat & (slope > TRUSTED_SLOPE))
    if check.size == 0:
        return flat
    n, k = indices.shape
    directed = np.zeros(n * k, dtype=bool)
    directed[np.flatnonzero(kept)] = flat  # flatness of each (point, neighbour column) of the graph
    directed = directed.reshape(n, k)
    a, b = rows[check], cols[check]
    common = (
        (indices[a][:, :, None] == indices[b][:, None, :]) & directed[a][:, :, None] & directed[b][:, None, :]
    ).any(axis=(1, 2))
    flat = flat.copy()
    flat[check[~common]] = False
    return flat


def _sheets(n: int, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """(N,) the components of the edges ``(rows, cols)``; -1 for those of fewer than :data:`PART_MIN_POINTS`.

    Numbered by their first point (:func:`scipy.sparse.csgraph.connected_components`). Compiled: read off the
    union-find of the orientation's forest (:func:`meshcurv._kernels.pointcloud_graph.spanning_sheets`).
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    _, labels = connected_components(
        coo_matrix((np.ones(rows.size, dtype=np.int8), (rows, cols)), shape=(n, n)), directed=False
    )
    return np.where(np.bincount(labels)[labels] >= PART_MIN_POINTS, labels, -1)


def facing_away(normals: np.ndarray, indices: np.ndarray, usable: np.ndarray | None = None) -> np.ndarray:
    """(N,) bool: points with a neighbour (of ``indices``, (N, k)) whose oriented normal faces away from theirs.

    Such a point's nearest neighbours hold another sheet (a neighbouring part, the other face of a thin
    part): its PCA normal may mix the two. A neighbour at right angles (cosine below :data:`SIGN_COSINE`: its sign
    is round-off, which the pose decides) counts as facing away, as the jets' check counts one below its own
    margin (:data:`meshcurv.jets.AWAY_DOT`). A neighbour that is not ``usable`` (N,) bool (an outlier, a point on
    a line) does not count: the orientation gives it no side (each is a part of its own, whose sign is the one
    the eigensolver gave its PCA normal, which the pose decides: fuzz_api 721/2, nine outliers of ogre's cloud
    turned over by a rigid motion, and 8 points beside them with other reasons, 11 <-> 9).
    """
    if usable is not None and not usable.all():  # (NaN cosines face nowhere)
        normals = np.where(usable[:, None], normals, np.nan)
    compiled = numba_kernels("pointcloud")
    if compiled is not None:  # the cosines without (N, 3) gathers
        return (compiled.edge_cosines(normals, np.ascontiguousarray(indices)) < SIGN_COSINE).any(axis=1)
    away = np.zeros(normals.shape[0], dtype=bool)
    for column in range(indices.shape[1]):
        away |= _dot(normals, normals[indices[:, column]]) < SIGN_COSINE  # (the kernel's sum: the same cosines)
    return away


def winding_numbers(
    points: np.ndarray,
    normals: np.ndarray,
    areas: np.ndarray,
    usable: np.ndarray,
    tree,
    queries: np.ndarray,
    sources: np.ndarray,
) -> np.ndarray:
    """(M,) the generalized winding number of the oriented cloud at the points ``queries`` (M,).

    ``w(q) = 1 / (4 pi) sum_j a_j n_j . (p_j - q) / |p_j - q|^3`` (Barill et al.
    2018) over the usable points ``j != q``: exactly over the
    :data:`WINDING_NEAR` nearest, and over the ``sources`` (S,) farther than
    those, each weighted by ``(usable points) / S`` (all usable points as
    sources: the exact sum). At a point of a closed surface with outward
    normals (or of a cavity with normals into the cavity) ``w = 1/2``: the
    mean of the 0 outside and the 1 inside; ``-1/2`` where the surface is
    inside out, ``3/2`` on an outward surface inside another. Each point
    stands for a disc of area ``a_j``: its term is softened to
    ``(|p_j - q|^2 + a_j / pi)^(3/2)`` (the disc's radius squared added) in the
    denominator, so that a neighbour much closer than the spacing (random
    samples have such pairs) adds about its disc's share, not a term that
    grows as ``1 / |p_j - q|^2``.
    """
    return _winding(points, normals, areas, usable, tree, points[queries], queries, sources)


def winding_at(
    points: np.ndarray,
    normals: np.ndarray,
    areas: np.ndarray,
    usable: np.ndarray,
    tree,
    positions: np.ndarray,
    sources: np.ndarray,
) -> np.ndarray:
    """(M,) the generalized winding number of the oriented cloud at ``positions`` (M, 3), off the points.

    As :func:`winding_numbers`, every usable point counted.
    """
    return _winding(points, normals, areas, usable, tree, positions, None, sources)


def _winding(points, normals, areas, usable, tree, q, queries, sources, labels=None):
    """:func:`winding_numbers` at the positions ``q`` (M, 3); ``queries`` (M,): the points there (left out of
    their own sums), or None. Given the points' part ``labels`` (N,) (with ``queries``): ``(total, own)``, the
    winding numbers and the shares of them of the part of each query (:func:`unconfirmed_parts`)."""
    k = min(WINDING_NEAR + 1, points.shape[0])
    near = tree.query(q, k=k, workers=-1)[1]
    offsets = points[near] - q[:, None, :]
    # (formed as the far sum forms them, left to right: the near points are exactly those it leaves out)
    squared = _dot(offsets, offsets)
    counted = usable[near] if queries is None else (near != queries[:, None]) & usable[near]
    softened = np.where(counted, squared + areas[near] / np.pi, 1.0)
    terms = np.where(
        counted, areas[near] * np.einsum("mkj,mkj->mk", offsets, normals[near]) / (softened * np.sqrt(softened)), 0.0
    )
    total = terms.sum(axis=1)
    # the far sum takes the sources beyond the farthest near point. The tree's distance squared again
    # (sqrt, then squared: a unit of the last place either way of the far sum's own) left the farthest near point
    # among the far ones at about 2% of the queries, which the pose chose: its term counted a second time, weighed
    # by the points per source (ogre as a cloud, shifted by 1024 sizes: winding numbers 0.15 apart, 34 points
    # turned at the next evaluation)
    reach_squared = squared.max(axis=1)
    weights = areas[sources] * (np.count_nonzero(usable) / sources.size)
    soft = areas[sources] / np.pi
    total += _far_winding(points, normals, weights, soft, sources, q, queries, reach_squared)
    if labels is None:
        return total / (4.0 * np.pi)
    own = np.where(labels[near] == labels[queries][:, None], terms, 0.0).sum(axis=1)
    part = labels[queries]
    for label in np.unique(part):  # the far sum over each part's own sources
        mine, theirs = np.flatnonzero(part == label), labels[sources] == label
        own[mine] += _far_winding(
            points, normals, weights[theirs], soft[theirs], sources[theirs], q[mine], queries[mine], reach_squared[mine]
        )
    return total / (4.0 * np.pi), own / (4.0 * np.pi)


def _far_winding(points, normals, weights, soft, sources, q, queries, reach_squared):
    """(M,) ``4 pi`` times the far part of :func:`_winding` at ``q`` (M, 3): the sum over the ``sources`` (S,)
    (``weights`` and ``soft`` (S,) per source) beyond ``reach_squared`` (M,) of each; ``queries`` as there."""
    total = np.zeros(q.shape[0])
    if sources.size == 0:
        return total
    compiled = numba_kernels("pointcloud")
    if compiled is not None:
        if queries is None:  # the positions appended to the points: the kernel reads its queries by index
            n = points.shape[0]
            extended = np.concatenate([points, q])
            total += compiled.far_winding(
                extended,
                np.concatenate([normals, np.zeros_like(q)]),
                weights,
                soft,
                sources,
                np.arange(n, n + q.shape[0]),
                reach_squared,
            )
        else:
            total += compiled.far_winding(points, normals, weights, soft, sources, queries, reach_squared)
    else:
        x, y, z = points[sources].T
        nx, ny, nz = normals[sources].T
        for start in range(0, q.shape[0], WINDING_CHUNK):
            rows = slice(start, start + WINDING_CHUNK)
            dx, dy, dz = x - q[rows, :1], y - q[rows, 1:2], z - q[rows, 2:]
            squared = dx * dx + dy * dy + dz * dz
            far = squared > reach_squared[rows, None]
            squared = squared + soft
            term = weights * (dx * nx + dy * ny + dz * nz) / (squared * np.sqrt(squared))
            # added source after source as the kernel adds them (sum() adds pairwise): the same sums to the bit
            total[rows] += np.cumsum(np.where(far, term, 0.0), axis=1)[:, -1]
    return total


def winding_sides(
    points: np.ndarray, normals: np.ndarray, usable: np.ndarray, spacing: np.ndarray, tree, indices: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """``(flips, unsettled)``: the side of oriented ``normals`` checked against the winding number of the cloud.

    The orientation of :func:`oriented_signs` can still cross a gap of a
    spacing or two between two parts (or the rim of a part thinner than the
    spacing) and turn one part, or one face, inside out; and it turns each
    part outward of itself, also a closed part inside another. The
    generalized winding number of the oriented cloud (:func:`winding_numbers`,
    areas ``spacing**2``) at a point is ``1/2`` where its side agrees with the
    whole cloud's (outward, or into a cavity as for meshes), ``-1/2`` where
    its part is inside out, ``3/2`` where its part is an outward surface
    inside another (a cavity's wall). The points farther than
    :data:`WINDING_WRONG` from ``1/2`` are turned and the winding number
    evaluated again, :data:`WINDING_ROUNDS` evaluations at most; the points
    still wrong at the last are ``unsettled``. (The faces of a thin part
    oriented alike: the winding number is wrong on the face facing the
    other's normals; turned, the part is inside out, and turned again whole.) The winding number is
    evaluated at :data:`WINDING_QUERIES` points at most (evenly spaced in the
    index order, the Morton order of :func:`meshcurv.pointcloud.point_cloud_curvatures`);
    the others take the verdict of the nearest of them along flat edges
    (:func:`_nearest_queries`). On an open surface the winding number lies
    between: nothing is turned.

    Parameters
    ----------
    points, normals : ndarray of shape (N, 3)
        The points and their consistently oriented unit normals.
    usable : ndarray of shape (N,), bool
        Points that count (outliers do not; they are never turned).
    spacing : ndarray of shape (N,)
        The local spacing (:func:`local_spacing`).
    tree : scipy.spatial.cKDTree
        The points' tree.
    indices : ndarray of shape (N, k)
        The nearest neighbours of each point (:func:`knn`).

    Returns
    -------
    flips : ndarray of shape (N,)
        +1 or -1: ``flips[i] * normals[i]`` is on the side the winding number settles.
    unsettled : ndarray of shape (N,), bool
        Points whose side is still wrong after the last evaluation.

    References
    ----------
    G. Barill, N. G. Dickson, R. Schmidt, D. I. W. Levin, A. Jacobson (2018).
    Fast winding numbers for soups and clouds. ACM Transactions on Graphics
    37(4), 43. https://doi.org/10.1145/3197517.3201337
    """
    n = points.shape[0]
    flips = np.ones(n)
    candidates = np.flatnonzero(usable)
    if candidates.size < 2:
        return flips, np.zeros(n, dtype=bool)
    queries = _spread(candidates, WINDING_QUERIES, points, spacing)
    sources = _spread(candidates, WINDING_SOURCES, points, spacing)
    areas = np.where(usable, spacing**2, 0.0)
    nearest = None
    for evaluation in range(WINDING_ROUNDS):
        winding = winding_numbers(points, normals * flips[:, None], areas, usable, tree, queries, sources)
        wrong_queries = np.abs(winding - 0.5) > WINDING_WRONG
        if not wrong_queries.any():
            return flips, np.zeros(n, dtype=bool)
        if nearest is None:  # (the graph's edges only when a side is wrong)
            rows, cols, _ = _graph_edges(indices[:, :GRAPH_NEIGHBOURS], usable)
            nearest = _nearest_queries(points, normals, usable, queries, rows, cols)
        wrong = np.zeros(n, dtype=bool)
        wrong[usable] = wrong_queries[nearest[usable]]
        if evaluation == WINDING_ROUNDS - 1:
            return flips, wrong
        # turn every wrong point: the winding number at a point does not depend on its own normal (its own
        # term is left out), so a point that noise alone put there is turned twice, back, and is unsettled
        flips = np.where(wrong, -flips, flips)
    return flips, np.zeros(n, dtype=bool)


def _nearest_queries(points, normals, usable, queries, rows, cols) -> np.ndarray:
    """(N,) the position in ``queries`` of each usable point's nearest query along the graph's flat edges.

    Along the edges ``(rows, cols)`` within :data:`SHEET_SLOPE` of both tangent
    planes (one sheet: a verdict does not cross a gap), their lengths the
    weights; a point no flat path joins to a query takes the nearest query in
    space. Other points get 0.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import dijkstra
    from scipy.spatial import cKDTree

    n = points.shape[0]
    position = np.full(n, -1, dtype=np.int64)
    position[queries] = np.arange(queries.size)
    if (position[usable] >= 0).all():
        return np.maximum(position, 0)
    offsets = points[cols] - points[rows]
    length = np.linalg.norm(offsets, axis=1)
    steep = np.maximum(
        np.abs(np.einsum("ij,ij->i", offsets, normals[rows])), np.abs(np.einsum("ij,ij->i", offsets, normals[cols]))
    )
    flat = (steep <= SHEET_SLOPE * length) & (length > 0)
    graph = coo_matrix((length[flat], (rows[flat], cols[flat])), shape=(n, n)).tocsr()
    _, _, source = dijkstra(graph, directed=False, indices=queries, min_only=True, return_predecessors=True)
    lost = np.flatnonzero(usable & (source < 0))
    if lost.size:
        source[lost] = queries[cKDTree(points[queries]).query(points[lost], workers=-1)[1]]
    return np.maximum(position[np.maximum(source, 0)], 0)


def two_sheets(
    points: np.ndarray,
    normals: np.ndarray,
    usable: np.ndarray,
    spacing: np.ndarray,
    tree,
    noise: float | None = None,
    lattice: Lattice = NO_LATTICE,
) -> tuple[np.ndarray, np.ndarray]:
    """``(alike, interleaved)``: (N,) bool, points beside a second sheet whose side cannot be trusted.

    Two sheets stacked within a few spacings (the faces of a thin part, two
    parts a gap apart) have opposite outward normals: back to back across a
    part, facing across a gap (a cavity's wall faces into the cavity, away
    from the shell around it). ``alike``: a point with
    :data:`STACKED_ALIKE_MIN` neighbours (of its :data:`WINDING_NEAR` nearest)
    on a sheet stacked on its own with normals the same way, and those
    neighbours: one of the two sheets is inside out, and nothing local says
    which (a patch of a face turned with the other face is consistent with
    itself; the winding number at a point does not depend on its own normal).
    Stacked sheets as :func:`_stacked` finds them, at least
    :data:`STACKED_ALIKE_OFFSET` spacings apart, or, with the ``noise`` level
    (in spacings) measured, :data:`ALIKE_NOISE` times it (and at least
    :data:`ALIKE_MIN_OFFSET`) when that is less.

    ``interleaved``: points in a region where two sheets lie closer than
    :data:`STACKED_OFFSET` spacings (a part thinner than that, the rim of a
    thin part): the points of the two sheets mix in every neighbourhood, the
    orientation cannot tell them apart and the normals there are a coin's
    toss. A point has two sheets when the heights of its neighbours within
    :data:`INTERLEAVED_REACH` spacings across the least-variance direction of
    its :data:`INTERLEAVED_NEIGHBOURS` nearest fall into two groups of at least
    :data:`INTERLEAVED_GROUP` points apart by :data:`INTERLEAVED_GAP` to
    :data:`STACKED_OFFSET` spacings (noise of 0.2 spacings leaves gaps below
    0.35 in 99% of neighbourhoods); it is ``interleaved`` when at least
    :data:`INTERLEAVED_SHARE` of its nearest neighbours have two sheets.

    Both are evaluated at :data:`WINDING_QUERIES` evenly spaced points first,
    and at every point when any of those is ``alike`` or at least
    :data:`INTERLEAVED_SAMPLE` of them have two sheets.
    """
    n = points.shape[0]
    alike, interleaved = np.zeros(n, dtype=bool), np.zeros(n, dtype=bool)
    candidates = np.flatnonzero(usable)
    if candidates.size <= INTERLEAVED_NEIGHBOURS:
        return alike, interleaved
    step = float(np.median(spacing[candidates]))
    offset = STACKED_ALIKE_OFFSET
    if noise is not None and np.isfinite(noise):
        offset = min(STACKED_ALIKE_OFFSET, max(ALIKE_MIN_OFFSET, ALIKE_NOISE * noise))
    sample = _spread(candidates, WINDING_QUERIES, points, spacing)
    # (a lattice coarser than the spacing is steeper than the orientation's flat edges)
    lattice = lattice if lattice.steps.max() <= LATTICE_RESOLVED * step else NO_LATTICE
    found = _sheet_signs(points, normals, usable, spacing, step, tree, sample, offset=offset)
    if found[0].any():
        found = _off_the_steps(points, normals, sample, found, lattice)
    if sample.size < candidates.size and (found[0].any() or found[3].mean() >= INTERLEAVED_SAMPLE):
        # every point (the stacked sheets' 48 neighbours only when the sample has any: a thin sheet of 1M
        # points costs about 20 us a point with them)
        found = _sheet_signs(
            points, normals, usable, spacing, step, tree, candidates, with_alike=found[0].any(), offset=offset
        )
        sample = candidates
        found = _off_the_steps(points, normals, sample, found, lattice)
    hit, near, flags, two, group = found
    alike[sample[hit]] = True
    alike[near[hit][flags[hit]]] = True
    if two.any():
        # the share of each point's nearest neighbours with two sheets (a region, not a point that noise split)
        mark = np.zeros(n)
        mark[sample[two]] = 1.0
        crowd = group[:, 1:]  # (the point itself first, and in the slots of neighbours tied at the cut)
        counted = usable[crowd] & (crowd != sample[:, None])
        share = (mark[sample] + (mark[crowd] * counted).sum(axis=1)) / (1.0 + counted.sum(axis=1))
        interleaved[sample[share >= INTERLEAVED_SHARE]] = True
    return alike & usable, interleaved & usable


def _sheet_signs(
    points,
    normals,
    usable,
    spacing,
    step,
    tree,
    queries,
    *,
    with_alike: bool = True,
    offset: float = STACKED_ALIKE_OFFSET,
):
    """``(hit, near, alike, two, group)`` of :func:`two_sheets` at ``queries`` (M,), in chunks of :data:`CHUNK`.

    ``hit`` (M,): stacked neighbours oriented alike; ``near`` (M, k): the
    nearest neighbours (the query itself first); ``alike`` (M, k): which of
    them; ``two`` (M,): two sheets closer than :data:`STACKED_OFFSET` spacings,
    read from the ``group`` (M, :data:`INTERLEAVED_NEIGHBOURS` + 1) of the nearest.
    ``with_alike=False``: ``hit`` and ``alike`` all False, and ``near`` the
    ``group``. In ``near`` and ``group`` the neighbours tied at the cut are
    dropped whole (:func:`_whole_rows`).
    """
    k = min((WINDING_NEAR if with_alike else INTERLEAVED_NEIGHBOURS) + 1, points.shape[0])
    width = min(INTERLEAVED_NEIGHBOURS + 1, k)
    hit, two = np.zeros(queries.size, dtype=bool), np.zeros(queries.size, dtype=bool)
    near = np.zeros((queries.size, k), dtype=np.int64)
    groups = np.zeros((queries.size, width), dtype=np.int64)
    flags = np.zeros((queries.size, k), dtype=bool)
    for start in range(0, queries.size, CHUNK):
        rows = slice(start, start + CHUNK)
        q = queries[rows]
        distances, found = tree.query(points[q], k=min(k + 1, points.shape[0]), workers=-1)
        ball = _whole_rows(distances, found, q, k)
        near[rows] = ball
        if with_alike:
            alike = _stacked(points, normals, usable, step, q, ball, alike=True, offset=offset)
            hit[rows] = alike.sum(axis=1) >= STACKED_ALIKE_MIN
            flags[rows] = alike
        group = groups[rows] = _whole_rows(distances, found, q, width)
        # the spacing of the neighbourhood (the median over the cloud is another part's in a cloud of two densities)
        local = np.median(np.where(usable[group], spacing[group], np.nan), axis=1)
        two[rows] = _two_heights(points, group, usable, np.where(np.isfinite(local), local, step))
    return hit, near, flags, two, groups


def _whole_rows(distances: np.ndarray, found: np.ndarray, queries: np.ndarray, k: int) -> np.ndarray:
    """(M, k) the nearest points ``found`` (M, j), at ``distances`` (M, j), of the ``queries`` (M,) (each itself
    first) cut to ``k``, the neighbours tied with the next beyond the cut dropped whole (:func:`whole_ties`: their
    slots hold the query). On a lattice (a voxel surface read as a cloud) a query's cut falls through a ring of
    neighbours at one distance, and the search's order, which a rigid motion changes by round-off, chose among
    them: the two-sheets reading of a turned voxel sphere's points changed at 24 of its 14,778 points."""
    if found.shape[1] <= k:
        return found
    _, rest = whole_ties(distances[:, 1 : k + 1], found[:, 1 : k + 1], k - 1, centres=queries)
    return np.concatenate([found[:, :1], rest], axis=1)


def _stacked(points, normals, usable, step, queries, near, *, alike: bool, offset: float = STACKED_ALIKE_OFFSET):
    """(M, k) bool: the neighbours ``near`` (M, k) of ``queries`` (M,) on a sheet stacked on theirs.

    Each of the two points at least :data:`STACKED_ALIKE_OFFSET` times ``step``
    (the spacing), plus :data:`STACKED_ALIKE_TILT` times their distance times
    the tilt of the query's normal (the median angle to its
    :data:`GRAPH_NEIGHBOURS` nearest neighbours' normals, those tied with the
    next dropped whole as :func:`whole_ties` drops them: noise tilts them and
    lifts far neighbours), off the
    other's tangent plane, on the sides that parallel planes give; their
    normals the same way (``alike``: ``n_i . n_j >=`` :data:`FACING_COSINE`,
    ``(n_i . d)(n_j . d) > 0``) or opposite ones (``n_i . n_j <= -FACING_COSINE``,
    ``(n_i . d)(n_j . d) < 0``). On one curved sheet the offsets of two points
    with normals the same way have opposite signs. Compiled:
    :func:`meshcurv._kernels.pointcloud.stacked`.
    """
    compiled = numba_kernels("pointcloud")
    if compiled is not None:
        return compiled.stacked(
            points,
            normals,
            usable,
            np.ascontiguousarray(queries),
            np.ascontiguousarray(near),
            min(GRAPH_NEIGHBOURS, near.shape[1] - 1),
            offset * step,
            STACKED_ALIKE_TILT,
            FACING_COSINE,
            alike,
            TIE_TOLERANCE,
            TIE_LEAST,
        )
    # (the kernel's products, left to right: the same decisions to the bit)
    offsets = points[near] - points[queries][:, None, :]
    own = normals[queries][:, None, :]
    ahead = _dot(offsets, own)
    behind = _dot(offsets, normals[near])
    cosine = _dot(own, normals[near])
    size = min(GRAPH_NEIGHBOURS, near.shape[1] - 1)
    angles = np.arccos(np.minimum(np.abs(_dot(own, normals[near[:, 1 : size + 1]])), 1.0))
    if size + 1 < near.shape[1]:
        # (the ring's neighbours tied with the next beyond it dropped whole, as :func:`whole_ties`: the pose ordered
        # them; fuzz_api 660/37, ogre's cloud: its 6th and 7th neighbours at one distance, tilts 0.449 and 0.046)
        distances = np.sqrt(_dot(offsets[:, 1 : size + 2], offsets[:, 1 : size + 2]))
        tied = distances[:, :size] >= distances[:, size:] * (1.0 - TIE_TOLERANCE)
        tied &= (near[:, size + 1] != queries)[:, None]
        angles = np.where(tied & (size - tied.sum(axis=1) >= min(TIE_LEAST, size))[:, None], np.nan, angles)
    tilt = np.nanmedian(angles, axis=1)
    reach = offset * step + STACKED_ALIKE_TILT * tilt[:, None] * np.sqrt(_dot(offsets, offsets))
    sides = (
        (cosine >= FACING_COSINE) & (ahead * behind > 0) if alike else (cosine <= -FACING_COSINE) & (ahead * behind < 0)
    )
    return usable[near] & (near != queries[:, None]) & sides & (np.minimum(np.abs(ahead), np.abs(behind)) >= reach)


def _off_the_steps(points, normals, queries, found, lattice):
    """``found`` of :func:`_sheet_signs` at ``queries`` (M,) with the stacked neighbours oriented alike kept only
    where they and the query lie farther off each other's tangent plane than :data:`STACKED_ALIKE_LATTICE`
    ``max_k |n_k| h_k`` (``h`` the steps of the :class:`Lattice` ``lattice``, ``n`` the query's normal in its axes)."""
    hit, near, flags, two, group = found
    rows = np.flatnonzero(hit)
    if rows.size == 0 or not lattice.steps.any():
        return found
    offsets = points[near[rows]] - points[queries[rows]][:, None, :]
    ahead = np.einsum("mkj,mj->mk", offsets, normals[queries[rows]])
    behind = np.einsum("mkj,mkj->mk", offsets, normals[near[rows]])
    steps = STACKED_ALIKE_LATTICE * np.max(np.abs(lattice.along(normals[queries[rows]])) * lattice.steps, axis=1)
    flags = flags.copy()
    flags[rows] &= np.minimum(np.abs(ahead), np.abs(behind)) >= steps[:, None]
    hit = hit.copy()
    hit[rows] = flags[rows].sum(axis=1) >= STACKED_ALIKE_MIN
    return hit, near, flags, two, group


def lattice_treads(
    points: np.ndarray,
    normals: np.ndarray,
    radii: np.ndarray,
    candidates: np.ndarray,
    tree,
    estimate: tuple[np.ndarray, np.ndarray, np.ndarray],
    lattice: Lattice,
):
    """``(tread, problems)``: (N,) bool, the ``candidates`` (N,) bool whose ball does not resolve a lattice's steps.

    A voxel surface read as a cloud (its grid ``lattice``, see :func:`read_lattice`) is a staircase whose treads, where the surface is
    nearly at right angles to an axis, are about ``sqrt(2 R h)`` wide (``R`` its radius of curvature, ``h`` the
    voxel): a ball within one sees a plane, curvature 0, and nothing in it says that the surface curves. Such are:

    - a point whose ball of radius ``radii`` (N,) holds at least :data:`TREAD_SHARE` of its
      :data:`TREAD_NEIGHBOURS` nearest neighbours on its own plane of the grid, across the axis most along its
      ``normals`` (N, 3) (a flat face of a box in voxels too: flat as far as the ball sees);
    - on a grid of all three axes, a point whose ball spans at most :data:`STEP_PLANES` planes of the grid across
      that axis: one step, whose curvature is what the ball reads, whatever the surface's;
    - on a grid of all three axes, a point whose ``estimate`` ``(k_min, k_max, fitted)`` (N,) each, the principal
      curvatures and the radius of the ball they were taken over, rises over that ball by less than
      :data:`FACET_SAGITTA` of the staircase's relief along the normal: a ball on a facet of another slope, where
      the surface is nearly at right angles to a diagonal of the grid (a plane of rational slope sampled on such a
      grid is one too; a plane sampled on a grid of two axes, a range image, is not).

    ``problems``: the phrase of the call's warning (none when no point is).
    """
    tread = np.zeros(points.shape[0], dtype=bool)
    rows = np.flatnonzero(candidates)
    # (the grid of the whole cloud: the candidates alone may lie on too few of its planes, two treads at the poles)
    if rows.size == 0 or not lattice.steps.any():
        return tread, []
    snapped = lattice.snap(points)
    steps = lattice.steps
    k_min, k_max, fitted = estimate
    # every coordinate on the grid, as marching cubes over a mask puts them (a plane sampled on a grid of two axes,
    # a range image, is flat; a steep one spans few planes of it between samples)
    staircase = bool(steps.all())
    if staircase:
        with np.errstate(invalid="ignore"):
            sagitta = np.maximum(np.abs(k_min[rows]), np.abs(k_max[rows])) * fitted[rows] ** 2 / 2
            tread[rows] = sagitta < FACET_SAGITTA * np.max(np.abs(lattice.along(normals[rows])) * steps, axis=1)
    # (the point itself, its STEP_NEIGHBOURS nearest and the next: on a lattice many neighbours tie at a cut, and
    # which of them the search returned was the pose's order; the neighbours tied with the first left out at either
    # cut, or with the ball's radius, are left out: fuzz_api 572/2, 3 points read on one tread in one pose only)
    k = min(STEP_NEIGHBOURS + 2, points.shape[0])
    for start in range(0, rows.size, TREAD_CHUNK):
        chunk = rows[start : start + TREAD_CHUNK]
        distances, near = tree.query(points[chunk], k=k, workers=-1)
        distances, near = distances[:, 1:], near[:, 1:]  # (the point itself first)
        tied = _tied_at(distances, STEP_NEIGHBOURS)
        distances, near = distances[:, :STEP_NEIGHBOURS], near[:, :STEP_NEIGHBOURS]
        inside = (distances <= radii[chunk][:, None] * (1.0 - TIE_TOLERANCE)) & ~tied
        # the axis most along the normal: a point facing an axis off the grid (a cylinder's side, its rings on a
        # grid along the axis) is on no tread
        axis = np.argmax(np.abs(lattice.along(normals[chunk])), axis=1)
        step = np.where(steps[axis] > 0, steps[axis], np.nan)[:, None]
        height = snapped[near, axis[:, None]] - snapped[chunk, axis][:, None]
        nearest = inside[:, :TREAD_NEIGHBOURS] & ~_tied_at(distances, TREAD_NEIGHBOURS)
        plane = nearest & (np.abs(height[:, :TREAD_NEIGHBOURS]) <= LATTICE_TOLERANCE * step)
        tread[chunk] |= plane.sum(axis=1) >= TREAD_SHARE * np.maximum(nearest.sum(axis=1), 1)
        if staircase:  # the planes of the grid the ball spans along the axis (the centre's own included)
            span = np.maximum(np.where(inside, height, -np.inf).max(axis=1), 0.0) - np.minimum(
                np.where(inside, height, np.inf).min(axis=1), 0.0
            )
            tread[chunk] |= span <= (STEP_PLANES - 1 + LATTICE_TOLERANCE) * step[:, 0]
    if not tread.any():
        return tread, []
    return tread, [
        f"{int(tread.sum())} points see a flat facet or a single step of a voxel staircase (at least "
        f"{TREAD_SHARE:g} of their ball on one plane of the voxels' grid, a ball spanning {STEP_PLANES} planes of "
        f"it or fewer, or an estimate rising over the ball by less than {FACET_SAGITTA:g} of the steps: the "
        "surface may curve there by less than the voxels resolve at this radius): NaN"
    ]


def _tied_at(distances: np.ndarray, cut: int) -> np.ndarray:
    """(M, min(cut, K)) bool: of the sorted ``distances`` (M, K), those of the first ``cut`` columns within
    :data:`TIE_TOLERANCE` of the first column after the cut (none where there is no such column)."""
    if distances.shape[1] <= cut:
        return np.zeros(distances.shape, dtype=bool)
    return distances[:, :cut] >= distances[:, cut : cut + 1] * (1.0 - TIE_TOLERANCE)


def _two_heights(points, group, usable, step):
    """(M,) bool: the heights of the points ``group`` (M, k) (the centre first) across their least-variance
    direction, within :data:`INTERLEAVED_REACH` of the centre along it, fall into two groups (see :func:`two_sheets`).
    ``step`` (M,): the spacing of each group. Slots after the first that hold the centre (neighbours tied at the cut
    dropped, :func:`_whole_rows`) are left out."""
    cloud = points[group]
    kept = np.ones(group.shape, dtype=bool)
    kept[:, 1:] = group[:, 1:] != group[:, :1]
    weights = kept[:, :, None].astype(float)
    centred = (cloud - (cloud * weights).sum(axis=1, keepdims=True) / kept.sum(axis=1)[:, None, None]) * weights
    _, vectors = np.linalg.eigh(np.einsum("mki,mkj->mij", centred, centred))
    offsets = cloud - cloud[:, :1]
    height = np.einsum("mkj,mj->mk", offsets, vectors[:, :, 0])
    across = np.einsum("mkj,mkj->mk", offsets, offsets) - height * height
    inside = (across <= (INTERLEAVED_REACH * step[:, None]) ** 2) & usable[group] & kept
    height = np.sort(np.where(inside, height, np.inf), axis=1)
    count = inside.sum(axis=1)
    with np.errstate(invalid="ignore"):
        gaps = np.where(np.isfinite(height[:, 1:]), np.diff(height, axis=1), -np.inf)
    rows = np.arange(gaps.shape[0])
    # the widest gap: on a lattice, planes evenly spaced give several, equal to round-off, of which the pose chose
    # one (and the sign of the direction, which end comes first): the heights fall into two groups at each of them
    largest = gaps.max(axis=1, initial=-np.inf)
    tied = gaps >= largest[:, None] - TIE_TOLERANCE * step[:, None]
    split = np.ones(rows.size, dtype=bool)
    for widest in (np.argmax(tied, axis=1), gaps.shape[1] - 1 - np.argmax(tied[:, ::-1], axis=1)):
        gap = gaps[rows, widest]
        below = widest + 1
        # the spread of each group: two clean sheets closer than the noise of a noisy one are two sheets too
        lower = height[rows, widest] - height[:, 0]
        upper = height[rows, np.maximum(count - 1, 0)] - height[rows, np.minimum(widest + 1, height.shape[1] - 1)]
        apart = (gap >= INTERLEAVED_GAP * step) | (
            (gap >= INTERLEAVED_SPREAD * np.maximum(lower, upper)) & (gap >= INTERLEAVED_MIN_GAP * step)
        )
        split &= (
            apart & (gap <= STACKED_OFFSET * step) & (below >= INTERLEAVED_GROUP) & (count - below >= INTERLEAVED_GROUP)
        )
    return split


def between_sides(
    points: np.ndarray, normals: np.ndarray, usable: np.ndarray, spacing: np.ndarray, tree, indices: np.ndarray
) -> np.ndarray:
    """(N,) +1 or -1: turns the points of two stacked sheets that face each other across an inside-out part.

    Where two sheets are stacked a spacing or more apart with opposite
    normals (see :func:`two_sheets`), the space between them is either
    inside the cloud's solid (the faces of a thin part: normals back to back)
    or outside (a gap between two parts: normals facing). Turned together,
    both faces of a stretch of a thin part face each other as across a gap,
    consistent with themselves and with the winding number at each of their
    points; the winding number *between* them tells: 1 inside a part, 0 in a
    gap, and about -1 in a part whose faces both point inward (their near
    sums -1, the rest of a thin part adding about 0). A point whose nearest
    stacked neighbour across such a space (the midpoint's winding number
    below :data:`BETWEEN_WRONG`) is turned; the points that are not
    evaluated (beyond :data:`WINDING_QUERIES`) take the verdict of their
    nearest evaluated point along flat edges.
    """
    n = points.shape[0]
    flips = np.ones(n)
    candidates = np.flatnonzero(usable)
    if candidates.size <= INTERLEAVED_NEIGHBOURS:
        return flips
    step = float(np.median(spacing[candidates]))
    queries = _spread(candidates, WINDING_QUERIES, points, spacing)
    k = min(WINDING_NEAR + 1, n)
    _, near = tree.query(points[queries], k=k, workers=-1)
    stacked = _stacked(points, normals, usable, step, queries, near, alike=False)
    rows = np.flatnonzero(stacked.any(axis=1))
    if rows.size == 0:
        return flips
    first = np.argmax(stacked[rows], axis=1)  # the nearest stacked neighbour (the rows are in distance order)
    middle = 0.5 * (points[queries[rows]] + points[near[rows, first]])
    areas = np.where(usable, _sheet_areas(points, normals, indices), 0.0)
    winding = winding_at(
        points, normals, areas, usable, tree, middle, _spread(candidates, WINDING_SOURCES, points, spacing)
    )
    wrong_rows = rows[winding < BETWEEN_WRONG]
    if wrong_rows.size == 0:
        return flips
    wrong = np.zeros(queries.size, dtype=bool)
    wrong[wrong_rows] = True
    if queries.size == candidates.size:
        flips[queries[wrong]] = -1.0
        return flips
    edge_rows, edge_cols, _ = _graph_edges(indices[:, :GRAPH_NEIGHBOURS], usable)
    nearest = _nearest_queries(points, normals, usable, queries, edge_rows, edge_cols)
    flips[usable] = np.where(wrong[nearest[usable]], -1.0, 1.0)
    return flips


def _sheet_areas(points: np.ndarray, normals: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """(N,) the area each point stands for on its own sheet: ``pi d^2 / (m + 1)``.

    ``d`` the distance to the farthest of the neighbours ``indices`` (N, k),
    ``m`` how many of them lie within :data:`SHEET_SLOPE` of the point's
    tangent plane. Where the neighbours hold a second sheet (the other face of
    a thin part) :func:`local_spacing` counts both and halves the areas.
    """
    n = points.shape[0]
    areas = np.zeros(n)
    for start in range(0, n, CHUNK):
        rows = slice(start, min(n, start + CHUNK))
        offsets = points[indices[rows]] - points[rows][:, None, :]
        distance = np.linalg.norm(offsets, axis=2)
        along = np.abs(np.einsum("mkj,mj->mk", offsets, normals[rows]))
        own = (along <= SHEET_SLOPE * distance).sum(axis=1)
        areas[rows] = np.pi * distance.max(axis=1) ** 2 / (own + 1)
    return areas
