"""Compiled kernels (numba) for the hot loops; each mirrors a NumPy path elsewhere.

Importing this module imports numba; :mod:`meshcurv._backend` decides whether
to. Every kernel computes exactly what its NumPy counterpart computes (the tests
compare the two), in one pass over the elements and without (N, 3, 3)
temporaries. Compiled code is cached on disk (``cache=True``).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

_JIT = dict(cache=True, nogil=True, fastmath=False, error_model="numpy")
#: Sums that may be reassociated (vectorized); no other fast-math assumption (NaN and inf stay meaningful).
_JIT_REASSOC = {**_JIT, "fastmath": {"reassoc", "contract"}}


# -- shared pieces ----------------------------------------------------------------
@nb.njit(inline="always", **_JIT)
def _edge_length(vertices, p, q):
    x = vertices[q, 0] - vertices[p, 0]
    y = vertices[q, 1] - vertices[p, 1]
    z = vertices[q, 2] - vertices[p, 2]
    return math.sqrt(x * x + y * y + z * z)


@nb.njit(inline="always", **_JIT)
def _face_cross(vertices, a, b, c):
    """cross(b - a, c - a): the face normal times twice its area."""
    ux = vertices[b, 0] - vertices[a, 0]
    uy = vertices[b, 1] - vertices[a, 1]
    uz = vertices[b, 2] - vertices[a, 2]
    wx = vertices[c, 0] - vertices[a, 0]
    wy = vertices[c, 1] - vertices[a, 1]
    wz = vertices[c, 2] - vertices[a, 2]
    return uy * wz - uz * wy, uz * wx - ux * wz, ux * wy - uy * wx


@nb.njit(inline="always", **_JIT)
def _degenerate(a, b, c, half_area, threshold):
    """A face that repeats a vertex or whose area is at most ``threshold`` (``diagnosis.degenerate_faces``)."""
    return a == b or b == c or c == a or half_area <= threshold


@nb.njit(parallel=True, **_JIT)
def _mean_edge_length(vertices, edges):
    """Mean length of the edges (0 when there are none), a parallel reduction."""
    total = 0.0
    for e in nb.prange(edges.shape[0]):
        total += _edge_length(vertices, edges[e, 0], edges[e, 1])
    return total / edges.shape[0] if edges.shape[0] else 0.0


@nb.njit(parallel=True, **_JIT)
def face_cross_products(vertices, faces):
    """``geometry.face_cross_products``: (F, 3) ``cross(b - a, c - a)`` of every face."""
    out = np.empty((faces.shape[0], 3))
    for f in nb.prange(faces.shape[0]):
        out[f, 0], out[f, 1], out[f, 2] = _face_cross(vertices, faces[f, 0], faces[f, 1], faces[f, 2])
    return out


@nb.njit(**_JIT)
def vertex_normal_sums(cross, faces, n_vertices):
    """(V, 3) sums of the face cross products over the faces of each vertex, in face order (as ``np.bincount``)."""
    out = np.zeros((n_vertices, 3))
    for f in range(faces.shape[0]):
        for k in range(3):
            v = faces[f, k]
            for a in range(3):
                out[v, a] += cross[f, a]
    return out


@nb.njit(parallel=True, **_JIT)
def normalize_normal_sums(summed):
    """``geometry.normalize_normal_sums``: unit rows of ``summed``, NaN where they (nearly) cancel."""
    out = np.empty_like(summed)
    tiny = np.finfo(np.float64).tiny
    for v in nb.prange(summed.shape[0]):
        x, y, z = summed[v, 0], summed[v, 1], summed[v, 2]
        norm = math.sqrt(x * x + y * y + z * z)
        scale = max(abs(x), abs(y), abs(z))
        if norm > 1e-12 * max(scale, tiny):
            out[v, 0], out[v, 1], out[v, 2] = x / norm, y / norm, z / norm
        else:
            out[v, 0] = out[v, 1] = out[v, 2] = np.nan
    return out


@nb.njit(**_JIT)
def vertex_edge_lengths(vertices, edges, n_vertices):
    """``geometry.vertex_edge_lengths``: (V,) mean length of the edges at each vertex (NaN where none)."""
    total = np.zeros(n_vertices)
    count = np.zeros(n_vertices)
    for e in range(edges.shape[0]):
        length = _edge_length(vertices, edges[e, 0], edges[e, 1])
        for k in range(2):
            total[edges[e, k]] += length
            count[edges[e, k]] += 1.0
    out = np.empty(n_vertices)
    for v in range(n_vertices):
        out[v] = total[v] / count[v] if count[v] > 0 else np.nan
    return out


def mean_edge_length(vertices, edges):
    """``geometry.mean_edge_length``."""
    return _mean_edge_length(vertices, edges)


@nb.njit(parallel=True, **_JIT)
def edge_lengths(vertices, edges):
    """``geometry.edge_lengths``: (E,) length of each edge."""
    out = np.empty(edges.shape[0])
    for e in nb.prange(edges.shape[0]):
        out[e] = _edge_length(vertices, edges[e, 0], edges[e, 1])
    return out


# -- topology -------------------------------------------------------------------
def threads() -> int:
    """The threads numba's parallel kernels use (``NUMBA_NUM_THREADS``, ``numba.set_num_threads``)."""
    return nb.get_num_threads()


@nb.njit(parallel=True, **_JIT)
def build_edges(faces, n_vertices, n_chunks):
    """Edges of the triangles, their faces and counts (see MeshTopology._build).

    Sides are bucketed by their smaller vertex (counting sort), each bucket is
    sorted by (larger vertex, direction) with a stable insertion sort, so the
    edges come out in lexicographic order, as ``np.unique`` would give them.
    Each thread buckets the sides of its own range of vertices (scanning all
    faces), then sorts and numbers the buckets of its vertices; the edge numbers
    come from a prefix sum of the edges per vertex. ``n_chunks``: the number of
    vertex ranges (one per thread, :func:`threads`).
    """
    n_faces = faces.shape[0]
    n_chunks = max(1, min(n_chunks, n_vertices))
    bounds = np.empty(n_chunks + 1, np.int64)
    for c in range(n_chunks + 1):
        bounds[c] = (n_vertices * c) // n_chunks
    bucket_start = np.zeros(n_vertices + 1, np.int64)
    for c in nb.prange(n_chunks):
        first, last = bounds[c], bounds[c + 1]
        for f in range(n_faces):
            for k in range(3):
                a = faces[f, k]
                b = faces[f, (k + 1) % 3]
                low = min(a, b)
                if a != b and first <= low < last:
                    bucket_start[low + 1] += 1
    for i in range(n_vertices):
        bucket_start[i + 1] += bucket_start[i]
    n_sides = bucket_start[n_vertices]
    sort_key = np.empty(n_sides, np.int64)  # 2 * larger vertex + backward
    side_of = np.empty(n_sides, np.int64)
    fill = bucket_start[:-1].copy()
    for c in nb.prange(n_chunks):
        first, last = bounds[c], bounds[c + 1]
        for f in range(n_faces):
            for k in range(3):
                a = faces[f, k]
                b = faces[f, (k + 1) % 3]
                low = min(a, b)
                if a != b and first <= low < last:
                    slot = fill[low]
                    fill[low] += 1
                    sort_key[slot] = 2 * max(a, b) + (1 if a > b else 0)
                    side_of[slot] = 3 * f + k
    edges_before = np.zeros(n_vertices + 1, np.int64)
    for v in nb.prange(n_vertices):  # stable insertion sort of each (small) bucket; count its edges
        start, stop = bucket_start[v], bucket_start[v + 1]
        for i in range(start + 1, stop):
            key = sort_key[i]
            side = side_of[i]
            j = i - 1
            while j >= start and sort_key[j] > key:
                sort_key[j + 1] = sort_key[j]
                side_of[j + 1] = side_of[j]
                j -= 1
            sort_key[j + 1] = key
            side_of[j + 1] = side
        distinct = 0
        for i in range(start, stop):
            if i == start or (sort_key[i] >> 1) != (sort_key[i - 1] >> 1):
                distinct += 1
        edges_before[v + 1] = distinct
    for v in range(n_vertices):
        edges_before[v + 1] += edges_before[v]
    n_edges = edges_before[n_vertices]
    edges = np.empty((n_edges, 2), np.int64)
    edge_faces = np.full((n_edges, 2), -1, np.int64)
    counts = np.zeros(n_edges, np.int64)
    forward = np.zeros(n_edges, np.int64)
    face_edges = np.full(3 * n_faces, -1, np.int64)
    for v in nb.prange(n_vertices):
        e = edges_before[v] - 1
        previous_high = -1
        for i in range(bucket_start[v], bucket_start[v + 1]):
            high = sort_key[i] >> 1
            backward = sort_key[i] & 1
            side = side_of[i]
            face = side // 3
            if high != previous_high:
                e += 1
                previous_high = high
                edges[e, 0] = v
                edges[e, 1] = high
                if backward:
                    edge_faces[e, 1] = face
                else:
                    edge_faces[e, 0] = face
            elif counts[e] == 1:
                if edge_faces[e, 1] == -1:
                    edge_faces[e, 1] = face
                else:
                    edge_faces[e, 0] = face
            counts[e] += 1
            if not backward:
                forward[e] += 1
            face_edges[side] = e
    return edges, face_edges.reshape(n_faces, 3), edge_faces, counts, forward


# -- normal cycle ---------------------------------------------------------------
@nb.njit(parallel=True, **_JIT)
def normal_cycle_sums(vertices, faces, edges, edge_faces, counts, forward, scales, area_ratio, n_chunks):
    """Per-vertex measures, barycentric areas and normal sums; the zero-area faces.

    A face is degenerate when it repeats a vertex or its area is at most
    ``area_ratio`` x ``scales[a]^2`` (``diagnosis.degenerate_faces``); an
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
    sums = np.zeros((n_vertices, 10))
    for chunk in nb.prange(n_chunks):
        first = (n_vertices * chunk) // n_chunks
        last = (n_vertices * (chunk + 1)) // n_chunks
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
            weight = 0.5 * math.atan2(sine, cosine) * length
            for v in (p, q):
                if first <= v < last:
                    sums[v, 0] += weight * ex * ex
                    sums[v, 1] += weight * ey * ey
                    sums[v, 2] += weight * ez * ez
                    sums[v, 3] += weight * ex * ey
                    sums[v, 4] += weight * ex * ez
                    sums[v, 5] += weight * ey * ez
    return sums, degenerate


@nb.njit(parallel=True, **_JIT)
def normal_cycle_finish(sums, invalid, indptr, indices, steps):
    """From :func:`normal_cycle_sums` to the curvatures, in one kernel.

    The measures and areas of valid vertices (invalid ones count as zero) are
    smoothed ``steps`` times over 1-rings (``smoothing.smooth_vertex_field``),
    divided, restricted to the tangent plane of the unit normal and solved in
    closed form (``tangent_principal`` with ``rotate`` and ``mean_from_trace``).
    Returns ``(k_min, k_max, dir_min, dir_max, normals, valid)``, NaN where not valid.
    """
    n = sums.shape[0]
    current = np.empty((n, 7))
    for i in nb.prange(n):
        weight = 0.0 if invalid[i] else 1.0
        for c in range(7):
            current[i, c] = sums[i, c] * weight
    if steps > 0:
        following = np.empty((n, 7))
        for _ in range(steps):
            for i in nb.prange(n):
                start, stop = indptr[i], indptr[i + 1]
                scale = 1.0 / (stop - start + 1.0)
                t0, t1, t2, t3 = current[i, 0], current[i, 1], current[i, 2], current[i, 3]
                t4, t5, t6 = current[i, 4], current[i, 5], current[i, 6]
                for j in range(start, stop):  # one pass over the neighbours, seven sums in registers
                    w = indices[j]
                    t0 += current[w, 0]
                    t1 += current[w, 1]
                    t2 += current[w, 2]
                    t3 += current[w, 3]
                    t4 += current[w, 4]
                    t5 += current[w, 5]
                    t6 += current[w, 6]
                following[i, 0], following[i, 1], following[i, 2] = t0 * scale, t1 * scale, t2 * scale
                following[i, 3], following[i, 4], following[i, 5] = t3 * scale, t4 * scale, t5 * scale
                following[i, 6] = t6 * scale
            current, following = following, current
    k_min = np.full(n, np.nan)
    k_max = np.full(n, np.nan)
    dir_min = np.full((n, 3), np.nan)
    dir_max = np.full((n, 3), np.nan)
    normals = np.full((n, 3), np.nan)
    valid = np.zeros(n, np.bool_)
    tiny = np.finfo(np.float64).tiny
    for i in nb.prange(n):
        sx, sy, sz = sums[i, 7], sums[i, 8], sums[i, 9]
        norm = math.sqrt(sx * sx + sy * sy + sz * sz)
        if not norm > 1e-12 * max(max(abs(sx), abs(sy), abs(sz)), tiny):  # geometry.normalize_normal_sums
            continue
        nx, ny, nz = sx / norm, sy / norm, sz / norm
        normals[i, 0], normals[i, 1], normals[i, 2] = nx, ny, nz
        area = current[i, 6]
        if invalid[i] or not area > 0:
            continue
        valid[i] = True
        lo, hi, d0, d1, d2, d3, d4, d5 = _tangent_eigen(
            current[i, 0] / area, current[i, 1] / area, current[i, 2] / area, current[i, 3] / area,
            current[i, 4] / area, current[i, 5] / area, nx, ny, nz, True, True)
        k_min[i], k_max[i] = lo, hi
        dir_min[i, 0], dir_min[i, 1], dir_min[i, 2] = d0, d1, d2
        dir_max[i, 0], dir_max[i, 1], dir_max[i, 2] = d3, d4, d5
    return k_min, k_max, dir_min, dir_max, normals, valid


@nb.njit(**_JIT)
def _tangent_frame(nx, ny, nz):
    ax, ay, az = abs(nx), abs(ny), abs(nz)
    # cross(n, axis) with the axis least aligned with n (first minimum, as np.argmin)
    if ax <= ay and ax <= az:
        tx, ty, tz = 0.0, nz, -ny
    elif ay <= az:
        tx, ty, tz = -nz, 0.0, nx
    else:
        tx, ty, tz = ny, -nx, 0.0
    norm = math.sqrt(tx * tx + ty * ty + tz * tz)
    tx /= norm
    ty /= norm
    tz /= norm
    return tx, ty, tz, ny * tz - nz * ty, nz * tx - nx * tz, nx * ty - ny * tx


@nb.njit(inline="always", **_JIT)
def _tangent_eigen(xx, yy, zz, xy, xz, yz, nx, ny, nz, rotate, mean_from_trace):
    """k_min, k_max, dir_min (3), dir_max (3) of one tensor restricted to the plane normal to n."""
    t1x, t1y, t1z, t2x, t2y, t2z = _tangent_frame(nx, ny, nz)
    s1x = xx * t1x + xy * t1y + xz * t1z
    s1y = xy * t1x + yy * t1y + yz * t1z
    s1z = xz * t1x + yz * t1y + zz * t1z
    a = t1x * s1x + t1y * s1y + t1z * s1z
    b = t2x * s1x + t2y * s1y + t2z * s1z
    c = (t2x * (xx * t2x + xy * t2y + xz * t2z) + t2y * (xy * t2x + yy * t2y + yz * t2z)
         + t2z * (xz * t2x + yz * t2y + zz * t2z))
    half_sum = 0.5 * (a + c)
    if mean_from_trace:
        half_sum = 0.5 * (xx + yy + zz)
    half_diff = 0.5 * (a - c)
    radius = math.hypot(half_diff, b)
    theta = 0.5 * math.atan2(b, half_diff)
    co, si = math.cos(theta), math.sin(theta)
    alx, aly, alz = co * t1x + si * t2x, co * t1y + si * t2y, co * t1z + si * t2z
    acx, acy, acz = -si * t1x + co * t2x, -si * t1y + co * t2y, -si * t1z + co * t2z
    if rotate:
        alx, aly, alz, acx, acy, acz = acx, acy, acz, alx, aly, alz
    return half_sum - radius, half_sum + radius, acx, acy, acz, alx, aly, alz


@nb.njit(parallel=True, **_JIT)
def principal_from_shape_operator(tensor, normals, rotate, mean_from_trace):
    """``_tensors.principal_from_shape_operator``: (N,) k_min, k_max and (N, 3) dir_min, dir_max."""
    n = tensor.shape[0]
    k_min = np.empty(n)
    k_max = np.empty(n)
    dir_min = np.empty((n, 3))
    dir_max = np.empty((n, 3))
    for i in nb.prange(n):
        lo, hi, d0, d1, d2, d3, d4, d5 = _tangent_eigen(
            tensor[i, 0], tensor[i, 1], tensor[i, 2], tensor[i, 3], tensor[i, 4], tensor[i, 5],
            normals[i, 0], normals[i, 1], normals[i, 2], rotate, mean_from_trace)
        k_min[i], k_max[i] = lo, hi
        dir_min[i, 0], dir_min[i, 1], dir_min[i, 2] = d0, d1, d2
        dir_max[i, 0], dir_max[i, 1], dir_max[i, 2] = d3, d4, d5
    return k_min, k_max, dir_min, dir_max


# -- symmetric 3x3 eigen-decomposition -----------------------------------------
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


@nb.njit(parallel=True, **_JIT)
def matgeom_principal(tensors):
    """matGeom's step 7 per vertex: eigenpairs by magnitude, the two largest as curvatures, swapped so c1 <= c2.

    Returns ``(c1, c2, u1, u2, normal)``: the eigenvalues of middle and largest
    magnitude (ordered), their eigenvectors (the curvature directions) and the
    eigenvector of the smallest magnitude (the normal); NaN rows where a
    component is not finite. As ``estimators._eigen.sorted_by_magnitude`` and the
    swap of ``estimators.matgeom.estimate``.
    """
    n = tensors.shape[0]
    c1 = np.empty(n)
    c2 = np.empty(n)
    u1 = np.empty((n, 3))
    u2 = np.empty((n, 3))
    normal = np.empty((n, 3))
    for i in nb.prange(n):
        finite = True
        for k in range(6):
            if not math.isfinite(tensors[i, k]):
                finite = False
        if not finite:
            c1[i] = c2[i] = np.nan
            for k in range(3):
                u1[i, k] = u2[i, k] = normal[i, k] = np.nan
            continue
        w0, w1, w2, v00, v01, v02, v10, v11, v12, v20, v21, v22 = _jacobi3(
            tensors[i, 0], tensors[i, 1], tensors[i, 2], tensors[i, 3], tensors[i, 4], tensors[i, 5]
        )
        o0, o1, o2 = _magnitude_order(w0, w1, w2)
        w = (w0, w1, w2)
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
            normal[i, k] = small[k]
    return c1, c2, u1, u2, normal


# -- matGeom's edge tensors -----------------------------------------------------
@nb.njit(parallel=True, **_JIT)
def matgeom_vertex_tensors(vertices, faces, ev1, ev2, ef1, ef2, n_chunks):
    """Steps 2 to 5 of matGeom's meshCurvatures (see estimators/matgeom.py).

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
    for f in nb.prange(n_faces):
        nx, ny, nz = _face_cross(vertices, faces[f, 0], faces[f, 1], faces[f, 2])  # Octave's cross
        norm = math.sqrt((nx * nx + ny * ny) + nz * nz)
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
    return sums


# -- bow-tie vertices -----------------------------------------------------------
@nb.njit(inline="always", **_JIT)
def _find(parent, x):
    while parent[x] != x:
        parent[x] = parent[parent[x]]
        x = parent[x]
    return x


@nb.njit(inline="always", **_JIT)
def _corner_at(faces, f, v):
    """The corner (3 f + k) of face ``f`` at vertex ``v``."""
    if faces[f, 0] == v:
        return 3 * f
    if faces[f, 1] == v:
        return 3 * f + 1
    return 3 * f + 2


@nb.njit(parallel=True, **_JIT)
def bowtie_vertices(faces, edges, edge_faces, linked, proper, n_vertices, n_chunks):
    """Vertices whose face corners fall in more than one fan (see MeshTopology.bowtie_vertices).

    Union-find over the ``3 F`` corners: at each end of a linked edge (two
    faces, both without a repeated vertex) the corners of its two faces are
    joined. Corners are only ever joined to corners at the same vertex, so each
    of ``n_chunks`` threads does the joins and the finds at its own range of
    vertices.
    """
    n_corners = 3 * faces.shape[0]
    parent = np.empty(n_corners, np.int64)
    for c in nb.prange(n_corners):
        parent[c] = c
    n_chunks = max(1, min(n_chunks, n_vertices))
    root_of = np.full(n_vertices, -1, np.int64)
    several = np.zeros(n_vertices, np.bool_)
    for chunk in nb.prange(n_chunks):
        first = (n_vertices * chunk) // n_chunks
        last = (n_vertices * (chunk + 1)) // n_chunks
        for e in range(edges.shape[0]):
            if not linked[e]:
                continue
            f1, f2 = edge_faces[e, 0], edge_faces[e, 1]
            if not (proper[f1] and proper[f2]):
                continue
            for v in (edges[e, 0], edges[e, 1]):
                if first <= v < last:
                    ra = _find(parent, _corner_at(faces, f1, v))
                    rb = _find(parent, _corner_at(faces, f2, v))
                    if ra != rb:
                        parent[max(ra, rb)] = min(ra, rb)
        for f in range(faces.shape[0]):
            if not proper[f]:
                continue
            for k in range(3):
                v = faces[f, k]
                if first <= v < last:
                    r = _find(parent, 3 * f + k)
                    if root_of[v] < 0:
                        root_of[v] = r
                    elif root_of[v] != r:
                        several[v] = True
    return several


# -- mesh facts -------------------------------------------------------------------
@nb.njit(**_JIT)
def count_components(edges, referenced, n_vertices):
    """Connected components of the vertex graph among the referenced vertices (union-find)."""
    parent = np.arange(n_vertices)
    for e in range(edges.shape[0]):
        a = _find(parent, edges[e, 0])
        b = _find(parent, edges[e, 1])
        if a != b:
            parent[max(a, b)] = min(a, b)
    count = 0
    for v in range(n_vertices):
        if referenced[v] and _find(parent, v) == v:
            count += 1
    return count


@nb.njit(**_JIT)
def component_labels(edges, referenced, n_vertices):
    """(V,) component of each vertex of the edge graph (0, 1, ... by first vertex; -1: unreferenced) and the count."""
    parent = np.arange(n_vertices)
    for e in range(edges.shape[0]):
        a = _find(parent, edges[e, 0])
        b = _find(parent, edges[e, 1])
        if a != b:
            parent[max(a, b)] = min(a, b)
    labels = np.full(n_vertices, -1, np.int64)
    count = 0
    for v in range(n_vertices):
        if not referenced[v]:
            continue
        root = _find(parent, v)
        if labels[root] < 0:
            labels[root] = count
            count += 1
        labels[v] = labels[root]
    return labels, count


@nb.njit(parallel=True, **_JIT)
def degenerate_faces(vertices, faces, scales, area_ratio):
    """(F,) bool: faces that repeat a vertex or whose area is at most ``area_ratio`` x ``scales[a]^2``.

    ``scales`` (V,) is the length scale at each vertex (``geometry.vertex_length_scales``),
    read at the first corner ``a`` (the corners of a face share their component).
    """
    out = np.empty(faces.shape[0], np.bool_)
    for f in nb.prange(faces.shape[0]):
        a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
        nx, ny, nz = _face_cross(vertices, a, b, c)
        threshold = area_ratio * scales[a] * scales[a]
        out[f] = _degenerate(a, b, c, 0.5 * math.sqrt(nx * nx + ny * ny + nz * nz), threshold)
    return out


@nb.njit(parallel=True, **_JIT)
def mesh_facts(vertices, faces, edges, referenced, scales, area_ratio, zero_length_ratio):
    """The measured facts of :func:`meshcurv.diagnose`, in one pass over vertices, faces and edges.

    Returns ``(lower, upper, area, six_volume, mean_length, n_degenerate, n_zero_length)``:
    the bounding box of the referenced vertices, the total area, the sum over
    faces of ``(a - centre) . cross(b - a, c - a)`` (``centre`` the mean of the
    referenced vertices), the mean edge length, the faces that repeat a vertex or
    whose area is at most ``area_ratio`` x ``scales[a]^2``, the edges no longer
    than ``zero_length_ratio`` x ``scales`` at their first end (``scales``: the
    length scale of each vertex, ``geometry.vertex_length_scales``). The passes over edges and faces
    are parallel reductions (sums in another order than a loop: equal to ~1e-16).
    """
    lower = np.full(3, np.inf)
    upper = np.full(3, -np.inf)
    centre = np.zeros(3)
    used = 0
    for v in range(vertices.shape[0]):
        if not referenced[v]:
            continue
        used += 1
        for k in range(3):
            x = vertices[v, k]
            centre[k] += x
            lower[k] = min(lower[k], x)
            upper[k] = max(upper[k], x)
    if used:
        centre /= used
    n_edges = edges.shape[0]
    lengths = np.empty(n_edges)
    total = 0.0
    for e in nb.prange(n_edges):
        lengths[e] = _edge_length(vertices, edges[e, 0], edges[e, 1])
        total += lengths[e]
    mean = total / n_edges if n_edges else 0.0
    n_zero_length = 0
    for e in nb.prange(n_edges):
        n_zero_length += 1 if lengths[e] <= zero_length_ratio * scales[edges[e, 0]] else 0
    area = 0.0
    six_volume = 0.0
    n_degenerate = 0
    for f in nb.prange(faces.shape[0]):
        a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
        nx, ny, nz = _face_cross(vertices, a, b, c)
        half = 0.5 * math.sqrt(nx * nx + ny * ny + nz * nz)
        area += half
        n_degenerate += 1 if _degenerate(a, b, c, half, area_ratio * scales[a] * scales[a]) else 0
        six_volume += ((vertices[a, 0] - centre[0]) * nx + (vertices[a, 1] - centre[1]) * ny
                       + (vertices[a, 2] - centre[2]) * nz)
    return lower, upper, area, six_volume, mean, n_degenerate, n_zero_length


# -- smoothing ------------------------------------------------------------------
@nb.njit(parallel=True, **_JIT)
def neighbour_lists(edges, n_vertices, n_chunks):
    """CSR lists of the edge neighbours of every vertex: ``(indptr, indices)``.

    Each of ``n_chunks`` threads fills the lists of its own range of vertices,
    scanning the edges in order: the lists are the same for any number of threads.
    """
    n_chunks = max(1, min(n_chunks, n_vertices))
    indptr = np.zeros(n_vertices + 1, np.int64)
    for chunk in nb.prange(n_chunks):
        first = (n_vertices * chunk) // n_chunks
        last = (n_vertices * (chunk + 1)) // n_chunks
        for e in range(edges.shape[0]):
            for v in (edges[e, 0], edges[e, 1]):
                if first <= v < last:
                    indptr[v + 1] += 1
    for v in range(n_vertices):
        indptr[v + 1] += indptr[v]
    indices = np.empty(indptr[n_vertices], np.int64)
    fill = indptr[:-1].copy()
    for chunk in nb.prange(n_chunks):
        first = (n_vertices * chunk) // n_chunks
        last = (n_vertices * (chunk + 1)) // n_chunks
        for e in range(edges.shape[0]):
            p, q = edges[e, 0], edges[e, 1]
            if first <= p < last:
                indices[fill[p]] = q
                fill[p] += 1
            if first <= q < last:
                indices[fill[q]] = p
                fill[q] += 1
    return indptr, indices


@nb.njit(parallel=True, **_JIT)
def smooth_over_neighbours(values, indptr, indices, steps):
    """``steps`` passes of the 1-ring mean (self + neighbours) / (degree + 1), by gathering."""
    n_vertices, n_columns = values.shape
    current = values.copy()
    following = np.empty_like(current)
    for _ in range(steps):
        for i in nb.prange(n_vertices):
            start, stop = indptr[i], indptr[i + 1]
            scale = 1.0 / (stop - start + 1.0)
            for c in range(n_columns):
                following[i, c] = current[i, c]
            for j in range(start, stop):  # neighbours outside, columns inside: each row read once
                w = indices[j]
                for c in range(n_columns):
                    following[i, c] += current[w, c]
            for c in range(n_columns):
                following[i, c] *= scale
        current, following = following, current
    return current


# -- balls and jets -----------------------------------------------------------------
#: A ball grid has at most this many columns of cells per point (and at least 4096 in all).
_GRID_COLUMNS_PER_POINT = 4


@nb.njit(**_JIT)
def _grid(points, reach):
    """Points sorted into a grid of cubic cells: ``(order, starts, levels, lo, cell, nx, ny)``.

    The cells have a side ``cell`` of at least ``reach`` (a ball of that radius
    spans at most three cells per axis) from the origin ``lo``. ``order`` lists
    the points column by column (``x`` cell, then ``y`` cell), and within a
    column by ``z`` cell: a stable counting sort, so ties keep their index
    order. The points of column ``ix * ny + iy`` are ranks
    ``starts[c]:starts[c + 1]`` of ``order``, their ``z`` cells ``levels[rank]``.
    The cell is widened when the columns would outnumber
    ``_GRID_COLUMNS_PER_POINT`` per point (a sparse or very flat cloud).
    """
    n = points.shape[0]
    lo = np.zeros(3)
    hi = np.zeros(3)
    for a in range(3):
        if n:
            lo[a] = points[:, a].min()
            hi[a] = points[:, a].max()
    extent = max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2])
    cell = max(reach, extent / 2.0**60)  # z cells fit in an int64
    if not cell > 0:  # every point in one place and a zero reach: any side
        cell = 1.0
    limit = max(_GRID_COLUMNS_PER_POINT * n, 4096)
    while ((hi[0] - lo[0]) / cell + 1) * ((hi[1] - lo[1]) / cell + 1) > limit:
        cell *= 2.0
    nx = np.int64((hi[0] - lo[0]) / cell) + 1
    ny = np.int64((hi[1] - lo[1]) / cell) + 1
    column = np.empty(n, np.int64)
    starts = np.zeros(nx * ny + 1, np.int64)
    for i in range(n):
        c = np.int64((points[i, 0] - lo[0]) / cell) * ny + np.int64((points[i, 1] - lo[1]) / cell)
        column[i] = c
        starts[c + 1] += 1
    for c in range(nx * ny):
        starts[c + 1] += starts[c]
    order = np.empty(n, np.int64)
    filled = starts[:-1].copy()
    for i in range(n):
        order[filled[column[i]]] = i
        filled[column[i]] += 1
    levels = np.empty(n, np.int64)
    for i in range(n):
        levels[i] = np.int64((points[order[i], 2] - lo[2]) / cell)
    for c in range(nx * ny):  # within a column, by z cell (stable)
        first, last = starts[c], starts[c + 1]
        if last - first > 32:
            by_level = np.argsort(levels[first:last], kind="mergesort")
            order[first:last] = order[first:last][by_level]
            levels[first:last] = levels[first:last][by_level]
            continue
        for i in range(first + 1, last):  # insertion sort of a short column
            level, point = levels[i], order[i]
            j = i
            while j > first and levels[j - 1] > level:
                levels[j] = levels[j - 1]
                order[j] = order[j - 1]
                j -= 1
            levels[j] = level
            order[j] = point
    return order, starts, levels, lo, cell, nx, ny


@nb.njit(**_JIT)
def _ball_members(points, grid, cx, cy, cz, cutoff, out):
    """Ranks of the points within ``cutoff`` of ``(cx, cy, cz)`` written to ``out`` (grown when full).

    ``points`` are in the order of ``grid`` (:func:`_grid`), so that the
    cells of a column around the centre (``ceil(cutoff / cell)`` each way) are
    one contiguous run of memory. Returns ``(out, count)``.
    """
    _, starts, levels, lo, cell, nx, ny = grid
    fx = (cx - lo[0]) / cell
    fy = (cy - lo[1]) / cell
    fz = (cz - lo[2]) / cell
    cutoff2 = cutoff * cutoff
    count = 0
    span = np.int64(math.ceil(cutoff / cell))  # cells each way from the centre's
    if not (fx > -1 - span and fy > -1 - span and fz > -1 - span and fx < nx + span and fy < ny + span
            and fz < 2.0**61):
        return out, count
    bx = np.int64(math.floor(fx))
    by = np.int64(math.floor(fy))
    bz = np.int64(math.floor(fz))
    for ix in range(max(bx - span, 0), min(bx + span + 1, nx)):
        for iy in range(max(by - span, 0), min(by + span + 1, ny)):
            c = ix * ny + iy
            k = starts[c]
            last = starts[c + 1]
            high = last
            while k < high:  # first rank of the column at z cell bz - span or above
                middle = (k + high) // 2
                if levels[middle] < bz - span:
                    k = middle + 1
                else:
                    high = middle
            end = k
            while end < last and levels[end] <= bz + span:
                end += 1
            if count + end - k > out.shape[0]:
                grown = np.empty(2 * (count + end - k), np.int64)
                grown[:count] = out[:count]
                out = grown
            for j in range(k, end):  # branch-free: every candidate is written, the inside ones kept
                dx = points[j, 0] - cx
                dy = points[j, 1] - cy
                dz = points[j, 2] - cz
                out[count] = j
                count += dx * dx + dy * dy + dz * dz <= cutoff2
    return out, count


@nb.njit(**_JIT)
def _cholesky_solve(a, b, low, m, min_pivot):
    """Solve ``a[:m, :m] x = b[:m]`` in place of ``b``; False if a pivot <= min_pivot.

    ``a`` is symmetric with a unit diagonal; only its lower triangle is read.
    The same operations in the same order as ``quadric._cholesky_solve``; ``low`` is scratch
    (the factor below its diagonal, the inverse of each pivot's root on it: m
    divisions instead of m (m + 3) / 2, the slowest operations of a fit).
    """
    for k in range(m):
        d = a[k, k]
        for j in range(k):
            d -= low[k, j] * low[k, j]
        if not d > min_pivot:
            return False
        inverse = 1.0 / math.sqrt(d)
        low[k, k] = inverse
        for i in range(k + 1, m):
            s = a[i, k]
            for j in range(k):
                s -= low[i, j] * low[k, j]
            low[i, k] = s * inverse
    for i in range(m):
        s = b[i]
        for j in range(i):
            s -= low[i, j] * b[j]
        b[i] = s * low[i, i]
    for i in range(m - 1, -1, -1):
        s = b[i]
        for j in range(i + 1, m):
            s -= low[j, i] * b[j]
        b[i] = s * low[i, i]
    return True


@nb.njit(parallel=True, **_JIT)
def fit_jets(vertices, normals, radius, degree, iterations, exponents, min_pivot, centres, n_chunks, pool, facing,
             check_facing, away_fraction):
    """``quadric.fit_jets``: weighted jets over the balls of ``radius``, frame re-estimated from each fit.

    Fits the jets of the vertices ``centres`` (the other rows of the outputs
    stay NaN). Only the vertices ``pool`` (int64 ids) enter the balls. With
    ``check_facing``, a fit whose ball holds more than ``away_fraction`` of its
    points (of non-zero weight) with a ``facing`` normal opposite to the centre's
    (``n_j . n_v < 0``; NaN normals are not counted) is not a height function over
    the tangent plane and is left NaN. Returns ``(coefficients (V, 6), t1, t2,
    n, counts, away)``, ``away`` the share of points facing away (NaN
    unless checked); the neighbours of each vertex are found on a grid of cells
    (:func:`_grid`).
    """
    n = vertices.shape[0]
    n_pool = pool.shape[0]
    pooled = np.empty((n_pool, 3))
    for k in range(n_pool):
        pooled[k] = vertices[pool[k]]
    grid = _grid(pooled, radius)
    order = grid[0]
    points = np.empty((n_pool, 3))
    ids = np.empty(n_pool, np.int64)
    for k in range(n_pool):
        points[k] = pooled[order[k]]
        ids[k] = pool[order[k]]
    # centres in grid order: consecutive balls share cells (cache); centres outside the pool last
    chosen = np.zeros(n, np.bool_)
    chosen[centres] = True
    sorted_centres = np.empty(centres.shape[0], np.int64)
    m = 0
    for k in range(n_pool):
        if chosen[ids[k]]:
            sorted_centres[m] = ids[k]
            chosen[ids[k]] = False
            m += 1
    for k in range(centres.shape[0]):
        if chosen[centres[k]]:
            sorted_centres[m] = centres[k]
            chosen[centres[k]] = False
            m += 1
    centres = sorted_centres[:m]
    coefficients, t1s, t2s, ns, counts, away = _jet_outputs(n)
    n_terms = exponents.shape[0]
    n_chunks = max(min(m, n_chunks), 1)
    for chunk in nb.prange(n_chunks):
        members = np.empty(64, np.int64)
        work, moments, right, matrix, low, scale, solution = _jet_scratch(degree, n_terms)
        for i in range(chunk * m // n_chunks, (chunk + 1) * m // n_chunks):
            v = centres[i]
            members, size = _ball_members(points, grid, vertices[v, 0], vertices[v, 1], vertices[v, 2], radius,
                                          members)
            work = _fit_one(vertices, points, normals, radius, degree, iterations, exponents, min_pivot, v, v,
                            members, size, work, moments, right, matrix, low, scale, solution, coefficients, t1s,
                            t2s, ns, counts, ids, facing, check_facing, away_fraction, away)
    return coefficients, t1s, t2s, ns, counts, away


#: Rows of a jet fit's scratch before the powers of u and v: the offsets x, y, z, the weight, weight * height.
_JET_ROWS = 5


@nb.njit(**_JIT)
def _jet_outputs(rows):
    """The outputs of the jet fits, ``coefficients (rows, 6), t1, t2, n (rows, 3), counts, away``: NaN, counts 0."""
    return (np.full((rows, 6), np.nan), np.full((rows, 3), np.nan), np.full((rows, 3), np.nan),
            np.full((rows, 3), np.nan), np.zeros(rows), np.full(rows, np.nan))


@nb.njit(**_JIT)
def _jet_scratch(degree, n_terms):
    """The buffers of :func:`_fit_one` (once per chunk of vertices, not per vertex):
    ``work, moments, right, matrix, low, scale, solution``."""
    work = np.empty((_JET_ROWS + 3 * (2 * degree + 1) + degree + 1, 64))
    return (work, np.empty((2 * degree + 1, 2 * degree + 1)), np.empty(n_terms), np.empty((n_terms, n_terms)),
            np.empty((n_terms, n_terms)), np.empty(n_terms), np.empty(n_terms))


@nb.njit(**_JIT_REASSOC)
def _dot(a, b, size):
    """``sum_i a[i] b[i]`` over the first ``size`` entries, reassociated (vectorized)."""
    total = 0.0
    for i in range(size):
        total += a[i] * b[i]
    return total


@nb.njit(**_JIT)
def _fit_one(vertices, points, normals, radius, degree, iterations, exponents, min_pivot, v, row, members, size, work,
             moments, right, matrix, low, scale, solution, coefficients, t1s, t2s, ns, counts, ids, facing,
             check_facing, away_fraction, away_out):
    """One vertex of :func:`fit_jets` in the caller's buffers; returns ``work`` (grown when too small).

    The ball's points are ``points[members[:size]]`` (vertex ``ids[members[a]]``);
    the fit is written to row ``row`` of the outputs. ``work`` holds one column per ball member: its offset from the centre in
    units of the radius, its weight, its weighted height, the powers
    ``u^0..u^2d`` and ``v^0..v^2d`` of its tangent coordinates and the products
    of the weight with ``u^0..u^2d`` and of the weighted height with ``u^0..u^d``
    (:func:`_jet_scratch`), so that each moment of the normal equations is one
    vectorized dot product of two rows (the products are those of the three
    factors in their order: the same numbers).
    """
    n_terms = exponents.shape[0]
    top = 2 * degree
    if size > work.shape[1]:
        work = np.empty((work.shape[0], 2 * size))
    ox, oy, oz, weight, lift = work[0], work[1], work[2], work[3], work[4]
    inverse = 1.0 / radius
    pu = work[_JET_ROWS:_JET_ROWS + top + 1]
    pv = work[_JET_ROWS + top + 1:_JET_ROWS + 2 * (top + 1)]
    wu = work[_JET_ROWS + 2 * (top + 1):_JET_ROWS + 3 * (top + 1)]
    lu = work[_JET_ROWS + 3 * (top + 1):]
    count = 0.0
    for a in range(size):
        k = members[a]
        x = (points[k, 0] - vertices[v, 0]) * inverse
        y = (points[k, 1] - vertices[v, 1]) * inverse
        z = (points[k, 2] - vertices[v, 2]) * inverse
        ox[a], oy[a], oz[a] = x, y, z
        w = max(1.0 - (x * x + y * y + z * z), 0.0)
        weight[a] = w * w
        count += weight[a] > 0
        pu[0, a] = 1.0
        pv[0, a] = 1.0
    counts[row] = count
    graph = True
    if check_facing:  # the ball must not hold the other side of the surface (a height function over the plane)
        fx, fy, fz = facing[v, 0], facing[v, 1], facing[v, 2]
        total = 0.0
        away = 0.0
        for a in range(size):
            if not weight[a] > 0:
                continue
            k = ids[members[a]]
            total += 1.0
            if fx * facing[k, 0] + fy * facing[k, 1] + fz * facing[k, 2] < 0.0:
                away += 1.0
        away_out[row] = away / total if total > 0 else 0.0
        graph = not away > away_fraction * total
    nx, ny, nz = normals[v, 0], normals[v, 1], normals[v, 2]
    ax, ay, az, bx, by, bz = _tangent_frame(nx, ny, nz)
    fitted = False
    for step in range(iterations):
        for a in range(size):
            pu[1, a] = ox[a] * ax + oy[a] * ay + oz[a] * az
            pv[1, a] = ox[a] * bx + oy[a] * by + oz[a] * bz
            lift[a] = weight[a] * (ox[a] * nx + oy[a] * ny + oz[a] * nz)
        for p in range(2, top + 1):  # power by power over all members (no chain of products per member)
            for a in range(size):
                pu[p, a] = pu[p - 1, a] * pu[1, a]
                pv[p, a] = pv[p - 1, a] * pv[1, a]
        for p in range(top + 1):  # the weight (and weighted height) times each power of u, once
            for a in range(size):
                wu[p, a] = weight[a] * pu[p, a]
        for p in range(degree + 1):
            for a in range(size):
                lu[p, a] = lift[a] * pu[p, a]
        for total in range(top + 1):
            for k in range(total + 1):
                moments[total - k, k] = _dot(wu[total - k], pv[k], size)
        for t in range(n_terms):
            right[t] = _dot(lu[exponents[t, 0]], pv[exponents[t, 1]], size)
        fitted = False
        for d in range(degree, 1, -1):
            m = (d + 1) * (d + 2) // 2
            if count < m:
                continue
            for r in range(m):
                scale[r] = 1.0 / math.sqrt(max(moments[2 * exponents[r, 0], 2 * exponents[r, 1]],
                                               2.2250738585072014e-308))
            for r in range(m):  # the lower triangle: all the Cholesky factorization reads
                for c in range(r + 1):
                    matrix[r, c] = (moments[exponents[r, 0] + exponents[c, 0], exponents[r, 1] + exponents[c, 1]]
                                    * scale[r] * scale[c])
                solution[r] = right[r] * scale[r]
            if _cholesky_solve(matrix, solution, low, m, min_pivot):
                for r in range(6):
                    solution[r] = solution[r] * scale[r]
                fitted = True
                break
        if step + 1 < iterations and fitted:
            p, q = solution[1], solution[2]
            tx = nx - p * ax - q * bx
            ty = ny - p * ay - q * by
            tz = nz - p * az - q * bz
            norm = math.sqrt(tx * tx + ty * ty + tz * tz)
            tx, ty, tz = tx / norm, ty / norm, tz / norm
            if math.isfinite(tx) and math.isfinite(ty) and math.isfinite(tz):
                nx, ny, nz = tx, ty, tz
                ax, ay, az, bx, by, bz = _tangent_frame(nx, ny, nz)
    if fitted and graph:
        for r in range(6):
            coefficients[row, r] = solution[r]
    t1s[row, 0], t1s[row, 1], t1s[row, 2] = ax, ay, az
    t2s[row, 0], t2s[row, 1], t2s[row, 2] = bx, by, bz
    ns[row, 0], ns[row, 1], ns[row, 2] = nx, ny, nz
    return work


# -- surface-connected balls (breadth-first over the mesh) -----------------------------
@nb.njit(inline="always", **_JIT)
def _segment_meets_ball(ax, ay, az, bx, by, bz, radius2):
    """Whether the segment from ``a`` to ``b`` (relative to the ball's centre, both ends outside
    the ball) passes through it: its closest point to the centre is inside, without a division."""
    dx, dy, dz = bx - ax, by - ay, bz - az
    along = -(ax * dx + ay * dy + az * dz)  # the closest point is a + (along / |d|^2) d, clamped to the segment
    if not along > 0:
        return False  # the segment leads away from the centre: a is its closest point
    length2 = dx * dx + dy * dy + dz * dz
    if not along < length2:
        return False  # b is its closest point
    return (ax * ax + ay * ay + az * az) * length2 - along * along <= radius2 * length2


@nb.njit(**_JIT)
def _connected_members(vertices, indptr, indices, allowed, v, cutoff, mark, members, queue):
    """The vertices of the surface-connected piece of the ball ``B(x_v, cutoff)`` written to ``members``.

    Breadth-first from ``v`` over the edges ``indptr, indices`` (CSR) that meet
    the closed ball (an end inside, or the segment passing through it): every
    vertex within ``cutoff`` reached so (and ``allowed``) is a member, ``v``
    first when allowed. When the ball's part of the surface is connected these
    are exactly the vertices of the Euclidean ball (a path inside it crosses
    from face to face through edges that meet it, and every edge of a face
    meets the ball at a corner shared with the next such edge); vertices of
    another sheet of the surface (the far side of a part thinner than the
    ball) are left out. ``mark`` (V,) holds, per vertex, the last centre that
    queued it (no clearing between centres); ``queue`` is scratch. ``members``
    and ``queue`` hold V entries (a vertex is queued at most once per centre):
    no buffer is grown, so no array is reassigned in the loop, which keeps
    numba's reference counting out of it (six times slower with it). Returns
    the number of members.
    """
    cx, cy, cz = vertices[v, 0], vertices[v, 1], vertices[v, 2]
    cutoff2 = cutoff * cutoff
    size = 0
    mark[v] = v
    queue[0] = v
    head, tail = 0, 1
    if allowed[v]:
        members[0] = v
        size = 1
    while head < tail:
        a = queue[head]
        head += 1
        ax, ay, az = vertices[a, 0] - cx, vertices[a, 1] - cy, vertices[a, 2] - cz
        a2 = ax * ax + ay * ay + az * az
        for j in range(indptr[a], indptr[a + 1]):
            b = indices[j]
            if mark[b] == v:
                continue
            bx, by, bz = vertices[b, 0] - cx, vertices[b, 1] - cy, vertices[b, 2] - cz
            b2 = bx * bx + by * by + bz * bz
            if b2 <= cutoff2:
                if allowed[b]:
                    members[size] = b
                    size += 1
            elif not a2 <= cutoff2 and not _segment_meets_ball(ax, ay, az, bx, by, bz, cutoff2):
                continue  # both ends outside, and the segment passes outside too
            mark[b] = v
            queue[tail] = b
            tail += 1
    return size


@nb.njit(parallel=True, **_JIT)
def fit_jets_connected(vertices, normals, radius, degree, iterations, exponents, min_pivot, centres, n_chunks,
                       allowed, indptr, indices, facing, check_facing, away_fraction, normals_only):
    """:func:`fit_jets` over the surface-connected piece of each ball (:func:`_connected_members`).

    The same fits, outputs and checks as :func:`fit_jets`, with the points of
    each ball found breadth-first over the mesh's edges (``indptr, indices``,
    CSR) instead of on a grid: no search structure over all the points is
    built, so a fit at a few centres costs only their balls. Only ``allowed``
    (V,) vertices enter the balls. ``n_chunks``: three (V,) int64 arrays each.
    With ``normals_only``, returns ``(fitted, ...)``: the (V, 3) unit normals of
    the fitted jets, ``(n - c10 t1 - c01 t2) / sqrt(1 + c10^2 + c01^2)`` as
    ``quadric.jet_normals`` computes them (NaN where no fit), and one-row
    placeholders for the other outputs (136 bytes per vertex never written).
    """
    n = vertices.shape[0]
    m = centres.shape[0]
    coefficients, t1s, t2s, ns, counts, away = _jet_outputs(1 if normals_only else n)
    fitted = np.full((n if normals_only else 1, 3), np.nan)
    ids = np.arange(n)
    n_terms = exponents.shape[0]
    n_chunks = max(min(m, n_chunks), 1)
    for chunk in nb.prange(n_chunks):
        mark = np.full(n, -1, np.int64)
        members = np.empty(n, np.int64)
        queue = np.empty(n, np.int64)
        work, moments, right, matrix, low, scale, solution = _jet_scratch(degree, n_terms)
        one = _jet_outputs(1)
        for i in range(chunk * m // n_chunks, (chunk + 1) * m // n_chunks):
            v = centres[i]
            size = _connected_members(vertices, indptr, indices, allowed, v, radius, mark, members, queue)
            if not normals_only:
                work = _fit_one(vertices, vertices, normals, radius, degree, iterations, exponents, min_pivot, v,
                                v, members, size, work, moments, right, matrix, low, scale, solution, coefficients,
                                t1s, t2s, ns, counts, ids, facing, check_facing, away_fraction, away)
                continue
            c, a, b, nn = one[0], one[1], one[2], one[3]
            c[0, :] = np.nan  # a failed fit leaves the row as it finds it
            work = _fit_one(vertices, vertices, normals, radius, degree, iterations, exponents, min_pivot, v, 0,
                            members, size, work, moments, right, matrix, low, scale, solution, c, a, b, nn, one[4],
                            ids, facing, check_facing, away_fraction, one[5])
            p, q = c[0, 1], c[0, 2]
            width = np.sqrt(1 + p * p + q * q)
            for k in range(3):
                fitted[v, k] = (nn[0, k] - p * a[0, k] - q * b[0, k]) / width
    if normals_only:
        return fitted, t1s, t2s, ns, counts, away
    return coefficients, t1s, t2s, ns, counts, away


@nb.njit(**_JIT)
def vertex_face_lists(faces, n_vertices):
    """CSR lists of the faces around every vertex: ``(indptr, indices)``, faces in index order."""
    indptr = np.zeros(n_vertices + 1, np.int64)
    for f in range(faces.shape[0]):
        for k in range(faces.shape[1]):
            indptr[faces[f, k] + 1] += 1
    for v in range(n_vertices):
        indptr[v + 1] += indptr[v]
    indices = np.empty(indptr[n_vertices], np.int64)
    fill = indptr[:-1].copy()
    for f in range(faces.shape[0]):
        for k in range(faces.shape[1]):
            indices[fill[faces[f, k]]] = f
            fill[faces[f, k]] += 1
    return indptr, indices


@nb.njit(parallel=True, **_JIT)
def connected_face_sums(vertices, faces, centroids, reach, usable, values, radius, indptr, indices, n_chunks, start,
                        stop):
    """(V, k) sums of ``share * values`` over the faces of the surface-connected piece of each ball.

    ``share`` is ``neighborhoods.face_in_ball_ratios`` (1 inside, 0 outside,
    linear in between by the corners' and centroid's distances). The faces are
    found breadth-first from the faces around each vertex (``indptr, indices``:
    :func:`vertex_face_lists`), on through the corners of every face that has a
    point of an edge, a corner or its centroid in the closed ball ``B(x_v, radius)``
    (``centroids`` and ``reach`` of :func:`cell_centres`: a face whose centroid is
    farther than ``radius + reach`` is outside, one distance; each vertex's
    distance is computed once per ball):
    when the ball's part of the surface is connected, every face of the
    Euclidean ball (a path inside the ball goes from face to face across edges
    that meet it); another sheet of the surface inside the ball is left out.
    Faces not ``usable`` (F,) lead the search on but add nothing. Only the
    balls of the vertices ``start`` to ``stop`` are summed (the other rows are
    0). ``n_chunks``: four (V,) arrays and one (F,) array each.
    """
    n = vertices.shape[0]
    n_faces = faces.shape[0]
    n_values = values.shape[1]
    out = np.zeros((n, n_values))
    radius2 = radius * radius
    start = max(min(start, n), 0)
    m = max(min(stop, n), start) - start
    n_chunks = max(min(m, n_chunks), 1)
    for chunk in nb.prange(n_chunks):
        seen = np.full(n_faces, -1, np.int64)
        mark = np.full(n, -1, np.int64)  # queued for this centre
        known = np.full(n, -1, np.int64)  # distance to this centre in `squared`
        squared = np.empty(n)
        queue = np.empty(n, np.int64)  # a vertex is queued at most once per centre: never grown
        for v in range(start + chunk * m // n_chunks, start + (chunk + 1) * m // n_chunks):
            cx, cy, cz = vertices[v, 0], vertices[v, 1], vertices[v, 2]
            mark[v] = v
            queue[0] = v
            head, tail = 0, 1
            while head < tail:
                a = queue[head]
                head += 1
                for j in range(indptr[a], indptr[a + 1]):
                    f = indices[j]
                    if seen[f] == v:
                        continue
                    seen[f] = v
                    d = (centroids[f, 0] - cx) ** 2 + (centroids[f, 1] - cy) ** 2 + (centroids[f, 2] - cz) ** 2
                    if d > (radius + reach[f]) ** 2:
                        continue  # every point of the face is outside
                    low = d
                    high = d
                    for corner in range(3):
                        c = faces[f, corner]
                        if known[c] != v:
                            known[c] = v
                            squared[c] = ((vertices[c, 0] - cx) ** 2 + (vertices[c, 1] - cy) ** 2
                                          + (vertices[c, 2] - cz) ** 2)
                        low = min(low, squared[c])
                        high = max(high, squared[c])
                    if high <= radius2:
                        share = 1.0
                    elif low >= radius2:  # corners and centroid outside: on through the face if an edge crosses
                        share = 0.0
                        crossed = False
                        for corner in range(3):
                            p = faces[f, corner]
                            q = faces[f, (corner + 1) % 3]
                            crossed = crossed or _segment_meets_ball(
                                vertices[p, 0] - cx, vertices[p, 1] - cy, vertices[p, 2] - cz,
                                vertices[q, 0] - cx, vertices[q, 1] - cy, vertices[q, 2] - cz, radius2)
                        if not crossed:
                            continue
                    else:
                        root = math.sqrt(low)
                        share = (radius - root) / (math.sqrt(high) - root)
                    if share != 0.0 and usable[f]:
                        for k in range(n_values):
                            out[v, k] += share * values[f, k]
                    for corner in range(3):
                        c = faces[f, corner]
                        if mark[c] != v:
                            mark[c] = v
                            queue[tail] = c
                            tail += 1
    return out


@nb.njit(parallel=True, **_JIT)
def cell_centres(vertices, cells):
    """``neighborhoods._ball_sums``'s (C, 3) centroids of cells (faces or edges) and (C,) their reach.

    The reach is the largest distance from the centroid to a corner.
    """
    n, corners = cells.shape
    centres = np.zeros((n, 3))
    reach = np.zeros(n)
    for c in nb.prange(n):
        for k in range(corners):
            for a in range(3):
                centres[c, a] += vertices[cells[c, k], a]
        for a in range(3):
            centres[c, a] /= corners
        for k in range(corners):
            d = 0.0
            for a in range(3):
                d += (vertices[cells[c, k], a] - centres[c, a]) ** 2
            reach[c] = max(reach[c], math.sqrt(d))
    return centres, reach


@nb.njit(parallel=True, **_JIT)
def ball_cell_sums(vertices, cells, centroids, values, radius, cutoff, n_chunks, start, stop):
    """``neighborhoods._ball_sums`` for one group of cells: (V, k) sums of ``weight * values``.

    Cells are faces (three corners; weight: the share of the face inside the
    ball, ``neighborhoods.face_in_ball_ratios``) or edges (two corners; weight:
    the length of the edge inside the ball, ``neighborhoods.segment_in_ball_lengths``).
    They are found by their ``centroids`` within ``cutoff`` (radius + the
    group's largest reach) on a grid of cells (:func:`_grid`); their corners,
    centroids and values are copied in grid order first, so that a ball reads
    contiguous memory. Only the balls of ranks ``start`` to ``stop`` of the
    vertices in grid order are summed (the caller splits a long computation
    into calls; the other rows are 0).
    """
    n = vertices.shape[0]
    n_cells, corners = cells.shape
    n_values = values.shape[1]
    grid = _grid(centroids, cutoff)
    order = grid[0]
    points = np.empty((n_cells, corners + 1, 3))  # the corners, then the centroid
    sorted_values = np.empty((n_cells, n_values))
    for k in nb.prange(n_cells):
        c = order[k]
        for corner in range(corners):
            points[k, corner] = vertices[cells[c, corner]]
        points[k, corners] = centroids[c]
        sorted_values[k] = values[c]
    out = np.zeros((n, n_values))
    centres = _grid(vertices, grid[4])[0]  # centres in grid order: consecutive balls share cells (cache)
    start = max(min(start, n), 0)
    m = max(min(stop, n), start) - start
    n_chunks = max(min(m, n_chunks), 1)
    for chunk in nb.prange(n_chunks):
        members = np.empty(64, np.int64)
        for rank in range(start + chunk * m // n_chunks, start + (chunk + 1) * m // n_chunks):
            members = _cell_weight_sums(vertices, points, grid, sorted_values, radius, cutoff, centres[rank],
                                        members, out)
    return out


@nb.njit(inline="always", **_JIT)
def _face_share(points, f, cx, cy, cz, radius, radius2):
    """``face_in_ball_ratios`` of face ``f`` (corners and centroid in ``points[f]``); squared
    distances, the square roots only for faces the sphere cuts."""
    low = np.inf
    high = -np.inf
    for corner in range(4):
        dx = points[f, corner, 0] - cx
        dy = points[f, corner, 1] - cy
        dz = points[f, corner, 2] - cz
        dist = dx * dx + dy * dy + dz * dz
        low = min(low, dist)
        high = max(high, dist)
    if high <= radius2:
        return 1.0
    if low >= radius2:
        return 0.0
    low = math.sqrt(low)
    return (radius - low) / (math.sqrt(high) - low)


@nb.njit(inline="always", **_JIT)
def _segment_length(points, e, cx, cy, cz, radius2):
    """``segment_in_ball_lengths`` of edge ``e`` (its ends in ``points[e, :2]``)."""
    dx = points[e, 1, 0] - points[e, 0, 0]
    dy = points[e, 1, 1] - points[e, 0, 1]
    dz = points[e, 1, 2] - points[e, 0, 2]
    fx = points[e, 0, 0] - cx
    fy = points[e, 0, 1] - cy
    fz = points[e, 0, 2] - cz
    a = dx * dx + dy * dy + dz * dz
    b = 2 * (dx * fx + dy * fy + dz * fz)
    c = fx * fx + fy * fy + fz * fz - radius2
    disc = b * b - 4 * a * c
    if not (disc > 0 and a > 0):
        return 0.0
    root = math.sqrt(disc)
    t0 = min(max((-b - root) / (2 * a), 0.0), 1.0)
    t1 = min(max((-b + root) / (2 * a), 0.0), 1.0)
    return (t1 - t0) * math.sqrt(a)


@nb.njit(**_JIT)
def _cell_weight_sums(vertices, points, grid, values, radius, cutoff, v, members, out):
    """One vertex of :func:`ball_cell_sums`; returns the (possibly grown) member buffer."""
    cx, cy, cz = vertices[v, 0], vertices[v, 1], vertices[v, 2]
    radius2 = radius * radius
    corners = points.shape[1] - 1
    members, size = _ball_members(points[:, corners], grid, cx, cy, cz, cutoff, members)
    for a in range(size):
        c = members[a]
        if corners == 3:
            weight = _face_share(points, c, cx, cy, cz, radius, radius2)
        else:
            weight = _segment_length(points, c, cx, cy, cz, radius2)
        if weight == 0.0:
            continue
        for k in range(values.shape[1]):
            out[v, k] += weight * values[c, k]
    return members


@nb.njit(parallel=True, **_JIT)
def icc_face_measures(vertices, faces, normals):
    """``icc.face_measures``: (F, 9) ``mu_0, mu_1, mu_2`` and the symmetrized ``mu^{X,Y}`` per face."""
    out = np.empty((faces.shape[0], 9))
    for f in nb.prange(faces.shape[0]):
        i, j, k = faces[f, 0], faces[f, 1], faces[f, 2]
        ax, ay, az = vertices[j, 0] - vertices[i, 0], vertices[j, 1] - vertices[i, 1], vertices[j, 2] - vertices[i, 2]
        bx, by, bz = vertices[k, 0] - vertices[i, 0], vertices[k, 1] - vertices[i, 1], vertices[k, 2] - vertices[i, 2]
        u0x, u0y, u0z = normals[i, 0], normals[i, 1], normals[i, 2]
        u1x, u1y, u1z = normals[j, 0], normals[j, 1], normals[j, 2]
        u2x, u2y, u2z = normals[k, 0], normals[k, 1], normals[k, 2]
        mx, my, mz = (u0x + u1x + u2x) / 3, (u0y + u1y + u2y) / 3, (u0z + u1z + u2z) / 3
        cx, cy, cz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
        out[f, 0] = 0.5 * (mx * cx + my * cy + mz * cz)
        # (u0 - u2) x a + (u1 - u0) x b
        px, py, pz = u0x - u2x, u0y - u2y, u0z - u2z
        qx, qy, qz = u1x - u0x, u1y - u0y, u1z - u0z
        sx = (py * az - pz * ay) + (qy * bz - qz * by)
        sy = (pz * ax - px * az) + (qz * bx - qx * bz)
        sz = (px * ay - py * ax) + (qx * by - qy * bx)
        out[f, 1] = 0.5 * (mx * sx + my * sy + mz * sz)
        out[f, 2] = 0.5 * (u0x * (u1y * u2z - u1z * u2y) + u0y * (u1z * u2x - u1x * u2z) + u0z * (u1x * u2y - u1y * u2x))
        # M = 1/2 [ (a x m) (u2 - u0)^T - (b x m) (u1 - u0)^T ]
        gx, gy, gz = ay * mz - az * my, az * mx - ax * mz, ax * my - ay * mx
        hx, hy, hz = by * mz - bz * my, bz * mx - bx * mz, bx * my - by * mx
        ex, ey, ez = u2x - u0x, u2y - u0y, u2z - u0z
        m00 = 0.5 * (gx * ex - hx * qx)
        m11 = 0.5 * (gy * ey - hy * qy)
        m22 = 0.5 * (gz * ez - hz * qz)
        m01 = 0.5 * (gx * ey - hx * qy)
        m10 = 0.5 * (gy * ex - hy * qx)
        m02 = 0.5 * (gx * ez - hx * qz)
        m20 = 0.5 * (gz * ex - hz * qx)
        m12 = 0.5 * (gy * ez - hy * qz)
        m21 = 0.5 * (gz * ey - hz * qy)
        out[f, 3], out[f, 4], out[f, 5] = m00, m11, m22
        out[f, 6], out[f, 7], out[f, 8] = 0.5 * (m01 + m10), 0.5 * (m02 + m20), 0.5 * (m12 + m21)
    return out
