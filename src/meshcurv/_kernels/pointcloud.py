"""Compiled twins of the point-cloud code (:mod:`meshcurv._pointcloud_normals` and ``_estimators``).

:func:`ball_triangle_sums` does in one pass per centre what
:func:`meshcurv._pointcloud_estimators.corrected_measures` does with arrays:
draw the triangles, turn them, compute the measures of
:func:`meshcurv.measures.face_measures` and sum them (tests compare the two).
"""

from __future__ import annotations

import numba as nb
import numpy as np

from ._common import _JIT, _tangent_frame
from .icc import _triangle_measures
from .neighborhoods import _ball_members


@nb.njit(**_JIT)
def _edge_on(points, normals, i, j, k, tolerance):
    """Whether the triangle ``(i, j, k)`` holds the mean of its corners' normals in its plane, within
    ``tolerance`` of the product of their (Euclidean) lengths, or is flat (the length of the cross product of its two
    edges from ``i`` within ``tolerance`` of the product of theirs): its corrected area is round-off, and so is the
    sign that turns it (:data:`meshcurv._pointcloud_estimators.EDGE_ON`). Squared lengths, which no rotation
    changes (L1 ones do, by up to 3 times): the operations of the NumPy path, in its order."""
    ax, ay, az = points[j, 0] - points[i, 0], points[j, 1] - points[i, 1], points[j, 2] - points[i, 2]
    bx, by, bz = points[k, 0] - points[i, 0], points[k, 1] - points[i, 1], points[k, 2] - points[i, 2]
    mx = normals[i, 0] + normals[j, 0] + normals[k, 0]
    my = normals[i, 1] + normals[j, 1] + normals[k, 1]
    mz = normals[i, 2] + normals[j, 2] + normals[k, 2]
    cx, cy, cz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
    squared = tolerance * tolerance
    area = cx * cx + cy * cy + cz * cz
    if area <= squared * (ax * ax + ay * ay + az * az) * (bx * bx + by * by + bz * bz):
        return True
    facing = mx * cx + my * cy + mz * cz
    return facing * facing <= squared * (mx * mx + my * my + mz * mz) * area


@nb.njit(**_JIT)
def ball_triangle_sums(points, normals, index, counts, pattern, edge_on, rows=None):
    """(M, 9) sums of ``mu_0, mu_1, mu_2, mu^{X,Y}`` (xx, yy, zz, xy, xz, yz) over the triangles of each ball.

    ``index`` (M, K): the ball's points first (``counts`` of them, >= 3);
    ``pattern`` (T, 3): uniform numbers in [0, 1) that pick three distinct ranks; a triangle edge-on to its
    corners' normals (:func:`_edge_on` within ``edge_on``) adds nothing. ``rows`` (R,): the balls to sum (then
    (R, 9), row ``r`` that of ball ``rows[r]``; default: every ball), read in place (no gathered copy of
    ``index``).
    """
    if rows is None:
        rows = np.arange(index.shape[0])
    most = 3
    for r in range(rows.shape[0]):
        most = max(most, counts[rows[r]])
    return _ball_triangle_sums(points, normals, index, counts, _rank_table(pattern, most), edge_on, rows)


@nb.njit(**_JIT)
def _rank_table(pattern, most):
    """(most + 1, T, 3) the ranks of the triangles ``pattern`` (T, 3) in a ball of ``c`` points (rows 3 ..
    ``most``): ``floor(u c)``, ``floor(u' (c - 1))`` and ``floor(u'' (c - 2))`` each moved past the ranks before
    it, three distinct ranks. Drawn once per call instead of once per triangle (1M balls: 32M of each)."""
    table = np.zeros((most + 1, pattern.shape[0], 3), dtype=np.int32)
    for c in range(3, most + 1):
        for t in range(pattern.shape[0]):
            a = int(np.floor(pattern[t, 0] * c))
            b = int(np.floor(pattern[t, 1] * (c - 1)))
            if b >= a:
                b += 1
            z = int(np.floor(pattern[t, 2] * (c - 2)))
            low, high = min(a, b), max(a, b)
            if z >= low:
                z += 1
            if z >= high:
                z += 1
            table[c, t, 0], table[c, t, 1], table[c, t, 2] = a, b, z
    return table


@nb.njit(parallel=True, **_JIT)
def _ball_triangle_sums(points, normals, index, counts, table, edge_on, rows):
    """:func:`ball_triangle_sums` of the balls ``rows``, the ranks of the triangles of a ball of ``c`` points
    ``table[c]`` (:func:`_rank_table`)."""
    m = rows.shape[0]
    out = np.zeros((m, 9))
    for r in nb.prange(m):
        row = rows[r]
        c = counts[row]
        s0 = s1 = s2 = s3 = s4 = s5 = s6 = s7 = s8 = 0.0  # sums in registers, written once per row
        for t in range(table.shape[1]):
            i, j, k = index[row, table[c, t, 0]], index[row, table[c, t, 1]], index[row, table[c, t, 2]]
            if _edge_on(points, normals, i, j, k, edge_on):
                continue
            # the measures of (i, j, k) as they come, turned by a sign: the turned triangle (i, k, j) of
            # _triangle_measures' `turn` swaps a, b and u1, u2, which negates every product and difference of its
            # closed forms and swaps the operands of its sums, so that each of its measures is exactly minus
            # that of (i, j, k) (IEEE negation, overflows included); the sign of mu_0 (half the corrected
            # area) is that of the area. The same sums to the bit, without a branch that random triangles
            # mispredict half the time (with the ranks' table: 50 -> 35 ns a triangle on one core)
            m0, m1, m2, m3, m4, m5, m6, m7, m8 = _triangle_measures(points, normals, i, j, k, False)
            turn = -1.0 if m0 < 0 else 1.0
            s0, s1, s2 = s0 + turn * m0, s1 + turn * m1, s2 + turn * m2
            s3, s4, s5 = s3 + turn * m3, s4 + turn * m4, s5 + turn * m5
            s6, s7, s8 = s6 + turn * m6, s7 + turn * m7, s8 + turn * m8
        out[r, 0], out[r, 1], out[r, 2] = s0, s1, s2
        out[r, 3], out[r, 4], out[r, 5] = s3, s4, s5
        out[r, 6], out[r, 7], out[r, 8] = s6, s7, s8
    return out


#: ``A - lambda I`` counts as rank 1 (a double smallest eigenvalue: a collinear neighbourhood) where its
#: rows' largest squared cross product is below this times its longest row's squared length, squared: the
#: gap of the two smallest eigenvalues below 1e-12 of the largest, where the cross products' rounding
#: (eps times the inverse of that ratio) would turn the normal by more than 1e-4.
RANK_ONE = 1e-24


@nb.njit(**_JIT)
def _covariance(points, indices, i):
    """``xx, xy, xz, yy, yz, zz``: the (unnormalised) covariance of point ``i`` and its neighbours ``indices[i]``."""
    k = indices.shape[1]
    cx, cy, cz = points[i, 0], points[i, 1], points[i, 2]
    for j in range(k):
        cx += points[indices[i, j], 0]
        cy += points[indices[i, j], 1]
        cz += points[indices[i, j], 2]
    cx, cy, cz = cx / (k + 1), cy / (k + 1), cz / (k + 1)
    dx, dy, dz = points[i, 0] - cx, points[i, 1] - cy, points[i, 2] - cz
    xx, xy, xz, yy, yz, zz = dx * dx, dx * dy, dx * dz, dy * dy, dy * dz, dz * dz
    for j in range(k):
        q = indices[i, j]
        xx, xy, xz, yy, yz, zz = _add_outer(
            xx, xy, xz, yy, yz, zz, points[q, 0] - cx, points[q, 1] - cy, points[q, 2] - cz
        )
    return xx, xy, xz, yy, yz, zz


@nb.njit(**_JIT)
def _add_outer(xx, xy, xz, yy, yz, zz, dx, dy, dz):
    """The six entries of a symmetric 3 x 3 sum plus those of ``d d^T``."""
    return xx + dx * dx, xy + dx * dy, xz + dx * dz, yy + dy * dy, yz + dy * dz, zz + dz * dz


@nb.njit(parallel=True, **_JIT)
def line_spread(points, indices):
    """(N,) ``sqrt(lambda_2 / lambda_1)`` of the covariance of each point with its neighbours ``indices`` (N, k).

    The compiled :func:`meshcurv._pointcloud_normals.line_spread`: the same closed form (Smith 1961).
    """
    n = indices.shape[0]
    out = np.ones(n)
    for i in nb.prange(n):
        xx, xy, xz, yy, yz, zz = _covariance(points, indices, i)
        mean = (xx + yy + zz) / 3
        sxx, syy, szz = xx - mean, yy - mean, zz - mean
        spread = np.sqrt((sxx * sxx + syy * syy + szz * szz + 2 * (xy * xy + xz * xz + yz * yz)) / 6)
        scale = spread if spread > 0 else 1.0
        bxx, byy, bzz, bxy, bxz, byz = sxx / scale, syy / scale, szz / scale, xy / scale, xz / scale, yz / scale
        half = 0.5 * (bxx * (byy * bzz - byz * byz) - bxy * (bxy * bzz - byz * bxz) + bxz * (bxy * byz - byy * bxz))
        angle = np.arccos(min(1.0, max(-1.0, half))) / 3
        largest = mean + 2 * spread * np.cos(angle)
        smallest = mean + 2 * spread * np.cos(angle + 2 * np.pi / 3)
        second = max(3 * mean - largest - smallest, 0.0)
        if largest > 0:
            out[i] = np.sqrt(second / largest)
    return out


@nb.njit(**_JIT)
def flat_balls(points, centres, index, counts, stride, iterations, offset, share, least, rows=None):
    """(M,) bool: the compiled :func:`meshcurv._pointcloud_estimators.flat_balls` (its constants as arguments).

    Every ``stride``-th column of each ball ``index`` (M, k) (its first ``counts`` are points); ``iterations`` of
    the power method from the farthest of them; a ball holds a surface when ``least`` and ``share`` of them lie
    farther than ``offset`` times the farthest one's distance from the line along the main direction.
    ``rows`` (R,): the balls to check (then (R,) bool; default: every ball), read in place.
    """
    if rows is None:
        return _flat_balls(
            points, centres, index, counts, stride, iterations, offset, share, least, np.arange(index.shape[0])
        )
    return _flat_balls(points, centres, index, counts, stride, iterations, offset, share, least, rows)


#: Runs of balls of a call of :func:`flat_balls`, shared out to the threads (a thread that finishes early takes
#: more; a constant, not per thread: ``numba.get_num_threads`` in a kernel keeps it out of the cache).
_FLAT_CHUNKS = 128


@nb.njit(parallel=True, **_JIT)
def _flat_balls(points, centres, index, counts, stride, iterations, offset, share, least, rows):
    """:func:`flat_balls` of the balls ``rows``: :data:`_FLAT_CHUNKS` runs of them shared out to the threads,
    each with a scratch of its own (:func:`_flat_chunk`)."""
    out = np.zeros(rows.shape[0], dtype=np.bool_)
    m = rows.shape[0]
    n_chunks = max(min(m, _FLAT_CHUNKS), 1)
    for chunk in nb.prange(n_chunks):
        lo, hi = chunk * m // n_chunks, (chunk + 1) * m // n_chunks
        _flat_chunk(lo, hi, points, centres, index, counts, (stride, iterations), (offset, share, least), rows, out)
    return out


@nb.njit(**_JIT)
def _flat_chunk(lo, hi, points, centres, index, counts, walk, test, rows, out):
    """The balls ``rows[lo:hi]`` of :func:`flat_balls`. The offsets of a ball's checked points, in units of its
    extent, are divided once and kept for the second pass that reads them (three divisions a point fewer: 12% of
    the kernel's time on one core); a function of its own, not the parallel loop's body, so that the scratch is
    the thread's own. ``walk``: ``(stride, iterations)``, ``test``: ``(offset, share, least)``."""
    stride, iterations = walk
    offset, share, least = test
    k = index.shape[1]
    offsets = np.empty((k // max(stride, 1) + 1, 3))
    for r in range(lo, hi):
        row = rows[r]
        c = centres[row]
        px, py, pz = points[c, 0], points[c, 1], points[c, 2]
        xx = xy = xz = yy = yz = zz = 0.0
        far, ux, uy, uz = 0.0, 0.0, 0.0, 0.0
        members = 0
        scale = 0.0  # the ball in units of its extent (as the NumPy path): no overflow at 1e75, no underflow
        for a in range(0, min(counts[row], k), stride):
            j = index[row, a]
            scale = max(scale, abs(points[j, 0] - px), abs(points[j, 1] - py), abs(points[j, 2] - pz))
        if scale == 0.0:
            scale = 1.0
        for a in range(0, min(counts[row], k), stride):
            j = index[row, a]
            dx, dy, dz = (points[j, 0] - px) / scale, (points[j, 1] - py) / scale, (points[j, 2] - pz) / scale
            offsets[members, 0], offsets[members, 1], offsets[members, 2] = dx, dy, dz
            xx, xy, xz, yy, yz, zz = _add_outer(xx, xy, xz, yy, yz, zz, dx, dy, dz)
            d = dx * dx + dy * dy + dz * dz
            if d > far:
                far, ux, uy, uz = d, dx, dy, dz
            members += 1
        for _ in range(iterations):
            vx, vy, vz = xx * ux + xy * uy + xz * uz, xy * ux + yy * uy + yz * uz, xz * ux + yz * uy + zz * uz
            length = max(np.sqrt(vx * vx + vy * vy + vz * vz), 2.2250738585072014e-308)
            ux, uy, uz = vx / length, vy / length, vz / length
        beside = 0
        limit = offset * offset * far
        for a in range(members):
            dx, dy, dz = offsets[a, 0], offsets[a, 1], offsets[a, 2]
            along = dx * ux + dy * uy + dz * uz
            if dx * dx + dy * dy + dz * dz - along * along > limit:
                beside += 1
        out[r] = beside >= max(least, share * members)


@nb.njit(parallel=True, **_JIT)
def pca_normals(points, indices):
    """(N, 3) unit least-variance directions of each point with its neighbours ``indices`` (N, k).

    The covariance ``A``'s smallest eigenvalue in closed form (Smith 1961:
    ``q + 2 p cos(acos(det(B) / 2) / 3 + 2 pi / 3)``, ``q = tr(A) / 3``,
    ``B = (A - q I) / p``), its eigenvector the longest cross product of two
    rows of ``A - lambda I`` (where that matrix has rank 1, :data:`RANK_ONE`, a
    direction orthogonal to its longest row). The NumPy path
    (:func:`meshcurv._pointcloud_normals.pca_normals`) uses ``numpy.linalg.eigh``:
    the same vector up to its sign (tests compare the two).
    """
    n = indices.shape[0]
    out = np.zeros((n, 3))
    for i in nb.prange(n):
        xx, xy, xz, yy, yz, zz = _covariance(points, indices, i)
        trace = xx + yy + zz  # in units of its trace: the rank test below squares squared rows (1e60^8 overflows)
        if trace > 0:
            xx, xy, xz, yy, yz, zz = xx / trace, xy / trace, xz / trace, yy / trace, yz / trace, zz / trace
        off = xy * xy + xz * xz + yz * yz
        mean = (xx + yy + zz) / 3
        spread = np.sqrt(((xx - mean) ** 2 + (yy - mean) ** 2 + (zz - mean) ** 2 + 2 * off) / 6)
        if not spread > 0:  # isotropic (or a single repeated point): every direction is as good
            out[i, 2] = 1.0
            continue
        bxx, byy, bzz = (xx - mean) / spread, (yy - mean) / spread, (zz - mean) / spread
        bxy, bxz, byz = xy / spread, xz / spread, yz / spread
        half = 0.5 * (bxx * (byy * bzz - byz * byz) - bxy * (bxy * bzz - byz * bxz) + bxz * (bxy * byz - byy * bxz))
        angle = np.arccos(min(1.0, max(-1.0, half))) / 3
        smallest = mean + 2 * spread * np.cos(angle + 2 * np.pi / 3)
        r0x, r0y, r0z = xx - smallest, xy, xz
        r1x, r1y, r1z = xy, yy - smallest, yz
        r2x, r2y, r2z = xz, yz, zz - smallest
        ax, ay, az = r0y * r1z - r0z * r1y, r0z * r1x - r0x * r1z, r0x * r1y - r0y * r1x
        bx, by, bz = r0y * r2z - r0z * r2y, r0z * r2x - r0x * r2z, r0x * r2y - r0y * r2x
        ex, ey, ez = r1y * r2z - r1z * r2y, r1z * r2x - r1x * r2z, r1x * r2y - r1y * r2x
        la, lb, le = ax * ax + ay * ay + az * az, bx * bx + by * by + bz * bz, ex * ex + ey * ey + ez * ez
        if lb > la and lb >= le:
            ax, ay, az, la = bx, by, bz, lb
        elif le > la:
            ax, ay, az, la = ex, ey, ez, le
        # the longest row of A - lambda I: along the largest eigenvector when the smallest eigenvalue is double
        # (a collinear neighbourhood), where A - lambda I has rank 1 and the cross products are rounding noise
        s0, s1, s2 = (
            r0x * r0x + r0y * r0y + r0z * r0z,
            r1x * r1x + r1y * r1y + r1z * r1z,
            r2x * r2x + r2y * r2y + r2z * r2z,
        )
        if s1 > s0 and s1 >= s2:
            r0x, r0y, r0z, s0 = r1x, r1y, r1z, s1
        elif s2 > s0:
            r0x, r0y, r0z, s0 = r2x, r2y, r2z, s2
        if not la > RANK_ONE * s0 * s0:  # any direction orthogonal to the line: the frame of the line's direction
            if not s0 > 0:
                out[i, 2] = 1.0
                continue
            root = np.sqrt(s0)
            ax, ay, az, _, _, _ = _tangent_frame(r0x / root, r0y / root, r0z / root)
            out[i, 0], out[i, 1], out[i, 2] = ax, ay, az
            continue
        length = np.sqrt(la)
        out[i, 0], out[i, 1], out[i, 2] = ax / length, ay / length, az / length
    return out


@nb.njit(**_JIT)
def _ball_buffers(size):
    """Scratch buffers of :func:`_search_ball` for balls of up to ``size`` candidates: the members, their squared
    distances and ids as found, then in order, and the buckets' starts."""
    return (
        np.empty(size, np.int64),
        np.empty(size),
        np.empty(size, np.int64),
        np.empty(size),
        np.empty(size, np.int64),
        np.empty(size + 1, np.int64),
    )


@nb.njit(**_JIT)
def _search_ball(pool_points, ids, grid, px, py, pz, radius, buffers):
    """``(buffers, found)``: the ``found`` points of the pool strictly closer than ``radius`` to ``(px, py, pz)``,
    their squared distances ``buffers[3][:found]`` and ids ``buffers[4][:found]`` in the order of ``(squared
    distance, id)`` (:func:`_ball_members`' candidates, :func:`_sort_ball`); the buffers (:func:`_ball_buffers`)
    grown when a ball needs more."""
    members, found_squared, found_ids, sorted_squared, sorted_ids, starts = buffers
    limit = radius * radius
    members, size = _ball_members(pool_points, grid, px, py, pz, radius, members)
    if size > found_squared.shape[0]:
        _, found_squared, found_ids, sorted_squared, sorted_ids, starts = _ball_buffers(members.shape[0])
    found = 0
    for a in range(size):  # (branch-free: every member written, the inside ones kept)
        t = members[a]
        dx, dy, dz = pool_points[t, 0] - px, pool_points[t, 1] - py, pool_points[t, 2] - pz
        d = dx * dx + dy * dy + dz * dz
        found_squared[found] = d
        found_ids[found] = ids[t]
        found += d < limit
    _sort_ball(found_squared, found_ids, found, limit, sorted_squared, sorted_ids, starts)
    return (members, found_squared, found_ids, sorted_squared, sorted_ids, starts), found


@nb.njit(inline="always", **_JIT)
def _bucket(squared, scale, found):
    """The bucket of ``squared`` among ``found`` (0 .. found - 1; the last when the product rounds up or is NaN:
    a limit so small that ``found / limit`` overflows)."""
    position = squared * scale
    return int(position) if position < found - 1 else found - 1


@nb.njit(inline="always", **_JIT)
def _sort_ball(squared, ids, found, limit, sorted_squared, sorted_ids, starts):
    """``sorted_squared, sorted_ids``: the first ``found`` of ``squared`` (each below ``limit``) and ``ids`` in the
    order of ``(squared, ids)``.

    A bucket sort (``found`` buckets of equal width in the squared distance: a surface's points spread evenly
    over them), then one insertion pass over the nearly sorted whole, which makes the order exact whatever the
    buckets' rounding: each point's rank is that of an insertion sort, in a third fewer instructions than
    inserting the points one by one into the row as they are met (the measures' ball search at 1M points: 2.6 ->
    1.9 CPU s).
    """
    if found == 0:
        return
    scale = found / limit
    for b in range(found + 1):
        starts[b] = 0
    for a in range(found):
        starts[_bucket(squared[a], scale, found) + 1] += 1
    for b in range(found):
        starts[b + 1] += starts[b]
    for a in range(found):
        b = _bucket(squared[a], scale, found)
        p = starts[b]
        sorted_squared[p] = squared[a]
        sorted_ids[p] = ids[a]
        starts[b] = p + 1
    for a in range(1, found):
        d, q = sorted_squared[a], sorted_ids[a]
        j = a
        while j > 0 and (sorted_squared[j - 1] > d or (sorted_squared[j - 1] == d and sorted_ids[j - 1] > q)):
            sorted_squared[j] = sorted_squared[j - 1]
            sorted_ids[j] = sorted_ids[j - 1]
            j -= 1
        sorted_squared[j] = d
        sorted_ids[j] = q


@nb.njit(inline="always", **_JIT)
def _unit_offset(points, j, c):
    """The unit offset from point ``c`` to point ``j`` (0 where they coincide)."""
    dx, dy, dz = points[j, 0] - points[c, 0], points[j, 1] - points[c, 1], points[j, 2] - points[c, 2]
    length = np.sqrt(dx * dx + dy * dy + dz * dz)
    if length > 0.0:
        return dx / length, dy / length, dz / length
    return 0.0, 0.0, 0.0


@nb.njit(inline="always", **_JIT)
def _tie_key(points, normals, j, c):
    """The place of point ``j`` among the points of the ball of ``c`` at its distance: a sum of four cosines of
    the unit offset ``u`` from ``c`` to ``j`` and the two normals (``n_c . u``, ``n_j . u``, ``n_c . n_j`` and
    ``n_c . (u x n_j)``) with weights of no common ratio, which rigid motions keep (the last one tells mirror images
    apart); +inf where it is NaN. The NumPy twin: :func:`meshcurv._pointcloud_estimators._tie_keys`."""
    ux, uy, uz = _unit_offset(points, j, c)
    ax, ay, az = normals[c, 0], normals[c, 1], normals[c, 2]
    bx, by, bz = normals[j, 0], normals[j, 1], normals[j, 2]
    height = ax * ux + ay * uy + az * uz
    slope = bx * ux + by * uy + bz * uz
    cosine = ax * bx + ay * by + az * bz
    twist = ax * (uy * bz - uz * by) + ay * (uz * bx - ux * bz) + az * (ux * by - uy * bx)
    key = height + 0.6180339887498949 * slope + 0.41421356237309515 * cosine + 0.3247179572447460 * twist
    return key if key == key else np.inf


@nb.njit(inline="always", **_JIT)
def _ball_direction(points, normals, c, ids, count, radius):
    """:func:`_tie_turn`'s direction of the ball of ``c`` (its ``count`` points ``ids``, in the order of (squared
    distance, index)): its mean offset plus ``radius`` times its mean turn of the normals; 0 for a centre without a
    normal (its ties by index, as its keys). The NumPy twin: in
    :func:`meshcurv._pointcloud_estimators._whole_ties`."""
    gx = gy = gz = hx = hy = hz = 0.0
    for a in range(count):
        q = ids[a]
        gx += points[q, 0] - points[c, 0]
        gy += points[q, 1] - points[c, 1]
        gz += points[q, 2] - points[c, 2]
        tx, ty, tz = normals[q, 0] - normals[c, 0], normals[q, 1] - normals[c, 1], normals[q, 2] - normals[c, 2]
        hx += tx if np.isfinite(tx) else 0.0
        hy += ty if np.isfinite(ty) else 0.0
        hz += tz if np.isfinite(tz) else 0.0
    if count > 0:
        gx, gy, gz = (gx + radius * hx) / count, (gy + radius * hy) / count, (gz + radius * hz) / count
    if not normals[c, 0] * normals[c, 0] + normals[c, 1] * normals[c, 1] + normals[c, 2] * normals[c, 2] > 0.0:
        gx = gy = gz = 0.0
    return gx, gy, gz


@nb.njit(inline="always", **_JIT)
def _tie_turn(points, normals, j, c, gx, gy, gz, radius):
    """The place of point ``j`` among the points of the ball of ``c`` whose :func:`_tie_key` it shares (a symmetry
    of the centre and the normals: a flat facet's points at one distance): ``(u . g + w n_c . (u x g)) / radius`` of
    the unit offset ``u`` from ``c`` to ``j`` and ``g`` the ball's mean offset plus ``radius`` times its mean turn of
    the normals, which rigid motions keep; +inf where it is NaN. The NumPy twin: :func:`meshcurv._pointcloud_estimators._tie_turns`."""
    ux, uy, uz = _unit_offset(points, j, c)
    ax, ay, az = normals[c, 0], normals[c, 1], normals[c, 2]
    along = ux * gx + uy * gy + uz * gz
    twist = ax * (uy * gz - uz * gy) + ay * (uz * gx - ux * gz) + az * (ux * gy - uy * gx)
    key = (along + 0.6180339887498949 * twist) / radius
    return key if key == key else np.inf


@nb.njit(**_JIT)
def _whole_row(points, normals, c, ids, squared, count, limit, tie, least, out, row, n, radius):
    """Row ``row`` of ``out`` (M, k) from the ball of point ``c``: its ``count`` points ``ids`` (K,) in the order of
    ``(squared distance, index)`` and their ``squared`` distances, cut to the radius and to ``k`` points with the
    points tied in distance taken or dropped whole and ordered among themselves by the geometry; returns its count.

    The compiled :func:`meshcurv._pointcloud_estimators._whole_ties` (see there): the points at the radius within
    ``tie`` (of the squared distance: ``limit`` is the squared radius less the tie) go; a row holding more than
    ``k`` loses the points tied with its ``k + 1``-th (unless fewer than ``least`` would be left: then its first
    ``k``); each run of points tied with the one before is sorted by :func:`_tie_key` (keys within ``tie``: by
    index, :func:`_sort_tied`, which takes the ball's mean offset and ``radius``). Padded with ``n``. ``ids`` and
    ``squared``: the search's buffers."""
    k = out.shape[1]
    while count > 0 and squared[count - 1] >= limit:
        count -= 1
    if count > k:
        cut = squared[k] * (1.0 - tie)
        keep = k
        while keep > 0 and squared[keep - 1] >= cut:
            keep -= 1
        count = keep if keep >= least else k
    for a in range(count):
        out[row, a] = ids[a]
    for a in range(count, k):
        out[row, a] = n
    start = 0
    found = False  # the ball's direction, read at its first run of tied points only (most balls have none)
    gx = gy = gz = 0.0
    for a in range(1, count + 1):
        if a == count or squared[a - 1] < squared[a] * (1.0 - tie):  # a run [start, a) ends
            if a - start > 1:
                if not found:
                    gx, gy, gz = _ball_direction(points, normals, c, ids, count, radius)
                    found = True
                _sort_tied(points, normals, c, out, row, start, a, tie, gx, gy, gz, radius)
            start = a
    return count


@nb.njit(parallel=True, **_JIT)
def measured_balls(
    points, normals, centres, radius, k, wide, k_wide, pool_points, ids, grid, sheets, tie, least, margin, n_chunks
):
    """The balls of :func:`meshcurv._pointcloud_estimators.corrected_measures` in one pass: ``(index, counts,
    wide_index, wide_counts)``, (M, k) and (M,) the balls of ``radius`` of the ``centres`` (M,), (M, k_wide) and
    (M,) those of ``wide`` (``k_wide`` 0: none, (M, 0)).

    Each ball is what the NumPy twin's steps give in turn, to the bit: the search (the ``k + 1`` nearest points
    strictly closer than the radius, in the order of ``(squared distance, index)``) over ``wide`` (``radius`` when
    ``k_wide`` is 0; the smaller balls: the prefix of each row closer than ``radius``), the ties cut whole and
    ordered (``tie``, ``least``: :func:`_whole_row`), the points facing away (``margin``) or on another of the
    ``sheets`` dropped (:func:`_own_row`).
    Each row is found, cut and written by its thread from its own buffers: no (M, K) squared distances and
    rows of the search written and read again (four passes over (M, K) arrays). ``k_wide >= k``; the pool:
    :func:`~meshcurv._kernels.neighborhoods.pool_grid` with a reach of the search's radius or more.
    """
    m = centres.shape[0]
    index = np.empty((m, k), dtype=np.int64)  # (each row written whole by its thread)
    counts = np.zeros(m, dtype=np.int64)
    wide_index = np.empty((m, k_wide), dtype=np.int64)
    wide_counts = np.zeros(m, dtype=np.int64)
    n_chunks = max(min(m, n_chunks), 1)
    for chunk in nb.prange(n_chunks):  # (flat arguments: a parallel loop takes no tuples of arrays)
        lo, hi = chunk * m // n_chunks, (chunk + 1) * m // n_chunks
        _chunk_measured_balls(
            lo,
            hi,
            points,
            normals,
            centres,
            sheets,
            pool_points,
            ids,
            grid,
            radius,
            wide,
            tie,
            least,
            margin,
            index,
            counts,
            wide_index,
            wide_counts,
        )
    return index, counts, wide_index, wide_counts


@nb.njit(**_JIT)
def _chunk_measured_balls(
    lo,
    hi,
    points,
    normals,
    centres,
    sheets,
    pool_points,
    ids,
    grid,
    radius,
    wide,
    tie,
    least,
    margin,
    index,
    counts,
    wide_index,
    wide_counts,
):
    """The rows ``lo:hi`` of :func:`measured_balls`, with scratch buffers of their own (a function of its own, not
    the parallel loop's body: numba hoists allocations of a fixed size out of that loop, and the threads would
    share them)."""
    n = points.shape[0]
    k, k_wide = index.shape[1], wide_index.shape[1]
    search = wide if k_wide > 0 else radius
    inner = radius * radius
    by_sheet = sheets.shape[0] == n
    buffers = _ball_buffers(256)
    for row in range(lo, hi):
        c = centres[row]
        buffers, found = _search_ball(pool_points, ids, grid, points[c, 0], points[c, 1], points[c, 2], search, buffers)
        sorted_squared, sorted_ids = buffers[3], buffers[4]
        own = sheets[c] if by_sheet else -1
        # the smaller ball: the search's first k + 1 points, the prefix closer than radius
        held = min(found, k + 1)
        if k_wide > 0:
            held = min(held, k_wide + 1)
        count = 0
        while count < held and sorted_squared[count] < inner:
            count += 1
        limit = inner * (1.0 - tie)
        count = _whole_row(
            points, normals, c, sorted_ids, sorted_squared, count, limit, tie, least, index, row, n, radius
        )
        counts[row] = _own_row(normals, c, index, row, count, sheets, own, margin, n)
        if k_wide > 0:
            count = _whole_row(
                points,
                normals,
                c,
                sorted_ids,
                sorted_squared,
                min(found, k_wide + 1),
                wide * wide * (1.0 - tie),
                tie,
                least,
                wide_index,
                row,
                n,
                wide,
            )
            wide_counts[row] = _own_row(normals, c, wide_index, row, count, sheets, own, margin, n)


@nb.njit(**_JIT)
def _sort_tied(points, normals, c, out, row, start, end, tie, gx, gy, gz, radius):
    """Sort ``out[row, start:end]`` by :func:`_tie_key`, keys within ``tie`` of the one before (a chain) by
    :func:`_tie_turn` (of the ball's direction ``g`` and ``radius``), those within ``tie`` of the one before by
    index: insertion sorts (a few points). Points whose keys differ by round-off alone (a symmetry of the ball: the
    same geometry) keep one order on both backends."""
    _sort_places(points, normals, c, out, row, start, end, gx, gy, gz, radius, False)
    first = start
    while first < end:
        stop = _chain_end(points, normals, c, out, row, first, end, tie, gx, gy, gz, radius, False)
        if stop - first > 1:
            _sort_places(points, normals, c, out, row, first, stop, gx, gy, gz, radius, True)
            inner = first
            while inner < stop:
                last = _chain_end(points, normals, c, out, row, inner, stop, tie, gx, gy, gz, radius, True)
                for b in range(inner + 1, last):  # by index
                    q = out[row, b]
                    j = b
                    while j > inner and out[row, j - 1] > q:
                        out[row, j] = out[row, j - 1]
                        j -= 1
                    out[row, j] = q
                inner = last
        first = stop


@nb.njit(inline="always", **_JIT)
def _place(points, normals, j, c, gx, gy, gz, radius, turn):
    """:func:`_tie_turn` of ``j`` (``turn``) or its :func:`_tie_key`."""
    return _tie_turn(points, normals, j, c, gx, gy, gz, radius) if turn else _tie_key(points, normals, j, c)


@nb.njit(**_JIT)
def _sort_places(points, normals, c, out, row, start, end, gx, gy, gz, radius, turn):
    """Sort ``out[row, start:end]`` by ``(`` :func:`_place` ``, index)``: an insertion sort."""
    for a in range(start + 1, end):
        q = out[row, a]
        key = _place(points, normals, q, c, gx, gy, gz, radius, turn)
        j = a
        while j > start:
            p = out[row, j - 1]
            other = _place(points, normals, p, c, gx, gy, gz, radius, turn)
            if not (other > key or (other == key and p > q)):
                break
            out[row, j] = p
            j -= 1
        out[row, j] = q


@nb.njit(**_JIT)
def _chain_end(points, normals, c, out, row, first, end, tie, gx, gy, gz, radius, turn):
    """The end of the chain of ``out[row, first:end]`` (sorted by :func:`_place`) from ``first``: the first point
    whose place is more than ``tie`` above the one before (``end`` when none)."""
    before = _place(points, normals, out[row, first], c, gx, gy, gz, radius, turn)
    for a in range(first + 1, end):
        key = _place(points, normals, out[row, a], c, gx, gy, gz, radius, turn)
        if key - before > tie:
            return a
        before = key
    return end


@nb.njit(**_JIT)
def _root(parent, flip, i):
    """The root of ``i`` in the union-find forest and whether ``i``'s sign is flipped relative to it.

    Halves the paths as it goes (each node then points to its grandparent,
    its flip relative to it updated).
    """
    flipped = 0
    while parent[i] != i:
        up = parent[i]
        if parent[up] != up:
            flip[i] ^= flip[up]
            parent[i] = parent[up]
        flipped ^= flip[i]
        i = parent[i]
    return i, flipped


@nb.njit(**_JIT)
def spanning_signs(n, rows, cols, opposite, order):
    """(N,) +1/-1 and (N,) component roots: signs propagated along the minimum spanning forest.

    Kruskal's algorithm over the edges ``(rows, cols)`` taken in ``order``
    (increasing weight), with a union-find that keeps each point's flip
    relative to its root: an edge that joins two trees sets the relative
    flip of their roots so that its ends differ by ``opposite`` (their normals
    point apart). The signs are then those of the propagation along the
    minimum spanning tree (Hoppe et al. 1992), each root +1.
    """
    parent = np.arange(n)
    flip = np.zeros(n, dtype=np.int8)
    size = np.ones(n, dtype=np.int64)
    for e in order:
        a, fa = _root(parent, flip, rows[e])
        b, fb = _root(parent, flip, cols[e])
        if a == b:
            continue
        if size[a] < size[b]:
            a, b = b, a
        parent[b] = a
        flip[b] = fa ^ fb ^ opposite[e]
        size[a] += size[b]
    signs = np.ones(n)
    roots = np.zeros(n, dtype=np.int64)
    for i in range(n):
        r, f = _root(parent, flip, i)
        roots[i] = r
        if f:
            signs[i] = -1.0
    return signs, roots


@nb.njit(parallel=True, **_JIT)
def edge_cosines(normals, indices):
    """(N, k) the cosines ``n_i . n_j`` of each point's normal with its neighbours' (``indices`` (N, k))."""
    n, k = indices.shape
    out = np.zeros((n, k))
    for i in nb.prange(n):
        for j in range(k):
            q = indices[i, j]
            out[i, j] = normals[i, 0] * normals[q, 0] + normals[i, 1] * normals[q, 1] + normals[i, 2] * normals[q, 2]
    return out


@nb.njit(parallel=True, **_JIT)
def far_winding(points, normals, weights, soft, sources, queries, reach_squared):
    """(M,) the sums ``sum_j w_j n_j . (p_j - q) / (|p_j - q|^2 + soft_j)^(3/2)`` over the far ``sources``.

    ``q`` = ``points[queries[i]]``, a source counted when its squared distance
    to ``q`` exceeds ``reach_squared[i]``; ``weights`` and ``soft`` (S,) per source. The
    far part of :func:`meshcurv._pointcloud_normals.winding_numbers` (times
    ``4 pi``); its NumPy path sums the same terms with arrays.
    """
    m = queries.shape[0]
    out = np.zeros(m)
    for i in nb.prange(m):
        q = queries[i]
        qx, qy, qz = points[q, 0], points[q, 1], points[q, 2]
        total = 0.0
        for j in range(sources.shape[0]):
            s = sources[j]
            dx, dy, dz = points[s, 0] - qx, points[s, 1] - qy, points[s, 2] - qz
            d = dx * dx + dy * dy + dz * dz
            if d > reach_squared[i]:
                d += soft[j]
                total += weights[j] * (dx * normals[s, 0] + dy * normals[s, 1] + dz * normals[s, 2]) / (d * np.sqrt(d))
        out[i] = total
    return out


@nb.njit(**_JIT)
def _own_row(normals, c, index, row, count, sheets, own, margin, n):
    """Row ``row`` of ``index`` less its points facing away from point ``c``, in place: the compiled
    :func:`meshcurv._pointcloud_estimators._own_side` (the ball of ``c``, ``count`` points; a point ``j`` goes when
    ``n_j . n_c < -margin``, or when ``sheets`` is not empty and ``j`` and ``c`` (``own``: its sheet, -1 for none)
    are on two sheets, both >= 0); the kept points stay in order, the row padded with ``n``. Returns its count."""
    cx, cy, cz = normals[c, 0], normals[c, 1], normals[c, 2]
    found = 0
    for a in range(count):
        j = index[row, a]
        if normals[j, 0] * cx + normals[j, 1] * cy + normals[j, 2] * cz < -margin:
            continue
        if own >= 0 and sheets[j] >= 0 and sheets[j] != own:
            continue
        index[row, found] = j
        found += 1
    for a in range(found, index.shape[1]):
        index[row, a] = n
    return found


@nb.njit(parallel=True, **_JIT)
def _neighbour_spacing(values, usable, indices, centres):
    """(M,) ``(values[c] + values[indices[c]].sum()) / (1 + count_nonzero(usable[indices[c]]))`` of the
    ``centres`` (M,) (``indices`` (N, k), k at most 128): the mean spacing of :func:`meshcurv.pointcloud._radius_groups`
    on every core, without its (M, k) gathers (1M points: 0.24 CPU s on one core). The row's sum as NumPy's
    ``sum(axis=1)`` adds it (its pairwise sum: below 8 terms left to right, else eight running sums of every
    eighth term, added in pairs, then the terms left over): the same numbers to the bit."""
    m = centres.shape[0]
    k = indices.shape[1]
    out = np.zeros(m)
    for row in nb.prange(m):
        c = centres[row]
        count = 0
        for j in range(k):
            count += usable[indices[c, j]]
        if k < 8:
            total = 0.0 if k == 0 else values[indices[c, 0]]
            for j in range(1, k):
                total += values[indices[c, j]]
        else:
            r0, r1, r2, r3 = values[indices[c, 0]], values[indices[c, 1]], values[indices[c, 2]], values[indices[c, 3]]
            r4, r5, r6, r7 = values[indices[c, 4]], values[indices[c, 5]], values[indices[c, 6]], values[indices[c, 7]]
            j = 8
            while j + 8 <= k:
                r0 += values[indices[c, j]]
                r1 += values[indices[c, j + 1]]
                r2 += values[indices[c, j + 2]]
                r3 += values[indices[c, j + 3]]
                r4 += values[indices[c, j + 4]]
                r5 += values[indices[c, j + 5]]
                r6 += values[indices[c, j + 6]]
                r7 += values[indices[c, j + 7]]
                j += 8
            total = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
            while j < k:
                total += values[indices[c, j]]
                j += 1
        out[row] = (values[c] + total) / (1.0 + count)
    return out


@nb.njit(parallel=True, **_JIT)
def graph_edges(points, normals, indices, usable):
    """The edges of the graph ``indices`` (N, k) between ``usable`` points, and their geometry, in one pass.

    Returns ``rows, cols`` (E,) (the edges ``i -> indices[i, c]``, both ends usable and distinct, in the order
    of the rows of ``indices``), ``kept`` (N k,) (which entries of ``indices`` they are), and (E,) ``ahead`` =
    ``n_i . d``, ``behind`` = ``n_j . d``, ``cosine`` = ``n_i . n_j`` and ``slope`` = ``max(|ahead|, |behind|) /
    |d|`` of ``d = p_j - p_i`` (NaN where ``|d|`` is 0): the compiled
    :func:`meshcurv._pointcloud_normals._graph_geometry`, on every core instead of NumPy over (E,) arrays (each
    product's three terms added left to right).
    """
    n, k = indices.shape
    kept = np.zeros(n * k, dtype=np.bool_)
    starts = np.zeros(n + 1, dtype=np.int64)
    for i in nb.prange(n):
        found = 0
        if usable[i]:
            for c in range(k):
                j = indices[i, c]
                if usable[j] and j != i:
                    kept[i * k + c] = True
                    found += 1
        starts[i + 1] = found
    for i in range(n):
        starts[i + 1] += starts[i]
    e = starts[n]
    rows, cols = np.zeros(e, dtype=np.int64), np.zeros(e, dtype=np.int64)
    ahead, behind, cosine, slope = np.zeros(e), np.zeros(e), np.zeros(e), np.zeros(e)
    for i in nb.prange(n):
        t = starts[i]
        px, py, pz = points[i, 0], points[i, 1], points[i, 2]
        ax, ay, az = normals[i, 0], normals[i, 1], normals[i, 2]
        for c in range(k):
            if not kept[i * k + c]:
                continue
            j = indices[i, c]
            dx, dy, dz = points[j, 0] - px, points[j, 1] - py, points[j, 2] - pz
            bx, by, bz = normals[j, 0], normals[j, 1], normals[j, 2]
            length = np.sqrt(dx * dx + dy * dy + dz * dz)
            a = dx * ax + dy * ay + dz * az
            b = dx * bx + dy * by + dz * bz
            rows[t], cols[t] = i, j
            ahead[t], behind[t], cosine[t] = a, b, ax * bx + ay * by + az * bz
            larger = abs(a) if abs(a) >= abs(b) or a != a else abs(b)  # numpy.maximum: NaN wins
            slope[t] = larger / length
            t += 1
    return rows, cols, kept, ahead, behind, cosine, slope


@nb.njit(parallel=True, **_JIT)
def edge_weights(flat, ahead, behind, cosine, slope, spacing, rows, cols, offset, facing):
    """(E,) ``stacked``, ``weights`` and ``opposite`` of the edges of
    :func:`meshcurv._pointcloud_normals.oriented_signs`: the compiled
    :func:`meshcurv._pointcloud_normals._edge_weights`, the same operations (``offset``: ``STACKED_OFFSET``,
    ``facing``: ``FACING_COSINE``).

    An edge not ``flat`` is stacked when ``|cosine| >= facing``, both ends at least ``offset`` times the mean
    ``spacing`` of its ends off the other's tangent plane, on the sides parallel planes give
    (``ahead behind cosine > 0``). Weights: ``3 + (1 - |cosine|)`` for stacked edges, else ``1 - |cosine| +
    slope + 1e-6`` (a NaN slope read as 0); ``opposite``: ``cosine < 0`` unless stacked (then reversed).
    """
    e = flat.shape[0]
    stacked = np.zeros(e, dtype=np.bool_)
    weights = np.zeros(e)
    opposite = np.zeros(e, dtype=np.bool_)
    half = offset * 0.5
    for t in nb.prange(e):
        a, b, c = ahead[t], behind[t], cosine[t]
        reach = half * (spacing[rows[t]] + spacing[cols[t]])
        near = abs(a) if abs(a) <= abs(b) or a != a else abs(b)  # numpy.minimum: NaN wins
        up = (not flat[t]) and abs(c) >= facing and near >= reach and a * b * c > 0
        stacked[t] = up
        if up:
            weights[t] = 3.0 + (1.0 - min(abs(c), 1.0))  # |cos| rounds up to 1 + 4e-16: stacked stays >= 3
        else:
            s = slope[t]
            if s != s:
                s = 0.0
            elif s == np.inf:
                s = 1.7976931348623157e308
            elif s == -np.inf:
                s = -1.7976931348623157e308
            weights[t] = 1.0 - abs(c) + s + 1e-6
        opposite[t] = (c < 0) != up
    return stacked, weights, opposite


@nb.njit(parallel=True, **_JIT)
def stacked(points, normals, usable, queries, near, ring, offset, tilt_factor, facing, alike, tie, least):
    """(M, k) bool: the compiled :func:`meshcurv._pointcloud_normals._stacked` (its constants as arguments).

    ``near`` (M, k) the neighbours of ``queries`` (M,), ``ring``: how many of them after the first give the tilt
    (the median angle of the query's normal to theirs; those tied within ``tie`` with the next beyond dropped whole
    unless fewer than ``least`` would be left, as :func:`cut_neighbours`); ``offset``: the reach at distance 0;
    ``tilt_factor``: its growth per unit of distance and of tilt; ``facing``: the cosine; ``alike``: normals the
    same way (else opposite).
    """
    m, k = near.shape
    out = np.zeros((m, k), dtype=np.bool_)
    for row in nb.prange(m):
        q = queries[row]
        px, py, pz = points[q, 0], points[q, 1], points[q, 2]
        ax, ay, az = normals[q, 0], normals[q, 1], normals[q, 2]
        used = ring
        if ring + 1 < k and near[row, ring + 1] != q:
            j = near[row, ring + 1]
            dx, dy, dz = points[j, 0] - px, points[j, 1] - py, points[j, 2] - pz
            cut = np.sqrt(dx * dx + dy * dy + dz * dz) * (1.0 - tie)
            kept = ring
            while kept > 0:
                j = near[row, kept]
                dx, dy, dz = points[j, 0] - px, points[j, 1] - py, points[j, 2] - pz
                if np.sqrt(dx * dx + dy * dy + dz * dz) < cut:
                    break
                kept -= 1
            if kept >= min(least, ring):
                used = kept
        angles = np.empty(used)
        for c in range(used):
            j = near[row, c + 1]
            angles[c] = np.arccos(min(abs(ax * normals[j, 0] + ay * normals[j, 1] + az * normals[j, 2]), 1.0))
        angles.sort()
        half = used // 2
        tilt = angles[half] if used % 2 else 0.5 * (angles[half - 1] + angles[half])
        for c in range(k):
            j = near[row, c]
            if j == q or not usable[j]:
                continue
            dx, dy, dz = points[j, 0] - px, points[j, 1] - py, points[j, 2] - pz
            ahead = dx * ax + dy * ay + dz * az
            behind = dx * normals[j, 0] + dy * normals[j, 1] + dz * normals[j, 2]
            cosine = ax * normals[j, 0] + ay * normals[j, 1] + az * normals[j, 2]
            if alike:
                if not (cosine >= facing and ahead * behind > 0):
                    continue
            elif not (cosine <= -facing and ahead * behind < 0):
                continue
            reach = offset + tilt_factor * tilt * np.sqrt(dx * dx + dy * dy + dz * dz)
            out[row, c] = min(abs(ahead), abs(behind)) >= reach
    return out


@nb.njit(parallel=True, **_JIT)
def nearest_neighbours(points, k, reach, pool_points, ids, grid, n_chunks):
    """(N, k) distances and indices of the ``k`` nearest other points of each point, and (N,) which rows are exact.

    The candidates of each point are those of the grid ``(pool_points, ids, grid)`` of all the points
    (:func:`~meshcurv._kernels.neighborhoods.pool_grid` with a reach of ``reach`` or more) closer than
    ``reach``; the ``k + 1`` nearest are kept in distance order. A row is exact when ``k + 1`` others lie
    closer than ``reach`` at distinct distances, the first above 0: its ``k`` nearest and their order are then
    the only ones, those of :meth:`scipy.spatial.cKDTree.query` less the point itself, to the bit (the
    distance is the square root of ``dx^2 + dy^2 + dz^2`` summed in that order, as the k-d tree's). The other
    rows (ties, sparse parts, outliers) are for the caller to search again. ``n_chunks``: runs of points
    shared out to the threads.
    """
    n = points.shape[0]
    distances = np.zeros((n, k))
    indices = np.zeros((n, k), dtype=np.int64)
    exact = np.zeros(n, dtype=np.bool_)
    limit = reach * reach
    n_chunks = max(min(n, n_chunks), 1)
    for chunk in nb.prange(n_chunks):
        members = np.empty(256, np.int64)
        best = np.empty(k + 1)
        which = np.empty(k + 1, np.int64)
        for c in range(chunk * n // n_chunks, (chunk + 1) * n // n_chunks):
            px, py, pz = points[c, 0], points[c, 1], points[c, 2]
            members, size = _ball_members(pool_points, grid, px, py, pz, reach, members)
            found = 0
            for a in range(size):
                t = members[a]
                q = ids[t]
                if q == c:
                    continue
                dx, dy, dz = pool_points[t, 0] - px, pool_points[t, 1] - py, pool_points[t, 2] - pz
                d = dx * dx + dy * dy + dz * dz
                if not d < limit or (found == k + 1 and not d < best[k]):
                    continue
                j = found if found <= k else k  # insert in order, dropping the last when full
                while j > 0 and best[j - 1] > d:
                    best[j] = best[j - 1]
                    which[j] = which[j - 1]
                    j -= 1
                best[j] = d
                which[j] = q
                if found <= k:
                    found += 1
            ok = found == k + 1 and best[0] > 0.0
            for j in range(min(found, k)):
                ok = ok and best[j] < best[j + 1]
                distances[c, j] = np.sqrt(best[j])
                indices[c, j] = which[j]
            exact[c] = ok
    return distances, indices, exact


@nb.njit(parallel=True, **_JIT)
def cut_neighbours(distances, indices, k, centres, tolerance, least):
    """(N, k) distances and indices: the nearest neighbours ``distances, indices`` (N, k + 1) cut to ``k``, a
    group tied (within ``tolerance``) with the ``k + 1``-th dropped whole unless fewer than ``least`` would be
    left, its slots holding the row's point (``centres`` (N,), or the row's number when empty) at the cut's
    distance.

    The compiled :func:`meshcurv._pointcloud_normals._cut_neighbours` (see
    :func:`meshcurv._pointcloud_normals.whole_ties`): the same products and comparisons, each row copied and cut
    by its thread (no serial copies of the (N, k) columns, no gathered rows).
    """
    n = distances.shape[0]
    out_distances = np.empty((n, k))
    out_indices = np.empty((n, k), dtype=np.int64)
    shrink = 1.0 - tolerance
    least = min(least, k)
    by_centre = centres.shape[0] == n
    for row in nb.prange(n):
        cut = distances[row, k]
        bound = cut * shrink
        tied = 0
        for a in range(k):
            out_distances[row, a] = distances[row, a]
            out_indices[row, a] = indices[row, a]
            tied += distances[row, a] >= bound
        if not distances[row, k - 1] >= bound or k - tied < least:
            continue
        own = centres[row] if by_centre else row
        for a in range(k):
            if distances[row, a] >= bound:
                out_distances[row, a] = cut
                out_indices[row, a] = own
    return out_distances, out_indices


@nb.njit(**_JIT)
def kept_rows(distances, indices, keep):
    """The nearest neighbours ``distances, indices`` (N, k) of the points ``keep`` (N,) renumbered among them, in
    place: ``(m, again)``, the kept rows the first ``m`` (in order), and (m,) the rows that held a point not kept.

    The compiled :func:`meshcurv.pointcloud._kept_rows` (the index of a point not kept is that of the last kept
    point before it, as ``cumsum(keep) - 1`` gives; those rows are for the caller to search again): one pass
    without (N, k) copies. Each row moves up (to its kept rank, at most its own), after it was read.
    """
    n, k = indices.shape
    position = np.zeros(n, dtype=np.int64)
    m = 0
    for i in range(n):
        if keep[i]:
            m += 1
        position[i] = m - 1
    again = np.zeros(m, dtype=np.bool_)
    for i in range(n):
        if not keep[i]:
            continue
        row = position[i]
        for j in range(k):
            q = indices[i, j]
            if not keep[q]:
                again[row] = True
            distances[row, j] = distances[i, j]
            indices[row, j] = position[q]
    return m, again


@nb.njit(parallel=True, **_JIT)
def neighbour_differences(k_min, k_max, indices, valid, spacing, flat_turn, n_chunks):
    """(N,) the median over the neighbours ``indices`` (N, k) of a ``valid`` point of how far their principal
    curvatures are from its own, in units of the smaller largest ``|k|`` (at least ``flat_turn / (3 spacing)``).

    The compiled :func:`meshcurv._pointcloud_estimators.erratic`'s ``typical``: the neighbours with an estimate
    (``k_min`` and ``k_max`` finite) count; NaN where none does and at the points not ``valid``. The median of an
    even count is the mean of the two middle values, as :func:`numpy.nanmedian`'s (of an odd count, the middle
    one added to itself and halved, as there). ``n_chunks``: runs of points shared out to the threads.
    """
    n, k = indices.shape
    out = np.full(n, np.nan)
    n_chunks = max(min(n, n_chunks), 1)
    for chunk in nb.prange(n_chunks):
        values = np.empty(max(k, 1))
        for i in range(chunk * n // n_chunks, (chunk + 1) * n // n_chunks):
            if not valid[i]:
                continue
            a0, a1 = k_min[i], k_max[i]
            if not (np.isfinite(a0) and np.isfinite(a1)):
                continue  # (NaN: no estimate reproduces it)
            big = max(abs(a0), abs(a1))
            floor = flat_turn / (3.0 * spacing[i])
            m = 0
            for j in range(k):
                q = indices[i, j]
                b0, b1 = k_min[q], k_max[q]
                if not (np.isfinite(b0) and np.isfinite(b1)):
                    continue
                scale = max(min(big, max(abs(b0), abs(b1))), floor)
                d = max(abs(b0 - a0), abs(b1 - a1)) / scale
                t = m  # insert in order
                while t > 0 and values[t - 1] > d:
                    values[t] = values[t - 1]
                    t -= 1
                values[t] = d
                m += 1
            if m:
                high = m // 2
                low = high if m % 2 else high - 1
                out[i] = (values[low] + values[high]) / 2.0
    return out
