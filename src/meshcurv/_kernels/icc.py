"""Compiled twins of :mod:`meshcurv.estimators.icc`: the corrected curvature measures of every face, and
the curvatures of their sums over balls.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ._common import _JIT, run_chunks, threaded
from .geometry import _unadvised_array
from .jets import _fit_one, _general, _grown_work, _jet_outputs, _jet_scratch
from .neighborhoods import _connected_members, _connected_walk_levels, _vertex_spans
from .tensors import _principal_from_mean_gaussian, _tangent_eigen


@nb.njit(inline="always", **_JIT)
def _triangle_measures(points, normals, i, j, k, turn):
    """``mu_0, mu_1, mu_2`` and the symmetrized ``mu^{X,Y}`` (xx, yy, zz, xy, xz, yz) of the triangle ``(i, j, k)``.

    The closed forms of :func:`meshcurv.measures.face_measures`, relative
    to the first corner. With ``turn``, a triangle whose corrected area is
    negative is taken as ``(i, k, j)`` (the random triangles of a point cloud's
    ball have no orientation of their own).
    """
    ax, ay, az = points[j, 0] - points[i, 0], points[j, 1] - points[i, 1], points[j, 2] - points[i, 2]
    bx, by, bz = points[k, 0] - points[i, 0], points[k, 1] - points[i, 1], points[k, 2] - points[i, 2]
    u0x, u0y, u0z = normals[i, 0], normals[i, 1], normals[i, 2]
    u1x, u1y, u1z = normals[j, 0], normals[j, 1], normals[j, 2]
    u2x, u2y, u2z = normals[k, 0], normals[k, 1], normals[k, 2]
    mx, my, mz = (u0x + u1x + u2x) / 3, (u0y + u1y + u2y) / 3, (u0z + u1z + u2z) / 3
    cx, cy, cz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
    if turn and mx * cx + my * cy + mz * cz < 0:  # (i, j, k) -> (i, k, j)
        ax, ay, az, bx, by, bz = bx, by, bz, ax, ay, az
        u1x, u1y, u1z, u2x, u2y, u2z = u2x, u2y, u2z, u1x, u1y, u1z
        cx, cy, cz = -cx, -cy, -cz
    mu0 = 0.5 * (mx * cx + my * cy + mz * cz)
    # (u0 - u2) x a + (u1 - u0) x b
    px, py, pz = u0x - u2x, u0y - u2y, u0z - u2z
    qx, qy, qz = u1x - u0x, u1y - u0y, u1z - u0z
    sx = (py * az - pz * ay) + (qy * bz - qz * by)
    sy = (pz * ax - px * az) + (qz * bx - qx * bz)
    sz = (px * ay - py * ax) + (qx * by - qy * bx)
    mu1 = 0.5 * (mx * sx + my * sy + mz * sz)
    mu2 = 0.5 * (u0x * (u1y * u2z - u1z * u2y) + u0y * (u1z * u2x - u1x * u2z) + u0z * (u1x * u2y - u1y * u2x))
    # M = 1/2 [ (a x m) (u2 - u0)^T - (b x m) (u1 - u0)^T ], symmetrized
    gx, gy, gz = ay * mz - az * my, az * mx - ax * mz, ax * my - ay * mx
    hx, hy, hz = by * mz - bz * my, bz * mx - bx * mz, bx * my - by * mx
    ex, ey, ez = u2x - u0x, u2y - u0y, u2z - u0z
    return (
        mu0,
        mu1,
        mu2,
        0.5 * (gx * ex - hx * qx),
        0.5 * (gy * ey - hy * qy),
        0.5 * (gz * ez - hz * qz),
        0.25 * ((gx * ey - hx * qy) + (gy * ex - hy * qx)),
        0.25 * ((gx * ez - hx * qz) + (gz * ex - hz * qx)),
        0.25 * ((gy * ez - hy * qz) + (gz * ey - hz * qy)),
    )


@threaded
def face_measures(vertices, faces, normals):
    """``measures.face_measures``: (F, 9) ``mu_0, mu_1, mu_2`` and the symmetrized ``mu^{X,Y}`` per face."""
    # every element written by its chunk: no fill (calloc's memset on reused pages); no huge pages (geometry._unadvised_array)
    out = _unadvised_array((faces.shape[0], 9), np.float64)
    chunks = _CHUNKS_PER_THREAD * nb.get_num_threads()
    run_chunks(_face_measures_chunk, faces.shape[0], chunks, vertices, faces, normals, out)
    return out


#: :func:`face_measures` and :func:`curvatures_from_measures` cut their rows into this many chunks per thread
#: (:func:`~._common.run_chunks`): a thread that finishes its share early takes chunks of the others.
_CHUNKS_PER_THREAD = 4


@nb.njit(**_JIT)
def _face_measures_chunk(lo, hi, vertices, faces, normals, out):
    """Faces ``lo:hi`` of :func:`face_measures` (chunks on threads: no parallel pipeline to compile, issue 31)."""
    for f in range(lo, hi):
        m0, m1, m2, m3, m4, m5, m6, m7, m8 = _triangle_measures(
            vertices, normals, faces[f, 0], faces[f, 1], faces[f, 2], False
        )
        out[f, 0], out[f, 1], out[f, 2], out[f, 3], out[f, 4], out[f, 5] = m0, m1, m2, m3, m4, m5
        out[f, 6], out[f, 7], out[f, 8] = m6, m7, m8


@threaded
def curvatures_from_measures(summed, normals):
    """``measures.curvatures_from_measures``: (N,) k_min, k_max and (N, 3) dir_min, dir_max of summed measures."""
    n = summed.shape[0]
    # each chunk writes every row of its own, NaN where undefined: no fill, serial or calloc's (issue 31)
    out = tuple(_unadvised_array(shape, np.float64) for shape in ((n,), (n,), (n, 3), (n, 3)))
    run_chunks(_curvatures_chunk, n, _CHUNKS_PER_THREAD * nb.get_num_threads(), summed, normals, *out)
    return out


@nb.njit(**_JIT)
def _curvatures_chunk(lo, hi, summed, normals, k_min, k_max, dir_min, dir_max):
    """Rows ``lo:hi`` of :func:`curvatures_from_measures` (chunks on threads, as :func:`face_measures`); NaN in
    the rows without a positive area or a finite normal."""
    for i in range(lo, hi):
        area = summed[i, 0]
        nx, ny, nz = normals[i, 0], normals[i, 1], normals[i, 2]
        if not (area > 0 and math.isfinite(nx) and math.isfinite(ny) and math.isfinite(nz)):
            k_min[i], k_max[i] = np.nan, np.nan
            for k in range(3):
                dir_min[i, k], dir_max[i, k] = np.nan, np.nan
            continue
        k_min[i], k_max[i] = _principal_from_mean_gaussian(summed[i, 1] / (2 * area), summed[i, 2] / area)
        _, _, d0, d1, d2, d3, d4, d5 = _tangent_eigen(
            -summed[i, 3] / area,
            -summed[i, 4] / area,
            -summed[i, 5] / area,
            -summed[i, 6] / area,
            -summed[i, 7] / area,
            -summed[i, 8] / area,
            nx,
            ny,
            nz,
            False,
            False,
        )
        dir_min[i, 0], dir_min[i, 1], dir_min[i, 2] = d0, d1, d2
        dir_max[i, 0], dir_max[i, 1], dir_max[i, 2] = d3, d4, d5


@threaded
def nested_jet_normals(
    vertices,
    normals,
    radii,
    degree,
    iterations,
    exponents,
    min_spread,
    centres,
    n_chunks,
    allowed,
    indptr,
    indices,
    settled,
):
    """(R, M, 3) unit normals of the jets of ``jets.fit_jet_normals`` at R non-decreasing ``radii`` around
    ``centres`` (M,), one walk per centre for all of them (``icc.estimate_multiscale``'s fits).

    Row ``r`` is ``kernels.jets.fit_jets_connected(..., normals_only=True)`` at ``radii[r]`` (the same
    points, frames and checks, no areas). Each centre's largest ball is walked once
    (:func:`~meshcurv._kernels.neighborhoods._connected_walk_levels`): its fit takes the points of the
    single walk in the same order (the same numbers), and a smaller ball's fit takes the vertices within
    its radius that the walk reached through edges meeting it (the same points, in another order:
    round-off), unless a vertex within it was reached only through a larger ball, where that ball is
    walked on its own (:func:`~meshcurv._kernels.neighborhoods._connected_members`). NaN where no jet
    could be fitted. The centres run in ``n_chunks`` ranges (:func:`_nested_fits_chunk`) on threads.
    """
    fitted = np.full((radii.shape[0], centres.shape[0], 3), np.nan)
    limits = np.array([1.0, settled])  # no facing check: the away fraction is not read
    run_chunks(
        _nested_fits_chunk,
        centres.shape[0],
        n_chunks,
        vertices,
        normals,
        radii,
        degree,
        iterations,
        exponents,
        min_spread,
        centres,
        allowed,
        indptr,
        indices,
        limits,
        fitted,
        _general(degree),
        _vertex_spans(vertices, indptr, indices),
    )
    return fitted


@nb.njit(**_JIT)
def _nested_fits_chunk(
    lo,
    hi,
    vertices,
    normals,
    radii,
    degree,
    iterations,
    exponents,
    min_spread,
    centres,
    allowed,
    indptr,
    indices,
    limits,
    fitted,
    general,
    spans,
):
    """The fits of ``centres[lo:hi]`` of :func:`nested_jet_normals`, written to their columns of ``fitted``
    (``spans``: :func:`~meshcurv._kernels.neighborhoods._vertex_spans`, which the walks skip far vertices with)."""
    n = vertices.shape[0]
    n_radii = radii.shape[0]
    top = n_radii - 1
    mark = np.full(n, -1, np.int64)
    members = np.empty(n, np.int64)  # the largest ball's, then each smaller one's
    # a vertex is queued at most once a walk: the queue and levels, the inner vertices, levels and distances
    walk = (np.empty(n, np.int64), np.empty(n, np.int64), np.empty(n, np.int64), np.empty(n, np.int64), np.empty(n))
    spare = np.empty(n, np.int64)  # the queue of a smaller ball's own walk
    cutoffs2 = radii * radii
    ids = np.arange(n)
    facing = np.empty((0, 3))  # no facing check
    areas = np.empty(0)  # unweighted
    work, moments, right, matrix, low, inverse_binomials, solution = _jet_scratch(degree, exponents.shape[0])
    c, a, b, nn, one_count, one_away = _jet_outputs(1)  # one row, rewritten for each fit
    only_row = np.int64(0)  # an int64 as jets._grid_chunk's rows: one compiled _fit_one (not one for a literal 0)
    _, _, inner, inner_levels, squared = walk
    for i in range(lo, hi):
        v = centres[i]
        stamp = i * (n_radii + 1)  # the walks of a centre: its largest ball's, then a smaller one's each
        top_size, n_inner = _connected_walk_levels(
            vertices, indptr, indices, allowed, v, cutoffs2, mark, stamp, walk, members, spans
        )
        size = top_size
        for r in range(top, -1, -1):  # the largest ball first: the smaller ones' members then take its place
            if r < top:
                size = 0
                vouched = True
                for j in range(n_inner):  # the queued vertices inside ball r: reached through it?
                    if squared[j] <= cutoffs2[r]:
                        vouched = vouched and inner_levels[j] <= r
                        members[size] = inner[j]
                        size += 1
                if not vouched:
                    size = _connected_members(
                        vertices, indptr, indices, allowed, v, radii[r], mark, stamp + 1 + r, members, spare, spans
                    )
            c[0, :] = np.nan
            work = _grown_work(work, size)
            # numba refuses *args there, hence the whole list
            _fit_one(
                vertices,
                vertices,
                normals,
                radii[r],
                degree,
                iterations,
                exponents,
                min_spread,
                v,
                only_row,
                members,
                size,
                work,
                moments,
                right,
                matrix,
                low,
                inverse_binomials,
                solution,
                c,
                a,
                b,
                nn,
                one_count,
                ids,
                facing,
                limits,
                one_away,
                areas,
                general,
            )
            p, q = c[0, 1], c[0, 2]
            width = np.sqrt(1 + p * p + q * q)
            for k in range(3):
                fitted[r, i, k] = (nn[0, k] - p * a[0, k] - q * b[0, k]) / width
