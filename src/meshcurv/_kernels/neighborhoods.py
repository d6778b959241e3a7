"""Compiled twins of :mod:`meshcurv.neighborhoods`: balls on a grid of cells and surface-connected
balls walked over the mesh, and the sums of face values over them.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ._common import _JIT, _ONE, _UNSIGNED, run_chunks, run_slots, threaded
from .geometry import _unadvised_array  # (also the ball sums' arrays, for ..neighborhoods)
from .topology import _BUCKET_CHUNKS, _bucket_starts, _find


#: A ball grid has at most this many columns of cells per point (and at least 4096 in all).
_GRID_COLUMNS_PER_POINT = 4


@threaded
def vertex_face_lists(faces, n_vertices, n_chunks):
    """CSR lists of the faces around every vertex: ``(indptr, indices)``, faces in index order.

    Each of ``n_chunks`` ranges of faces (at most :data:`~meshcurv._kernels.topology._BUCKET_CHUNKS`)
    counts, then places, the corners of its own faces, on threads (:func:`_count_corners`,
    :func:`_place_corners`, :func:`~meshcurv._kernels._common.run_chunks`): a vertex's list holds the
    faces of the first range, then of the next, each in face order (the order of one pass
    over all faces, whatever the number of threads), as ``topology.build_edges`` places its sides.
    The faces are int32 while their count fits in it (half the memory of the lists, which the walks read for
    every vertex they queue), int64 beyond.
    """
    n_faces = faces.shape[0]
    n_chunks = max(1, min(int(n_chunks), _BUCKET_CHUNKS, n_faces))
    # cursor[c, v]: corners of face range c at vertex v, then where range c's next such face goes
    cursor = np.zeros((n_chunks, n_vertices), np.int64)
    run_chunks(_count_corners, n_chunks, n_chunks, faces, cursor)
    indptr = _bucket_starts(cursor)
    indices = np.empty(indptr[n_vertices], np.int32 if n_faces < np.iinfo(np.int32).max else np.int64)
    run_chunks(_place_corners, n_chunks, n_chunks, faces, cursor, indices)
    return indptr, indices


@nb.njit(**_JIT)
def _count_corners(lo, hi, faces, cursor):
    """:func:`vertex_face_lists`' counts of the face ranges ``lo`` to ``hi - 1`` in ``cursor``."""
    n_faces, corners = faces.shape
    n_chunks = cursor.shape[0]
    for c in range(lo, hi):
        counts = cursor[c]
        for f in range(n_faces * c // n_chunks, n_faces * (c + 1) // n_chunks):
            for k in range(corners):
                counts[_UNSIGNED(faces[f, k])] += 1  # unsigned: no code for negative indices


@nb.njit(**_JIT)
def _place_corners(lo, hi, faces, cursor, indices):
    """:func:`vertex_face_lists`' placing of the faces of the face ranges ``lo`` to ``hi - 1``."""
    n_faces, corners = faces.shape
    n_chunks = cursor.shape[0]
    for c in range(lo, hi):
        fill = cursor[c]
        for f in range(n_faces * c // n_chunks, n_faces * (c + 1) // n_chunks):
            for k in range(corners):
                a = _UNSIGNED(faces[f, k])  # unsigned: no code for negative indices
                indices[_UNSIGNED(fill[a])] = f
                fill[a] += 1


@nb.njit(**_JIT)
def _merge_sort_column(levels, order, first, last):
    """``levels[first:last]`` sorted, stably, and ``order[first:last]`` moved with them: a bottom-up merge sort
    (what ``np.argsort(kind="mergesort")`` and two fancy-indexed assignments gave, the same order: a stable sort
    has one result). Written out: numba's argsort and the assignments' shape checks (their error messages)
    compiled 2.5-3 s of the default's cold compile (issue 31)."""
    n = last - first
    keys, values = np.empty(n, np.int64), np.empty(n, np.int64)
    spare_keys, spare_values = np.empty(n, np.int64), np.empty(n, np.int64)
    for k in range(n):
        keys[k], values[k] = levels[first + k], order[first + k]
    width = 1
    while width < n:
        for start in range(0, n, 2 * width):
            middle = start + width if start + width < n else n
            end = start + 2 * width if start + 2 * width < n else n
            i, j = start, middle
            for k in range(start, end):
                if j >= end or (i < middle and keys[i] <= keys[j]):  # ties: the left run's first (stable)
                    spare_keys[k], spare_values[k] = keys[i], values[i]
                    i += 1
                else:
                    spare_keys[k], spare_values[k] = keys[j], values[j]
                    j += 1
        keys, spare_keys = spare_keys, keys
        values, spare_values = spare_values, values
        width *= 2
    for k in range(n):
        levels[first + k], order[first + k] = keys[k], values[k]


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
    lo = np.empty(3)  # zeros (without numba's np.zeros and its fill: issue 31)
    hi = np.empty(3)
    for a in range(3):  # the bounds as points[:, a].min() and .max() (NaN if any is), without compiling them
        lo[a] = hi[a] = 0.0
        if n:
            low = high = points[0, a]
            for i in range(1, n):
                x = points[i, a]
                low = x if x < low or x != x else low  # (a NaN bound stays NaN: no comparison is true)
                high = x if x > high or x != x else high
            lo[a], hi[a] = low, high
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
    starts = np.empty(nx * ny + 1, np.int64)
    for c in range(nx * ny + 1):  # zeros, as above
        starts[c] = 0
    for i in range(n):
        here = np.int64((points[i, 0] - lo[0]) / cell) * ny + np.int64((points[i, 1] - lo[1]) / cell)
        column[i] = here
        starts[here + 1] += 1
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
            _merge_sort_column(levels, order, first, last)
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
def pool_grid(points, pool, reach):
    """``(pool_points, ids, grid)``: the points ``pool`` (int64 ids) sorted into a grid of cells of side ``reach``
    or more (:func:`_grid`), their coordinates in that order and their ids.

    The search structure of ``pointcloud.measured_balls``, ``pointcloud.nearest_neighbours`` and ``jets.fit_jets``
    (balls on a grid),
    built once for all the centres of a computation.
    """
    m = pool.shape[0]
    gathered = np.empty((m, 3))
    # coordinate by coordinate: a row assigned whole compiles numba's shape checks and their messages (1.9 s)
    for k in range(m):
        for a in range(3):
            gathered[k, a] = points[pool[k], a]
    grid = _grid(gathered, reach)
    order = grid[0]
    pool_points = np.empty((m, 3))
    ids = np.empty(m, np.int64)
    for k in range(m):
        for a in range(3):
            pool_points[k, a] = gathered[order[k], a]
        ids[k] = pool[order[k]]
    return pool_points, ids, grid


#: Cells nearer than this share of a cell to a ball's surface are walked (the rounding of the cells' bounds).
_WALK_SLACK = 0.01


@nb.njit(**_JIT)
def _ball_members(points, grid, cx, cy, cz, cutoff, out):
    """Ranks of the points within ``cutoff`` of ``(cx, cy, cz)`` written to ``out`` (grown when full).

    ``points`` are in the order of ``grid`` (:func:`_grid`), so that the
    cells of a column around the centre are one contiguous run of memory.
    Returns ``(out, count)``; the ranks come in increasing order (columns by
    ``x`` cell, then ``y`` cell, each by ``z`` cell: the order of ``grid``).

    The candidates are the cells of the cube of ``2 ceil(cutoff / cell) + 1``
    cells a side around the centre's cell that the ball reaches: the columns
    whose ``x, y`` rectangle lies within ``cutoff`` of the centre and, in each,
    the ``z`` cells within ``sqrt(cutoff^2 - d_xy^2)`` (each bound widened by
    :data:`_WALK_SLACK` cells and by the rounding of the coordinates: a point
    skipped fails the distance test, so the members are those of the whole
    cube, in the same order, from fewer candidates).
    """
    _, starts, levels, lo, cell, nx, ny = grid
    fx = (cx - lo[0]) / cell
    fy = (cy - lo[1]) / cell
    fz = (cz - lo[2]) / cell
    cutoff2 = cutoff * cutoff
    count = 0
    span = np.int64(math.ceil(cutoff / cell))  # cells each way from the centre's
    if not (
        fx > -1 - span and fy > -1 - span and fz > -1 - span and fx < nx + span and fy < ny + span and fz < 2.0**61
    ):
        return out, count
    bx = np.int64(math.floor(fx))
    by = np.int64(math.floor(fy))
    bz = np.int64(math.floor(fz))
    reach = cutoff / cell
    slack = _WALK_SLACK + 1e-12 * (abs(fx) + abs(fy) + abs(fz) + (abs(cx) + abs(cy) + abs(cz)) / cell)
    for ix in range(max(bx - span, np.int64(0)), min(bx + span + 1, nx)):
        gx = max(max(ix - fx, fx - ix - 1.0) - slack, 0.0)  # from the centre to the column's x range, in cells
        for iy in range(max(by - span, np.int64(0)), min(by + span + 1, ny)):
            gy = max(max(iy - fy, fy - iy - 1.0) - slack, 0.0)
            rest = reach * reach - gx * gx - gy * gy
            if rest < 0.0:
                continue
            half = math.sqrt(rest) + slack
            bottom = max(np.int64(math.floor(fz - half)), bz - span)
            top = min(np.int64(math.floor(fz + half)), bz + span)
            c = ix * ny + iy
            k = starts[c]
            last = starts[c + 1]
            high = last
            while k < high:  # first rank of the column at z cell `bottom` or above
                middle = (k + high) // 2
                if levels[middle] < bottom:
                    k = middle + 1
                else:
                    high = middle
            end = k
            while end < last and levels[end] <= top:
                end += 1
            if count + end - k > out.shape[0]:
                grown = np.empty(2 * (count + end - k), np.int64)
                for rank in range(count):  # (a slice assigned compiles numba's shape checks: 1.9 s)
                    grown[rank] = out[rank]
                out = grown
            for j in range(k, end):  # branch-free: every candidate is written, the inside ones kept
                dx = points[j, 0] - cx
                dy = points[j, 1] - cy
                dz = points[j, 2] - cz
                out[count] = j
                count += dx * dx + dy * dy + dz * dz <= cutoff2
    return out, count


@nb.njit(**_JIT)
def _pair_counts(probe, probe2, x, y, z, sub2, limits, out):
    """``out[i]``: the sample points ``(x, y, z)`` within ``sqrt(limits[i])`` of ``probe[i]`` (``limits`` (P,), or
    (1,): one for all), by ``neighborhoods._pairs_within``'s squared distances: ``(|p|^2 + |s|^2) - 2 (p_x s_x) -
    2 (p_y s_y) - 2 (p_z s_z)`` (``probe2``, ``sub2``: the squared lengths), the operations of its NumPy blocks
    in their order, so the same counts (issue 30: 3-4 ms a call in NumPy, four calls a dense voxel call)."""
    one = limits.shape[0] == 1
    for i in range(probe.shape[0]):
        limit = limits[0 if one else i]
        px, py, pz = probe[i, 0], probe[i, 1], probe[i, 2]
        p2 = probe2[i]
        count = 0
        for j in range(x.shape[0]):
            d = p2 + sub2[j]
            d = d - 2.0 * (px * x[j])
            d = d - 2.0 * (py * y[j])
            d = d - 2.0 * (pz * z[j])
            if d <= limit:
                count += 1
        out[i] = count


@nb.njit(inline="always", **_JIT)
def _segment_meets_ball(ax, ay, az, bx, by, bz, radius2):
    """Whether the segment from ``a`` to ``b`` (relative to the ball's centre, both ends outside
    the ball) passes through it: its closest point to the centre is inside and not an end. From the
    end nearer the centre, the closest point itself (``|a|^2 |d|^2 - (a.d)^2`` cancels on a segment far
    longer than the ball: a spike's edge; issue 29)."""
    if (bx * bx + by * by) + bz * bz < (ax * ax + ay * ay) + az * az:
        ax, ay, az, bx, by, bz = bx, by, bz, ax, ay, az
    dx, dy, dz = bx - ax, by - ay, bz - az
    along = -((ax * dx + ay * dy) + az * dz)  # the closest point is a + (along / |d|^2) d, clamped to the segment
    if not along > 0:
        return False  # the segment leads away from the centre: a is its closest point
    length2 = (dx * dx + dy * dy) + dz * dz
    if not along < length2:
        return False  # b is its closest point
    share = along / length2
    hx = ax + share * dx
    hy = ay + share * dy
    hz = az + share * dz
    return (hx * hx + hy * hy) + hz * hz <= radius2


#: :func:`_outside_edge_meets` widens a vertex's reach by this share: the round-off of the distances it compares
#: (relative to those distances, each a difference of two coordinates rounded once) stays far below it.
_FAR_SLACK = 1e-9


@threaded
def _vertex_spans(vertices, indptr, indices):
    """(V,) the length of the longest edge at each vertex of the CSR lists ``indptr, indices`` (0 without edges):
    what the walks of :func:`_connected_members` read to leave out, at the first look, the vertices no edge of
    which meets a ball (:func:`_outside_edge_meets`). Ranges of vertices on threads
    (:func:`~._common.run_chunks`)."""
    n = vertices.shape[0]
    spans = np.zeros(n)
    run_chunks(_spans_chunk, n, 4 * nb.get_num_threads(), vertices, indptr, indices, spans)
    return spans


@nb.njit(**_JIT)
def _spans_chunk(lo, hi, vertices, indptr, indices, spans):
    """:func:`_vertex_spans` of the vertices ``lo`` to ``hi - 1``."""
    for a in range(lo, hi):
        longest = 0.0
        for j in range(indptr[a], indptr[a + 1]):
            b = indices[j]
            length = math.sqrt(
                (vertices[b, 0] - vertices[a, 0]) ** 2
                + (vertices[b, 1] - vertices[a, 1]) ** 2
                + (vertices[b, 2] - vertices[a, 2]) ** 2
            )
            longest = length if length > longest else longest
        spans[a] = longest


@nb.njit(inline="always", **_JIT)
def _outside_edge_meets(spans, b, b2, cutoff, mark, stamp, ax, ay, az, bx, by, bz, cutoff2):
    """Whether the edge from ``a`` to ``b``, both outside the ball ``B(x, cutoff)`` (relative to ``x``; ``b2``:
    ``|b|^2``), passes through it (:func:`_segment_meets_ball`). With ``spans`` (not None), a vertex ``b``
    farther from the ball than its longest edge ``spans[b]`` (with :data:`_FAR_SLACK`) is stamped in ``mark``
    first and False returned: none of its edges meets the ball, so no walk of the ball queues it, and the other
    edges that reach it skip it at the stamp."""
    if spans is not None:
        reach = (cutoff + spans[b]) * (1.0 + _FAR_SLACK)
        if b2 > reach * reach:
            mark[b] = stamp
            return False
    return _segment_meets_ball(ax, ay, az, bx, by, bz, cutoff2)


@nb.njit(**_JIT)
def _connected_members(vertices, indptr, indices, allowed, v, cutoff, mark, stamp, members, queue, spans=None):
    """The vertices of the surface-connected piece of the ball ``B(x_v, cutoff)`` written to ``members``.

    Breadth-first from ``v`` over the edges ``indptr, indices`` (CSR) that meet
    the closed ball (an end inside, or the segment passing through it): every
    vertex within ``cutoff`` reached so (and ``allowed``) is a member, ``v``
    first when allowed. When the ball's part of the surface is connected these
    are exactly the vertices of the Euclidean ball (a path inside it crosses
    from face to face through edges that meet it, and every edge of a face
    meets the ball at a corner shared with the next such edge); vertices of
    another sheet of the surface (the far side of a part thinner than the
    ball) are left out. ``mark`` (V,) holds, per vertex, the ``stamp`` (>= 0) of the
    last search that queued it (no clearing between searches: each search of
    a caller passes a stamp of its own, such as its position in the list of
    centres, so that a centre listed twice is searched twice); ``queue`` is scratch. ``members``
    and ``queue`` hold V entries (a vertex is queued at most once per centre):
    no buffer is grown, so no array is reassigned in the loop, which keeps
    numba's reference counting out of it (six times slower with it). Returns
    the number of members.

    ``spans``: the (V,) longest edge at each vertex (:func:`_vertex_spans`), or None. With it, a vertex
    reached from outside the ball that is farther from it than its longest edge is stamped in ``mark``
    without being queued (:func:`_outside_edge_meets`): no edge of it meets the ball, so the walk would never
    queue it, and the other edges that reach it skip it at the stamp instead of testing their segments (on
    a 1M icosphere at 3 h, without spans: 58.5 segment tests per centre, all negative, 24 of them a vertex
    tested before). The members and their order are the same.
    """
    cx, cy, cz = vertices[v, 0], vertices[v, 1], vertices[v, 2]
    cutoff2 = cutoff * cutoff
    size = 0
    mark[v] = stamp
    queue[0] = v
    head, tail = 0, 1
    if allowed[v]:
        members[0] = v
        size = 1
    while head < tail:
        a = _UNSIGNED(queue[head])  # unsigned indices (here and below): no code for negative ones
        head += 1
        ax, ay, az = vertices[a, 0] - cx, vertices[a, 1] - cy, vertices[a, 2] - cz
        a2 = ax * ax + ay * ay + az * az
        for j in range(_UNSIGNED(indptr[a]), _UNSIGNED(indptr[a + _ONE])):
            b = _UNSIGNED(indices[j])
            if mark[b] == stamp:
                continue
            bx, by, bz = vertices[b, 0] - cx, vertices[b, 1] - cy, vertices[b, 2] - cz
            b2 = bx * bx + by * by + bz * bz
            if b2 <= cutoff2:
                if allowed[b]:
                    members[_UNSIGNED(size)] = b
                    size += 1
            elif not a2 <= cutoff2 and not _outside_edge_meets(
                spans, b, b2, cutoff, mark, stamp, ax, ay, az, bx, by, bz, cutoff2
            ):
                continue  # both ends outside, and the segment passes outside too
            mark[b] = stamp
            queue[_UNSIGNED(tail)] = b
            tail += 1
    return size


@nb.njit(inline="always", **_JIT)
def _edge_level(first, top, a2, b2, ax, ay, az, bx, by, bz, cutoffs2):
    """The smallest ball ``r >= first`` (up to ``top``) that the edge from ``a`` to ``b`` meets (an end inside, or
    the segment passing through it; ``a``, ``b`` relative to the centre, ``a2``, ``b2`` their squared
    distances, ``cutoffs2`` the squared radii, non-decreasing); ``top + 1`` if none does."""
    r = first
    while r <= top and not (
        b2 <= cutoffs2[r] or a2 <= cutoffs2[r] or _segment_meets_ball(ax, ay, az, bx, by, bz, cutoffs2[r])
    ):
        r += 1
    return r


@nb.njit(**_JIT)
def _connected_walk_levels(vertices, indptr, indices, allowed, v, cutoffs2, mark, stamp, walk, members, spans=None):
    """The walk of :func:`_connected_members` for the largest ball ``B(x_v, sqrt(cutoffs2[-1]))``, each vertex it
    queues with the smallest ball it was reached through. Returns ``(size, n_inner)``.

    ``members[:size]``: the members of the largest ball, in the order of :func:`_connected_members` (the
    same list). ``walk``: ``(queue, levels, inner, inner_levels, squared)``: the queued vertices and, per
    position in the queue, the smallest ball ``r`` such that the walk reached the vertex over edges that
    each meet ball ``r`` or a smaller one (the centre: 0); ``inner[:n_inner]`` the ``allowed`` queued
    vertices within the second largest ball, with their levels and squared distances to ``x_v``. A vertex of
    level ``r`` is in the surface-connected piece of ball ``r`` (a path of edges meeting it leads there); a
    vertex within ball ``r`` reached at a larger level may or may not be (:func:`_nested_fits_chunk` then
    walks that ball on its own). ``cutoffs2`` (R,): the squared radii, non-decreasing; ``mark`` stamped
    with ``stamp``; ``spans`` as :func:`_connected_members` (vertices that no edge leads into the largest ball
    from are stamped, not queued).
    """
    queue, levels, inner, inner_levels, squared = walk
    top = cutoffs2.shape[0] - 1
    outer2 = cutoffs2[top]
    outer = math.sqrt(outer2)
    inner2 = cutoffs2[top - 1] if top > 0 else -1.0
    cx, cy, cz = vertices[v, 0], vertices[v, 1], vertices[v, 2]
    size = 0
    n_inner = 0
    mark[v] = stamp
    queue[0] = v
    levels[0] = 0
    head, tail = 0, 1
    if allowed[v]:
        members[0] = v
        size = 1
    if top > 0 and allowed[v]:
        inner[0] = v
        inner_levels[0] = 0
        squared[0] = 0.0
        n_inner = 1
    while head < tail:
        a = _UNSIGNED(queue[head])  # unsigned indices (here and below), as _connected_members: no code for negative
        through = levels[head]  # ones (the walk took 2.2 s of CPU instead of 1.6 at 3, 6, 12 h on a 100k icosphere)
        head += 1
        ax, ay, az = vertices[a, 0] - cx, vertices[a, 1] - cy, vertices[a, 2] - cz
        a2 = ax * ax + ay * ay + az * az
        for j in range(_UNSIGNED(indptr[a]), _UNSIGNED(indptr[a + _ONE])):
            b = _UNSIGNED(indices[j])
            if mark[b] == stamp:
                continue
            bx, by, bz = vertices[b, 0] - cx, vertices[b, 1] - cy, vertices[b, 2] - cz
            b2 = bx * bx + by * by + bz * bz
            if b2 <= outer2:
                if allowed[b]:
                    members[_UNSIGNED(size)] = b
                    size += 1
            elif not a2 <= outer2 and not _outside_edge_meets(
                spans, b, b2, outer, mark, stamp, ax, ay, az, bx, by, bz, outer2
            ):
                continue  # both ends outside, and the segment passes outside too
            mark[b] = stamp
            queue[_UNSIGNED(tail)] = b
            level = through if through == top else _edge_level(through, top, a2, b2, ax, ay, az, bx, by, bz, cutoffs2)
            levels[_UNSIGNED(tail)] = level
            tail += 1
            if b2 <= inner2 and allowed[b]:
                inner[_UNSIGNED(n_inner)] = b
                inner_levels[_UNSIGNED(n_inner)] = level
                squared[_UNSIGNED(n_inner)] = b2
                n_inner += 1
    return size, n_inner


@nb.njit(inline="always", **_JIT)
def _face_extent(vertices, faces, f, d, cx, cy, cz, v, known, squared):
    """The smallest and largest squared distance from ``(cx, cy, cz)`` to the corners of face ``f``
    and its centroid (squared distance ``d``); each corner's distance computed once per centre
    ``v`` (``known``, ``squared``)."""
    low = d
    high = d
    for corner in range(3):
        c = _UNSIGNED(faces[f, corner])
        if known[c] != v:
            known[c] = v
            squared[c] = (vertices[c, 0] - cx) ** 2 + (vertices[c, 1] - cy) ** 2 + (vertices[c, 2] - cz) ** 2
        low = min(low, squared[c])
        high = max(high, squared[c])
    return low, high


@nb.njit(inline="always", **_JIT)
def _face_level(vertices, faces, f, d, low, high, reach, ball, ball2, cx, cy, cz):
    """The first ``r`` whose closed ball ``B(x, ball[r])`` (``ball2``: the squared radii) face ``f`` meets
    (``ball.shape[0]``: none), given that its centroid is within the largest radius plus its reach.

    A face meets a ball when its centroid is within the radius plus its reach
    and a corner or the centroid is inside (``low``, ``high``: their smallest and
    largest squared distance, ``d`` the centroid's) or a side crosses the sphere.
    """
    n_radii = ball.shape[0]
    for r in range(n_radii):
        if r + 1 < n_radii and d > (ball[r] + reach) ** 2:
            continue  # every point of the face is outside
        radius2 = ball2[r]
        if high <= radius2 or low < radius2:
            return r
        for corner in range(3):  # corners and centroid outside: it meets the ball if a side crosses it
            p = faces[f, corner]
            q = faces[f, (corner + 1) % 3]
            if _segment_meets_ball(
                vertices[p, 0] - cx,
                vertices[p, 1] - cy,
                vertices[p, 2] - cz,
                vertices[q, 0] - cx,
                vertices[q, 1] - cy,
                vertices[q, 2] - cz,
                radius2,
            ):
                return r
    return n_radii


@nb.njit(inline="always", **_JIT)
def _met_share(vertices, faces, f, d, cx, cy, cz, v, radius, radius2, known, squared):
    """``(met, share, low, high)`` of face ``f`` (centroid at squared distance ``d``) in the closed ball
    ``B((cx, cy, cz), radius)``: whether it meets it (a corner or its centroid inside, or a side crossing the
    sphere), its share (``neighborhoods.face_in_ball_ratios``) and the smallest and largest squared distances
    of :func:`_face_extent`."""
    low, high = _face_extent(vertices, faces, f, d, cx, cy, cz, v, known, squared)
    if high <= radius2:
        return True, 1.0, low, high
    if low >= radius2:  # corners and centroid outside: met if a side crosses the sphere
        crossed = False
        for corner in range(3):
            p = _UNSIGNED(faces[f, corner])
            q = _UNSIGNED(faces[f, (corner + 1) % 3])
            crossed = crossed or _segment_meets_ball(
                vertices[p, 0] - cx,
                vertices[p, 1] - cy,
                vertices[p, 2] - cz,
                vertices[q, 0] - cx,
                vertices[q, 1] - cy,
                vertices[q, 2] - cz,
                radius2,
            )
        return crossed, 0.0, low, high
    root = math.sqrt(low)
    return True, (radius - root) / (math.sqrt(high) - root), low, high


@nb.njit(inline="always", **_JIT)
def _walk_face(
    vertices, faces, centroids, reach, usable, values, f, v, stamp, radius, known, squared, total, mark, queue, tail
):
    """Face ``f`` reached by the walk of the ball ``B(x_v, radius)`` (:func:`connected_face_sums`): where it
    meets the closed ball (a corner or its centroid inside, or a side crossing the sphere), ``share *
    values[f]`` added to ``total`` (``usable`` faces) and its corners queued (``mark`` stamped with
    ``stamp``: ``v``, or another number for a second walk around the same centre). Returns the queue's new
    tail."""
    cx, cy, cz = vertices[v, 0], vertices[v, 1], vertices[v, 2]
    radius2 = radius * radius
    g = _UNSIGNED(f)  # unsigned indices (here and below): no code for negative ones
    d = (centroids[g, 0] - cx) ** 2 + (centroids[g, 1] - cy) ** 2 + (centroids[g, 2] - cz) ** 2
    if d > (radius + reach[g]) ** 2:
        return tail  # every point of the face is outside
    met, share, _, _ = _met_share(vertices, faces, g, d, cx, cy, cz, v, radius, radius2, known, squared)
    if not met:
        return tail
    if share != 0.0 and usable[g]:
        for k in range(values.shape[1]):
            total[k] += share * values[g, k]
    for corner in range(3):
        c = _UNSIGNED(faces[g, corner])
        if mark[c] != stamp:
            mark[c] = stamp
            queue[_UNSIGNED(tail)] = c
            tail += 1
    return tail


@threaded
def connected_face_sums(
    vertices, faces, centroids, reach, usable, values, radii, indptr, indices, out, scratch, start, stop, ready=None
):
    """Write to rows ``start`` to ``stop`` of ``out`` (V, k) the sums of ``share * values`` over the faces of the
    surface-connected piece of each vertex's ball, of radius ``radii[v]`` ((V,): one per vertex) or
    ``radii[0]`` ((1,): one for all). :func:`connected_face_sums_nested` sums several nested balls in one walk;
    this kernel is its one-ball case without the passes (15% faster, measured at 400k vertices on one thread).

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
    Faces not ``usable`` (F,) lead the search on but add nothing. The other
    rows of ``out`` are not touched: a caller that splits the vertices into
    ranges fills one array, unfilled before (no zeros to write first: 72 MB at 1M
    vertices, issue 31). ``scratch``: ``neighborhoods._face_sum_scratch``, one
    thread per row of its arrays (reused from call to call); ``ready`` (rows,) bool, False where a row's
    stamps (``seen``, ``mark``, ``known``) are still to be filled with -1, by the thread that takes the
    row, then True (None: all filled).

    The ranges of vertices (:func:`_face_sums_chunk`) run on threads (:func:`~meshcurv._kernels._common.run_slots`),
    each with the scratch row of its thread, not in a ``parallel=True`` kernel: numba's parallel pipeline compiled the inlined walk twice (issue 31: 6.2 of the
    default's cold compile CPU s, 1.9 s as a plain function, the same machine code).
    """
    n = vertices.shape[0]
    start = max(min(start, n), 0)
    m = max(min(stop, n), start) - start
    slots = scratch[0].shape[0]
    run_slots(
        _face_sums_chunk,
        m,
        _RANGES_PER_SLOT * slots,
        slots,
        np.ones(slots, np.bool_) if ready is None else ready,
        vertices,
        faces,
        centroids,
        reach,
        usable,
        values,
        radii,
        indptr,
        indices,
        out,
        scratch,
        start,
    )


#: :func:`connected_face_sums` cuts its vertices into this many ranges per thread (:func:`~._common.run_slots`):
#: a thread that finishes its share early takes ranges of the others.
_RANGES_PER_SLOT = 8


@nb.njit(**_JIT)
def _face_sums_chunk(
    lo, hi, slot, ready, vertices, faces, centroids, reach, usable, values, radii, indptr, indices, out, scratch, start
):
    """The vertices ``start + lo`` to ``start + hi - 1`` of :func:`connected_face_sums`, with row ``slot`` of each
    ``scratch`` array (its stamps filled first unless ``ready[slot]``)."""
    n_values = values.shape[1]
    per_vertex = radii.shape[0] > 1
    all_seen, all_mark, all_known, all_squared, all_queue, _, _ = scratch
    seen = all_seen[slot]
    mark = all_mark[slot]  # queued for this centre
    known = all_known[slot]  # distance to this centre in `squared`
    if not ready[slot]:  # (other names than the walk's unsigned f and c: one type per variable)
        for item in range(seen.shape[0]):
            seen[item] = -1
        for item in range(mark.shape[0]):
            mark[item] = -1
            known[item] = -1
        ready[slot] = True
    squared = all_squared[slot]
    queue = all_queue[slot]  # a vertex is queued at most once per centre: never grown
    total = np.empty(n_values)  # the centre's sums, in the order of the face visits, then stored once
    # icc's nine measures: the running sums in scalars (registers), not in `total` (memory): each face's nine
    # additions without a load and a store of each sum (-5% of the walk's instructions); the same additions
    nine = n_values == 9
    for v in range(start + lo, start + hi):
        radius = radii[v if per_vertex else 0]
        radius2 = radius * radius
        s0 = s1 = s2 = s3 = s4 = s5 = s6 = s7 = s8 = 0.0
        if not nine:
            for k in range(n_values):
                total[k] = 0.0
        # the walk of _face_walk and _walk_face written out: their arrays bound once, not once per face
        # (inlined, each face's call took and dropped a reference to each of its arrays: 3x the walk's time)
        cx, cy, cz = vertices[v, 0], vertices[v, 1], vertices[v, 2]
        mark[v] = v
        queue[0] = v
        head, tail = 0, 1
        while head < tail:
            a = _UNSIGNED(queue[head])  # unsigned indices: no code for negative ones
            head += 1
            for j in range(_UNSIGNED(indptr[a]), _UNSIGNED(indptr[a + _ONE])):
                f = _UNSIGNED(indices[j])
                if seen[f] == v:
                    continue
                seen[f] = v
                d = (centroids[f, 0] - cx) ** 2 + (centroids[f, 1] - cy) ** 2 + (centroids[f, 2] - cz) ** 2
                if d > (radius + reach[f]) ** 2:
                    continue  # every point of the face is outside
                low = d  # _met_share written out: the corners' and centroid's distances
                high = d
                for corner in range(3):
                    c = _UNSIGNED(faces[f, corner])
                    if known[c] != v:
                        known[c] = v
                        squared[c] = (
                            (vertices[c, 0] - cx) ** 2 + (vertices[c, 1] - cy) ** 2 + (vertices[c, 2] - cz) ** 2
                        )
                    corner2 = squared[c]
                    low = corner2 if corner2 < low else low  # min(low, corner2)
                    high = corner2 if corner2 > high else high  # max(high, corner2)
                if high <= radius2:
                    share = 1.0
                elif low < radius2:
                    root = math.sqrt(low)
                    share = (radius - root) / (math.sqrt(high) - root)
                else:  # corners and centroid outside: met if a side crosses the sphere
                    share = 0.0
                    crossed = False
                    for corner in range(3):
                        p = _UNSIGNED(faces[f, corner])
                        q = _UNSIGNED(faces[f, (corner + 1) % 3])
                        crossed = crossed or _segment_meets_ball(
                            vertices[p, 0] - cx,
                            vertices[p, 1] - cy,
                            vertices[p, 2] - cz,
                            vertices[q, 0] - cx,
                            vertices[q, 1] - cy,
                            vertices[q, 2] - cz,
                            radius2,
                        )
                    if not crossed:
                        continue
                if share != 0.0 and usable[f]:
                    if nine:
                        s0 += share * values[f, 0]
                        s1 += share * values[f, 1]
                        s2 += share * values[f, 2]
                        s3 += share * values[f, 3]
                        s4 += share * values[f, 4]
                        s5 += share * values[f, 5]
                        s6 += share * values[f, 6]
                        s7 += share * values[f, 7]
                        s8 += share * values[f, 8]
                    else:
                        for k in range(n_values):
                            total[k] += share * values[f, k]
                for corner in range(3):
                    c = _UNSIGNED(faces[f, corner])
                    if mark[c] != v:
                        mark[c] = v
                        queue[_UNSIGNED(tail)] = c
                        tail += 1
        if nine:
            out[v, 0], out[v, 1], out[v, 2], out[v, 3], out[v, 4], out[v, 5] = s0, s1, s2, s3, s4, s5
            out[v, 6], out[v, 7], out[v, 8] = s6, s7, s8
            continue
        for k in range(n_values):
            out[v, k] = total[k]


@nb.njit(inline="always", **_JIT)
def _inner_rows(first, top, low, high, ball, ball2, values, f, total):
    """``share * values[r, f]`` (``values[0, f]`` for every ball) added to the rows ``first`` to ``top - 1`` of
    ``total``, the share in ball ``r`` as :func:`_walk_face` computes it (the roots taken once)."""
    per_ball = values.shape[0] > 1
    root = -1.0
    span = 0.0
    for r in range(first, top):
        radius2 = ball2[r]
        if high <= radius2:
            share = 1.0
        elif low >= radius2:
            share = 0.0
        else:
            if root < 0.0:
                root = math.sqrt(low)
                span = math.sqrt(high) - root
            share = (ball[r] - root) / span
        if share != 0.0:
            row = r if per_ball else 0
            for k in range(values.shape[2]):
                total[r, k] += share * values[row, f, k]


@nb.njit(parallel=True, **_JIT)
def connected_face_sums_nested(
    vertices, faces, centroids, reach, usable, values, radii, indptr, indices, out, scratch, start, stop
):
    """Add to rows ``start`` to ``stop`` of ``out`` (R, V, k) the sums of ``share * values`` over the faces of the
    surface-connected piece of each vertex's balls, one ball per row of ``radii`` (R, 1) or (R, V).

    ``values`` (1, F, k): the same values for every ball, or (R, F, k): ball ``r`` sums ``values[r]``.

    ``radii[r, 0]`` is the radius of ball ``r`` around every vertex, ``radii[r, v]``
    that around vertex ``v`` (one column per vertex); the balls of a vertex are
    nested (``radii[r, v] <= radii[r + 1, v]``). Row ``r`` holds what
    :func:`connected_face_sums` gives at ball ``r``'s radius: the same faces and
    shares (``neighborhoods.face_in_ball_ratios``), the largest ball's row to the
    bit (the same walk, additions in the same order), the smaller ones to
    round-off (another order). Faces not ``usable`` (F,) lead the walks on but add
    nothing. The other rows of ``out`` are not touched: a caller that splits the
    vertices into ranges sums them into one array. ``scratch``:
    ``neighborhoods._face_sum_scratch`` with ``nested``, one chunk of the vertices per
    row of its arrays (reused from call to call).

    One walk per vertex, that of the largest ball (:func:`connected_face_sums`), certifies
    the smaller balls' faces on the way: each queued vertex carries the smallest ball
    ``tau`` that the walk reached it through (every face on its way meets ball ``tau``
    or a smaller one; the centre: 0), and a face met first by ball ``met`` and reached
    from a vertex of level ``tau`` belongs to the pieces of the balls ``max(met, tau)``
    and up (a path of faces that meet each of them leads to it), whose rows it adds to.
    Where a face meets a ball smaller than the level it was reached at, the walk does
    not tell whether that ball's own walk reaches it (the piece of that ball may be
    connected to it through other faces only, or not at all): the row of each such ball
    is summed again by its own walk (:func:`_walk_face`), for that vertex alone. On a
    surface whose balls are connected pieces, as breadth-first walks reach the nearer
    faces first, that is rare (none on a 100k icosphere at h, 2 h, 4 h); the cost of the
    smaller balls is then their faces' additions, not their walks.
    """
    n = vertices.shape[0]
    n_values = values.shape[2]
    n_radii = radii.shape[0]
    top = n_radii - 1
    per_vertex = radii.shape[1] > 1
    per_ball = values.shape[0] > 1
    top_row = top if per_ball else 0
    start = max(min(start, n), 0)
    m = max(min(stop, n), start) - start
    all_seen, all_mark, all_known, all_squared, all_queue, all_level, _ = scratch
    n_chunks = all_seen.shape[0]
    for chunk in nb.prange(n_chunks):
        seen = all_seen[chunk]
        mark = all_mark[chunk]  # queued for this centre
        known = all_known[chunk]  # distance to this centre in `squared`
        squared = all_squared[chunk]
        queue = all_queue[chunk]  # a vertex is queued at most once per centre: never grown
        level = all_level[chunk]  # the smallest ball each queued vertex was reached through
        total = np.empty((n_radii, n_values))  # the centre's sums, in the order of the face visits, then stored once
        ball = np.empty(n_radii)  # the centre's radii
        ball2 = np.empty(n_radii)  # and their squares
        unsure = np.zeros(n_radii, np.bool_)  # the balls to walk on their own
        for v in range(start + chunk * m // n_chunks, start + (chunk + 1) * m // n_chunks):
            w = v if per_vertex else 0
            for r in range(n_radii):
                ball[r] = radii[r, w]
                ball2[r] = ball[r] * ball[r]
                unsure[r] = False
            outer = ball[top]
            outer2 = ball2[top]
            inner = ball[top - 1] if top > 0 else 0.0
            cx, cy, cz = vertices[v, 0], vertices[v, 1], vertices[v, 2]
            for r in range(n_radii):
                for k in range(n_values):
                    total[r, k] = out[r, v, k]
            mark[v] = v
            if top > 0:
                level[v] = 0
            queue[0] = v
            head, tail = 0, 1
            while head < tail:
                a = queue[head]
                head += 1
                through = level[a] if top > 0 else 0
                for j in range(indptr[a], indptr[a + 1]):
                    f = indices[j]
                    if seen[f] == v:
                        continue
                    seen[f] = v
                    d = (centroids[f, 0] - cx) ** 2 + (centroids[f, 1] - cy) ** 2 + (centroids[f, 2] - cz) ** 2
                    if d > (outer + reach[f]) ** 2:
                        continue  # every point of the face is outside
                    met, share, low, high = _met_share(
                        vertices, faces, f, d, cx, cy, cz, v, outer, outer2, known, squared
                    )  # the largest ball: as _walk_face
                    if not met:
                        continue
                    if share != 0.0 and usable[f]:
                        for k in range(n_values):
                            total[top, k] += share * values[top_row, f, k]
                    reached = top
                    if top > 0 and d <= (inner + reach[f]) ** 2:  # it may meet a smaller ball
                        met = _face_level(vertices, faces, f, d, low, high, reach[f], ball, ball2, cx, cy, cz)
                        reached = max(met, through)
                        if usable[f]:
                            _inner_rows(reached, top, low, high, ball, ball2, values, f, total)
                            for r in range(met, through):  # met by ball r, reached through a larger one
                                unsure[r] = True
                    for corner in range(3):
                        c = faces[f, corner]
                        if mark[c] != v:
                            mark[c] = v
                            if top > 0:
                                level[c] = reached
                            queue[tail] = c
                            tail += 1
                        elif reached < top and reached < level[c]:  # a smaller ball's way to it (used if still queued)
                            level[c] = reached
            for r in range(top):
                if unsure[r]:
                    _walk_ball(
                        vertices,
                        faces,
                        centroids,
                        reach,
                        usable,
                        values[r if per_ball else 0],
                        indptr,
                        indices,
                        v,
                        ball[r],
                        (known, squared, seen, mark, queue),
                        total[r],
                        out[r, v],
                    )
            for r in range(n_radii):
                for k in range(n_values):
                    out[r, v, k] = total[r, k]


@nb.njit(inline="always", **_JIT)
def _face_walk(vertices, faces, centroids, reach, usable, values, indptr, indices, v, stamp, radius, buffers, total):
    """The walk of :func:`connected_face_sums` around vertex ``v``: the faces of the surface-connected piece of
    ``B(x_v, radius)`` (:func:`_walk_face`) added to ``total``. ``buffers``: ``(known, squared, seen, mark,
    queue)``, ``seen`` and ``mark`` stamped with ``stamp``. Returns the number of vertices queued
    (``queue[:returned]``)."""
    known, squared, seen, mark, queue = buffers
    mark[v] = stamp
    queue[0] = v
    head, tail = 0, 1
    while head < tail:
        a = _UNSIGNED(queue[head])  # unsigned indices: no code for negative ones
        head += 1
        for j in range(_UNSIGNED(indptr[a]), _UNSIGNED(indptr[a + _ONE])):
            f = _UNSIGNED(indices[j])
            if seen[f] == stamp:
                continue
            seen[f] = stamp
            tail = _walk_face(
                vertices,
                faces,
                centroids,
                reach,
                usable,
                values,
                f,
                v,
                stamp,
                radius,
                known,
                squared,
                total,
                mark,
                queue,
                tail,
            )
    return tail


@nb.njit(**_JIT)
def _walk_ball(vertices, faces, centroids, reach, usable, values, indptr, indices, v, radius, buffers, total, first):
    """``total`` set to ``first`` plus the sums of :func:`connected_face_sums` over the ball ``B(x_v, radius)``, by
    its own walk (:func:`connected_face_sums_nested`'s balls it could not vouch for).

    ``buffers``: the nested walk's ``(known, squared, seen, mark, queue)``. The walk (:func:`_face_walk`)
    stamps ``seen`` and ``mark`` with -2 (no centre's number), reuses the distances to ``x_v`` in ``known``
    and ``squared``, and sets the entries it stamped back to -1 when done, so that the next such walk starts
    clean."""
    for k in range(total.shape[0]):
        total[k] = first[k]
    tail = _face_walk(vertices, faces, centroids, reach, usable, values, indptr, indices, v, -2, radius, buffers, total)
    _, _, seen, mark, queue = buffers
    for i in range(tail):  # every face it saw is around a vertex it queued
        a = queue[i]
        mark[a] = -1
        for j in range(indptr[a], indptr[a + 1]):
            seen[indices[j]] = -1


@threaded
def cell_centres(vertices, cells):
    """``neighborhoods._ball_sums``'s (C, 3) centroids of cells (faces or edges) and (C,) their reach.

    The reach is the largest distance from the centroid to a corner. The cells
    run in ranges (:func:`_centres_chunk`) on threads
    (:func:`~meshcurv._kernels._common.run_chunks`); each cell's sums are its own,
    in the same order whatever the ranges.
    """
    n = cells.shape[0]
    # every row written by its chunk; no huge pages (geometry._unadvised_array)
    centres = _unadvised_array((n, 3), np.float64)
    reach = _unadvised_array((n,), np.float64)
    run_chunks(_centres_chunk, n, 4 * nb.get_num_threads(), vertices, cells, centres, reach)
    return centres, reach


@nb.njit(**_JIT)
def _centres_chunk(lo, hi, vertices, cells, centres, reach):
    """:func:`cell_centres` of the cells ``lo`` to ``hi - 1``, written to ``centres`` and ``reach``."""
    corners = cells.shape[1]
    for c in range(lo, hi):
        # in registers, each cell's memory written once (the same sums, in the same order, as in the arrays)
        x = y = z = 0.0
        for k in range(corners):
            p = cells[c, k]
            x += vertices[p, 0]
            y += vertices[p, 1]
            z += vertices[p, 2]
        x /= corners
        y /= corners
        z /= corners
        # the largest squared distance, then one square root: the square root is correctly rounded and so
        # non-decreasing, hence the root of the largest square is the largest root (the same number, one root
        # instead of one per corner; a NaN is skipped by both comparisons alike)
        far2 = 0.0
        for k in range(corners):
            p = cells[c, k]
            squared = (vertices[p, 0] - x) ** 2 + (vertices[p, 1] - y) ** 2 + (vertices[p, 2] - z) ** 2
            far2 = squared if squared > far2 else far2  # max(far2, squared): numba compiles max once per options
        centres[c, 0] = x
        centres[c, 1] = y
        centres[c, 2] = z
        reach[c] = math.sqrt(far2)


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
            members = _cell_weight_sums(
                vertices, points, grid, sorted_values, radius, cutoff, centres[rank], members, out
            )
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
    """``segment_in_ball_lengths`` of edge ``e`` (its ends in ``points[e, :2]``): the same operations, in the
    same order (from the end nearer the centre; no quadratic formula, which cancels on long edges)."""
    ax = points[e, 0, 0] - cx
    ay = points[e, 0, 1] - cy
    az = points[e, 0, 2] - cz
    bx = points[e, 1, 0] - cx
    by = points[e, 1, 1] - cy
    bz = points[e, 1, 2] - cz
    if (bx * bx + by * by) + bz * bz < (ax * ax + ay * ay) + az * az:
        ax, ay, az, bx, by, bz = bx, by, bz, ax, ay, az
    dx = bx - ax
    dy = by - ay
    dz = bz - az
    length2 = (dx * dx + dy * dy) + dz * dz
    if not length2 > 0:
        return 0.0
    length = math.sqrt(length2)
    along = -((ax * dx + ay * dy) + az * dz) / length
    share = along / length
    hx = ax + share * dx
    hy = ay + share * dy
    hz = az + share * dz
    h2 = (hx * hx + hy * hy) + hz * hz
    if not h2 < radius2:
        return 0.0
    half = math.sqrt(max(radius2 - h2, 0.0))
    inside = min(along + half, length) - max(along - half, 0.0)
    return inside if inside > 0 else 0.0


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


@nb.njit(**_JIT)
def _face_cluster_parts(vertices, faces, cell, values, kept, indptr, indices):
    """The integer and bounding parts of ``neighborhoods._face_clusters`` for faces whose cube ``cell`` (F,)
    is given (cubes numbered 0 and up): ``(of, middle, spans, sums, links_indptr, links, shared_indptr,
    shared)``, equal to the bit to what the NumPy lines compute (issue 30: 20 ms of NumPy on a voxel sphere of
    20,000 faces).

    Two faces of one cube that share a corner are joined (union-find, over the faces around each vertex:
    ``indptr, indices``, :func:`vertex_face_lists`); the clusters are numbered by their first face, as the
    ranks of SciPy's ``connected_components`` labels number them (a label per component in the order of its
    smallest node, the faces being the first nodes). Each cluster's corners' bounding box (its middle), the
    farthest corner from it (``sqrt((x^2 + y^2) + z^2)``, ``np.linalg.norm``'s order over three), the sums of
    the ``kept`` faces' ``values`` in face order (``np.bincount``'s); the links: the ordered pairs of clusters
    that share a vertex, by first then second cluster, each with its shared vertices in increasing order.
    """
    n_faces = faces.shape[0]
    n_vertices = vertices.shape[0]
    parent = np.arange(n_faces)
    first = np.full(int(cell.max()) + 1 if n_faces else 0, -1, np.int64)  # a face of the cube at this vertex
    stamp = np.full(first.shape[0], -1, np.int64)
    for u in range(n_vertices):
        for j in range(indptr[u], indptr[u + 1]):
            g = np.int64(indices[j])
            c = cell[g]
            if stamp[c] != u:
                stamp[c] = u
                first[c] = g
                continue
            a, b = _find(parent, g), _find(parent, first[c])
            if a != b:  # the larger root under the smaller
                parent[max(a, b)] = min(a, b)
    of = np.empty(n_faces, np.int64)
    label = np.full(n_faces, -1, np.int64)
    n_clusters = 0
    for f in range(n_faces):
        r = _find(parent, f)
        if label[r] < 0:
            label[r] = n_clusters
            n_clusters += 1
        of[f] = label[r]
    # the bounding boxes, then the farthest corners, faces in increasing order within each cluster
    low = np.full((n_clusters, 3), np.inf)
    high = np.full((n_clusters, 3), -np.inf)
    for f in range(n_faces):
        c = of[f]
        for a in range(3):
            x0, x1, x2 = vertices[faces[f, 0], a], vertices[faces[f, 1], a], vertices[faces[f, 2], a]
            lo = _numpy_minimum(_numpy_minimum(x0, x1), x2)
            hi = _numpy_maximum(_numpy_maximum(x0, x1), x2)
            low[c, a] = _numpy_minimum(low[c, a], lo)
            high[c, a] = _numpy_maximum(high[c, a], hi)
    middle = np.empty((n_clusters, 3))
    for c in range(n_clusters):
        for a in range(3):
            middle[c, a] = 0.5 * (low[c, a] + high[c, a])
    spans = np.zeros(n_clusters)
    spans[:] = -np.inf
    for f in range(n_faces):
        c = of[f]
        far = -np.inf
        for k in range(3):
            p = faces[f, k]
            dx, dy, dz = vertices[p, 0] - middle[c, 0], vertices[p, 1] - middle[c, 1], vertices[p, 2] - middle[c, 2]
            far = _numpy_maximum(far, math.sqrt((dx * dx + dy * dy) + dz * dz))
        spans[c] = _numpy_maximum(spans[c], far)
    sums = np.zeros((n_clusters, values.shape[1]))
    for f in range(n_faces):
        if kept[f]:
            for k in range(values.shape[1]):
                sums[of[f], k] += values[f, k]
    # each vertex's clusters, increasing; the ordered pairs of them, generated by vertex (increasing)
    seen = np.full(n_clusters, -1, np.int64)
    around = np.empty(n_faces, np.int64)  # a vertex's distinct clusters (no more than its faces)
    count = np.zeros(n_clusters + 1, np.int64)  # triples per tail
    n_triples = 0
    for u in range(n_vertices):
        d = _vertex_clusters(u, indptr, indices, of, seen, around)
        for i in range(d):
            count[around[i] + 1] += d - 1
        n_triples += d * (d - 1)
    tails = np.empty(n_triples, np.int64)
    heads = np.empty(n_triples, np.int64)
    at = np.empty(n_triples, np.int64)
    # a stable counting sort by head (the vertices stay increasing), then by tail: (tail, head, vertex) order;
    # a cluster is the head of as many triples as it is the tail of
    for c in range(n_clusters):
        count[c + 1] += count[c]
    by_head = count.copy()
    head_tails = np.empty(n_triples, np.int64)
    head_at = np.empty(n_triples, np.int64)
    head_heads = np.empty(n_triples, np.int64)
    seen[:] = -1
    for u in range(n_vertices):
        d = _vertex_clusters(u, indptr, indices, of, seen, around)
        for i in range(d):
            for j in range(d):
                if i != j:
                    h = around[j]
                    at_h = by_head[h]
                    by_head[h] += 1
                    head_tails[at_h], head_heads[at_h], head_at[at_h] = around[i], h, u
    for t in range(n_triples):
        tail = head_tails[t]
        k = count[tail]
        count[tail] += 1
        tails[k], heads[k], at[k] = tail, head_heads[t], head_at[t]
    n_links = 0
    for t in range(n_triples):
        if t == 0 or tails[t] != tails[t - 1] or heads[t] != heads[t - 1]:
            n_links += 1
    links = np.empty(n_links, np.int64)
    links_indptr = np.zeros(n_clusters + 1, np.int64)
    shared_indptr = np.empty(n_links + 1, np.int64)
    k = 0
    for t in range(n_triples):
        if t == 0 or tails[t] != tails[t - 1] or heads[t] != heads[t - 1]:
            links[k] = heads[t]
            shared_indptr[k] = t
            links_indptr[tails[t] + 1] += 1
            k += 1
    shared_indptr[n_links] = n_triples
    for c in range(n_clusters):
        links_indptr[c + 1] += links_indptr[c]
    return of, middle, spans, sums, links_indptr, links, shared_indptr, at


@nb.njit(inline="always", **_JIT)
def _vertex_clusters(u, indptr, indices, of, seen, around):
    """The distinct clusters ``of`` the faces around vertex ``u``, increasing, in ``around[:d]``; returns ``d``
    (``seen``: the vertex each cluster was last listed for)."""
    d = 0
    for j in range(indptr[u], indptr[u + 1]):
        c = of[indices[j]]
        if seen[c] == u:
            continue
        seen[c] = u
        i = d  # insertion: the lists are a few clusters long
        while i > 0 and around[i - 1] > c:
            around[i] = around[i - 1]
            i -= 1
        around[i] = c
        d += 1
    return d


@nb.njit(**_JIT)
def _cluster_kind(centres, spans, c, cx, cy, cz, radius, slack):
    """0 when every point of cluster ``c`` (its bounding sphere: ``centres[c]``, ``spans[c]``) is inside the
    ball ``B((cx, cy, cz), radius)`` by more than ``slack``, 1 when every point is outside by more than
    ``slack``, 2 otherwise (the sphere of the ball may cut it: its faces are taken one by one). The margin
    keeps round-off out of the decision: a face of a cluster inside has every corner inside in the exact
    tests of :func:`connected_face_sums` too, and one of a cluster outside meets the ball in none."""
    d = math.sqrt((centres[c, 0] - cx) ** 2 + (centres[c, 1] - cy) ** 2 + (centres[c, 2] - cz) ** 2)
    if d + spans[c] < radius - slack:
        return 0
    if d - spans[c] > radius + slack:
        return 1
    return 2


@nb.njit(parallel=True, **_JIT)
def clustered_face_sums(
    vertices, faces, centroids, reach, usable, values, radii, indptr, indices, clusters, out, scratch, start, stop
):
    """:func:`connected_face_sums` with the faces grouped in clusters whose sums are added whole.

    ``clusters``: ``(of, centres, spans, sums, links_indptr, links, shared_indptr, shared, slack)`` of
    ``neighborhoods._face_clusters``: the cluster of each face (F,), each cluster's bounding sphere
    (C, 3), (C,), the sums of its usable faces' ``values`` (C, k), its neighbour clusters (the clusters
    that share a vertex with it, CSR over the C clusters), for each such link the shared vertices (CSR
    over the links) and the margin ``slack`` of the inside and outside tests (round-off of the
    coordinates). Every cluster is connected through the corners of its faces.

    The walk is that of :func:`connected_face_sums`, over clusters where it can be: a cluster reached
    (one of its faces met by the walk, or a neighbour of a cluster added whole) that lies inside the ball
    adds its precomputed sums and leads the walk on to its neighbours (to the vertices it shares with
    those the sphere cuts); one that lies outside the ball is skipped (none of its faces meets the ball);
    the faces of one the sphere cuts are walked one by one, as :func:`connected_face_sums` does. The faces
    added are those of :func:`connected_face_sums` (a connected cluster inside the ball is wholly reached
    once one of its faces is, and its faces lead on to exactly the faces around its vertices); the sums
    differ by round-off (another order of the additions). ``scratch``: ``neighborhoods._face_sum_scratch``
    and then the clusters' ``(stamp, kind, queue)`` (n_chunks, C) each.
    """
    n = vertices.shape[0]
    n_values = values.shape[1]
    per_vertex = radii.shape[0] > 1
    start = max(min(start, n), 0)
    m = max(min(stop, n), start) - start
    of, cluster_centres, spans, sums, links_indptr, links, shared_indptr, shared, slack = clusters
    all_seen, all_mark, all_known, all_squared, all_queue, all_stamp, all_kind, all_waiting = scratch
    n_chunks = all_seen.shape[0]
    for chunk in nb.prange(n_chunks):
        seen = all_seen[chunk]
        mark = all_mark[chunk]  # queued for this centre
        known = all_known[chunk]  # distance to this centre in `squared`
        squared = all_squared[chunk]
        queue = all_queue[chunk]  # a vertex is queued at most once per centre: never grown
        stamp = all_stamp[chunk]  # the centre a cluster was last classified for
        kind = all_kind[chunk]  # and its kind (_cluster_kind)
        waiting = all_waiting[chunk]  # the clusters inside the ball, each queued once per centre
        total = np.empty(n_values)  # the centre's sums, in the order of the visits, then stored once
        for v in range(start + chunk * m // n_chunks, start + (chunk + 1) * m // n_chunks):
            radius = radii[v if per_vertex else 0]
            margin = 1e-9 * radius + slack
            cx, cy, cz = vertices[v, 0], vertices[v, 1], vertices[v, 2]
            for k in range(n_values):
                total[k] = out[v, k]
            mark[v] = v
            queue[0] = v
            head, tail = 0, 1
            first, last = 0, 0  # the queue of clusters
            while head < tail or first < last:
                while first < last:  # a cluster inside the ball: its sums, then its neighbours
                    c = waiting[first]
                    first += 1
                    for k in range(n_values):
                        total[k] += sums[c, k]
                    for link in range(links_indptr[c], links_indptr[c + 1]):
                        e = links[link]
                        if stamp[e] != v:
                            stamp[e] = v
                            kind[e] = _cluster_kind(cluster_centres, spans, e, cx, cy, cz, radius, margin)
                            if kind[e] == 0:
                                waiting[last] = e
                                last += 1
                        if kind[e] == 2:  # cut by the sphere: its faces at the shared vertices, one by one
                            for s in range(shared_indptr[link], shared_indptr[link + 1]):
                                b = shared[s]
                                if mark[b] != v:
                                    mark[b] = v
                                    queue[tail] = b
                                    tail += 1
                while head < tail:
                    a = queue[head]
                    head += 1
                    for j in range(indptr[a], indptr[a + 1]):
                        f = indices[j]
                        if seen[f] == v:
                            continue
                        seen[f] = v
                        c = of[f]
                        if stamp[c] != v:
                            stamp[c] = v
                            kind[c] = _cluster_kind(cluster_centres, spans, c, cx, cy, cz, radius, margin)
                            if kind[c] == 0:
                                waiting[last] = c
                                last += 1
                        if kind[c] == 2:  # cut by the sphere: face by face
                            tail = _walk_face(
                                vertices,
                                faces,
                                centroids,
                                reach,
                                usable,
                                values,
                                f,
                                v,
                                v,
                                radius,
                                known,
                                squared,
                                total,
                                mark,
                                queue,
                                tail,
                            )
            for k in range(n_values):
                out[v, k] = total[k]


@nb.njit(inline="always", **_JIT)
def _cluster_share(centres, spans, middles, c, cx, cy, cz, radius):
    """The share of cluster ``c`` in the ball ``B((cx, cy, cz), radius)`` by its sphere (``centres[c]``,
    ``spans[c]``): 1 inside, 0 outside, linear in between by the distances of its nearest and farthest points
    from the sphere of radius ``sqrt(radius^2 - span^2 / 3)`` (``neighborhoods.coarse_share``; ``middles``: that
    radius for each cluster, or (0,): computed here). A cluster whose squared distance exceeds that of the far
    end of the ramp by far more than its round-off is outside without the square root (the same 0)."""
    span = spans[c]
    middle = math.sqrt(max(radius * radius - span * span / 3.0, 0.0)) if middles.shape[0] == 0 else middles[c]
    d2 = (centres[c, 0] - cx) ** 2 + (centres[c, 1] - cy) ** 2 + (centres[c, 2] - cz) ** 2
    beyond = (middle + span) * (1.0 + _FAR_SLACK)
    if d2 > beyond * beyond:
        return 0.0
    d = math.sqrt(d2)
    if d + span <= middle:
        return 1.0
    if not d - span < middle:
        return 0.0
    return (middle - (d - span)) / (2.0 * span)


@nb.njit(parallel=True, **_JIT)
def coarse_face_sums(vertices, indptr, indices, radii, clusters, out, scratch, start, stop):
    """The sums of :func:`connected_face_sums` on the clusters of faces alone (an approximation): each cluster
    reached adds its precomputed sums times its share of the ball (:func:`_cluster_share`, by its bounding
    sphere), and leads the walk on to its neighbour clusters while that share is positive.

    The walk starts from the clusters of the faces around each vertex (``indptr, indices``). ``clusters``
    as :func:`clustered_face_sums`; ``scratch``: the clusters' stamps, shares (float) and queue, (n_chunks, C)
    each. The work of a ball is the number of its clusters, whatever the density of its faces. Each centre's
    sums are added in a row of their own, from ``out``'s, then stored.
    """
    n = vertices.shape[0]
    n_values = out.shape[1]
    per_vertex = radii.shape[0] > 1
    start = max(min(start, n), 0)
    m = max(min(stop, n), start) - start
    of, cluster_centres, spans, sums, links_indptr, links, _, _, _ = clusters
    # one radius for all: each cluster's inner sphere once, not at every share
    middles = np.empty(0 if per_vertex else spans.shape[0])
    for c in range(middles.shape[0]):
        middles[c] = math.sqrt(max(radii[0] * radii[0] - spans[c] * spans[c] / 3.0, 0.0))
    widest = 0  # the most links of a cluster
    for c in range(links_indptr.shape[0] - 1):
        widest = max(widest, links_indptr[c + 1] - links_indptr[c])
    all_stamp, all_share, all_waiting = scratch
    n_chunks = all_stamp.shape[0]
    for chunk in nb.prange(n_chunks):
        stamp = all_stamp[chunk]
        share = all_share[chunk]
        waiting = all_waiting[chunk]
        fresh = np.empty_like(links[:widest])  # the links of a cluster not stamped yet, in their order
        total = np.empty(n_values)
        for v in range(start + chunk * m // n_chunks, start + (chunk + 1) * m // n_chunks):
            radius = radii[v if per_vertex else 0]
            cx, cy, cz = vertices[v, 0], vertices[v, 1], vertices[v, 2]
            for k in range(n_values):
                total[k] = out[v, k]
            first, last = 0, 0
            for j in range(indptr[v], indptr[v + 1]):
                c = of[indices[j]]
                if stamp[c] != v:
                    stamp[c] = v
                    share[c] = _cluster_share(cluster_centres, spans, middles, c, cx, cy, cz, radius)
                    if share[c] > 0.0:
                        waiting[last] = c
                        last += 1
            while first < last:
                c = waiting[first]
                first += 1
                part = share[c]
                for k in range(n_values):
                    total[k] += part * sums[c, k]
                # the links not stamped yet listed first, without a branch (a stamp is stored whatever it was: the
                # test's outcome, new or not, came unpredictably and its branch cost 8% of the kernel), then their
                # shares in the same order: the same queue, the same sums
                new = 0
                for link in range(links_indptr[c], links_indptr[c + 1]):
                    e = links[link]
                    fresh[new] = e
                    new += stamp[e] != v
                    stamp[e] = v
                for i in range(new):
                    e = fresh[i]
                    share[e] = _cluster_share(cluster_centres, spans, middles, e, cx, cy, cz, radius)
                    if share[e] > 0.0:
                        waiting[last] = e
                        last += 1
            for k in range(n_values):
                out[v, k] = total[k]


#: :func:`_ring_pass` cuts the vertices into this many ranges per thread (:func:`~._common.run_chunks`).
_RING_CHUNKS_PER_THREAD = 4


@threaded
def _ring_pass(indptr, indices, values, out, largest):
    """One ring of :func:`meshcurv.neighborhoods.ring_sums` (``largest`` False) or of
    :func:`meshcurv.neighborhoods.ring_max` (``largest`` True): ``out`` (V, k) receives, for each vertex, the sum
    (the largest) of ``values`` (V, k) over the vertex and its neighbours ``indices[indptr[v]:indptr[v + 1]]``
    (each list increasing, without the vertex itself).

    The sum runs from 0 over the vertex and its neighbours in increasing order, the vertex in its place (what the
    product of ``values`` by the CSR matrix of the lists plus the identity computes, row by row, in SciPy); the
    largest is the vertex's own against the running largest of its neighbours in their order (what
    ``np.maximum`` of it and ``np.maximum.reduceat`` of theirs gives: NaN if any is), the vertex's own where it
    has none. The same numbers to the bit as those NumPy forms but the sign of a zero (which of 0.0 and -0.0
    NumPy keeps depends on its loop; the caller makes zeros 0.0), on any number of threads (each range writes
    its own rows).
    """
    chunks = _RING_CHUNKS_PER_THREAD * nb.get_num_threads()
    if largest:
        run_chunks(_ring_max_chunk, values.shape[0], chunks, indptr, indices, values, out)
    else:
        run_chunks(_ring_sum_chunk, values.shape[0], chunks, indptr, indices, values, out)


@nb.njit(**_JIT)
def _ring_sum_chunk(lo, hi, indptr, indices, values, out):
    """Vertices ``lo:hi`` of :func:`_ring_pass`'s sums (each column's in the order of the NumPy form)."""
    width = values.shape[1]
    for v in range(lo, hi):
        for k in range(width):
            out[v, k] = 0.0
        own = False
        for j in range(indptr[v], indptr[v + 1]):
            u = indices[j]
            if not own and u > v:
                for k in range(width):
                    out[v, k] += values[v, k]
                own = True
            for k in range(width):
                out[v, k] += values[u, k]
        if not own:
            for k in range(width):
                out[v, k] += values[v, k]


@nb.njit(inline="always", **_JIT)
def _numpy_minimum(a, b):
    """``np.minimum(a, b)``: NaN if either is, else the smaller, ``b`` of two equal ones (0.0 and -0.0)."""
    if a != a:
        return a
    if b != b:
        return b
    return a if a < b else b


@nb.njit(inline="always", **_JIT)
def _numpy_maximum(a, b):
    """``np.maximum(a, b)``: NaN if either is, else the larger, ``b`` of two equal ones (0.0 and -0.0)."""
    if a != a:
        return a
    if b != b:
        return b
    return a if a > b else b


@nb.njit(**_JIT)
def _ring_max_chunk(lo, hi, indptr, indices, values, out):
    """Vertices ``lo:hi`` of :func:`_ring_pass`'s largest values (one column: the running largest in a local, not
    in ``out``, which may share memory with ``values`` as far as the compiler knows: a load and a store per
    neighbour, 0.7 of a millisecond a pass on 10,172 vertices; the same comparisons in the same order)."""
    width = values.shape[1]
    for v in range(lo, hi):
        start, stop = indptr[v], indptr[v + 1]
        if stop == start:
            for k in range(width):
                out[v, k] = values[v, k]
            continue
        if width == 1:
            largest = values[indices[start], 0]
            for j in range(start + 1, stop):
                largest = _numpy_maximum(largest, values[indices[j], 0])
            out[v, 0] = _numpy_maximum(values[v, 0], largest)
            continue
        u = indices[start]
        for k in range(width):
            out[v, k] = values[u, k]
        for j in range(start + 1, stop):
            u = indices[j]
            for k in range(width):
                out[v, k] = _numpy_maximum(out[v, k], values[u, k])
        for k in range(width):
            out[v, k] = _numpy_maximum(values[v, k], out[v, k])
