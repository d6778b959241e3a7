"""Compiled twins of the point-cloud orientation graph and checks (:mod:`meshcurv._pointcloud_normals`,
:mod:`meshcurv.pointcloud`).

:func:`spanning_sheets` grows the minimum spanning forest of the orientation
(Kruskal, the union-find of :func:`meshcurv._kernels.pointcloud.spanning_signs`)
and reads the flat edges' components (the sheets) off the same union-find
when the last flat edge is taken: every flat edge weighs less than every
stacked one, so the flat edges are a prefix of the order. :func:`torn_ends`
marks the ends of the flat edges left opposite; :func:`morton_codes` and
:func:`stable_order` are the Morton codes and their stable order of
:func:`meshcurv.pointcloud._spatial_order`; :func:`gathered_results` takes the
fields of the distinct points back to every input point.
Each returns what its NumPy twin returns, to the bit.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from ._common import _JIT
from .pointcloud import _root


@nb.njit(**_JIT)
def spanning_sheets(n, rows, cols, opposite, order, n_flat, least):
    """``(signs, roots, sheets)``: :func:`meshcurv._kernels.pointcloud.spanning_signs` and the sheets on the way.

    Kruskal's algorithm over the edges ``(rows, cols)`` taken in ``order``
    (E,), the same union-find and the same unions as ``spanning_signs``:
    ``signs`` (N,) and ``roots`` (N,) are its outputs to the bit. The first
    ``n_flat`` edges of ``order`` are the flat ones (the caller checks it);
    when the last of them is taken, the components of the union-find are
    those of the flat edges: ``sheets`` (N,) numbers them 0, 1, ... in the
    order of their first point (as
    :func:`scipy.sparse.csgraph.connected_components` does), -1 for those of
    fewer than ``least`` points (:func:`meshcurv._pointcloud_normals._sheets`).

    The union-find holds 32-bit indices below 2**31 points (half the memory its jumps touch; 1M points:
    0.32-0.35 -> 0.24-0.28 s of the walk with :func:`_flattened`).
    """
    if n < 2**31:
        return _spanning_walk(np.arange(n).astype(np.int32), rows, cols, opposite, order, n_flat, least)
    return _spanning_walk(np.arange(n), rows, cols, opposite, order, n_flat, least)


@nb.njit(**_JIT)
def first_point_parts(signs, roots):
    """``(signs, labels)``: (N,) ``signs[i] * signs[f]`` and (N,) the component of each point, the components of
    ``roots`` (N,) (a union-find's, indices below N) numbered 0, 1, ... in the order of their first point ``f``
    (the smallest index of the component), whose sign is then +1: the labels of the NumPy forest.

    One pass in the index order instead of ``np.minimum.at`` (1M points: 0.1 s of one core), its gathers and
    a dense numbering (:func:`meshcurv._pointcloud_normals._first_point_parts`): a component's first point comes
    before its other points, so its sign and label are set when they are read.
    """
    n = roots.shape[0]
    first = np.full(n, n, dtype=np.int64)  # (per root: its component's first point)
    label = np.zeros(n, dtype=np.int64)  # (per root: its component's label)
    out = np.zeros(n)
    labels = np.zeros(n, dtype=np.int64)
    count = 0
    for i in range(n):
        r = roots[i]
        if first[r] == n:
            first[r] = i
            label[r] = count
            count += 1
        out[i] = signs[i] * signs[first[r]]
        labels[i] = label[r]
    return out, labels


@nb.njit(parallel=True, **_JIT)
def _spanning_walk(parent, rows, cols, opposite, order, n_flat, least):
    """:func:`spanning_sheets` over the union-find ``parent`` (N,) (``np.arange(N)``, of the indices' type).

    The edges are gathered in ``order`` first, on every core: Kruskal's walk then reads them in sequence, and
    only its union-find jumps in memory (1M points, 6M edges: 1.07-1.19 -> 0.60-0.62 CPU s, the gather included).
    Each point's root is read on every core (:func:`_flattened`), for the sheets and at the end: which trees are
    joined and how depends on the roots and sizes only, not on the paths to the roots, so the unions after are
    the same.
    """
    n, m = parent.shape[0], order.shape[0]
    edge_rows, edge_cols = np.empty(m, parent.dtype), np.empty(m, parent.dtype)
    edge_opposite = np.empty(m, np.int8)
    for position in nb.prange(m):
        e = order[position]
        edge_rows[position], edge_cols[position], edge_opposite[position] = rows[e], cols[e], opposite[e]
    flip, size = np.zeros(n, dtype=np.int8), np.ones(n, dtype=parent.dtype)
    roots, flips = np.zeros(n, dtype=parent.dtype), np.zeros(n, dtype=np.int8)
    sheets = np.full(n, -1, dtype=np.int64)
    for position in range(m):
        if position == n_flat:  # (stacked edges follow: the sheets are the components now)
            _flattened(parent, flip, roots, flips)
            sheets[:] = roots
            _number_sheets(sheets, least)
        _join(parent, flip, size, edge_rows[position], edge_cols[position], edge_opposite[position])
    _flattened(parent, flip, roots, flips)
    signs = np.ones(n)
    for i in nb.prange(n):
        if flips[i]:
            signs[i] = -1.0
    if n_flat >= m:  # every edge flat: the sheets are the forest's components
        sheets[:] = roots
        _number_sheets(sheets, least)
    return signs, roots.astype(np.int64), sheets


@nb.njit(parallel=True, **_JIT)
def _flattened(parent, flip, roots, flips):
    """Each point's root ``roots`` (N,) and flip relative to it ``flips`` (N,) of the union-find, on every core
    (the walks read ``parent`` and ``flip`` only), then every point hung under its root (in a second pass: no
    walk sees a point's new parent with its old flip)."""
    n = parent.shape[0]
    for i in nb.prange(n):
        j, flipped = np.int64(i), 0
        while parent[j] != j:
            flipped ^= flip[j]
            j = np.int64(parent[j])
        roots[i], flips[i] = j, flipped
    for i in nb.prange(n):
        parent[i], flip[i] = roots[i], flips[i]


@nb.njit(**_JIT)
def _single_edges(indices, kept, used, weights):
    """(E,) bool: the ``used`` edges of the graph ``indices`` (N, k) (``kept`` (N k,): which entries are the edges,
    :func:`meshcurv._kernels.pointcloud.graph_edges`) less each edge ``i -> j`` with ``j < i`` whose reverse
    ``j -> i`` is used and weighs the same (``weights`` (E,)).

    Such a reverse edge comes first in the forest's stable order of the weights (an earlier row): when Kruskal's
    walk of :func:`spanning_sheets` reaches ``i -> j``, ``i`` and ``j`` are one tree and it is skipped. Without
    it the walk makes the same unions in the same order (the same signs, roots and sheets) over fewer edges, and
    fewer weights are sorted (a k nearest graph holds most of its edges both ways).
    """
    return _singles(indices, kept, used, weights, _row_starts(kept, indices.shape[0], indices.shape[1]))


@nb.njit(parallel=True, **_JIT)
def _row_starts(kept, n, k):
    """(N + 1,) the first edge of each row of a graph of ``n`` rows of ``k`` entries, ``kept`` (N k,) of them the
    edges, in order (:func:`meshcurv._kernels.pointcloud.graph_edges`); the edges' count last."""
    starts = np.zeros(n + 1, dtype=np.int64)
    for i in nb.prange(n):
        found = 0
        for c in range(k):
            found += kept[i * k + c]
        starts[i + 1] = found
    for i in range(n):
        starts[i + 1] += starts[i]
    return starts


@nb.njit(parallel=True, **_JIT)
def _singles(indices, kept, used, weights, starts):
    """:func:`_single_edges` of the graph whose rows' first edges are ``starts`` (:func:`_row_starts`)."""
    n, k = indices.shape
    single = used.copy()
    for i in nb.prange(n):
        e = starts[i]
        for c in range(k):
            if not kept[i * k + c]:
                continue
            j = indices[i, c]
            if j < i and used[e]:
                f = starts[j]
                for d in range(k):
                    if kept[j * k + d]:
                        if indices[j, d] == i:
                            if used[f] and weights[f] == weights[e]:
                                single[e] = False
                            break
                        f += 1
            e += 1
    return single


@nb.njit(parallel=True, **_JIT)
def _single_edge_keys(indices, kept, used, flat, weights, scale):
    """``(positions, codes, n_flat, fits)``: the edges :func:`_single_edges` keeps, compacted, with the keys of
    :func:`meshcurv._pointcloud_normals._forest_order`, in one pass on every core.

    ``positions`` (S,) int64 are the kept edges of ``used`` (E,) in increasing order (``np.flatnonzero`` of
    :func:`_single_edges`), ``codes`` (S,) uint64 their ``weights`` (E,) times ``scale`` rounded to the nearest
    integer (half to even, as ``np.rint``), ``n_flat`` how many of them are ``flat`` (E,) and ``fits`` whether
    every rounded weight lies in ``[0, 2**63)`` (NaN does not: then ``codes`` is not to be used). The caller's
    ``weights[single]``, ``flat[single]``, ``flatnonzero(single)`` and the keys' multiply, round, ``min``,
    ``max`` and conversion were each a serial pass over the edges (1M points: about 0.35 CPU s).
    """
    n = indices.shape[0]
    starts = _row_starts(kept, n, indices.shape[1])
    single = _singles(indices, kept, used, weights, starts)
    found = np.zeros(n + 1, dtype=np.int64)
    for i in nb.prange(n):
        count = 0
        for e in range(starts[i], starts[i + 1]):
            count += single[e]
        found[i + 1] = count
    for i in range(n):
        found[i + 1] += found[i]
    m = found[n]
    positions, codes = np.zeros(m, dtype=np.int64), np.zeros(m, dtype=np.uint64)
    flats, misfits = np.zeros(n, dtype=np.int64), np.zeros(n, dtype=np.int64)
    top = 2.0**63
    for i in nb.prange(n):
        s = found[i]
        for e in range(starts[i], starts[i + 1]):
            if single[e]:
                key = np.rint(weights[e] * scale)
                positions[s] = e
                if key >= 0.0 and key < top:
                    codes[s] = np.uint64(key)
                else:
                    misfits[i] += 1
                flats[i] += flat[e]
                s += 1
    return positions, codes, flats.sum(), misfits.sum() == 0


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
def _number_sheets(sheets, least):
    """``sheets`` (N,), each point's root in the union-find, in place: the components numbered by their first
    point, -1 for those of fewer than ``least`` points."""
    n = sheets.shape[0]
    label = np.full(n, -1, dtype=np.int64)
    counts = np.zeros(n, dtype=np.int64)
    found = 0
    for i in range(n):
        r = sheets[i]
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


#: The ranges of the codes :func:`stable_order` counts and places on every core: a fixed number, so that the
#: ranges (and the work of each pass) do not depend on the threads; a stable order is unique anyway.
SORT_RANGES = 64


@nb.njit(parallel=True, **_JIT)
def stable_order(code, values=None):
    """``(order, ordered)``: (N,) int64 ``np.argsort(code, kind="stable")`` of ``code`` (N,) uint64 and (N,)
    ``code[order]``: a least-significant-digit radix sort, 8 bits a pass, the passes over bytes every code holds
    as 0 skipped. A stable order is unique. With ``values`` (N,) int64: ``values[order]`` instead of ``order``
    (the values carried through the passes in its place: no gather of them in a random order after the sort,
    3.5M edges of 1M points: 0.05-0.25 s of one core).

    Each pass counts the digits of :data:`SORT_RANGES` consecutive ranges of the codes on every core, then
    places each range's codes on every core: a digit's codes of range ``r`` after those of the ranges before
    it, each range's in their order, which is the order of one serial pass (1M points, 3.5M edge weights, 4
    passes: 0.115 -> about 0.06 s of wall on two cores).
    """
    n = code.shape[0]
    if values is None:
        order = np.arange(n)
    else:
        order = values.copy()
    keys = code.copy()
    spare_order, spare_keys = np.zeros(n, dtype=np.int64), np.zeros(n, dtype=np.uint64)
    ranges = max(min(SORT_RANGES, n), 1)
    bounds = np.zeros(ranges + 1, dtype=np.int64)
    for r in range(ranges + 1):
        bounds[r] = r * n // ranges
    held = np.zeros(ranges, dtype=np.uint64)
    for r in nb.prange(ranges):
        value = np.uint64(0)
        for i in range(bounds[r], bounds[r + 1]):
            value |= code[i]
        held[r] = value
    used = np.uint64(0)
    for r in range(ranges):
        used |= held[r]
    counts = np.zeros((ranges, 256), dtype=np.int64)
    for byte in range(8):
        shift = np.uint64(8 * byte)
        if ((used >> shift) & np.uint64(255)) == 0:
            continue
        for r in nb.prange(ranges):
            for digit in range(256):
                counts[r, digit] = 0
            for i in range(bounds[r], bounds[r + 1]):
                counts[r, (keys[i] >> shift) & np.uint64(255)] += 1
        total = 0
        for digit in range(256):
            for r in range(ranges):
                count = counts[r, digit]
                counts[r, digit] = total
                total += count
        for r in nb.prange(ranges):
            for i in range(bounds[r], bounds[r + 1]):
                digit = (keys[i] >> shift) & np.uint64(255)
                place = counts[r, digit]
                spare_order[place] = order[i]
                spare_keys[place] = keys[i]
                counts[r, digit] = place + 1
        order, spare_order = spare_order, order
        keys, spare_keys = spare_keys, keys
    return order, keys


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
