"""Weighted osculating jets: polynomial height functions fitted over balls (Cazals and Pouget 2005).

For vertex ``v`` with a frame ``(t_1, t_2, n)``, every vertex ``x_j`` in the ball
``B(x_v, r)`` (the vertex itself included) gives local coordinates
``(u_j, v_j, w_j) = ((x_j - x_v) . t_1, (x_j - x_v) . t_2, (x_j - x_v) . n)``, and the
height function is fitted by weighted least squares as a polynomial (a *jet*) of
degree ``d``:

.. math::

    w(u, v) = \\sum_{i + k \\le d} c_{ik}\\, u^i v^k, \\qquad
    \\min_c \\sum_j \\omega_j \\big(w_j - w(u_j, v_j)\\big)^2, \\qquad
    \\omega_j = \\big(1 - |x_j - x_v|^2 / r^2\\big)^2 .

A fit of degree ``d`` falls back to ``d - 1`` (down to 2) where the ball holds
too few points, or too degenerate a set, for a well-conditioned fit: a set
whose spread (:data:`MIN_SPREAD`, a bound on the smallest eigenvalue of the
normal equations in a basis that a turn of the tangent plane leaves
orthonormal) is too small; the choice is the same in every pose. The
constant term is free (on a noisy mesh the vertex is not on the surface), and
so are the linear terms.

Normal re-estimation: the first fit runs in the frame of a given normal (the
area-weighted vertex normal); the fitted surface's normal ``(n - c_{10} t_1 -
c_{01} t_2) / sqrt(1 + c_{10}^2 + c_{01}^2)`` (Cazals and Pouget's Monge basis)
becomes the frame of a second fit, :data:`ITERATIONS` fits in all, so that the
final fit is a height function over (almost) its own tangent plane, where the
quadric coefficients are the second fundamental form (Panozzo et al. fit in the
frame of an estimated normal the same way). From the last fit, with
``p = c_{10}``, ``q = c_{01}`` and ``W = sqrt(1 + p^2 + q^2)``:

.. math::

    I = \\begin{pmatrix} 1 + p^2 & pq \\\\ pq & 1 + q^2 \\end{pmatrix}, \\qquad
    II = \\frac{1}{W} \\begin{pmatrix} 2 c_{20} & c_{11} \\\\ c_{11} & 2 c_{02} \\end{pmatrix}

and the shape operator in meshcurv's sign (positive where the surface bends
away from its normal) is ``-I^{-1} II``, turned into a symmetric 3D tensor
``J I^{-1} (-II) I^{-1} J^T`` with ``J = [t_1 + p n, t_2 + q n]``
(:func:`shape_operators`).

The fits serve the ``quadric`` estimator (:mod:`meshcurv.estimators.quadric`,
curvatures from the jets), the normals of ``icc`` (:mod:`meshcurv.estimators.icc`)
and the point clouds (:mod:`meshcurv.pointcloud`). A ball can be the
surface-connected piece of the Euclidean ball (``adjacency=``), on both
backends (:func:`meshcurv.neighborhoods.connected_ball_pairs` is the NumPy
twin of the compiled walk, :mod:`meshcurv._kernels.jets`).

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

from collections.abc import Sequence
from math import comb
from typing import Any

import numpy as np

from ._backend import kernel_threads, numba_kernels, twin
from ._tensors import principal_from_shape_operator, tangent_basis
from ._validation import checked_points
from .errors import InvalidMeshError, InvalidOptionError
from .neighborhoods import (
    _ball_pairs,
    call_ranges,
    centre_radii,
    check_ball_work,
    checked_adjacency,
    connected_ball_pairs,
)

#: Highest degree of the jet (lowered to 3, then 2, where the ball holds too few points).
DEGREE = 4

#: Fits per vertex: the first in the frame of the vertex normal, each next one in
#: the frame of the normal of the previous fit.
ITERATIONS = 2

#: Fewest points (with non-zero weight) a fit takes: the six coefficients of a quadric.
MIN_POINTS = 6

#: Smallest spread of a ball's points that a fit of degree ``d`` is solved on (else it falls
#: back to ``d - 1``): ``1 / (sum(w) trace(G^-1))``, the Gram matrix ``G = sum_j w_j
#: b(u_j, v_j) b(u_j, v_j)^T`` of the monomials in the basis ``b = sqrt(C(i + k, i)) u^i v^k``
#: (coordinates in units of the radius). A turn of the tangent plane acts on that basis by an
#: orthogonal matrix (the Bombieri norm of binary forms is invariant), so the spread, a
#: lower bound of the smallest eigenvalue of ``G / sum(w)`` (and above a ``1 / m`` of it), does
#: not depend on the frame chosen in the tangent plane, nor on a rigid motion or scaling of
#: the points: the degree of every fit is the same in every pose. (A bound on the pivots of
#: the Cholesky factor, the rule until 2026, was not: on a torus of 48 x 32 vertices, balls
#: over three meridians had pivots from 1e-8 to 1e-4 with the turn of the frame, and k_min of
#: the degree-4 fits they kept was off by up to 0.33 where the exact one is -0.05..0.025.)
#: Points along a line (or three meridians for degree 4) have a spread near 0; the balls of a
#: clean mesh of 2.5 edge lengths hold ~1e-4 (degree 4) and ~1e-3 (degree 3).
MIN_SPREAD = 1e-7

#: :data:`MIN_SPREAD` of the fits that give normals only (``icc``'s, of degree 3): their linear
#: coefficients bear a smaller spread than the curvatures do. From ``benchmarks/accuracy.py``
#: (icc): 1e-7 makes the median H error of the finest regular saddle's boundary 27% larger
#: (0.22% -> 0.28%), 1e-8 leaves every row as it was with the pivot rule; on the demo torus
#: (R 30, r 10, 60 x 60) both give max |H error| 4.9e-4 (pivot rule: 9.7e-4, and 1.7e-3
#: between two poses).
NORMAL_MIN_SPREAD = 1e-8

#: Smallest pivot of the ``L D L^T`` factorization of a normal matrix, relative to its diagonal
#: entry (the pivot of the matrix scaled to a unit diagonal), for which the factorization goes on
#: (a matrix numerically singular). Never decisive: a pivot of the scaled matrix is at least its
#: smallest eigenvalue, itself at least ``MIN_SPREAD / 6``, on a fit kept.
PIVOT_FLOOR = 1e-12

#: Centres per chunk of pair queries (bounds the memory of the per-pair arrays; fewer
#: where the balls are large, see :data:`meshcurv.neighborhoods.PAIRS_PER_CHUNK`).
CHUNK_SIZE = 4096

#: A fit whose ball holds more than this share of its points whose normal faces away from
#: the centre's (``dot(n_j, n_v) < 0``) is refused (:func:`fit_jets`, ``facing``): the ball
#: reaches past the part's silhouette to its other side. On a smooth surface sampled finer
#: than its thickness the share is 0; a ball across a needle thinner than the ball holds
#: about half; on a sphere of radius R a ball of radius 1.5 R holds 11% (2.5 R: 50%), and
#: from sqrt(2) R (where the share starts) the jet of degree 4 is far off anyway (k R = 0.5
#: for 1 at 1.5 R). Noisy normals of a clean surface rarely turn beyond 90 degrees: 5%
#: leaves room for a few that do.
AWAY_FRACTION = 0.05
#: Normals whose dot product is below this face away, orthogonal ones included (the surface is vertical
#: to the tangent plane there: no height function), whatever the round-off makes of their 0 (issue 29:
#: a voxel sphere scaled by 1e-8 lost quadric fits, faces at right angles giving -1e-17 or 1e-15).
AWAY_DOT = 1e-9

#: A fit whose first frame tilts its normal less than 0.5 degrees (slope ``c10^2 + c01^2``
#: below this) is settled: a refit in the frame of its own normal (``settled=`` of
#: :func:`fit_jets`) would turn it by 2e-6 degrees on a clean sphere (random or regular),
#: 0.04 on a noisy ellipsoid, 0.5 at most on a scanned or CAD model. Every vertex of a clean,
#: regular mesh is spared the second fit (the mean of its face normals is within 0.03
#: degrees), about half of those of a scan. From a sweep over the surfaces of
#: ``benchmarks/accuracy.py`` (all families and levels, and the ``--voxel`` family):
#: 0.25, 0.5 and 1 degree move no error by more than the coarsest torus moves between
#: them (a few percent, either way; the others within 1.6%), 2 degrees make that torus's
#: median k_max error 65% larger.
SETTLED_SLOPE = float(np.tan(np.radians(0.5)) ** 2)


def _exponents(degree: int) -> np.ndarray:
    """(m, 2) exponents ``(i, k)`` of the monomials ``u^i v^k``, by total degree."""
    return np.array([(total - k, k) for total in range(degree + 1) for k in range(total + 1)])


def _n_terms(degree: int) -> int:
    return (degree + 1) * (degree + 2) // 2


def _fit_chunk(
    offsets: np.ndarray, rows: np.ndarray, size: int, frame: Sequence[np.ndarray], weights: np.ndarray, degree: int
) -> tuple[np.ndarray, np.ndarray]:
    """Weighted normal equations of the jets of one chunk of centres, in units of the radius.

    ``offsets`` (P, 3) are ``(x_j - x_v) / r``, ``rows`` (P,) the centre of each
    pair within the chunk and ``frame`` the (size, 3) vectors ``t1, t2, n`` of
    the centres. Returns the (size, m, m) matrices and the (size, m) right-hand sides.
    """
    t1, t2, normal = frame
    u = np.einsum("ij,ij->i", offsets, t1[rows])
    v = np.einsum("ij,ij->i", offsets, t2[rows])
    w = np.einsum("ij,ij->i", offsets, normal[rows])
    exponents = _exponents(degree)
    m = exponents.shape[0]
    # the products of two monomials are monomials of degree <= 2d: sum each once
    u_powers = [np.ones_like(u)]
    v_powers = [np.ones_like(v)]
    for _ in range(2 * degree):
        u_powers.append(u_powers[-1] * u)
        v_powers.append(v_powers[-1] * v)
    moments = {}
    for total in range(2 * degree + 1):
        for k in range(total + 1):
            moments[total - k, k] = np.bincount(
                rows, weights=weights * u_powers[total - k] * v_powers[k], minlength=size
            )
    matrix = np.zeros((size, m, m))
    for a in range(m):
        for b in range(a, m):
            matrix[:, a, b] = matrix[:, b, a] = moments[tuple(exponents[a] + exponents[b])]
    right = np.stack(
        [np.bincount(rows, weights=weights * w * u_powers[i] * v_powers[k], minlength=size) for i, k in exponents],
        axis=1,
    )
    return matrix, right


def _binomials(degree: int) -> np.ndarray:
    """(m,) ``C(i + k, i)`` for the exponents ``(i, k)`` of :func:`_exponents`: the squares of the Bombieri weights."""
    return np.array([float(comb(i + k, i)) for i, k in _exponents(degree)])


def _cholesky_solve(
    matrix: np.ndarray, right: np.ndarray, factors: np.ndarray, total: np.ndarray, min_spread: float = MIN_SPREAD
) -> tuple[np.ndarray, np.ndarray]:
    """Solve the (N, m, m) symmetric systems by an ``L D L^T`` factorization, where their points are spread.

    Returns the (N, m) solutions and (N,) whether every pivot ``d_k`` exceeded :data:`PIVOT_FLOOR`
    ``max(matrix_kk, tiny)`` and ``total sum_j factors[j] (matrix^-1)_jj < 1 / min_spread``
    (:data:`MIN_SPREAD`; ``total`` (N,): the sums of the weights; the solutions of the others are
    meaningless). ``L`` is unit lower triangular, no square roots are taken;
    ``(matrix^-1)_jj = sum_i (L^-1)_ij^2 / d_i`` from column ``j`` of ``L^-1``, found by forward
    substitution, and the solution ``L^-T D^-1 L^-1 right`` from the same columns. A loop over the
    m <= 15 columns, vectorized over the systems; the compiled kernel does the same operations in
    the same order.
    """
    n, m = right.shape
    low = np.zeros_like(matrix)  # L below the diagonal, 1 / d on it, column j of L^-1 (negated) in row j above it
    unscaled = np.zeros_like(matrix)  # L times the pivots
    ok = np.ones(n, dtype=bool)
    tiny = np.finfo(float).tiny
    for k in range(m):
        d = matrix[:, k, k].copy()
        for j in range(k):
            d -= unscaled[:, k, j] * low[:, k, j]
        ok &= d > np.maximum(matrix[:, k, k], tiny) * PIVOT_FLOOR
        inverse = 1.0 / np.where(ok, d, 1.0)
        low[:, k, k] = inverse
        for i in range(k + 1, m):
            t = matrix[:, i, k].copy()
            for j in range(k):
                t -= unscaled[:, i, j] * low[:, k, j]
            unscaled[:, i, k] = t
            low[:, i, k] = t * inverse
    trace = np.zeros(n)
    with np.errstate(over="ignore", invalid="ignore"):  # inf or NaN traces: not spread (as the kernel)
        for j in range(m):
            norm = low[:, j, j].copy()
            for i in range(j + 1, m):
                t = low[:, i, j].copy()
                for k in range(j + 1, i):
                    t -= low[:, i, k] * low[:, j, k]
                low[:, j, i] = t
                norm += t * t * low[:, i, i]
            trace += norm * factors[j]
        ok &= trace * total * min_spread < 1.0
    x = right.copy()
    for i in range(m - 1, -1, -1):  # D^-1 L^-1 right (row i reads the rows above it, not yet replaced)
        for j in range(i):
            x[:, i] -= low[:, j, i] * x[:, j]
        x[:, i] *= low[:, i, i]
    for j in range(m):  # L^-T (row j reads the rows below it, not yet replaced)
        for i in range(j + 1, m):
            x[:, j] -= low[:, j, i] * x[:, i]
    return x, ok


def _solve_block(
    block: np.ndarray, right: np.ndarray, degree: int, min_spread: float = MIN_SPREAD
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The (N, m) solutions of the (N, m, m) normal equations ``block`` of ``degree``, whether each is
    kept (its points spread, ``min_spread``) and the (N, m, m) diagonally scaled matrices (unit diagonal:
    their condition numbers bound the solutions' round-off)."""
    scale = 1.0 / np.sqrt(np.maximum(np.einsum("nii->ni", block), np.finfo(float).tiny))
    scaled = block * scale[:, :, None] * scale[:, None, :]
    solution, ok = _cholesky_solve(block, right, 1.0 / _binomials(degree), block[:, 0, 0], min_spread)
    return solution, ok, scaled


def _solve(
    matrix: np.ndarray, right: np.ndarray, counts: np.ndarray, degree: int, min_spread: float = MIN_SPREAD
) -> np.ndarray:
    """(N, 6) the constant, linear and quadratic coefficients of the highest solvable degree (NaN: none).

    The monomials are ordered by degree, so the normal equations of a lower
    degree are the leading block of those of ``degree``. A degree is solved
    where the ball holds as many points as its coefficients and they are
    spread (``min_spread``, :data:`MIN_SPREAD`: a criterion that no turn of the frame changes).
    """
    out = np.full((matrix.shape[0], 6), np.nan)
    todo = np.ones(matrix.shape[0], dtype=bool)
    for d in range(degree, 1, -1):
        m = _n_terms(d)
        candidates = np.flatnonzero(todo & (counts >= m))
        if candidates.size == 0:
            continue
        solution, ok, _ = _solve_block(matrix[candidates, :m, :m], right[candidates, :m], d, min_spread)
        chosen = candidates[ok]
        if chosen.size:
            out[chosen] = solution[ok][:, :6]
            todo[chosen] = False
    return out


def fit_jets(
    vertices: np.ndarray,
    normals: np.ndarray,
    radius,
    *,
    degree: int = DEGREE,
    iterations: int = ITERATIONS,
    centres: np.ndarray | None = None,
    chunk_size: int = CHUNK_SIZE,
    neighbours: np.ndarray | None = None,
    facing: np.ndarray | None = None,
    details: dict | None = None,
    adjacency: tuple | None = None,
    settled: float = 0.0,
    compact: bool = False,
    areas: np.ndarray | None = None,
    min_spread: float = MIN_SPREAD,
    larger: float | None = None,
    agreement: float | None = None,
):
    """Fit a weighted jet at every vertex (or at ``centres``), re-estimating its frame from each fit.

    Parameters
    ----------
    vertices : ndarray of shape (V, 3)
    normals : ndarray of shape (V, 3)
        Unit normals of the first frame (finite at the centres).
    radius : float or ndarray of shape (M,)
        Radius of the ball of each fit (> 0): one for all, or one per centre
        (M: the number of ``centres``, V without them; positive and finite),
        each fit then that of the float call at its centre's radius.
    degree : int, default: DEGREE
    iterations : int, default: ITERATIONS
    centres : ndarray of int, optional
        The vertices to fit (default: all). The rows of the others are NaN
        (counts 0).
    neighbours : ndarray of bool of shape (V,), optional
        The vertices that may enter the balls (default: all). Pass
        ``topology.referenced_vertices`` so that points stored with the mesh but
        in no face (a point cloud, scanner leftovers) stay out of every fit: the
        fits of the referenced vertices are then those of the mesh without them.
    facing : ndarray of shape (V, 3), optional
        Normals for the check that each ball is a height function over the
        tangent plane: a fit whose ball holds more than :data:`AWAY_FRACTION` of
        its points (of non-zero weight) whose ``facing`` normal is opposite to the centre's
        (``n_j . n_v < 0``; rows of NaN are not counted) is left NaN. Such a ball
        holds the other side of a thin part (a needle thinner than the ball) or
        of the whole closed surface (a ball larger than the part): its jet is
        a fit through both sides, not the surface. Default: no check.
    details : dict, optional
        Receives ``"away"``: (V,) the share of the ball's points facing away at
        each fitted centre (NaN unless ``facing`` is given).
    adjacency : tuple of two ndarrays of int, optional
        ``(indptr, indices)``: the edge neighbours of every vertex in CSR form
        (:attr:`meshcurv.topology.MeshTopology.neighbour_lists`). Each ball is
        then the vertices reached from its centre over the edges that meet it
        (an end inside, or the segment passing through): the same points
        wherever the ball's part of the surface is connected (every ball of a
        radius below the surface's thickness and reach); another sheet of the
        surface within the ball (the far side of a part thinner than the ball)
        is left out. The compiled kernels walk each ball breadth-first, with no
        search structure over the whole mesh (a fit at a few centres costs only
        their balls); the NumPy path finds the same points by connected
        components (:func:`meshcurv.neighborhoods.connected_ball_pairs`).
    settled : float, default: 0.0
        A fit whose slope ``c10^2 + c01^2`` is below this ends the iterations
        of its vertex: its normal is within ``atan(sqrt(settled))`` of the
        frame's, and it is kept with that frame. 0: ``iterations`` fits everywhere.
    compact : bool, default: False
        One row per centre, in the order of ``centres``, instead of one per
        vertex (a fit at a few centres of a large mesh then allocates no row
        for the others; ``details["away"]`` likewise).
    areas : ndarray of shape (V,), optional
        Each point's weight is its kernel weight times its area (the fit then
        approximates the integral over the surface: a part sampled more densely
        does not outweigh its neighbours). Default: the kernel weight alone.
    min_spread : float, default: MIN_SPREAD
        Smallest spread of a ball's points that a degree is solved on (else
        the next lower degree): :data:`MIN_SPREAD` for curvatures,
        :data:`NORMAL_MIN_SPREAD` for fits that give normals only.
    larger : float, optional
        Also fit, with the same options, over balls of this radius (larger than
        ``radius``) at the same centres: ``details["larger"]`` receives that
        call's ``(coefficients, frame, counts)``. With the compiled kernels, one
        radius and no ``adjacency``, each centre's larger ball is walked once for
        both fits (the smaller ball's points are those of the larger one within
        ``radius``, in the same order: the fits over ``radius`` are those of the
        call without ``larger`` to the bit, those over ``larger`` within rounding
        of a call of their own).
    agreement : float, optional
        With ``facing``: the points whose ``facing`` normal has a cosine below this with the
        centre's are left out of its fit (weight 0; the same side of a thin part, whose other side
        and rim the ball reaches, :func:`thin_part_normals`). Default: every point of the ball.

    Returns
    -------
    coefficients : ndarray of shape (V, 6)
        ``c00, c10, c01, c20, c11, c02`` of the last fit, in units of ``radius``
        (NaN where no fit was possible).
    frame : tuple of three ndarrays of shape (V, 3)
        ``t1, t2, n``: the frame of the last fit.
    counts : ndarray of shape (V,)
        Points with non-zero weight in each ball.

    With ``compact``, M rows for the M ``centres`` instead of V.

    Raises
    ------
    InvalidOptionError
        The balls would hold more than :data:`meshcurv.neighborhoods.MAX_BALL_PAIRS`
        pairs in all (a radius far too large for the mesh); ``radius`` is an
        array that does not hold one positive finite radius per centre, or that
        gives a centre listed twice two radii; ``larger`` is given without
        ``details``, or is not a number larger than ``radius``.
    """
    return _fit_jets(
        checked_points(vertices),
        normals,
        radius,
        degree=degree,
        iterations=iterations,
        centres=centres,
        chunk_size=chunk_size,
        neighbours=neighbours,
        facing=facing,
        details=details,
        adjacency=adjacency,
        settled=settled,
        compact=compact,
        areas=areas,
        min_spread=min_spread,
        larger=larger,
        agreement=agreement,
    )


def _fit_jets(
    vertices: np.ndarray,
    normals: np.ndarray,
    radius,
    *,
    degree: int = DEGREE,
    iterations: int = ITERATIONS,
    centres: np.ndarray | None = None,
    chunk_size: int = CHUNK_SIZE,
    neighbours: np.ndarray | None = None,
    facing: np.ndarray | None = None,
    details: dict | None = None,
    adjacency: tuple | None = None,
    settled: float = 0.0,
    compact: bool = False,
    areas: np.ndarray | None = None,
    min_spread: float = MIN_SPREAD,
    larger: float | None = None,
    agreement: float | None = None,
):
    """:func:`fit_jets` on ``vertices`` already checked (:func:`checked_points`: C-contiguous float64 (V, 3), finite)."""
    n = vertices.shape[0]
    normals = np.ascontiguousarray(normals, dtype=np.float64)
    if normals.shape != vertices.shape:
        raise InvalidMeshError(f"`normals` must have shape {vertices.shape}; got {normals.shape}")
    every_vertex = centres is None  # the rows of the centres are those of all vertices
    centres = np.arange(n) if centres is None else np.asarray(centres, dtype=np.int64).ravel()
    if centres.size and (centres.min() < 0 or centres.max() >= n):
        raise InvalidMeshError(f"`centres` must be vertex indices in 0..{n - 1}")
    per_centre = np.ndim(radius) > 0
    if per_centre:
        radius = _checked_centre_radii(radius, centres)
    if neighbours is None:
        pool = np.arange(n)
    else:
        neighbours = np.asarray(neighbours, dtype=bool)
        if neighbours.shape != (n,):
            raise InvalidMeshError(f"`neighbours` must have shape ({n},); got {neighbours.shape}")
        pool = np.flatnonzero(neighbours)
    check = facing is not None
    if check:
        facing = np.ascontiguousarray(facing, dtype=np.float64)
        if facing.shape != vertices.shape:
            raise InvalidMeshError(f"`facing` must have shape {vertices.shape}; got {facing.shape}")
    if agreement is not None and not (facing is not None and -1.0 <= agreement <= 1.0):
        raise InvalidOptionError(f"`agreement` needs `facing` and must lie in [-1, 1]; got {agreement!r}")
    select = -2.0 if agreement is None else float(agreement)  # (the kernels' none: below every cosine)
    kernels = numba_kernels("jets")
    paired = False  # both radii in one walk
    wide = 0.0  # the larger radius (0: none)
    if larger is not None:
        wide = _checked_larger(larger, radius, details)
        paired = kernels is not None and n > 0 and adjacency is None and not per_centre and agreement is None
        if not paired:
            details["larger"] = _fit_jets(  # type: ignore[index]  # (details checked)
                vertices,
                normals,
                wide,
                degree=degree,
                iterations=iterations,
                centres=None if every_vertex else centres,
                chunk_size=chunk_size,
                neighbours=neighbours,
                facing=facing,
                adjacency=adjacency,
                settled=settled,
                compact=compact,
                areas=areas,
                min_spread=min_spread,
                agreement=agreement,
            )
    pool_points = vertices if pool.size == n else vertices[pool]  # (pool sorted: all of them is every vertex)
    areas = _checked_areas(areas, n)
    mean, _ = check_ball_work(pool_points, radius, centres.size, centres=vertices[centres])
    if paired:
        mean += check_ball_work(pool_points, wide, centres.size, centres=vertices[centres])[0]
    if kernels is not None and n:
        if adjacency is not None:  # one row per centre
            rows = _connected_fits(
                kernels,
                vertices,
                normals,
                radius,
                degree,
                iterations,
                centres,
                mean,
                neighbours,
                adjacency,
                facing,
                settled,
                normals_only=False,
                areas=areas,
                min_spread=min_spread,
                agreement=select,
            )
            if not compact and not every_vertex:
                rows = [_all_rows(row, centres, n, 0.0 if k == 4 else np.nan) for k, row in enumerate(rows)]
        else:
            radii = _all_rows(radius, centres, n, 0.0) if per_centre else np.array([float(radius)])  # by vertex
            ranges = call_ranges(centres.size, mean, radius * radius if per_centre else None)
            # one call: its outputs (rows of all vertices, NaN and counts 0 but at the centres) are the result
            whole = len(ranges) == 1 and not compact
            kernel, extra = (kernels.fit_jet_pairs, (wide,)) if paired else (kernels.fit_jets, ())
            fit = (degree, iterations, _exponents(degree), min_spread)
            checks = (pool, facing if check else vertices, check, AWAY_FRACTION, float(settled), areas)
            selected = () if agreement is None else (0.0, select)  # (the kernel's larger: none; then agreement)
            pieces = []  # each call's outputs, one row per centre of its part
            for lo, hi in ranges:
                part = centres[lo:hi]  # rows of all vertices: those of the part (a slice when the centres are all)
                outputs = kernel(
                    vertices, normals, radii, *extra, *fit, part, 64 * kernel_threads(), *checks, *selected
                )
                pieces.append(
                    outputs if whole else tuple(output[lo:hi] if every_vertex else output[part] for output in outputs)
                )
            rows = _joined(pieces)
            if not compact and not every_vertex and not whole:
                rows = [_all_rows(row, centres, n, 0.0 if k % 6 == 4 else np.nan) for k, row in enumerate(rows)]
        coefficients, t1, t2, normal, counts, away = rows[:6]
        if paired:
            details["larger"] = (rows[6], tuple(rows[7:10]), rows[10])  # type: ignore[index]  # (details checked)
        if details is not None:
            details["away"] = away
        return coefficients, (t1, t2, normal), counts
    frame = [np.full((n, 3), np.nan) for _ in range(3)]
    coefficients = np.full((n, 6), np.nan)
    counts = np.zeros(n)
    away = np.full(n, np.nan)
    given = centres  # the rows of the compact outputs
    if per_centre:  # by increasing radius: each chunk's search reaches little beyond its own balls
        order = np.argsort(radius, kind="stable")
        centres, radius = centres[order], radius[order]
    if adjacency is not None:  # the surface-connected balls, as the compiled walk finds them
        balls = connected_ball_pairs(vertices, centres, radius, adjacency, neighbours, chunk_size=chunk_size)
    else:
        balls = (
            (chunk, centre, pool[neighbour])
            for chunk, centre, neighbour in _ball_pairs(pool_points, vertices[centres], radius, chunk_size)
        )
    for chunk, centre, neighbour in balls:
        index = centres[chunk]
        size = index.size
        rows = centre - chunk.start
        inverse = (1.0 / radius)[centre][:, None] if per_centre else 1.0 / radius  # the kernels' operations
        offsets = (vertices[neighbour] - vertices[index[rows]]) * inverse
        # x, y and z summed in the kernel's order: a point exactly on the ball's sphere weighs 0 on both backends
        squared = offsets[:, 0] * offsets[:, 0] + offsets[:, 1] * offsets[:, 1] + offsets[:, 2] * offsets[:, 2]
        weights = np.maximum(1.0 - squared, 0.0) ** 2
        if areas.size:
            weights = weights * areas[neighbour]
        if agreement is not None and facing is not None:  # the same side only
            weights = np.where(np.einsum("ij,ij->i", facing[neighbour], facing[index[rows]]) < select, 0.0, weights)
        count = np.bincount(rows, weights=(weights > 0).astype(float), minlength=size)
        local = [*tangent_basis(normals[index]), normals[index]]
        settle = np.zeros((size, 1), dtype=bool)  # the centres whose iterations have ended (``settled``)
        fitted = np.full((size, 6), np.nan)  # (no iteration: the facing check alone)
        for step in range(iterations):
            matrix, right = _fit_chunk(offsets, rows, size, local, weights, degree)
            found = _solve(matrix, right, count, degree, min_spread)
            if step == 0:
                fitted = found
            else:  # the settled centres keep their earlier fit
                fitted = np.where(settle, fitted, found)
            if step + 1 < iterations:
                p, q = fitted[:, 1:2], fitted[:, 2:3]
                settle |= p * p + q * q < settled
                tilted = local[2] - p * local[0] - q * local[1]
                tilted /= np.linalg.norm(tilted, axis=1, keepdims=True)
                keep = np.isfinite(tilted).all(axis=1, keepdims=True) & ~settle
                new_normal = np.where(keep, tilted, local[2])
                local = [*tangent_basis(new_normal), new_normal]
        if facing is not None:
            opposite = np.einsum("ij,ij->i", facing[neighbour], facing[index[rows]]) < AWAY_DOT
            inside = weights > 0
            total = np.bincount(rows, weights=inside.astype(float), minlength=size)
            against = np.bincount(rows, weights=(inside & opposite).astype(float), minlength=size)
            with np.errstate(invalid="ignore", divide="ignore"):
                away[index] = np.where(total > 0, against / total, 0.0)
            fitted[against > AWAY_FRACTION * total] = np.nan
        for f, part in zip(frame, local):
            f[index] = part
        coefficients[index] = fitted
        counts[index] = count
    if compact:
        coefficients, frame, counts, away = (coefficients[given], [f[given] for f in frame], counts[given], away[given])
    if details is not None:
        details["away"] = away
    return coefficients, tuple(frame), counts


def _checked_larger(larger, radius, details: dict | None) -> float:
    """``larger`` of :func:`fit_jets` as a float, checked: a number above every ``radius``, and ``details`` given.

    Raises
    ------
    InvalidOptionError
        ``details`` is None (the larger fits are returned in it), or ``larger`` is not a finite
        number larger than ``radius``.
    """
    if details is None:
        raise InvalidOptionError("`larger` needs `details`: the fits over the larger balls are returned in it")
    value = float(larger) if isinstance(larger, (int, float, np.floating, np.integer)) else np.nan
    if not (np.isfinite(value) and value > np.max(radius)):
        raise InvalidOptionError(
            f"`larger` must be a finite number larger than `radius` {np.max(radius):g}; got {larger!r}"
        )
    return value


def _checked_areas(areas, n: int) -> np.ndarray:
    """(V,) float64 areas, or an empty array for none.

    Raises
    ------
    InvalidMeshError
        ``areas`` does not hold one finite number >= 0 per vertex.
    """
    if areas is None:
        return np.zeros(0)
    areas = np.ascontiguousarray(areas, dtype=np.float64)
    if areas.shape != (n,) or not np.all(np.isfinite(areas) & (areas >= 0)):
        raise InvalidMeshError(
            f"`areas` must hold one finite number >= 0 per vertex, shape ({n},); got shape {areas.shape}"
        )
    return areas


def _checked_centre_radii(radius, centres: np.ndarray) -> np.ndarray:
    """(M,) float64 radii of the M ``centres``, checked: positive, finite, one radius per vertex listed.

    Raises
    ------
    InvalidOptionError
        ``radius`` is not an array of M positive finite numbers, or gives a
        centre listed twice two radii.
    """
    radius = centre_radii(radius, centres.size)
    order = np.argsort(centres, kind="stable")
    ordered, radii = centres[order], radius[order]
    twice = (ordered[1:] == ordered[:-1]) & (radii[1:] != radii[:-1])
    if twice.any():
        raise InvalidOptionError(
            f"`radius` gives vertex {int(ordered[1:][twice][0])}, listed twice in `centres`, two radii"
        )
    return radius


def _joined(pieces: list) -> list[np.ndarray]:
    """The outputs of the calls of a kernel (a tuple of arrays per call), each joined over the calls."""
    return [column[0] if len(column) == 1 else np.concatenate(column) for column in zip(*pieces)]


def _connected_fits(
    kernels,
    vertices: np.ndarray,
    normals: np.ndarray,
    radius,
    degree: int,
    iterations: int,
    centres: np.ndarray,
    pairs_per_centre: float,
    neighbours: np.ndarray | None,
    adjacency: tuple,
    facing: np.ndarray | None,
    settled: float,
    *,
    normals_only: bool,
    areas: np.ndarray,
    min_spread: float,
    agreement: float = -2.0,
) -> list[np.ndarray]:
    """The compiled fits over the surface-connected balls of ``centres``, in calls of about
    :data:`~meshcurv.neighborhoods.PAIRS_PER_CALL` pairs (checked inputs; ``neighbours`` a (V,) bool
    array or None; ``radius`` a float or a checked (M,) array of one per centre). The kernel's outputs,
    one row per centre; with ``normals_only``, ``[normals]`` (M, 3), the fitted normals alone."""
    n = vertices.shape[0]
    allowed = np.ones(n, dtype=bool) if neighbours is None else neighbours
    indptr, indices = checked_adjacency(adjacency, n)
    check = facing is not None
    per_centre = np.ndim(radius) > 0
    radii = radius if per_centre else np.array([float(radius)])
    # read-only views: one numba signature whatever the callers' flags (each new one costs ~10 s of compilation)
    vertices, normals, allowed, indptr, indices = (
        _read_only_view(a) for a in (vertices, normals, allowed, indptr, indices)
    )
    pieces = []
    for lo, hi in call_ranges(centres.size, pairs_per_centre, radii * radii if per_centre else None):
        outputs = kernels.fit_jets_connected(
            vertices,
            normals,
            radii[lo:hi] if per_centre else radii,
            degree,
            iterations,
            _exponents(degree),
            min_spread,
            centres[lo:hi],
            kernel_threads(),
            allowed,
            indptr,
            indices,
            vertices if facing is None else _read_only_view(facing),
            check,
            AWAY_FRACTION,
            normals_only,
            float(settled),
            _read_only_view(areas),
            float(agreement),
        )
        pieces.append(outputs[:1] if normals_only else outputs)
    return _joined(pieces)


def _read_only_view(array: np.ndarray) -> np.ndarray:
    view = array.view()
    view.flags.writeable = False
    return view


def _all_rows(rows: np.ndarray, centres: np.ndarray, n: int, fill: float) -> np.ndarray:
    """(V, ...) rows of all vertices from the rows of ``centres``; ``fill`` elsewhere."""
    out = np.full((n, *rows.shape[1:]), fill)
    out[centres] = rows
    return out


def fit_jet_normals(
    vertices: np.ndarray,
    normals: np.ndarray,
    radius,
    *,
    degree: int = DEGREE,
    iterations: int = ITERATIONS,
    neighbours: np.ndarray | None = None,
    adjacency: tuple | None = None,
    settled: float = 0.0,
    areas: np.ndarray | None = None,
    min_spread: float = MIN_SPREAD,
) -> np.ndarray:
    """(V, 3) unit normals of the jets of :func:`fit_jets` at every vertex (NaN where no fit was possible).

    ``jet_normals(*fit_jets(...)[:2])`` with the same arguments; with the
    compiled kernels and ``adjacency``, one pass that writes only the normals
    (not the coefficients, frames and counts: 136 bytes per vertex). A vertex
    whose fit has a slope ``c10^2 + c01^2`` below ``settled`` takes its normal
    without further iterations (:func:`fit_jets`; 0: ``iterations`` fits everywhere).
    ``radius``: one for all vertices, or a (V,) array of one per vertex (as :func:`fit_jets`);
    ``areas``: the points weighted by their areas (:func:`fit_jets`); ``min_spread``: as :func:`fit_jets`
    (:data:`NORMAL_MIN_SPREAD` for normals that feed other estimates).
    """
    return _fit_jet_normals(
        checked_points(vertices),
        normals,
        radius,
        degree=degree,
        iterations=iterations,
        neighbours=neighbours,
        adjacency=adjacency,
        settled=settled,
        areas=areas,
        min_spread=min_spread,
    )


def _fit_jet_normals(
    vertices: np.ndarray,
    normals: np.ndarray,
    radius,
    *,
    degree: int = DEGREE,
    iterations: int = ITERATIONS,
    neighbours: np.ndarray | None = None,
    adjacency: tuple | None = None,
    settled: float = 0.0,
    areas: np.ndarray | None = None,
    min_spread: float = MIN_SPREAD,
    facing: np.ndarray | None = None,
) -> np.ndarray:
    """:func:`fit_jet_normals` on ``vertices`` already checked (as :func:`_fit_jets`); with ``facing`` (V, 3), the
    fits whose balls hold more than :data:`AWAY_FRACTION` of their points facing away are refused (NaN), as there."""
    kernels = numba_kernels("jets")
    n = vertices.shape[0]
    if kernels is None or adjacency is None or n == 0:
        coefficients, frame, _ = _fit_jets(
            vertices,
            normals,
            radius,
            degree=degree,
            iterations=iterations,
            neighbours=neighbours,
            adjacency=adjacency,
            settled=settled,
            areas=areas,
            min_spread=min_spread,
            facing=facing,
        )
        return jet_normals(coefficients, frame)
    if facing is not None:
        facing = np.ascontiguousarray(facing, dtype=np.float64)
        if facing.shape != vertices.shape:
            raise InvalidMeshError(f"`facing` must have shape {vertices.shape}; got {facing.shape}")
    normals = np.ascontiguousarray(normals, dtype=np.float64)
    if normals.shape != vertices.shape:
        raise InvalidMeshError(f"`normals` must have shape {vertices.shape}; got {normals.shape}")
    if neighbours is not None:
        neighbours = np.asarray(neighbours, dtype=bool)
        if neighbours.shape != (n,):
            raise InvalidMeshError(f"`neighbours` must have shape ({n},); got {neighbours.shape}")
    if np.ndim(radius):
        radius = centre_radii(radius, n)
    every = neighbours is None or bool(neighbours.all())  # (no copy of a whole mesh for a sample of it)
    mean, _ = check_ball_work(vertices if every else vertices[neighbours], radius, n, centres=vertices)
    return _connected_fits(
        kernels,
        vertices,
        normals,
        radius,
        degree,
        iterations,
        np.arange(n),
        mean,
        neighbours,
        adjacency,
        facing,
        settled,
        normals_only=True,
        areas=_checked_areas(areas, n),
        min_spread=min_spread,
    )[0]


def jet_normals(coefficients: np.ndarray, frame: tuple) -> np.ndarray:
    """(V, 3) unit normals of the fitted jets, ``(n - c10 t1 - c01 t2) / sqrt(1 + c10^2 + c01^2)``."""
    t1, t2, normal = frame
    p, q = coefficients[:, 1:2], coefficients[:, 2:3]
    return (normal - p * t1 - q * t2) / np.sqrt(1 + p * p + q * q)


def shape_operators(coefficients: np.ndarray, frame: tuple, radius: float):
    """(V, 6) shape operators (meshcurv's sign) and (V, 3) unit normals of the fitted jets."""
    t1, t2, normal = frame
    _, p, q, a, b, c = coefficients.T
    a, b, c = a / radius, b / radius, c / radius  # back from units of radius
    width = np.sqrt(1 + p * p + q * q)
    first = np.stack([1 + p * p, p * q, 1 + q * q], axis=1)
    second = -np.stack([2 * a, b, 2 * c], axis=1) / width[:, None]
    det = first[:, 0] * first[:, 2] - first[:, 1] ** 2
    inverse = np.stack([first[:, 2], -first[:, 1], first[:, 0]], axis=1) / det[:, None]

    def as2x2(s):
        return np.stack([np.stack([s[:, 0], s[:, 1]], axis=1), np.stack([s[:, 1], s[:, 2]], axis=1)], axis=1)

    middle = as2x2(inverse) @ as2x2(second) @ as2x2(inverse)
    jacobian = np.stack([t1 + p[:, None] * normal, t2 + q[:, None] * normal], axis=2)  # (V, 3, 2)
    tensor = jacobian @ middle @ jacobian.transpose(0, 2, 1)
    six = tensor[:, [0, 1, 2, 0, 0, 1], [0, 1, 2, 1, 2, 2]]
    return six, jet_normals(coefficients, frame)


@twin("jets")
def jet_curvatures(coefficients: np.ndarray, frame: tuple, radii: np.ndarray, normals: np.ndarray):
    """Principal curvatures, directions and normals of jets fitted in units of their radii.

    Parameters
    ----------
    coefficients : ndarray of shape (N, 6)
        The constant, linear and quadratic coefficients of each jet (:func:`fit_jets`), in units of
        its own radius; NaN where no fit.
    frame : tuple of three ndarrays of shape (N, 3)
        The frames ``t1, t2, n`` the jets were fitted in.
    radii : ndarray of shape (N,)
        The radius of each fit.
    normals : ndarray of shape (N, 3)
        The normals returned where a fit failed.

    Returns
    -------
    k_min, k_max : ndarray of shape (N,)
    dir_min, dir_max : ndarray of shape (N, 3)
        The eigen-pairs of :func:`shape_operators` divided by ``radii`` in the tangent plane of the
        fitted normal (:func:`meshcurv._tensors.principal_from_shape_operator`); NaN where a
        coefficient or the fitted normal is not finite.
    normals : ndarray of shape (N, 3)
        The fitted jets' unit normals (:func:`jet_normals`), the given ``normals`` where NaN.

    Notes
    -----
    The compiled twin (:func:`meshcurv._kernels.jets.jet_curvatures`) writes the 2 x 2 and 3 x 2
    matrix products out as sums of two products: NumPy's ``matmul`` may round them otherwise, the
    results agree to a few ulps (``tests/test_kernel_twins.py``).
    """
    six, fitted = shape_operators(coefficients, frame, 1.0)
    with np.errstate(invalid="ignore"):
        six = six / radii[:, None]
    ok = np.isfinite(coefficients).all(axis=1) & np.isfinite(fitted).all(axis=1)
    k_min, k_max, dir_min, dir_max = principal_from_shape_operator(
        np.where(ok[:, None], six, 0.0), np.where(ok[:, None], fitted, [0.0, 0.0, 1.0])
    )
    out_normals = np.where(ok[:, None], fitted, normals)
    for array in (k_min, k_max, dir_min, dir_max):
        array[~ok] = np.nan
    return k_min, k_max, dir_min, dir_max, out_normals


def nested_jet_normals(
    vertices: np.ndarray,
    normals: np.ndarray,
    radii,
    *,
    adjacency: tuple,
    neighbours: np.ndarray | None = None,
    degree: int,
    iterations: int,
    settled: float,
    min_spread: float,
) -> list[np.ndarray]:
    """(V, 3) unit normals of :func:`fit_jet_normals` at each of the increasing ``radii``.

    Element ``r`` equals ``fit_jet_normals(vertices, normals, radii[r], adjacency=adjacency, ...)``
    with the same options (NaN where no jet could be fitted) to round-off: the compiled
    kernel walks the surface-connected balls of every radius in one walk per vertex, the largest
    leading (``_kernels.icc.nested_jet_normals``: the fits of the smaller balls cost their fits,
    not their walks); the NumPy path fits each radius on its own (the trusting core
    :func:`_fit_jet_normals`: ``vertices`` are not checked again).

    Parameters
    ----------
    vertices, normals : ndarray of shape (V, 3)
        The points and the first frames of the fits (checked by the caller).
    radii : sequence of float
        Positive radii, non-decreasing.
    adjacency : tuple of ndarray
        CSR neighbour lists ``(indptr, indices)`` of the vertices (:attr:`MeshTopology.neighbour_lists`).
    neighbours : ndarray of bool of shape (V,), optional
        The vertices that may enter the balls (default: all).
    degree, iterations, settled, min_spread
        As :func:`fit_jet_normals`.

    Returns
    -------
    list of ndarray of shape (V, 3)

    Raises
    ------
    InvalidOptionError
        ``radii`` is empty, holds a radius that is not positive and finite, or decreases; or the
        largest balls would hold more than :data:`MAX_BALL_PAIRS` pairs (:func:`check_ball_work`).
    """
    radii = np.array(radii, dtype=np.float64, ndmin=1)
    if radii.ndim != 1 or radii.size == 0 or not (np.isfinite(radii).all() and (radii > 0).all()):
        raise InvalidOptionError(f"`radii` must be a non-empty sequence of positive finite radii; got {radii}")
    if (np.diff(radii) < 0).any():
        raise InvalidOptionError("`radii` must not decrease from one radius to the next (nested balls)")
    kernels = numba_kernels("icc")
    n = vertices.shape[0]
    options: dict[str, Any] = {"degree": degree, "iterations": iterations, "settled": settled, "min_spread": min_spread}
    if kernels is None or n == 0:
        return [
            _fit_jet_normals(vertices, normals, radius, adjacency=adjacency, neighbours=neighbours, **options)
            for radius in radii
        ]
    allowed = np.ones(n, dtype=bool) if neighbours is None else np.asarray(neighbours, dtype=bool)
    pool = vertices if allowed.all() else vertices[allowed]  # (no copy of a whole mesh for a sample of it)
    mean, _ = check_ball_work(pool, float(radii[-1]), n, centres=vertices)
    indptr, indices = checked_adjacency(adjacency, n)
    vertices, normals = (np.ascontiguousarray(a, dtype=np.float64) for a in (vertices, normals))
    pieces = [
        kernels.nested_jet_normals(
            vertices,
            normals,
            radii,
            degree,
            iterations,
            _exponents(degree),
            min_spread,
            np.arange(lo, hi),
            kernel_threads(),
            allowed,
            indptr,
            indices,
            float(settled),
        )
        for lo, hi in call_ranges(n, mean)
    ]
    fitted = np.concatenate(pieces, axis=1)
    return list(fitted)


#: :func:`sampled_jet_normals` fits one centre per cube of this many median radii of the fits (dense voxel
#: surfaces, on their coarse level: a cluster's side, ``COARSE_CELLS`` = 10 of icc; a tenth of the fits).
#: Against 0.05 (twice the fits, 0.07 CPU s more on the sphere R 6 of ``benchmarks/dense_voxel.py``): the 6 of
#: the 19 meshes of ``benchmarks/accuracy_voxel.md`` fitted on a coarse level move by -6.0% to +2.6% of their
#: median H error; 20 voxel spheres (4 spacings, 5 seeds) by -7% to +14% (mean +1%; ``benchmarks/dense_voxel.md``).
SAMPLED_SPACING = 0.1
#: The other centres interpolate the fitted samples within this many sample spacings: a weighted linear
#: least-squares fit over the centre's tangent plane, weights ``(1 - d^2 / h^2)^2`` ...
SAMPLED_WIDTH = 1.5
#: ... where those samples span the plane: the weighted variances of their two coordinates (in units of the
#: reach) multiplied exceed this; else the weighted mean of their normals.
SAMPLED_SPREAD = 1e-4


def sampled_jet_normals(
    points: np.ndarray,
    normals: np.ndarray,
    radius,
    *,
    centres: np.ndarray,
    spacing: float | None = None,
    width: float = SAMPLED_WIDTH,
    **options,
) -> np.ndarray:
    """(M, 3) unit jet normals at ``centres``: fitted at a sample of them, interpolated at the others.

    Normal fits over balls of thousands of points (a dense voxel surface) then cost the number of samples,
    which ``spacing`` sets, not the number of centres. The samples: in each cube of side ``spacing`` (the
    coordinate axes' cubes), the centre nearest the cube's middle (:func:`_cube_samples`: re-indexed points
    give the same samples). Each is fitted by :func:`fit_jets` with ``options`` at its own radius and keeps
    its :func:`jet_normals`. Every other centre takes the value at itself of a weighted linear
    least-squares fit of the samples' normals over its tangent plane (the plane of its ``normals`` row):
    the samples within ``h = width * spacing``, weights ``(1 - d^2 / h^2)^2``; where those do not span the
    plane (:data:`SAMPLED_SPREAD`), their weighted mean; without any, the nearest sample's normal. NaN where
    no sample could be fitted. The fitted normals vary smoothly over the fits' balls (about 20 spacings at
    the default): on a sphere the interpolation is exact (the tangential components of ``x / R`` are linear
    in the tangent-plane coordinates), elsewhere it averages the jitter of the fits over 1.5 spacings.

    Parameters
    ----------
    points, normals : ndarray of shape (P, 3)
        As :func:`fit_jets` (the first frames of the fits).
    radius : float or ndarray of shape (M,)
        The radius of each centre's ball; a sample fits over its own.
    centres : ndarray of int of shape (M,)
        Distinct point indices.
    spacing : float, optional
        Side of the cubes of one sample each (positive and finite). Default: :data:`SAMPLED_SPACING`
        times the median of ``radius``.
    width : float, default: SAMPLED_WIDTH
        Reach of the interpolation in units of ``spacing`` (at least 1).
    **options
        ``degree``, ``iterations``, ``neighbours``, ``adjacency``, ``settled``, ``areas``, ``min_spread`` of
        :func:`fit_jets`.

    Returns
    -------
    ndarray of shape (M, 3)

    Raises
    ------
    InvalidOptionError
        ``spacing`` is not positive and finite, or ``width`` is below 1.
    """
    return _sampled_jet_normals(
        checked_points(points), normals, radius, centres=centres, spacing=spacing, width=width, **options
    )


def _sampled_jet_normals(
    points: np.ndarray,
    normals: np.ndarray,
    radius,
    *,
    centres: np.ndarray,
    spacing: float | None = None,
    width: float = SAMPLED_WIDTH,
    **options,
) -> np.ndarray:
    """:func:`sampled_jet_normals` on ``points`` already checked (as :func:`_fit_jets`)."""
    from scipy.spatial import cKDTree

    centres = np.asarray(centres, dtype=np.int64).ravel()
    radii = np.broadcast_to(np.asarray(radius, dtype=np.float64), centres.shape)
    if spacing is None:
        spacing = SAMPLED_SPACING * float(np.median(radii)) if radii.size else 1.0
    if not (np.isfinite(spacing) and spacing > 0):
        raise InvalidOptionError(f"`spacing` must be a positive finite length; got {spacing!r}")
    if not width >= 1:
        raise InvalidOptionError(f"`width` must be at least 1 (samples within that many spacings); got {width!r}")
    m = centres.size
    out = np.full((m, 3), np.nan)
    if m == 0:
        return out
    at = points[centres]
    sampled = _cube_samples(at, spacing)
    coefficients, frame, _ = _fit_jets(
        points, normals, radii[sampled], centres=centres[sampled], compact=True, **options
    )
    fitted = jet_normals(coefficients, frame)
    usable = np.isfinite(fitted).all(axis=1)
    if not usable.any():
        return out
    sampled, fitted = sampled[usable], fitted[usable]
    t1, t2 = tangent_basis(np.ascontiguousarray(np.asarray(normals, dtype=np.float64)[centres]))
    kernels = numba_kernels("pilot")
    interpolate = interpolated_normals if kernels is None else kernels.interpolated_normals
    out, reached = interpolate(at, at[sampled], fitted, t1, t2, width * spacing, SAMPLED_SPREAD)
    if not reached.all():
        _, nearest = cKDTree(at[sampled]).query(at[~reached])
        out[~reached] = fitted[nearest]
    out /= np.linalg.norm(out, axis=1, keepdims=True)
    out[sampled] = fitted
    return out


def interpolated_normals(
    at: np.ndarray,
    samples: np.ndarray,
    fitted: np.ndarray,
    tangent1: np.ndarray,
    tangent2: np.ndarray,
    reach: float,
    spread: float,
    facing: np.ndarray | None = None,
    sample_normals: np.ndarray | None = None,
    agreement: float = 0.0,
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`sampled_jet_normals`' interpolation: ``(values, reached)`` at the centres ``at`` (M, 3).

    Each centre takes the value at itself of a weighted linear least-squares fit of the ``fitted`` (S, k) values
    (unit normals, k = 3; or any fields: ``icc``'s sampled ball sums) of the ``samples`` (S, 3) within ``reach``
    over its tangent plane ``(tangent1, tangent2)`` (M, 3), weights ``(1 - d^2 / reach^2)^2``; where the weighted
    variances of the samples' two coordinates (in units of ``reach``) multiplied do not exceed ``spread``, the
    weighted mean of their values. With ``facing`` (M, 3) and ``sample_normals`` (S, 3) unit normals, only the
    samples whose normal's cosine with the centre's exceeds ``agreement`` count (the far side of a part thinner
    than ``reach`` does not). Not normalised; NaN and ``reached`` False where no sample counts. The compiled twin
    (:func:`meshcurv._kernels.pilot.interpolated_normals`) finds the samples by cubes instead of k-d trees and
    solves by Cramer's rule: the results agree to round-off (``tests/test_jets_sampled.py``).
    """
    from scipy.spatial import cKDTree

    m, k = at.shape[0], fitted.shape[1]
    out = np.full((m, k), np.nan)
    pairs = cKDTree(at).sparse_distance_matrix(cKDTree(samples), reach, output_type="coo_matrix")
    row, col = pairs.row.astype(np.int64), pairs.col.astype(np.int64)
    if facing is not None and sample_normals is not None:
        kept = np.einsum("ij,ij->i", facing[row], sample_normals[col]) > agreement
        row, col = row[kept], col[kept]
    offsets = (samples[col] - at[row]) / reach
    weights = np.maximum(1.0 - np.einsum("ij,ij->i", offsets, offsets), 0.0) ** 2
    basis = (
        np.ones(row.size),
        np.einsum("ij,ij->i", offsets, tangent1[row]),
        np.einsum("ij,ij->i", offsets, tangent2[row]),
    )
    gram = np.zeros((m, 3, 3))
    moments = np.zeros((m, 3, k))
    for a in range(3):
        weighted = weights * basis[a]
        for b in range(3):
            gram[:, a, b] = np.bincount(row, weights=weighted * basis[b], minlength=m)
        for b in range(k):
            moments[:, a, b] = np.bincount(row, weights=weighted * fitted[col, b], minlength=m)
    total = gram[:, 0, 0]
    reached = total > 0
    planar = reached.copy()
    planar[reached] = np.linalg.det(gram[reached]) > spread * total[reached] ** 3
    out[planar] = np.linalg.solve(gram[planar], moments[planar])[:, 0, :]
    mean = reached & ~planar
    out[mean] = moments[mean, 0, :] / total[mean, None]
    return out, reached


#: The cube grids of :func:`turned_cubes` start these shares of a side before the points' lowest corner, along the
#: axis of the points' largest spread, the next and the last (:func:`axis_shifts`): irrational shares, so that no
#: boundary runs through a lattice of points (a voxel surface's vertices, at whole and half voxels, the corner
#: among them), where round-off (a scaled mesh) would choose; and one per axis, so that no cube's middle is as far
#: from two lattice points whose offsets are permuted. One share on every axis (1 / pi) tied such points nearest
#: the middles, and a perturbation of the vertices by 1e-9 of their size chose 19 of the 699 centres of a voxel
#: ellipsoid's pilot (:func:`_cube_samples`, ``icc._pilot_centres``); none with these.
CUBE_SHIFT = (1.0 / np.pi, 1.0 / np.e, np.sqrt(2.0) - 1.0)

#: :func:`axis_turns` reads points as symmetric along an axis where their third central moment is within this
#: share of that of its magnitudes: round-off (1e-16 per point, 1e-10 for points 1e6 sizes from the origin) is
#: far below it.
SYMMETRY = 1e-8


def axis_turns(points: np.ndarray) -> np.ndarray:
    """(3,) +1.0 or -1.0 per axis: -1 where the points' third central moment along the axis is negative by more
    than :data:`SYMMETRY` of the moment of its magnitudes.

    A mirror image of the points (an image flipped along an axis) has the opposite moment along that axis, so the
    points times these signs (:func:`turned_cubes`) are the same numbers, up to a translation, for the points and
    for their image; a translation, a scaling and a permutation of the axes keep the signs. Points symmetric along
    an axis (a voxel box, a blob of a few voxels: their moment is round-off, whose sign a scaling would choose)
    keep it as given: their mirror image is the same points, moved. A perturbation of the points moves the
    moment by as much: it turns an axis only where the points are that close to symmetric, or to the threshold.
    (The moments of the offsets scaled by their largest, so that a point flung far away overflows nothing.)
    """
    if points.shape[0] == 0:
        return np.ones(3)
    # one row per axis (reductions along rows of (N, 3) cost 2.5 times more: 8.9 against 3.9 ms on 113,072
    # points, called 7 times a voxel call); cubes by products (a power of 3 cost 70 times more)
    offsets = np.ascontiguousarray((points - points.mean(axis=0)).T)
    largest = np.abs(offsets).max(axis=1)
    scaled = offsets / np.where(largest > 0, largest, 1.0)[:, None]
    cubed = scaled * scaled * scaled
    return np.where(cubed.sum(axis=1) < -SYMMETRY * np.abs(cubed).sum(axis=1), -1.0, 1.0)


def axis_shifts(points: np.ndarray) -> np.ndarray:
    """(3,) where :func:`turned_cubes`' grid starts along each axis, in sides: :data:`CUBE_SHIFT` in the order of
    the points' spreads (their variances along the axes, largest first), so that a permutation of the axes (a
    transposed image) permutes them; axes whose spreads are within :data:`SYMMETRY` of each other (a voxel box
    with two equal sides: round-off would order them) take the first one's."""
    if points.shape[0] == 0:
        return np.full(3, CUBE_SHIFT[0])
    offsets = points - points.mean(axis=0)
    spread = np.einsum("ij,ij->j", offsets, offsets)
    order = np.argsort(-spread, kind="stable")
    shifts = np.empty(3)
    shifts[order] = CUBE_SHIFT
    for previous, axis in zip(order[:-1], order[1:]):
        if spread[axis] >= (1.0 - SYMMETRY) * spread[previous]:
            shifts[axis] = shifts[previous]
    return shifts


def turned_cubes(
    points: np.ndarray, side: float, *, limit: float = 2.0**20
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The cube of side ``side`` that holds each point, on a grid that a mirror image of the points mirrors.

    The points are turned along the axes of :func:`axis_turns` (a mirror image of them gives the same turned
    points, moved), and the cubes start :func:`axis_shifts` of a side before their lowest corner. Anchored at the lowest corner of the points as given, the grid met the surface of a flipped image
    elsewhere (issue 29, fuzz_labels seed 460 case 30: a voxel ball's default radius 5.5518 and 5.5279, k_min's
    5th percentile 0.0386 and 0.0491 on one mesh and its mirror image, ``icc``'s default). The corner moves with
    the points, by as much as any of them (a perturbation of 1e-4 edge lengths moves no lattice point across a
    boundary a share of a side away from the lattice; a grid from the middle of the points' box, tried first, put
    the middle of its central cubes on the lattice, where mirror pairs of vertices tie and the perturbation chose:
    a perturbed voxel ellipsoid's radius moved 2.7%).

    Parameters
    ----------
    points : ndarray of shape (N, 3)
        Finite coordinates.
    side : float
        The cubes' side, positive.
    limit : float, default: 2**20
        Largest cube index per axis: the cubes beyond it (a point flung far away) share the last one (a cast of
        such a float is undefined).

    Returns
    -------
    cubes : ndarray of int64 of shape (N, 3)
        Each point's cube, 0 to ``limit`` per axis.
    offsets : ndarray of shape (N, 3)
        Each point's offset from its cube's middle, in sides, in the turned axes.
    turned : ndarray of shape (N, 3)
        The turned points (the order of ties, :func:`_nearest_in_cubes`).
    """
    turned = points * axis_turns(points)
    shifted = (turned - turned.min(axis=0)) / side + axis_shifts(turned)
    cubes = np.minimum(np.floor(shifted), limit).astype(np.int64)
    return cubes, shifted - cubes - 0.5, turned


def _cube_samples(points: np.ndarray, spacing: float) -> np.ndarray:
    """Sorted indices into ``points``: in each cube of side ``spacing`` (:func:`turned_cubes`), the point nearest
    its middle (distances rounded to 1e-9 of a side, ties taken by the turned coordinates, never by the index)."""
    cube, offset, turned = turned_cubes(points, spacing)
    key = cube[:, 0] << 42 | cube[:, 1] << 21 | cube[:, 2]
    off_middle = np.round(np.einsum("ij,ij->i", offset, offset), 9)
    return _nearest_in_cubes(turned, key, off_middle)


def _nearest_in_cubes(points: np.ndarray, key: np.ndarray, off_middle: np.ndarray) -> np.ndarray:
    """Sorted indices into ``points`` (N, 3): of the points of each cube ``key`` (N,) int64, the first in the order
    (``off_middle``, x, y, z): ``np.lexsort((z, y, x, off_middle, key))``'s first of each key, by one sort of the
    keys and a sort of the points tied nearest their cube's middle."""
    order = np.argsort(key, kind="stable")
    sorted_keys = key[order]
    starts = np.flatnonzero(np.r_[True, sorted_keys[1:] != sorted_keys[:-1]])
    nearest = np.minimum.reduceat(off_middle[order], starts)
    tied = order[off_middle[order] == np.repeat(nearest, np.diff(np.r_[starts, key.size]))]
    ties = np.lexsort((points[tied, 2], points[tied, 1], points[tied, 0], key[tied]))
    first = tied[ties][np.r_[True, key[tied][ties][1:] != key[tied][ties][:-1]]]
    return np.sort(first)


#: On a voxel surface, a normal fit whose ball wraps round a thin part (more than :data:`AWAY_FRACTION` of its
#: points facing away from its centre, by the fitted normals) while the cubic over the same ball's points that face
#: the centre's way (:data:`THIN_AGREEMENT`) bends less than this (its largest ``|k|`` times the radius) is on a flat
#: part thinner than the ball: the wrap is the other side, not the centre's own bend (the far side of a part curved
#: all round is within a ball only where ``k r`` reaches about ``sqrt(2)``). On the wrapped samples of the voxel
#: spheres, tori and ellipsoids of ``accuracy.py --voxel --quick`` the same-side cubics read 0.73 and more; on the
#: flat faces of ``voxel_ellipsoid((8, 8, 2))`` half of them 0.5 or less. (The cubic over the whole ball, both
#: sides, reads 0.1 to 1.6 on those flat faces and fell below 1 at one to three samples of four of those
#: ellipsoids.) ...
THIN_BEND = 0.7
#: ... and its normal is fitted again over a ball this many times wider (the terraces of a flat part's staircase
#: are about ``sqrt(2 h R)`` wide, 8 voxels at the pole of that ellipsoid, wider than the first ball: their edges
#: tilted its fits, 13.8 degrees off the exact normals at the median) ...
THIN_WIDEN = 3.0
#: ... of the points whose fitted normal has a cosine above this with the centre's (46 degrees: the other side and
#: the rim are left out of the fit, ``fit_jets(agreement=)``).
THIN_AGREEMENT = 0.7
#: The test and the wider fits are made at one centre per cube of this many median normal-fit radii
#: (:func:`_cube_samples`); the other centres take the samples' flags and normals interpolated over their tangent
#: planes (:func:`interpolated_normals`, the samples within :data:`SAMPLED_WIDTH` spacings that face their way).
THIN_SPACING = 0.5
#: A centre is thin where its interpolated flag exceeds one half by more than this: a centre midway between thin
#: and other samples reads one half to round-off (the voxel lattice's symmetry), and the last bits, which differ
#: between the compiled interpolation and its NumPy twin, chose (``voxel_ellipsoid((8, 8, 2), seed=2)``: 17 of 604
#: centres thin on one backend only, their normals up to 1.96 apart).
THIN_TIE = 1e-9


def _thin_part_normals(
    vertices: np.ndarray,
    fitted: np.ndarray,
    radius,
    centres: np.ndarray,
    *,
    neighbours: np.ndarray | None,
    adjacency: tuple,
    degree: int,
    iterations: int,
    settled: float,
    min_spread: float,
    areas: np.ndarray | None = None,
    widen: float = THIN_WIDEN,
    sampled: bool = True,
    bend: float = THIN_BEND,
) -> np.ndarray:
    """(V, 3) ``fitted`` (unit normals of the fits over balls of ``radius``, float or (V,)) with those of the
    ``centres`` (M,) on thin flat parts of a voxel surface fitted again over wider balls of their own side
    (``widen`` times wider: :data:`THIN_WIDEN`; a smooth mesh's, the same balls: 1). ``sampled``: the test and
    the fits at samples of the centres, interpolated (below); else at every centre (a smooth mesh's rim, where the
    normals turn fast: the interpolated ones left a clean ellipsoid (3, 3, 0.15) 1-8 degrees off at 0.9 of its
    radius). ``bend``: the largest ``|k| r`` of a flat part's same-side cubic (:data:`THIN_BEND`).

    At one centre per cube of :data:`THIN_SPACING` median radii (:func:`_cube_samples`), fits over the same ball
    tell whether it wraps round a thin part while the cubic of its own side hardly bends (:data:`THIN_BEND`); those
    that do are fitted again over balls :data:`THIN_WIDEN` times wider, of the points whose ``fitted`` normals face
    the centre's way (:data:`THIN_AGREEMENT`, :func:`fit_jets` ``agreement=``; ``degree``, ``iterations``,
    ``settled``, ``min_spread``, ``areas`` as there). Each centre takes the flags of the samples near it that
    face its way, interpolated over its tangent plane (:func:`interpolated_normals`), and where they say thin,
    the wider fits' normals interpolated the same way. The fits then cost the samples, not the centres.

    Issue 29/30: on ``shapes.voxel_ellipsoid((8, 8, 2), seed=2)`` the normal fits on the flat faces were 13.8 degrees
    off the exact normals at the median (the edges of the terraces tilt a cubic over a ball narrower than them, and
    the ball reaches the other side round the rim), and 236 of their 371 vertices off by more than half of their
    own ``|k|``; with the exact normals at the same radii none.
    """
    out = np.array(fitted, copy=True)
    finite = np.isfinite(fitted).all(axis=1)
    centres = np.asarray(centres, dtype=np.int64)
    centres = centres[finite[centres]]
    if not centres.size:
        return out
    facing = np.where(finite[:, None], fitted, 0.0)  # (a row of no normal faces no way: left out of every fit)
    radii = np.broadcast_to(np.asarray(radius, dtype=np.float64), (vertices.shape[0],))[centres]
    spacing = THIN_SPACING * float(np.median(radii))
    samples = _cube_samples(vertices[centres], spacing) if sampled else np.arange(centres.size)
    at, over = centres[samples], radii[samples]
    common: dict[str, Any] = {"neighbours": neighbours, "adjacency": adjacency, "compact": True}
    details: dict = {}
    # the share facing away (no iteration: the walk and the check alone, no moments summed)
    _fit_jets(vertices, facing, over, degree=1, iterations=0, centres=at, facing=facing, details=details, **common)
    with np.errstate(invalid="ignore"):
        wrapped = np.flatnonzero(details["away"] > AWAY_FRACTION)
    if not wrapped.size:
        return out
    coefficients, frame, _ = _fit_jets(
        vertices,
        facing,
        over[wrapped],
        degree=3,
        iterations=1,
        centres=at[wrapped],
        facing=facing,
        agreement=THIN_AGREEMENT,
        min_spread=min_spread,
        **common,
    )
    k_min, k_max = jet_curvatures(coefficients, frame, over[wrapped], facing[at[wrapped]])[:2]
    with np.errstate(invalid="ignore"):
        flat = np.maximum(np.abs(k_min), np.abs(k_max)) * over[wrapped] < bend  # (no fit: NaN, not flat)
    if not flat.any():
        return out
    thin = np.zeros(at.size, dtype=bool)
    thin[wrapped[flat]] = True
    coefficients, frame, _ = _fit_jets(
        vertices,
        facing,
        widen * over[thin],
        degree=degree,
        iterations=iterations,
        centres=at[thin],
        facing=facing,
        agreement=THIN_AGREEMENT,
        settled=settled,
        areas=areas,
        min_spread=min_spread,
        **common,
    )
    wide = jet_normals(coefficients, frame)
    kept = np.isfinite(wide).all(axis=1)
    if not kept.any():
        return out
    if not sampled:
        out[at[thin][kept]] = wide[kept]
        return out
    kernels = numba_kernels("pilot")
    interpolate = interpolated_normals if kernels is None else kernels.interpolated_normals
    reach = SAMPLED_WIDTH * spacing
    own = np.ascontiguousarray(facing[centres])
    t1, t2 = tangent_basis(own)
    flags, reached = interpolate(
        vertices[centres], vertices[at], thin[:, None].astype(np.float64), t1, t2, reach, SAMPLED_SPREAD,
        own, np.ascontiguousarray(facing[at]), THIN_AGREEMENT,
    )  # fmt: skip
    chosen = np.flatnonzero(reached & (flags[:, 0] > 0.5 + THIN_TIE))
    if not chosen.size:
        return out
    wide = np.ascontiguousarray(wide[kept])
    values, reached = interpolate(
        vertices[centres[chosen]], vertices[at[thin][kept]], wide, t1[chosen], t2[chosen], reach,
        SAMPLED_SPREAD, own[chosen], wide, THIN_AGREEMENT,
    )  # fmt: skip
    with np.errstate(invalid="ignore", divide="ignore"):
        values = values / np.linalg.norm(values, axis=1, keepdims=True)
    usable = reached & np.isfinite(values).all(axis=1)
    out[centres[chosen[usable]]] = values[usable]
    return out
