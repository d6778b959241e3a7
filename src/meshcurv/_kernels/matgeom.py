"""Compiled twins of :mod:`meshcurv.estimators.matgeom` and :mod:`meshcurv.estimators._eigen`: matGeom's
edge tensors summed per vertex and their eigen-decomposition in matGeom's order.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from .._geometry import FOLD_ANGLE
from ._common import _JIT, _degenerate, _face_cross

#: ``estimators.matgeom.NORMAL_GAP`` (the estimator passes it; the default for the direct calls of the twin tests).
NORMAL_GAP = 1e-8


@nb.njit(inline="always", **_JIT)
def _rotation(app, aqq, apq, sweep):
    """Jacobi rotation zeroing ``apq`` (Numerical Recipes, ``jacobi``).

    Returns ``(t, s, tau, apply)``; ``apply`` is False when ``apq`` is too small
    to change the diagonal (it is then simply set to zero by the caller).
    """
    g = 100.0 * abs(apq)
    if apq == 0.0 or (sweep > 2 and abs(app) + g == abs(app) and abs(aqq) + g == abs(aqq)):
        return 0.0, 0.0, 0.0, False
    h = aqq - app
    if abs(h) + g == abs(h):
        t = apq / h
    else:
        theta = 0.5 * h / apq
        t = 1.0 / (abs(theta) + math.sqrt(1.0 + theta * theta))
        if theta < 0.0:
            t = -t
    c = 1.0 / math.sqrt(t * t + 1.0)
    s = t * c
    return t, s, s / (1.0 + c), True


@nb.njit(**_JIT)
def _jacobi3(a00, a11, a22, a01, a02, a12):
    """Eigen-decomposition of a symmetric 3x3 by cyclic Jacobi rotations, on scalars.

    Returns the three eigenvalues and the nine entries of the eigenvector
    matrix (row-major, column k goes with eigenvalue k).
    """
    v00, v01, v02 = 1.0, 0.0, 0.0
    v10, v11, v12 = 0.0, 1.0, 0.0
    v20, v21, v22 = 0.0, 0.0, 1.0
    for sweep in range(50):
        # converged: the off-diagonal is below what a rotation could still change (NR's test, per element)
        off = abs(a01) + abs(a02) + abs(a12)
        if off == 0.0 or (sweep > 0 and 1e-18 * (abs(a00) + abs(a11) + abs(a22)) >= off):
            break
        # (p, q, r) = (0, 1, 2)
        t, s, tau, apply = _rotation(a00, a11, a01, sweep)
        if apply:
            a00 -= t * a01
            a11 += t * a01
            a02, a12 = a02 - s * (a12 + tau * a02), a12 + s * (a02 - tau * a12)
            v00, v01 = v00 - s * (v01 + tau * v00), v01 + s * (v00 - tau * v01)
            v10, v11 = v10 - s * (v11 + tau * v10), v11 + s * (v10 - tau * v11)
            v20, v21 = v20 - s * (v21 + tau * v20), v21 + s * (v20 - tau * v21)
        a01 = 0.0
        # (p, q, r) = (0, 2, 1)
        t, s, tau, apply = _rotation(a00, a22, a02, sweep)
        if apply:
            a00 -= t * a02
            a22 += t * a02
            a01, a12 = a01 - s * (a12 + tau * a01), a12 + s * (a01 - tau * a12)
            v00, v02 = v00 - s * (v02 + tau * v00), v02 + s * (v00 - tau * v02)
            v10, v12 = v10 - s * (v12 + tau * v10), v12 + s * (v10 - tau * v12)
            v20, v22 = v20 - s * (v22 + tau * v20), v22 + s * (v20 - tau * v22)
        a02 = 0.0
        # (p, q, r) = (1, 2, 0)
        t, s, tau, apply = _rotation(a11, a22, a12, sweep)
        if apply:
            a11 -= t * a12
            a22 += t * a12
            a01, a02 = a01 - s * (a02 + tau * a01), a02 + s * (a01 - tau * a02)
            v01, v02 = v01 - s * (v02 + tau * v01), v02 + s * (v01 - tau * v02)
            v11, v12 = v11 - s * (v12 + tau * v11), v12 + s * (v11 - tau * v12)
            v21, v22 = v21 - s * (v22 + tau * v21), v22 + s * (v21 - tau * v22)
        a12 = 0.0
    return a00, a11, a22, v00, v01, v02, v10, v11, v12, v20, v21, v22


@nb.njit(inline="always", **_JIT)
def _magnitude_order(w0, w1, w2):
    """Positions of three eigenvalues in ascending value (stable), then ascending magnitude (stable)."""
    o0, o1, o2 = 0, 1, 2
    w = (w0, w1, w2)
    if w[o0] > w[o1]:
        o0, o1 = o1, o0
    if w[o1] > w[o2]:
        o1, o2 = o2, o1
        if w[o0] > w[o1]:
            o0, o1 = o1, o0
    if abs(w[o0]) > abs(w[o1]):
        o0, o1 = o1, o0
    if abs(w[o1]) > abs(w[o2]):
        o1, o2 = o2, o1
        if abs(w[o0]) > abs(w[o1]):
            o0, o1 = o1, o0
    return o0, o1, o2


@nb.njit(inline="always", **_JIT)
def _ring_sums6(current, indptr, indices, i):
    """Columns 0 to 5 of row ``i``'s neighbours (in list order) plus those of row ``i`` itself (each
    column's sum in registers), and ``1 / (degree + 1)``: one pass of ``smoothing.smooth_over_neighbours``
    at ``i`` before its scaling, the same sums in the same order (the sparse product from 0, then the
    vertex's own value)."""
    start, stop = indptr[i], indptr[i + 1]
    t0 = t1 = t2 = t3 = t4 = t5 = 0.0
    for j in range(start, stop + 1):  # the neighbours in list order, then the vertex itself
        w = np.int64(indices[j]) if j < stop else np.int64(i)  # prange's i is unsigned: both int64
        t0 += current[w, 0]
        t1 += current[w, 1]
        t2 += current[w, 2]
        t3 += current[w, 3]
        t4 += current[w, 4]
        t5 += current[w, 5]
    return t0, t1, t2, t3, t4, t5, 1.0 / (stop - start + 1.0)


@nb.njit(inline="always", **_JIT)
def _principal_row(i, t0, t1, t2, t3, t4, t5, outputs, gap):
    """Row ``i`` of :func:`matgeom_principal` from the tensor ``(t0, ..., t5)`` (xx, yy, zz, xy, xz, yz).

    As ``estimators.matgeom._principal``: magnitudes within ``gap`` x the largest of each other give the
    smaller value to the normal; eigenvalues within that of the normal's leave it undefined (NaN).
    ``outputs`` is ``(c1, c2, u1, u2, normal)``, written at row ``i``."""
    c1, c2, u1, u2, normal = outputs
    if not (
        math.isfinite(t0)
        and math.isfinite(t1)
        and math.isfinite(t2)
        and math.isfinite(t3)
        and math.isfinite(t4)
        and math.isfinite(t5)
    ):
        c1[i] = c2[i] = np.nan
        for k in range(3):
            u1[i, k] = u2[i, k] = normal[i, k] = np.nan
        return
    w0, w1, w2, v00, v01, v02, v10, v11, v12, v20, v21, v22 = _jacobi3(t0, t1, t2, t3, t4, t5)
    o0, o1, o2 = _magnitude_order(w0, w1, w2)
    w = (w0, w1, w2)
    tolerance = gap * abs(w[o2])
    if abs(w[o1]) - abs(w[o0]) <= tolerance and w[o0] > w[o1]:  # a tie of magnitudes: matGeom's exact-tie order
        o0, o1 = o1, o0
    undefined = abs(w[o1] - w[o0]) <= tolerance  # the normal's eigenspace is a plane (or all of space)
    columns = ((v00, v10, v20), (v01, v11, v21), (v02, v12, v22))
    small, middle, large = columns[o0], columns[o1], columns[o2]
    a, b = w[o1], w[o2]
    if a > b:  # matGeom's swap: c1 <= c2, u1 with c1
        c1[i], c2[i] = b, a
        first, second = middle, large
    else:
        c1[i], c2[i] = a, b
        first, second = large, middle
    for k in range(3):
        u1[i, k] = first[k]
        u2[i, k] = second[k]
        normal[i, k] = np.nan if undefined else small[k]


@nb.njit(parallel=True, **_JIT)
def matgeom_principal(tensors, gap=NORMAL_GAP):
    """matGeom's step 7 per vertex: eigenpairs by magnitude, the two largest as curvatures, swapped so c1 <= c2.

    Returns ``(c1, c2, u1, u2, normal)``: the eigenvalues of middle and largest
    magnitude (ordered), their eigenvectors (the curvature directions) and the
    eigenvector of the smallest magnitude (the normal); NaN rows where a
    component is not finite, a NaN normal where it is undefined (``gap``: see
    ``estimators.matgeom.NORMAL_GAP``). As ``estimators.matgeom._principal``.
    """
    n = tensors.shape[0]
    outputs = (np.empty(n), np.empty(n), np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3)))
    for i in nb.prange(n):
        row = tensors[i]
        _principal_row(i, row[0], row[1], row[2], row[3], row[4], row[5], outputs, gap)
    return outputs


@nb.njit(parallel=True, **_JIT)
def matgeom_finish(tensors, indptr, indices, steps, gap=NORMAL_GAP, fields=None):
    """matGeom's steps 6 and 7 in one kernel: ``steps`` passes of the 1-ring mean over the (V, 6)
    ``tensors`` (overwritten), then :func:`matgeom_principal` of the result; with ``fields`` (V, k), its
    columns smoothed in the same passes, in place (the estimator's traces and round-off floors).

    Each pass is ``smoothing.smooth_over_neighbours``'s, its sums in the same
    order (the neighbours in list order, then the vertex's own value, times
    ``1 / (degree + 1)``), the six of a row in registers; the last pass goes
    straight into the eigen-decomposition, so that only one (V, 6) buffer is
    added to ``tensors``. The columns of ``fields`` get the same sums (one
    (V, k) buffer; the result copied back into ``fields`` after an odd number
    of passes): the lists are read once for both, not in a second kernel
    (issue 31, S32: 0.1 CPU s of matgeom's 1.7 at 1M vertices).
    """
    if fields is None:
        fields = np.empty((tensors.shape[0], 0))
    if steps == 0:
        return matgeom_principal(tensors, gap)
    n = tensors.shape[0]
    n_fields = fields.shape[1]
    outputs = (np.empty(n), np.empty(n), np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3)))
    current = tensors
    following = np.empty((n, 6)) if steps > 1 else tensors
    fields_now = fields
    fields_next = np.empty((n, n_fields))
    for step in range(steps):
        last = step == steps - 1
        for i in nb.prange(n):
            t0, t1, t2, t3, t4, t5, scale = _ring_sums6(current, indptr, indices, i)
            if last:
                _principal_row(i, t0 * scale, t1 * scale, t2 * scale, t3 * scale, t4 * scale, t5 * scale, outputs, gap)
            else:
                following[i, 0], following[i, 1], following[i, 2] = t0 * scale, t1 * scale, t2 * scale
                following[i, 3], following[i, 4], following[i, 5] = t3 * scale, t4 * scale, t5 * scale
            start, stop = indptr[i], indptr[i + 1]
            for c in range(n_fields):
                total = 0.0
                for j in range(start, stop):  # the neighbours in list order, then the vertex itself
                    total += fields_now[np.int64(indices[j]), c]
                fields_next[i, c] = (total + fields_now[i, c]) * scale
        current, following = following, current
        fields_now, fields_next = fields_next, fields_now
    if steps % 2 == 1:
        for i in nb.prange(n):
            for c in range(n_fields):
                fields[i, c] = fields_now[i, c]
    return outputs


@nb.njit(**_JIT)
def matgeom_vertex_tensors(vertices, faces, ev1, ev2, ef1, ef2, n_chunks):
    """Steps 2 to 5 of matGeom's meshCurvatures: the (V, 6) vertex tensors of
    :func:`matgeom_vertex_sums`, without the zero-area faces."""
    return matgeom_vertex_sums(vertices, faces, ev1, ev2, ef1, ef2, n_chunks, np.empty(0), 0.0, False)[0]


@nb.njit(parallel=True, **_JIT)
def matgeom_vertex_sums(vertices, faces, ev1, ev2, ef1, ef2, n_chunks, scales, area_ratio, with_degenerate):
    """Steps 2 to 5 of matGeom's meshCurvatures (see estimators/matgeom.py), and the zero-area faces.

    Returns ``(tensors, degenerate)``: the (V, 6) vertex tensors and, when
    ``with_degenerate``, the (F,) faces that repeat a vertex or whose area is at
    most ``area_ratio`` x ``scales[a]^2`` (``geometry.degenerate_faces``, the
    same test on the same cross product, found in the pass that normalises it;
    else an empty array).

    Same operations in the same order as Octave (sums of three products left
    to right), so that ``arccos`` of nearly parallel normals gets the same input.
    Face ids beyond the face count give NaN (matGeom stops with an index error).
    Face normals and edge lengths are computed in parallel (the lengths summed
    in order); the vertex sums in ``n_chunks`` vertex ranges, each thread adding
    the edges in order onto its own vertices.
    """
    n_vertices = vertices.shape[0]
    n_faces = faces.shape[0]
    n_edges = ev1.shape[0]
    normals = np.empty((n_faces, 3))
    degenerate = np.zeros(n_faces if with_degenerate else 0, np.bool_)
    for f in nb.prange(n_faces):
        a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
        nx, ny, nz = _face_cross(vertices, a, b, c)  # Octave's cross
        norm = math.sqrt((nx * nx + ny * ny) + nz * nz)
        if with_degenerate:
            degenerate[f] = _degenerate(a, b, c, 0.5 * norm, area_ratio * scales[a] * scales[a])
        normals[f, 0] = nx / norm if norm > 0 else np.nan
        normals[f, 1] = ny / norm if norm > 0 else np.nan
        normals[f, 2] = nz / norm if norm > 0 else np.nan
    lengths = np.empty(n_edges)
    for e in nb.prange(n_edges):
        p, q = ev1[e], ev2[e]
        x = vertices[q, 0] - vertices[p, 0]
        y = vertices[q, 1] - vertices[p, 1]
        z = vertices[q, 2] - vertices[p, 2]
        lengths[e] = math.sqrt((x * x + y * y) + z * z)
    total = 0.0
    for e in range(n_edges):
        total += lengths[e]
    mean = total / n_edges
    n_chunks = max(1, min(n_chunks, n_vertices))
    sums = np.zeros((n_vertices, 6))
    counts = np.zeros(n_vertices)
    for chunk in nb.prange(n_chunks):
        first = (n_vertices * chunk) // n_chunks
        last = (n_vertices * (chunk + 1)) // n_chunks
        for e in range(n_edges):
            p, q = ev1[e], ev2[e]
            p_here = first <= p < last
            q_here = first <= q < last
            if not (p_here or q_here):
                continue
            d = lengths[e]
            ex = (vertices[q, 0] - vertices[p, 0]) / d
            ey = (vertices[q, 1] - vertices[p, 1]) / d
            ez = (vertices[q, 2] - vertices[p, 2]) / d
            f1, f2 = ef1[e], ef2[e]
            if f1 >= n_faces or f2 >= n_faces:
                weight = np.nan
            else:
                ax, ay, az = normals[f1, 0], normals[f1, 1], normals[f1, 2]
                bx, by, bz = normals[f2, 0], normals[f2, 1], normals[f2, 2]
                dot = (ax * bx + ay * by) + az * bz
                beta = math.acos(min(max(dot, -1.0), 1.0)) if math.isfinite(dot) else np.nan
                if beta >= math.pi - FOLD_ANGLE:  # a fold: 0 in every pose, as an exact one (side 0) reads
                    beta = 0.0
                side = ((ay * bz - by * az) * ex + (az * bx - bz * ax) * ey) + (ax * by - bx * ay) * ez
                if side > 0:
                    weight = (d / mean) * beta
                elif side < 0:
                    weight = (d / mean) * -beta
                elif side == 0:
                    weight = 0.0 * beta
                else:
                    weight = np.nan
            for v in (p, q):
                if first <= v < last:
                    counts[v] += 1.0
                    sums[v, 0] += (ex * ex) * weight
                    sums[v, 1] += (ey * ey) * weight
                    sums[v, 2] += (ez * ez) * weight
                    sums[v, 3] += (ex * ey) * weight
                    sums[v, 4] += (ex * ez) * weight
                    sums[v, 5] += (ey * ez) * weight
    for i in nb.prange(n_vertices):
        if counts[i] > 0:
            for k in range(6):
                sums[i, k] /= counts[i]
    return sums, degenerate
