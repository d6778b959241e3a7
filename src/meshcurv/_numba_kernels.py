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


# -- normal cycle ---------------------------------------------------------------
@nb.njit(**_JIT)
def normal_cycle_sums(vertices, faces, edges, edge_faces, usable, degenerate):
    """Per-vertex measures (6 tensor components), barycentric areas and normal sums.

    Returns ``sums`` of shape (V, 10): columns 0-5 the anisotropic measure
    ``sum beta |e| / 2 e e^T`` (xx, yy, zz, xy, xz, yz), 6 the area, 7-9 the
    area-weighted face-normal sum.
    """
    n_vertices = vertices.shape[0]
    sums = np.zeros((n_vertices, 10))
    unit_normals = np.zeros((faces.shape[0], 3))
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
        double_area = math.sqrt(nx * nx + ny * ny + nz * nz)
        unit_normals[f, 0] = nx / double_area
        unit_normals[f, 1] = ny / double_area
        unit_normals[f, 2] = nz / double_area
        third = double_area / 6.0
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


@nb.njit(parallel=True, **_JIT)
def tangent_principal(tensors, normals, valid, rotate, mean_from_trace):
    """Per-vertex closed-form version of ``_tensors.principal_from_shape_operator``.

    Returns ``out`` of shape (V, 8): k_min, k_max, dir_min (3), dir_max (3); NaN
    where ``valid`` is False.
    """
    n = tensors.shape[0]
    out = np.full((n, 8), np.nan)
    for i in nb.prange(n):
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
        if a01 == 0.0 and a02 == 0.0 and a12 == 0.0:
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


@nb.njit(parallel=True, **_JIT)
def eigen_by_magnitude(tensors):
    """Eigenpairs of (N, 6) symmetric tensors ordered by |eigenvalue| (see _eigen.py).

    Eigenvalues are first put in ascending order (as LAPACK returns them), then
    stably re-ordered by magnitude. Rows with a non-finite component are NaN.
    """
    n = tensors.shape[0]
    values = np.full((n, 3), np.nan)
    vectors = np.full((n, 3, 3), np.nan)
    for i in nb.prange(n):
        finite = True
        for k in range(6):
            if not math.isfinite(tensors[i, k]):
                finite = False
        if not finite:
            continue
        w0, w1, w2, v00, v01, v02, v10, v11, v12, v20, v21, v22 = _jacobi3(
            tensors[i, 0], tensors[i, 1], tensors[i, 2], tensors[i, 3], tensors[i, 4], tensors[i, 5]
        )
        # order: ascending value (stable), then ascending magnitude (stable)
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
        columns = ((v00, v10, v20), (v01, v11, v21), (v02, v12, v22))
        for k, o in enumerate((o0, o1, o2)):
            values[i, k] = w[o]
            column = columns[o]
            vectors[i, 0, k] = column[0]
            vectors[i, 1, k] = column[1]
            vectors[i, 2, k] = column[2]
    return values, vectors

# -- matGeom's edge tensors -----------------------------------------------------
@nb.njit(**_JIT)
def matgeom_vertex_tensors(vertices, faces, ev1, ev2, ef1, ef2):
    """Steps 2 to 5 of matGeom's meshCurvatures (see estimators/matgeom.py).

    Same operations in the same order as Octave (sums of three products left
    to right), so that ``arccos`` of nearly parallel normals gets the same input.
    Face ids beyond the face count give NaN (matGeom stops with an index error).
    """
    n_vertices = vertices.shape[0]
    n_faces = faces.shape[0]
    n_edges = ev1.shape[0]
    normals = np.empty((n_faces, 3))
    for f in range(n_faces):
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
        norm = math.sqrt((nx * nx + ny * ny) + nz * nz)
        normals[f, 0] = nx / norm if norm > 0 else np.nan
        normals[f, 1] = ny / norm if norm > 0 else np.nan
        normals[f, 2] = nz / norm if norm > 0 else np.nan
    lengths = np.empty(n_edges)
    total = 0.0
    for e in range(n_edges):
        p, q = ev1[e], ev2[e]
        x = vertices[q, 0] - vertices[p, 0]
        y = vertices[q, 1] - vertices[p, 1]
        z = vertices[q, 2] - vertices[p, 2]
        lengths[e] = math.sqrt((x * x + y * y) + z * z)
        total += lengths[e]
    mean = total / n_edges
    sums = np.zeros((n_vertices, 6))
    counts = np.zeros(n_vertices)
    for e in range(n_edges):
        p, q = ev1[e], ev2[e]
        counts[p] += 1.0
        counts[q] += 1.0
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
            sums[v, 0] += (ex * ex) * weight
            sums[v, 1] += (ey * ey) * weight
            sums[v, 2] += (ez * ez) * weight
            sums[v, 3] += (ex * ey) * weight
            sums[v, 4] += (ex * ez) * weight
            sums[v, 5] += (ey * ez) * weight
    for i in range(n_vertices):
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


@nb.njit(**_JIT)
def bowtie_vertices(faces, face_edges, linked, proper, n_vertices, n_edges):
    """Vertices whose face corners fall in more than one fan (see MeshTopology.bowtie_vertices).

    Union-find over the ``3 F`` corners: the corners at each end of a linked
    edge (two faces, both without a repeated vertex) are joined.
    """
    n_corners = 3 * faces.shape[0]
    parent = np.arange(n_corners)
    first = np.full(n_edges, -1, np.int64)
    for f in range(faces.shape[0]):
        if not proper[f]:
            continue
        for k in range(3):
            e = face_edges[f, k]
            if e < 0 or not linked[e]:
                continue
            side = 3 * f + k
            if first[e] < 0:
                first[e] = side
                continue
            one = first[e]
            head_one = one - one % 3 + (one % 3 + 1) % 3
            head_two = side - k + (k + 1) % 3
            if faces[one // 3, one % 3] == faces[f, k]:  # same direction
                pairs = ((one, side), (head_one, head_two))
            else:
                pairs = ((one, head_two), (head_one, side))
            for a, b in pairs:
                ra = _find(parent, a)
                rb = _find(parent, b)
                if ra != rb:
                    parent[max(ra, rb)] = min(ra, rb)
    root_of = np.full(n_vertices, -1, np.int64)
    several = np.zeros(n_vertices, np.bool_)
    for f in range(faces.shape[0]):
        if not proper[f]:
            continue
        for k in range(3):
            v = faces[f, k]
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
def mesh_measures(vertices, faces, edges, centre):
    """One pass over edges and faces: the facts :func:`meshcurv.diagnose` needs.

    Returns ``(edge_lengths (E,), double_areas (F,), area, six_volume)`` where
    ``six_volume`` is the sum over faces of ``(a - centre) . cross(b - a, c - a)``.
    """
    lengths = np.empty(edges.shape[0])
    for e in range(edges.shape[0]):
        p, q = edges[e, 0], edges[e, 1]
        x = vertices[q, 0] - vertices[p, 0]
        y = vertices[q, 1] - vertices[p, 1]
        z = vertices[q, 2] - vertices[p, 2]
        lengths[e] = math.sqrt(x * x + y * y + z * z)
    double_areas = np.empty(faces.shape[0])
    area = 0.0
    six_volume = 0.0
    for f in range(faces.shape[0]):
        a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
        ux = vertices[b, 0] - vertices[a, 0]
        uy = vertices[b, 1] - vertices[a, 1]
        uz = vertices[b, 2] - vertices[a, 2]
        wx = vertices[c, 0] - vertices[a, 0]
        wy = vertices[c, 1] - vertices[a, 1]
        wz = vertices[c, 2] - vertices[a, 2]
        nx = uy * wz - uz * wy
        ny = uz * wx - ux * wz
        nz = ux * wy - uy * wx
        double_areas[f] = math.sqrt(nx * nx + ny * ny + nz * nz)
        area += 0.5 * double_areas[f]
        six_volume += ((vertices[a, 0] - centre[0]) * nx + (vertices[a, 1] - centre[1]) * ny
                       + (vertices[a, 2] - centre[2]) * nz)
    return lengths, double_areas, area, six_volume


# -- smoothing ------------------------------------------------------------------
@nb.njit(**_JIT)
def neighbour_lists(edges, n_vertices):
    """CSR lists of the edge neighbours of every vertex: ``(indptr, indices)``."""
    indptr = np.zeros(n_vertices + 1, np.int64)
    for e in range(edges.shape[0]):
        indptr[edges[e, 0] + 1] += 1
        indptr[edges[e, 1] + 1] += 1
    for v in range(n_vertices):
        indptr[v + 1] += indptr[v]
    fill = indptr[:-1].copy()
    indices = np.empty(indptr[n_vertices], np.int64)
    for e in range(edges.shape[0]):
        p, q = edges[e, 0], edges[e, 1]
        indices[fill[p]] = q
        fill[p] += 1
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
                total = current[i, c]
                for j in range(start, stop):
                    total += current[indices[j], c]
                following[i, c] = total * scale
        current, following = following, current
    return current
