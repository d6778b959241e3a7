"""Compiled twins of the point-cloud orientation graph and checks (:mod:`meshcurv._pointcloud_normals`,
:mod:`meshcurv.pointcloud`).

:func:`spanning_sheets` grows the minimum spanning forest of the orientation
(Kruskal, the union-find of :func:`meshcurv._kernels.pointcloud.spanning_signs`)
and reads the flat edges' components (the sheets) off the same union-find
when the last flat edge is taken: every flat edge weighs less than every
stacked one, so the flat edges are a prefix of the order. :func:`torn_ends`
marks the ends of the flat edges left opposite; :func:`morton_order` is the
Morton code and its stable order of :func:`meshcurv.pointcloud._spatial_order`.
Each returns what its NumPy twin returns, to the bit.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from ._common import _JIT
from .pointcloud import _root


@nb.njit(**_JIT)
def spanning_sheets(n, rows, cols, opposite, order, flat, least):
    """``(signs, roots, sheets)``: :func:`meshcurv._kernels.pointcloud.spanning_signs` and the sheets on the way.

    Kruskal's algorithm over the edges ``(rows, cols)`` taken in ``order``
    (E,), the same union-find and the same unions as ``spanning_signs``:
    ``signs`` (N,) and ``roots`` (N,) are its outputs to the bit. The edges
    ``flat`` (E,) (int8, 1 for a flat edge) come first in ``order`` (a flat
    edge taken after another raises ``ValueError``); when the last of them is
    taken, the components of the union-find are those of the flat edges:
    ``sheets`` (N,) numbers them 0, 1, ... in the order of their first point
    (as :func:`scipy.sparse.csgraph.connected_components` does), -1 for those
    of fewer than ``least`` points (:func:`meshcurv._pointcloud_normals._sheets`).
    """
    parent, flip, size = np.arange(n), np.zeros(n, dtype=np.int8), np.ones(n, dtype=np.int64)
    n_flat = 0
    for e in range(flat.shape[0]):
        n_flat += flat[e]
    sheets = np.full(n, -1, dtype=np.int64)
    for position in range(order.shape[0] + 1):
        if position == n_flat:
            _number_sheets(parent, flip, least, sheets)
        if position == order.shape[0]:
            break
        e = order[position]
        if (position < n_flat) != (flat[e] != 0):
            raise ValueError("spanning_sheets: the flat edges must come first in the order")
        _join(parent, flip, size, rows[e], cols[e], opposite[e])
    signs, roots = np.ones(n), np.zeros(n, dtype=np.int64)
    for i in range(n):
        roots[i], flipped = _root(parent, flip, i)
        signs[i] = -1.0 if flipped else 1.0
    return signs, roots, sheets


@nb.njit(inline="always", **_JIT)
def _join(parent, flip, size, i, j, opposite):
    """Kruskal's step of ``spanning_signs``: the trees of ``i`` and ``j`` joined (the smaller under the larger,
    ``i``'s on a tie), their ends' signs differing by ``opposite``; nothing when they are one tree."""
    a, fa = _root(parent, flip, i)
    b, fb = _root(parent, flip, j)
    if a != b:
        if size[a] < size[b]:
            a, b = b, a
        parent[b] = a
        flip[b] = fa ^ fb ^ opposite
        size[a] += size[b]


@nb.njit(**_JIT)
def _number_sheets(parent, flip, least, sheets):
    """``sheets`` (N,): the components of the union-find numbered by their first point, -1 below ``least``."""
    n = parent.shape[0]
    label = np.full(n, -1, dtype=np.int64)
    counts = np.zeros(n, dtype=np.int64)
    found = 0
    for i in range(n):
        r = _root(parent, flip, i)[0]
        if label[r] < 0:
            label[r] = found
            found += 1
        sheets[i] = label[r]
        counts[label[r]] += 1
    for i in range(n):
        if counts[sheets[i]] < least:
            sheets[i] = -1


@nb.njit(**_JIT)
def torn_ends(flat, cosine, signs, rows, cols, parallel, doubtful):
    """``doubtful`` (N,) bool, in place: the ends of the ``flat`` (E,) edges ``(rows, cols)`` whose ``cosine``
    ``n_i . n_j`` is at least ``parallel`` in magnitude and whose oriented normals (``signs`` (N,)) are opposite
    (:func:`meshcurv._pointcloud_normals.oriented_signs`). Returns ``doubtful``."""
    for e in range(rows.shape[0]):
        if flat[e] and abs(cosine[e]) >= parallel:
            a, b = rows[e], cols[e]
            if signs[a] * signs[b] * cosine[e] < 0:
                doubtful[a] = True
                doubtful[b] = True
    return doubtful


@nb.njit(parallel=True, **_JIT)
def morton_codes(points, low, scale, top):
    """(N,) uint64 the Morton codes of :func:`meshcurv.pointcloud._spatial_order`: the coordinates less ``low``
    (3,) times ``scale``, truncated to integers (at most ``top``), their bits interleaved (x lowest)."""
    n = points.shape[0]
    code = np.zeros(n, dtype=np.uint64)
    for i in nb.prange(n):
        value = np.uint64(0)
        for axis in range(3):
            value |= _spread(min(np.uint64((points[i, axis] - low[axis]) * scale), top)) << np.uint64(axis)
        code[i] = value
    return code


@nb.njit(inline="always", **_JIT)
def _spread(cell):
    """The 21 bits of ``cell`` (uint64) spread three apart (bit b to bit 3 b)."""
    cell = (cell | (cell << np.uint64(32))) & np.uint64(0x1F00000000FFFF)
    cell = (cell | (cell << np.uint64(16))) & np.uint64(0x1F0000FF0000FF)
    cell = (cell | (cell << np.uint64(8))) & np.uint64(0x100F00F00F00F00F)
    cell = (cell | (cell << np.uint64(4))) & np.uint64(0x10C30C30C30C30C3)
    return (cell | (cell << np.uint64(2))) & np.uint64(0x1249249249249249)


@nb.njit(**_JIT)
def stable_order(code):
    """``(order, ordered)``: (N,) int64 ``np.argsort(code, kind="stable")`` of ``code`` (N,) uint64 and (N,)
    ``code[order]``: a least-significant-digit radix sort, 8 bits a pass, the passes over bytes every code holds
    as 0 skipped. A stable order is unique."""
    n = code.shape[0]
    order, keys = np.arange(n), code.copy()
    spare_order, spare_keys = np.zeros(n, dtype=np.int64), np.zeros(n, dtype=np.uint64)
    used = np.uint64(0)
    for i in range(n):
        used |= code[i]
    counts = np.zeros(256, dtype=np.int64)
    for byte in range(8):
        shift = np.uint64(8 * byte)
        if ((used >> shift) & np.uint64(255)) == 0:
            continue
        counts[:] = 0
        for i in range(n):
            counts[(keys[i] >> shift) & np.uint64(255)] += 1
        total = 0
        for digit in range(256):
            count = counts[digit]
            counts[digit] = total
            total += count
        for i in range(n):
            digit = (keys[i] >> shift) & np.uint64(255)
            spare_order[counts[digit]] = order[i]
            spare_keys[counts[digit]] = keys[i]
            counts[digit] += 1
        order, spare_order = spare_order, order
        keys, spare_keys = spare_keys, keys
    return order, keys


@nb.njit(**_JIT)
def used_edges(flat, stacked, rows, cols, opposite, weights):
    """The edges of :func:`meshcurv._pointcloud_normals.oriented_signs`'s forest in one pass: of the
    ``used = flat | stacked`` (E,) edges, ``(rows[used], cols[used], opposite[used] as int8, weights[used],
    flat[used] as int8, np.flatnonzero(~used))``."""
    e = rows.shape[0]
    m = 0
    for i in range(e):
        if flat[i] or stacked[i]:
            m += 1
    used_rows, used_cols = np.zeros(m, dtype=rows.dtype), np.zeros(m, dtype=cols.dtype)
    used_opposite, used_weights = np.zeros(m, dtype=np.int8), np.zeros(m)
    used_flat, other = np.zeros(m, dtype=np.int8), np.zeros(e - m, dtype=np.int64)
    m = 0
    for i in range(e):
        if flat[i] or stacked[i]:
            used_rows[m], used_cols[m] = rows[i], cols[i]
            used_opposite[m] = 1 if opposite[i] else 0
            used_weights[m] = weights[i]
            used_flat[m] = 1 if flat[i] else 0
            m += 1
        else:
            other[i - m] = i
    return used_rows, used_cols, used_opposite, used_weights, used_flat, other


@nb.njit(parallel=True, **_JIT)
def gathered_results(take, k_min, k_max, dir_min, dir_max, normals, valid, reason, undefined):
    """The fields of the distinct points back to every input point, in one pass on every core.

    Row ``i`` takes row ``take[i]`` (M,) of ``k_min, k_max`` (N,), ``dir_min, dir_max, normals`` (N, 3),
    ``valid`` (N,) bool and ``reason`` (N,) int8; a row is valid when ``valid`` and both curvatures are finite,
    and an invalid row's curvatures and directions are NaN, its reason ``reason`` when above 0, else
    ``undefined`` (:func:`meshcurv.pointcloud._estimated`). Returns the seven (M,) and (M, 3) fields.
    """
    m = take.shape[0]
    out_min, out_max = np.full(m, np.nan), np.full(m, np.nan)
    out_dir_min, out_dir_max = np.full((m, 3), np.nan), np.full((m, 3), np.nan)
    out_normals, out_valid = np.zeros((m, 3)), np.zeros(m, dtype=np.bool_)
    out_reason = np.zeros(m, dtype=np.int8)
    for i in nb.prange(m):
        t = take[i]
        for j in range(3):
            out_normals[i, j] = normals[t, j]
        if valid[t] and np.isfinite(k_min[t]) and np.isfinite(k_max[t]):
            out_valid[i] = True
            out_min[i], out_max[i] = k_min[t], k_max[t]
            for j in range(3):
                out_dir_min[i, j], out_dir_max[i, j] = dir_min[t, j], dir_max[t, j]
        else:
            out_reason[i] = reason[t] if reason[t] > 0 else undefined
    return out_min, out_max, out_dir_min, out_dir_max, out_normals, out_valid, out_reason
