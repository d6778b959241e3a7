"""Compiled twin of :mod:`meshcurv.estimators.normal_cycle`: the edge sums of the normal-cycle tensor
and the curvatures from them.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from .._geometry import FOLD_ANGLE
from ._common import _JIT, _degenerate, _face_cross, _unit
from .tensors import _tangent_eigen


@nb.njit(parallel=True, **_JIT)
def normal_cycle_sums(vertices, faces, edges, edge_faces, counts, forward, scales, area_ratio, n_chunks):
    """Per-vertex measures, barycentric areas and normal sums; the zero-area faces.

    A face is degenerate when it repeats a vertex or its area is at most
    ``area_ratio`` x ``scales[a]^2`` (``geometry.degenerate_faces``); an
    edge contributes when it has two consistently oriented faces (``counts == 2``,
    ``forward == 1``), neither degenerate. Returns ``(sums, degenerate)``: ``sums``
    of shape (V, 10), columns 0-5 the anisotropic measure
    ``sum beta |e| / 2 e e^T`` (xx, yy, zz, xy, xz, yz), 6 the area, 7-9 the
    area-weighted face-normal sum; ``degenerate`` of shape (F,).

    The face normals are computed in parallel over faces; the sums in
    ``n_chunks`` vertex ranges, each thread adding what falls on its own
    vertices (a face or an edge across two ranges is visited by both), so no
    two threads write the same row.
    """
    n_vertices = vertices.shape[0]
    n_faces = faces.shape[0]
    degenerate = np.zeros(n_faces, np.bool_)
    face_normals = np.empty((n_faces, 4))  # the cross product and its norm (twice the area)
    for f in nb.prange(n_faces):
        a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
        nx, ny, nz = _face_cross(vertices, a, b, c)
        double_area = math.sqrt(nx * nx + ny * ny + nz * nz)
        face_normals[f, 0], face_normals[f, 1], face_normals[f, 2], face_normals[f, 3] = nx, ny, nz, double_area
        degenerate[f] = _degenerate(a, b, c, 0.5 * double_area, area_ratio * scales[a] * scales[a])
    n_chunks = max(1, min(n_chunks, n_vertices))
    sums = np.empty((n_vertices, 10))  # each chunk zeroes its own rows: the pages first touched on its thread
    for chunk in nb.prange(n_chunks):
        first = (n_vertices * chunk) // n_chunks
        last = (n_vertices * (chunk + 1)) // n_chunks
        for v in range(first, last):
            for c in range(10):
                sums[v, c] = 0.0
        for f in range(n_faces):
            if degenerate[f]:
                continue
            third = face_normals[f, 3] / 6.0
            for k in range(3):
                corner = faces[f, k]
                if first <= corner < last:
                    sums[corner, 6] += third
                    sums[corner, 7] += face_normals[f, 0]
                    sums[corner, 8] += face_normals[f, 1]
                    sums[corner, 9] += face_normals[f, 2]
        for e in range(edges.shape[0]):
            p, q = edges[e, 0], edges[e, 1]
            p_here = first <= p < last
            q_here = first <= q < last
            if not (p_here or q_here) or counts[e] != 2 or forward[e] != 1:
                continue
            f1, f2 = edge_faces[e, 0], edge_faces[e, 1]
            if degenerate[f1] or degenerate[f2]:
                continue
            ex = vertices[q, 0] - vertices[p, 0]
            ey = vertices[q, 1] - vertices[p, 1]
            ez = vertices[q, 2] - vertices[p, 2]
            length = math.sqrt(ex * ex + ey * ey + ez * ez)
            if length == 0.0:
                continue
            ex /= length
            ey /= length
            ez /= length
            d1, d2 = face_normals[f1, 3], face_normals[f2, 3]
            ax, ay, az = face_normals[f1, 0] / d1, face_normals[f1, 1] / d1, face_normals[f1, 2] / d1
            bx, by, bz = face_normals[f2, 0] / d2, face_normals[f2, 1] / d2, face_normals[f2, 2] / d2
            sine = (ay * bz - az * by) * ex + (az * bx - ax * bz) * ey + (ax * by - ay * bx) * ez
            cosine = ax * bx + ay * by + az * bz
            # + 0.0 turns a sine of -0.0 (an exact fold: the two faces on each other) into +0.0, so that the
            # angle is pi as on the NumPy path (_geometry.edge_dihedral_angles), not -pi
            angle = math.atan2(sine + 0.0, cosine)
            if math.pi - abs(angle) <= FOLD_ANGLE:  # a fold turned by a rigid motion: pi, whatever its last bits
                angle = math.pi
            weight = 0.5 * angle * length
            for v in (p, q):
                if first <= v < last:
                    sums[v, 0] += weight * ex * ex
                    sums[v, 1] += weight * ey * ey
                    sums[v, 2] += weight * ez * ez
                    sums[v, 3] += weight * ex * ey
                    sums[v, 4] += weight * ex * ez
                    sums[v, 5] += weight * ey * ez
    return sums, degenerate


@nb.njit(inline="always", **_JIT)
def _ring_sums7(source, invalid, weighted, indptr, indices, i):
    """Columns 0 to 6 of row ``i`` of ``source`` plus those of its neighbours, in list order, and
    ``1 / (degree + 1)``: one pass of ``smoothing.smooth_over_neighbours`` at ``i`` before its scaling.
    With ``weighted``, each row counts times 0.0 where ``invalid`` (1.0 elsewhere), as the rows of the
    weighted copy the first pass reads."""
    start, stop = indptr[i], indptr[i + 1]
    w = (0.0 if invalid[i] else 1.0) if weighted else 1.0
    t0, t1, t2 = source[i, 0] * w, source[i, 1] * w, source[i, 2] * w
    t3, t4, t5, t6 = source[i, 3] * w, source[i, 4] * w, source[i, 5] * w, source[i, 6] * w
    for j in range(start, stop):
        u = indices[j]
        w = (0.0 if invalid[u] else 1.0) if weighted else 1.0
        t0 += source[u, 0] * w
        t1 += source[u, 1] * w
        t2 += source[u, 2] * w
        t3 += source[u, 3] * w
        t4 += source[u, 4] * w
        t5 += source[u, 5] * w
        t6 += source[u, 6] * w
    return t0, t1, t2, t3, t4, t5, t6, 1.0 / (stop - start + 1.0)


@nb.njit(parallel=True, **_JIT)
def normal_cycle_finish(sums, invalid, indptr, indices, steps):
    """From :func:`normal_cycle_sums` to the curvatures, in one kernel.

    The measures and areas of valid vertices (invalid ones count as zero) are
    smoothed ``steps`` times over 1-rings (``smoothing.smooth_vertex_field``),
    divided, restricted to the tangent plane of the unit normal and solved in
    closed form (``tangent_principal`` with ``rotate`` and ``mean_from_trace``).
    Returns ``(k_min, k_max, dir_min, dir_max, normals, valid)``, NaN where not valid.

    The first pass reads ``sums`` times the weights as it goes, the last one
    goes straight into the eigen-problem, and the passes between alternate
    between one (V, 7) buffer and columns 0 to 6 of ``sums``, which are
    overwritten when ``steps >= 3`` (columns 7 to 9, the normal sums, are
    kept): no weighted copy, at most one buffer added, the same sums in the
    same order as smoothing a weighted copy.
    """
    n = sums.shape[0]
    spare = np.empty((n if steps >= 2 else 0, 7))
    for step in range(steps - 1):  # every pass but the last: into the other buffer
        source = spare if step % 2 == 1 else sums
        target = sums if step % 2 == 1 else spare
        for i in nb.prange(n):
            t0, t1, t2, t3, t4, t5, t6, scale = _ring_sums7(source, invalid, step == 0, indptr, indices, i)
            target[i, 0], target[i, 1], target[i, 2] = t0 * scale, t1 * scale, t2 * scale
            target[i, 3], target[i, 4], target[i, 5] = t3 * scale, t4 * scale, t5 * scale
            target[i, 6] = t6 * scale
    source = spare if steps >= 2 and steps % 2 == 0 else sums
    k_min, k_max = np.empty(n), np.empty(n)
    dir_min, dir_max, normals = np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3))
    valid = np.zeros(n, np.bool_)
    for i in nb.prange(n):
        nx, ny, nz, directed = _unit(sums[i, 7], sums[i, 8], sums[i, 9])
        normals[i, 0], normals[i, 1], normals[i, 2] = nx, ny, nz
        k_min[i] = k_max[i] = np.nan
        for c in range(3):
            dir_min[i, c] = dir_max[i, c] = np.nan
        if not directed or invalid[i]:
            continue
        if steps > 0:  # the last pass
            t0, t1, t2, t3, t4, t5, t6, scale = _ring_sums7(source, invalid, steps == 1, indptr, indices, i)
            t0, t1, t2, t3, t4, t5, area = (
                t0 * scale,
                t1 * scale,
                t2 * scale,
                t3 * scale,
                t4 * scale,
                t5 * scale,
                t6 * scale,
            )
        else:  # a valid vertex's own sums (times 1.0)
            t0, t1, t2, t3, t4, t5, area = (
                sums[i, 0],
                sums[i, 1],
                sums[i, 2],
                sums[i, 3],
                sums[i, 4],
                sums[i, 5],
                sums[i, 6],
            )
        if not area > 0:
            continue
        valid[i] = True
        lo, hi, d0, d1, d2, d3, d4, d5 = _tangent_eigen(
            t0 / area, t1 / area, t2 / area, t3 / area, t4 / area, t5 / area, nx, ny, nz, True, True
        )
        k_min[i], k_max[i] = lo, hi
        dir_min[i, 0], dir_min[i, 1], dir_min[i, 2] = d0, d1, d2
        dir_max[i, 0], dir_max[i, 1], dir_max[i, 2] = d3, d4, d5
    return k_min, k_max, dir_min, dir_max, normals, valid
