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

_JIT = dict(cache=True, nogil=True, fastmath=False)


# -- topology -------------------------------------------------------------------
@nb.njit(**_JIT)
def build_edges(faces, n_vertices):
    """Edges of the triangles, their faces and counts (see MeshTopology._build).

    Sides are bucketed by their smaller vertex (counting sort), each bucket is
    sorted by (larger vertex, direction) with a stable insertion sort, so the
    edges come out in lexicographic order, as ``np.unique`` would give them.
    """
    n_faces = faces.shape[0]
    bucket_start = np.zeros(n_vertices + 1, np.int64)
    for f in range(n_faces):
        for k in range(3):
            a = faces[f, k]
            b = faces[f, (k + 1) % 3]
            if a != b:
                bucket_start[min(a, b) + 1] += 1
    for i in range(n_vertices):
        bucket_start[i + 1] += bucket_start[i]
    n_sides = bucket_start[n_vertices]
    fill = bucket_start[:-1].copy()
    sort_key = np.empty(n_sides, np.int64)  # 2 * larger vertex + backward
    side_of = np.empty(n_sides, np.int64)
    for f in range(n_faces):
        for k in range(3):
            a = faces[f, k]
            b = faces[f, (k + 1) % 3]
            if a != b:
                low = min(a, b)
                slot = fill[low]
                fill[low] += 1
                sort_key[slot] = 2 * max(a, b) + (1 if a > b else 0)
                side_of[slot] = 3 * f + k
    for v in range(n_vertices):  # stable insertion sort of each (small) bucket
        for i in range(bucket_start[v] + 1, bucket_start[v + 1]):
            key = sort_key[i]
            side = side_of[i]
            j = i - 1
            while j >= bucket_start[v] and sort_key[j] > key:
                sort_key[j + 1] = sort_key[j]
                side_of[j + 1] = side_of[j]
                j -= 1
            sort_key[j + 1] = key
            side_of[j + 1] = side
    edges = np.empty((n_sides, 2), np.int64)
    edge_faces = np.full((n_sides, 2), -1, np.int64)
    counts = np.zeros(n_sides, np.int64)
    forward = np.zeros(n_sides, np.int64)
    face_edges = np.full(3 * n_faces, -1, np.int64)
    e = -1
    for v in range(n_vertices):
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
    n_edges = e + 1
    return (edges[:n_edges].copy(), face_edges.reshape(n_faces, 3), edge_faces[:n_edges].copy(),
            counts[:n_edges].copy(), forward[:n_edges].copy())


# -- smoothing ------------------------------------------------------------------
@nb.njit(**_JIT)
def smooth_over_edges(values, edges, n_vertices, steps):
    """``steps`` passes of the 1-ring mean (self + neighbours) / (degree + 1)."""
    n_columns = values.shape[1]
    degree = np.zeros(n_vertices, np.float64)
    for e in range(edges.shape[0]):
        degree[edges[e, 0]] += 1.0
        degree[edges[e, 1]] += 1.0
    current = values.copy()
    following = np.empty_like(current)
    for _ in range(steps):
        following[:] = current
        for e in range(edges.shape[0]):
            p = edges[e, 0]
            q = edges[e, 1]
            for c in range(n_columns):
                following[p, c] += current[q, c]
                following[q, c] += current[p, c]
        for i in range(n_vertices):
            scale = 1.0 / (degree[i] + 1.0)
            for c in range(n_columns):
                following[i, c] *= scale
        current, following = following, current
    return current


# -- normal cycle ---------------------------------------------------------------
@nb.njit(**_JIT)
def normal_cycle_sums(vertices, faces, edges, edge_faces, usable, degenerate, unit_normals):
    """Per-vertex measures (6 tensor components), barycentric areas and normal sums.

    Returns ``sums`` of shape (V, 10): columns 0-5 the anisotropic measure
    ``sum beta |e| / 2 e e^T`` (xx, yy, zz, xy, xz, yz), 6 the area, 7-9 the
    area-weighted face-normal sum.
    """
    n_vertices = vertices.shape[0]
    sums = np.zeros((n_vertices, 10))
    for f in range(faces.shape[0]):
        if degenerate[f]:
            continue
        a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
        ux = vertices[b, 0] - vertices[a, 0]
        uy = vertices[b, 1] - vertices[a, 1]
        uz = vertices[b, 2] - vertices[a, 2]
        vx = vertices[c, 0] - vertices[a, 0]
        vy = vertices[c, 1] - vertices[a, 1]
        vz = vertices[c, 2] - vertices[a, 2]
        nx = uy * vz - uz * vy
        ny = uz * vx - ux * vz
        nz = ux * vy - uy * vx
        third = math.sqrt(nx * nx + ny * ny + nz * nz) / 6.0
        for corner in (a, b, c):
            sums[corner, 6] += third
            sums[corner, 7] += nx
            sums[corner, 8] += ny
            sums[corner, 9] += nz
    for e in range(edges.shape[0]):
        if not usable[e]:
            continue
        p, q = edges[e, 0], edges[e, 1]
        f1, f2 = edge_faces[e, 0], edge_faces[e, 1]
        ex = vertices[q, 0] - vertices[p, 0]
        ey = vertices[q, 1] - vertices[p, 1]
        ez = vertices[q, 2] - vertices[p, 2]
        length = math.sqrt(ex * ex + ey * ey + ez * ez)
        if length == 0.0:
            continue
        ex /= length
        ey /= length
        ez /= length
        ax, ay, az = unit_normals[f1, 0], unit_normals[f1, 1], unit_normals[f1, 2]
        bx, by, bz = unit_normals[f2, 0], unit_normals[f2, 1], unit_normals[f2, 2]
        sine = (ay * bz - az * by) * ex + (az * bx - ax * bz) * ey + (ax * by - ay * bx) * ez
        cosine = ax * bx + ay * by + az * bz
        weight = 0.5 * math.atan2(sine, cosine) * length
        for v in (p, q):
            sums[v, 0] += weight * ex * ex
            sums[v, 1] += weight * ey * ey
            sums[v, 2] += weight * ez * ez
            sums[v, 3] += weight * ex * ey
            sums[v, 4] += weight * ex * ez
            sums[v, 5] += weight * ey * ez
    return sums


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


@nb.njit(**_JIT)
def tangent_principal(tensors, normals, valid, rotate, mean_from_trace):
    """Per-vertex closed-form version of ``_tensors.principal_from_shape_operator``.

    Returns ``out`` of shape (V, 8): k_min, k_max, dir_min (3), dir_max (3); NaN
    where ``valid`` is False.
    """
    n = tensors.shape[0]
    out = np.full((n, 8), np.nan)
    for i in range(n):
        if not valid[i]:
            continue
        xx, yy, zz, xy, xz, yz = (tensors[i, 0], tensors[i, 1], tensors[i, 2],
                                  tensors[i, 3], tensors[i, 4], tensors[i, 5])
        t1x, t1y, t1z, t2x, t2y, t2z = _tangent_frame(normals[i, 0], normals[i, 1], normals[i, 2])
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
        out[i, 0] = half_sum - radius
        out[i, 1] = half_sum + radius
        out[i, 2], out[i, 3], out[i, 4] = acx, acy, acz
        out[i, 5], out[i, 6], out[i, 7] = alx, aly, alz
    return out


# -- symmetric 3x3 eigen-decomposition -----------------------------------------
@nb.njit(**_JIT)
def _jacobi3(a, v):
    """Cyclic Jacobi on a symmetric 3x3 ``a`` (overwritten); eigenvectors into ``v``."""
    for i in range(3):
        for j in range(3):
            v[i, j] = 1.0 if i == j else 0.0
    for _ in range(50):
        off = a[0, 1] * a[0, 1] + a[0, 2] * a[0, 2] + a[1, 2] * a[1, 2]
        diag = a[0, 0] * a[0, 0] + a[1, 1] * a[1, 1] + a[2, 2] * a[2, 2]
        if off <= 1e-36 * diag or off == 0.0:
            break
        for p, q in ((0, 1), (0, 2), (1, 2)):
            apq = a[p, q]
            if apq == 0.0:
                continue
            theta = (a[q, q] - a[p, p]) / (2.0 * apq)
            t = 1.0 / (abs(theta) + math.sqrt(theta * theta + 1.0))
            if theta < 0.0:
                t = -t
            c = 1.0 / math.sqrt(t * t + 1.0)
            s = t * c
            for k in range(3):  # columns p, q of a
                akp = a[k, p]
                akq = a[k, q]
                a[k, p] = c * akp - s * akq
                a[k, q] = s * akp + c * akq
            for k in range(3):  # rows p, q of a
                apk = a[p, k]
                aqk = a[q, k]
                a[p, k] = c * apk - s * aqk
                a[q, k] = s * apk + c * aqk
            for k in range(3):
                vkp = v[k, p]
                vkq = v[k, q]
                v[k, p] = c * vkp - s * vkq
                v[k, q] = s * vkp + c * vkq


@nb.njit(**_JIT)
def eigen_by_magnitude(tensors):
    """Eigenpairs of (N, 6) symmetric tensors ordered by |eigenvalue| (see _eigen.py).

    Eigenvalues are first put in ascending order (as LAPACK returns them), then
    stably re-ordered by magnitude. Rows with a non-finite component are NaN.
    """
    n = tensors.shape[0]
    values = np.full((n, 3), np.nan)
    vectors = np.full((n, 3, 3), np.nan)
    a = np.empty((3, 3))
    v = np.empty((3, 3))
    w = np.empty(3)
    order = np.empty(3, np.int64)
    for i in range(n):
        finite = True
        for k in range(6):
            if not math.isfinite(tensors[i, k]):
                finite = False
        if not finite:
            continue
        a[0, 0], a[1, 1], a[2, 2] = tensors[i, 0], tensors[i, 1], tensors[i, 2]
        a[0, 1] = a[1, 0] = tensors[i, 3]
        a[0, 2] = a[2, 0] = tensors[i, 4]
        a[1, 2] = a[2, 1] = tensors[i, 5]
        _jacobi3(a, v)
        for k in range(3):
            w[k] = a[k, k]
            order[k] = k
        # ascending order, stable
        for x in range(1, 3):
            y = x
            while y > 0 and w[order[y - 1]] > w[order[y]]:
                order[y - 1], order[y] = order[y], order[y - 1]
                y -= 1
        # then by magnitude, stable
        for x in range(1, 3):
            y = x
            while y > 0 and abs(w[order[y - 1]]) > abs(w[order[y]]):
                order[y - 1], order[y] = order[y], order[y - 1]
                y -= 1
        for k in range(3):
            values[i, k] = w[order[k]]
            for r in range(3):
                vectors[i, r, k] = v[r, order[k]]
    return values, vectors
