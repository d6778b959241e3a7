"""Compiled twin of :func:`meshcurv.estimators.quadric.residual_spreads`: a quadric's fit over each ball, the
noise its residuals show and how far that noise moves its curvatures."""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ._common import _JIT, _tangent_frame, run_chunks, threaded
from .neighborhoods import _ball_members, pool_grid

#: The terms of a quadric ``1, x, y, x^2, x y, y^2`` (``jets._exponents(2)``).
_TERMS = 6

#: ``jets.PIVOT_FLOOR``: the smallest pivot (relative to its diagonal entry) of a solvable normal matrix.
_PIVOT_FLOOR = 1e-12

#: ``quadric.RESIDUAL_DOF_FLOOR``: the residuals' degrees of freedom, relative to the ball's weight, that give a noise.
_DOF_FLOOR = 1e-6


@threaded
def residual_spreads(vertices, pool, radii, normals, centres, n_chunks):
    """``quadric.residual_spreads``: per centre, a quadric over its ball, its residual noise and spread.

    ``vertices`` (V, 3), ``pool`` (int64 ids of the points that enter the balls), ``radii`` (V,) one per vertex,
    ``normals`` (V, 3) unit (the frame of each fit), ``centres`` (M,) int64. Returns ``(coefficients (M, 6), sigmas
    (M,), spreads (M,))`` in the order of ``centres`` (NaN, NaN, inf where the ball holds fewer than six points or
    a singular normal matrix; sigma NaN and spread inf where its residuals hold no degree of freedom: six points).
    """
    m = centres.shape[0]
    coefficients = np.full((m, _TERMS), np.nan)
    sigmas = np.full(m, np.nan)
    spreads = np.full(m, np.inf)
    if m == 0 or pool.shape[0] == 0:
        return coefficients, sigmas, spreads
    points, _, grid = pool_grid(vertices, pool, float(radii[centres].max()))  # cells as wide as the largest ball
    run_chunks(
        _spread_chunk, m, n_chunks, vertices, points, grid, radii, normals, centres, coefficients, sigmas, spreads
    )
    return coefficients, sigmas, spreads


@nb.njit(**_JIT)
def _spread_chunk(lo, hi, vertices, points, grid, radii, normals, centres, coefficients, sigmas, spreads):
    """:func:`residual_spreads` of ``centres[lo:hi]``: one walk of each ball, its weighted moments ``sum w x^i y^k``
    and ``sum w^2 x^i y^k`` (``i + k <= 4``: every entry of ``G`` and ``M``), ``sum w x^i y^k z`` and ``sum w z^2``
    (the residuals' squares ``sum w z^2 - c^T b``)."""
    members = np.empty(64, np.int64)
    single = np.empty((5, 5))  # single[i, k] = sum w x^i y^k
    double = np.empty((5, 5))  # the same with w^2
    right = np.empty(_TERMS)
    gram = np.empty((_TERMS, _TERMS))
    moments = np.empty((_TERMS, _TERMS))
    inverse = np.empty((_TERMS, _TERMS))
    factor = np.empty((_TERMS, _TERMS))
    powers = np.array([[0, 0], [1, 0], [0, 1], [2, 0], [1, 1], [0, 2]])
    for row in range(lo, hi):
        v = centres[row]
        radius = radii[v]
        cx, cy, cz = vertices[v, 0], vertices[v, 1], vertices[v, 2]
        nx, ny, nz = normals[v, 0], normals[v, 1], normals[v, 2]
        if not (radius > 0 and math.isfinite(nx + ny + nz)):
            continue
        ax, ay, az, bx, by, bz = _tangent_frame(nx, ny, nz)
        members, size = _ball_members(points, grid, cx, cy, cz, radius, members)
        single[:] = 0.0
        double[:] = 0.0
        right[:] = 0.0
        total = 0.0
        heights = 0.0
        count = 0
        for a in range(size):
            weight, x, y, z = _in_frame(points, members[a], cx, cy, cz, radius, ax, ay, az, bx, by, bz, nx, ny, nz)
            if not weight > 0:
                continue
            xi = weight
            for i in range(5):
                term = xi
                for k in range(5 - i):
                    single[i, k] += term
                    double[i, k] += term * weight
                    term *= y
                xi *= x
            wz = weight * z
            right[0] += wz
            right[1] += wz * x
            right[2] += wz * y
            right[3] += wz * x * x
            right[4] += wz * x * y
            right[5] += wz * y * y
            heights += wz * z
            total += weight
            count += 1
        if count < _TERMS:
            continue
        for r in range(_TERMS):
            for c in range(_TERMS):
                gram[r, c] = single[powers[r, 0] + powers[c, 0], powers[r, 1] + powers[c, 1]]
                moments[r, c] = double[powers[r, 0] + powers[c, 0], powers[r, 1] + powers[c, 1]]
        if not _inverted(gram, inverse, factor):
            continue
        squares = heights
        for r in range(_TERMS):
            s = 0.0
            for c in range(_TERMS):
                s += inverse[r, c] * right[c]
            coefficients[row, r] = s
            squares -= s * right[r]
        trace = 0.0  # tr(G^-1 M)
        for r in range(_TERMS):
            for c in range(_TERMS):
                trace += inverse[r, c] * moments[c, r]
        dof = total - trace
        if not dof > _DOF_FLOOR * total:  # six points: an exact fit, its dof 0 up to round-off
            continue
        sigma2 = max(squares, 0.0) / dof
        spread2 = 0.0
        for k in range(3, _TERMS):  # 4 var c20 + 2 var c11 + 4 var c02, var: (G^-1 M G^-1)_kk
            s = 0.0
            for r in range(_TERMS):
                for c in range(_TERMS):
                    s += inverse[k, r] * moments[r, c] * inverse[c, k]
            spread2 += (2.0 if k == 4 else 4.0) * s
        sigmas[row] = math.sqrt(sigma2) * radius
        spreads[row] = math.sqrt(max(sigma2 * spread2, 0.0)) / radius


@nb.njit(inline="always", **_JIT)
def _in_frame(points, j, cx, cy, cz, radius, ax, ay, az, bx, by, bz, nx, ny, nz):
    """``(w, x, y, z)`` of point ``j``: its weight ``(1 - d^2)^2`` (0 outside the ball) and its coordinates in the
    frame ``(a, b, n)``, both in units of ``radius`` from the centre ``c``."""
    ox = (points[j, 0] - cx) / radius
    oy = (points[j, 1] - cy) / radius
    oz = (points[j, 2] - cz) / radius
    weight = max(1.0 - (ox * ox + oy * oy + oz * oz), 0.0)
    return (
        weight * weight,
        ox * ax + oy * ay + oz * az,
        ox * bx + oy * by + oz * bz,
        ox * nx + oy * ny + oz * nz,
    )


@nb.njit(**_JIT)
def _inverted(gram, inverse, factor):
    """The inverse of the symmetric ``gram`` (its lower triangle read) written to ``inverse`` by ``L D L^T``
    (``factor``: scratch); False where a pivot is not above :data:`_PIVOT_FLOOR` times its diagonal entry."""
    n = gram.shape[0]
    for k in range(n):
        d = gram[k, k]
        for j in range(k):
            d -= factor[k, j] * factor[k, j] * factor[j, j]
        if not d > _PIVOT_FLOOR * max(gram[k, k], 1e-300):
            return False
        factor[k, k] = d
        for i in range(k + 1, n):
            s = gram[i, k]
            for j in range(k):
                s -= factor[i, j] * factor[k, j] * factor[j, j]
            factor[i, k] = s / d
    for col in range(n):  # solve L D L^T x = e_col
        for i in range(n):
            s = 1.0 if i == col else 0.0
            for j in range(i):
                s -= factor[i, j] * inverse[j, col]
            inverse[i, col] = s
        for i in range(n):
            inverse[i, col] /= factor[i, i]
        for i in range(n - 1, -1, -1):
            s = inverse[i, col]
            for j in range(i + 1, n):
                s -= factor[j, i] * inverse[j, col]
            inverse[i, col] = s
    return True
