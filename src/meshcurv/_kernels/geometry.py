"""Compiled twins of :mod:`meshcurv.geometry`: face cross products, vertex normals, edge lengths,
degenerate faces.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ._common import _JIT, _degenerate, _edge_length, _face_cross, _unit, run_chunks, threaded


#: the fixed number of runs of a reduction that must not depend on the thread count
_SUM_CHUNKS = 256

#: The passes over faces, edges or vertices run in this many chunks per thread (:func:`~._common.run_chunks`):
#: plain compiled chunks on threads, not ``parallel=True`` kernels (0.5-1 s of CPU each to compile, issue 31).
_CHUNKS_PER_THREAD = 4


@nb.njit(**_JIT)
def _unadvised_empty(shape, dtype):
    """An unfilled array of ``shape`` and ``dtype`` (a numpy scalar type: ``np.float64``) from numba's allocator
    (glibc's ``malloc``) rather than numpy's.

    NumPy asks the kernel to back every array of 4 MB or more with huge pages (``madvise(MADV_HUGEPAGE)``).
    Where transparent huge pages are given to advised memory only (``/sys/kernel/mm/transparent_hugepage``
    ``enabled`` and ``defrag`` both ``madvise``, the default of many distributions), the first write to each
    2 MB of a fresh buffer then waits while the kernel compacts memory to find one. The large arrays of a call
    are fresh on every call (glibc maps buffers above 32 MB afresh and hands them back when freed); those the
    kernels write whole, in order (the face measures, the curvatures of ``icc``), are taken here. Issue 31, at
    1M vertices (``benchmarks/faults_S24.py``): the face measures' (F, 9) took 0.15-0.29 s of system time on
    numpy's pages, 0.05-0.06 s on these, the same user time there and in the ball sums that read them. Where
    huge pages are given to all memory (``enabled`` ``always``), both are alike.
    """
    return np.empty(shape, dtype)


@nb.njit(**_JIT)
def _unadvised_zeros(shape):
    """float64 zeros of ``shape`` from numba's allocator (:func:`_unadvised_empty`; numba's ``memset``, on the
    calling thread)."""
    return np.zeros(shape)


@nb.njit(**_JIT)
def _unadvised_bytes(n_bytes, zero):
    """``n_bytes`` bytes from numba's allocator (:func:`_unadvised_empty`), zeroed when ``zero`` (numba's
    ``memset``, on the calling thread). 32-byte aligned (numba aligns every array it allocates so). The zeros as a
    loop (LLVM makes it the same ``memset``), not ``np.zeros``: numba compiles that and its fill beside the
    ``np.empty`` (issue 31)."""
    out = np.empty(n_bytes, np.uint8)
    if zero:
        for i in range(n_bytes):
            out[i] = 0
    return out


def _unadvised_array(shape, dtype, *, zero: bool = False) -> np.ndarray:
    """A C-contiguous array of ``shape`` and ``dtype`` from numba's allocator, unfilled (or zeros where ``zero``):
    :func:`_unadvised_empty` for any shape and type, through one compiled function (:func:`_unadvised_bytes`, a
    byte array viewed as ``dtype``), not one per shape and type (each a compilation on a cold cache). For the
    large arrays of a call outside the icc kernels (the topology's, the zero-area pass's, issue 31)."""
    dtype = np.dtype(dtype)
    shape = (int(shape),) if np.ndim(shape) == 0 else tuple(int(n) for n in shape)
    return _unadvised_bytes(math.prod(shape) * dtype.itemsize, zero).view(dtype).reshape(shape)


@threaded
def _mean_edge_length(vertices, edges):
    """Mean length of the edges (0 when there are none), summed in a fixed order.

    The edges are cut into :data:`_SUM_CHUNKS` runs whatever the thread count; each run is summed in order
    (:func:`_run_length_sums`, on threads: :func:`~meshcurv._kernels._common.run_chunks`) and the runs' sums are
    added in order, so the result (and every radius derived from it) is the same bit for bit on any number of
    threads. A ``parallel=True`` kernel did the same in about a second more of compile time (issue 31).
    """
    n = edges.shape[0]
    if n == 0:
        return 0.0
    chunks = min(_SUM_CHUNKS, n)
    partial = np.zeros(chunks)
    run_chunks(_run_length_sums, chunks, _CHUNKS_PER_THREAD * nb.get_num_threads(), vertices, edges, partial)
    total = 0.0
    for c in range(chunks):  # Python floats are IEEE doubles: the compiled loop's sum, bit for bit
        total += float(partial[c])
    return total / n


@nb.njit(**_JIT)
def _run_length_sums(lo, hi, vertices, edges, partial):
    """:func:`_mean_edge_length`: ``partial[c]``, the sum in order of the lengths of run ``c`` of the edges, for
    ``c`` in ``lo:hi``."""
    n = edges.shape[0]
    chunks = partial.shape[0]
    for c in range(lo, hi):
        total = 0.0
        for e in range(c * n // chunks, (c + 1) * n // chunks):
            total += _edge_length(vertices, edges[e, 0], edges[e, 1])
        partial[c] = total


@threaded
def _mean_and_longest_edge(vertices, edges):
    """``(mean, longest)``: :func:`_mean_edge_length` (the same runs, summed in the same order: the same number)
    and the length of the longest edge, in one pass over the edges without an (E,) array of their lengths
    (``_geometry.robust_mean_edge_length``, issue 31). ``edges`` not empty."""
    n = edges.shape[0]
    chunks = min(_SUM_CHUNKS, n)
    partial = np.zeros(chunks)
    longest = np.zeros(chunks)
    run_chunks(
        _run_length_sums_longest,
        chunks,
        _CHUNKS_PER_THREAD * nb.get_num_threads(),
        vertices,
        edges,
        partial,
        longest,
    )
    total = 0.0
    for c in range(chunks):  # in order, as _mean_edge_length
        total += float(partial[c])
    return total / n, float(longest.max())


@nb.njit(**_JIT)
def _run_length_sums_longest(lo, hi, vertices, edges, partial, longest):
    """:func:`_run_length_sums` of the runs ``lo:hi``, and the longest edge of each run in ``longest``."""
    n = edges.shape[0]
    chunks = partial.shape[0]
    for c in range(lo, hi):
        total = 0.0
        far = 0.0
        for e in range(c * n // chunks, (c + 1) * n // chunks):
            length = _edge_length(vertices, edges[e, 0], edges[e, 1])
            total += length
            far = length if length > far else far  # max(far, length): numba compiles max once per options
        partial[c] = total
        longest[c] = far


@threaded
def face_cross_products(vertices, faces):
    """``geometry.face_cross_products``: (F, 3) ``cross(b - a, c - a)`` of every face."""
    out = _unadvised_array((faces.shape[0], 3), np.float64)  # every row written by its chunk
    run_chunks(_face_cross_chunk, faces.shape[0], _CHUNKS_PER_THREAD * nb.get_num_threads(), vertices, faces, out)
    return out


@nb.njit(**_JIT)
def _face_cross_chunk(lo, hi, vertices, faces, out):
    """Faces ``lo:hi`` of :func:`face_cross_products`."""
    for f in range(lo, hi):
        out[f, 0], out[f, 1], out[f, 2] = _face_cross(vertices, faces[f, 0], faces[f, 1], faces[f, 2])


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


@threaded
def normalize_normal_sums(summed):
    """``geometry.normalize_normal_sums``: unit rows of ``summed``, NaN where they (nearly) cancel."""
    out = _unadvised_array(summed.shape, np.float64)  # every row written by its chunk
    run_chunks(_normalize_chunk, summed.shape[0], _CHUNKS_PER_THREAD * nb.get_num_threads(), summed, out)
    return out


@nb.njit(**_JIT)
def _normalize_chunk(lo, hi, summed, out):
    """Rows ``lo:hi`` of :func:`normalize_normal_sums`."""
    for v in range(lo, hi):
        out[v, 0], out[v, 1], out[v, 2], _ = _unit(summed[v, 0], summed[v, 1], summed[v, 2])


@nb.njit(**_JIT)
def vertex_edge_lengths(vertices, edges, n_vertices):
    """``geometry.vertex_edge_lengths``: (V,) mean length of the edges at each vertex (NaN where none)."""
    total = np.empty(n_vertices)
    count = np.empty(n_vertices)
    for v in range(n_vertices):  # zeros (numba's np.zeros compiles three functions more, issue 31)
        total[v] = count[v] = 0.0
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


@nb.njit(**_JIT)
def edge_lengths(vertices, edges):
    """``geometry.edge_lengths``: (E,) length of each edge. One thread: a ``parallel=True`` kernel took about
    0.6 s more CPU to compile on a cold cache (issue 31) for a pass bound by memory."""
    out = np.empty(edges.shape[0])
    for e in range(edges.shape[0]):
        out[e] = _edge_length(vertices, edges[e, 0], edges[e, 1])
    return out


@threaded
def cross_and_degenerate(vertices, faces, scales, area_ratio):
    """``(cross, degenerate)``: :func:`face_cross_products`, and (F,) bool the faces that repeat a vertex or whose
    area is at most ``area_ratio`` x ``scales[a]^2`` (``scales`` (V,) the length scale at each vertex,
    ``geometry.vertex_length_scales``, read at the first corner ``a``: the corners of a face share their
    component), in one pass over the faces (``geometry.degenerate_faces``), in chunks of faces on threads
    (:func:`~meshcurv._kernels._common.run_chunks`)."""
    cross = _unadvised_array((faces.shape[0], 3), np.float64)  # every row written by its chunk
    out = _unadvised_array(faces.shape[0], np.bool_)
    run_chunks(
        _cross_and_degenerate_chunk,
        faces.shape[0],
        _CHUNKS_PER_THREAD * nb.get_num_threads(),
        vertices,
        faces,
        scales,
        float(area_ratio),
        cross,
        out,
    )
    return cross, out


@nb.njit(**_JIT)
def _cross_and_degenerate_chunk(lo, hi, vertices, faces, scales, area_ratio, cross, out):
    """Faces ``lo:hi`` of :func:`cross_and_degenerate`."""
    for f in range(lo, hi):
        a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
        nx, ny, nz = _face_cross(vertices, a, b, c)
        cross[f, 0], cross[f, 1], cross[f, 2] = nx, ny, nz
        threshold = area_ratio * scales[a] * scales[a]
        out[f] = _degenerate(a, b, c, 0.5 * math.sqrt(nx * nx + ny * ny + nz * nz), threshold)


@nb.njit(inline="always", **_JIT)
def _add_to_corners(faces, f, x, y, z, third, sums, areas):
    """Face ``f``'s cross product ``(x, y, z)`` added to ``sums`` and ``third`` to ``areas`` at its three corners."""
    for k in range(3):
        v = faces[f, k]
        sums[v, 0] += x
        sums[v, 1] += y
        sums[v, 2] += z
        areas[v] += third


@nb.njit(**_JIT)
def vertex_normal_and_area_sums(cross, faces, dropped, n_vertices):
    """``(sums, areas)``: (V, 3) the sums of the face cross products at each vertex and (V,) a third of the
    faces' areas, both over the faces not ``dropped``, in face order (as ``np.bincount``). One thread: a
    scatter bound by memory."""
    sums = np.empty((n_vertices, 3))
    areas = np.empty(n_vertices)
    for v in range(n_vertices):  # zeros (numba's np.zeros compiles three functions more, issue 31)
        sums[v, 0] = sums[v, 1] = sums[v, 2] = areas[v] = 0.0
    for f in range(faces.shape[0]):
        if dropped[f]:
            continue
        x, y, z = cross[f, 0], cross[f, 1], cross[f, 2]
        _add_to_corners(faces, f, x, y, z, math.sqrt(x * x + y * y + z * z) / 6.0, sums, areas)
    return sums, areas


@nb.njit(**_JIT)
def _degenerate_normal_and_area_sums(vertices, faces, scales, area_ratio, degenerate, sums, areas):
    """:func:`cross_and_degenerate`'s zero-area faces and :func:`vertex_normal_and_area_sums` over the faces not
    degenerate, in one pass over the faces (``PreparedMesh`` of a mesh without needles, where the faces dropped
    from the vertex normals are the zero-area ones): the same test, the same cross products and the same sums in
    face order, written into ``degenerate`` (F,) and ``sums`` (V, 3), ``areas`` (V,) (zeros on entry), without the
    (F, 3) cross products in memory. One thread: a scatter bound by memory (issue 31)."""
    for f in range(faces.shape[0]):
        a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
        x, y, z = _face_cross(vertices, a, b, c)
        length = math.sqrt(x * x + y * y + z * z)
        dropped = _degenerate(a, b, c, 0.5 * length, area_ratio * scales[a] * scales[a])
        degenerate[f] = dropped
        if dropped:
            continue
        _add_to_corners(faces, f, x, y, z, length / 6.0, sums, areas)
