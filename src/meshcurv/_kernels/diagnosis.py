"""Compiled twin of :mod:`meshcurv.diagnosis`: the facts of a mesh in one pass over each of its arrays."""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ._common import _JIT, _UNSIGNED, _degenerate, _edge_length, _face_cross, run_chunks, threaded


#: :func:`mesh_facts` sums each of its passes in this many runs, whatever the thread count: the same sums, bit for
#: bit, on any number of threads.
_SUM_RUNS = 64

#: The runs of a pass go to the threads in this many chunks per thread (:func:`~._common.run_chunks`).
_CHUNKS_PER_THREAD = 4


@threaded
def mesh_facts(vertices, faces, edges, referenced, scales, area_ratio, zero_length_ratio):
    """The measured facts of :func:`meshcurv.diagnose`, in one pass over vertices, faces and edges.

    Returns ``(lower, upper, area, six_volume, mean_length, n_degenerate, n_zero_length)``:
    the bounding box of the referenced vertices, the total area, the sum over
    faces of ``(a - centre) . cross(b - a, c - a)`` (``centre`` the mean of the
    referenced vertices), the mean edge length, the faces that repeat a vertex or
    whose area is at most ``area_ratio`` x ``scales[a]^2``, the edges no longer
    than ``zero_length_ratio`` x ``scales`` at their first end (``scales``: the
    length scale of each vertex, ``geometry.vertex_length_scales``).

    Three passes (vertices, edges, faces: :func:`_facts_chunk`), each cut into
    :data:`_SUM_RUNS` runs summed in order on threads
    (:func:`~meshcurv._kernels._common.run_chunks`), the runs' sums then added
    in order: the sums do not depend on the number of threads (they differ from
    one pass in order by round-off). No (E,) array of the lengths.
    """
    sums = np.zeros((_SUM_RUNS, 3))  # centre sums, then (length, area, six volume) sums
    lower = np.full((_SUM_RUNS, 3), np.inf)
    upper = np.full((_SUM_RUNS, 3), -np.inf)
    counts = np.zeros((_SUM_RUNS, 3), np.int64)  # referenced vertices, zero-length edges, degenerate faces
    centre = np.zeros(3)
    chunks = _CHUNKS_PER_THREAD * nb.get_num_threads()
    arrays = (vertices, faces, edges, referenced, scales, area_ratio, zero_length_ratio, centre)
    run_chunks(_facts_chunk, _SUM_RUNS, chunks, 0, *arrays, sums, lower, upper, counts)
    used = 0
    for r in range(_SUM_RUNS):  # in order (Python floats are IEEE doubles, as the compiled sums)
        used += int(counts[r, 0])
        for k in range(3):
            centre[k] += float(sums[r, k])
    if used:
        for k in range(3):
            centre[k] /= used
    run_chunks(_facts_chunk, _SUM_RUNS, chunks, 1, *arrays, sums, lower, upper, counts)
    total = area = six_volume = 0.0
    for r in range(_SUM_RUNS):
        total += float(sums[r, 0])
        area += float(sums[r, 1])
        six_volume += float(sums[r, 2])
    n_edges = edges.shape[0]
    mean = total / n_edges if n_edges else 0.0
    n_zero_length, n_degenerate = int(counts[:, 1].sum()), int(counts[:, 2].sum())
    return lower.min(axis=0), upper.max(axis=0), area, six_volume, mean, n_degenerate, n_zero_length


@nb.njit(**_JIT)
def _facts_chunk(
    lo,
    hi,
    stage,
    vertices,
    faces,
    edges,
    referenced,
    scales,
    area_ratio,
    zero_length_ratio,
    centre,
    sums,
    lower,
    upper,
    counts,
):
    """Runs ``lo`` to ``hi - 1`` of a pass of :func:`mesh_facts`: ``stage`` 0, the referenced vertices (their
    count, coordinate sums, minima and maxima); 1, the edges (length sums, zero-length edges) and the faces
    (area and six-volume sums about ``centre``, zero-area faces), each run's values in its row."""
    runs = sums.shape[0]
    for r in range(lo, hi):
        if stage == 0:
            n = vertices.shape[0]
            used = 0
            for v in range(r * n // runs, (r + 1) * n // runs):
                if not referenced[v]:
                    continue
                used += 1
                for k in range(3):
                    x = vertices[v, k]
                    sums[r, k] += x
                    # min(lower, x), max(upper, x): numba compiles min and max once per caller's options (issue 31)
                    lower[r, k] = x if x < lower[r, k] else lower[r, k]
                    upper[r, k] = x if x > upper[r, k] else upper[r, k]
            counts[r, 0] = used
            continue
        n = edges.shape[0]
        total = 0.0
        n_zero_length = 0
        for e in range(r * n // runs, (r + 1) * n // runs):
            p = _UNSIGNED(edges[e, 0])
            length = _edge_length(vertices, p, _UNSIGNED(edges[e, 1]))
            total += length
            n_zero_length += 1 if length <= zero_length_ratio * scales[p] else 0
        n = faces.shape[0]
        area = 0.0
        six_volume = 0.0
        n_degenerate = 0
        for f in range(r * n // runs, (r + 1) * n // runs):
            a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
            nx, ny, nz = _face_cross(vertices, a, b, c)
            half = 0.5 * math.sqrt(nx * nx + ny * ny + nz * nz)
            area += half
            n_degenerate += 1 if _degenerate(a, b, c, half, area_ratio * scales[a] * scales[a]) else 0
            six_volume += (
                (vertices[a, 0] - centre[0]) * nx
                + (vertices[a, 1] - centre[1]) * ny
                + (vertices[a, 2] - centre[2]) * nz
            )
        sums[r, 0], sums[r, 1], sums[r, 2] = total, area, six_volume
        counts[r, 1], counts[r, 2] = n_zero_length, n_degenerate


@threaded
def long_edges(vertices, edges, reach):
    """(E,) bool: the edges longer than the smaller ``reach`` of their two ends (the NumPy path of
    :func:`meshcurv.defects.needle_vertices`: the same squared lengths, x + y + z in that order). In chunks of
    edges on threads (:func:`~meshcurv._kernels._common.run_chunks`, :func:`_long_chunk`)."""
    out = np.zeros(edges.shape[0], np.bool_)
    run_chunks(_long_chunk, edges.shape[0], _CHUNKS_PER_THREAD * nb.get_num_threads(), vertices, edges, reach, out)
    return out


@nb.njit(**_JIT)
def _long_chunk(lo, hi, vertices, edges, reach, out):
    """:func:`long_edges` of the edges ``lo`` to ``hi - 1``."""
    for e in range(lo, hi):
        a, b = edges[e, 0], edges[e, 1]
        dx, dy, dz = vertices[b, 0] - vertices[a, 0], vertices[b, 1] - vertices[a, 1], vertices[b, 2] - vertices[a, 2]
        ra, rb = reach[a], reach[b]
        r = rb if rb < ra else ra  # min(ra, rb)
        out[e] = dx * dx + dy * dy + dz * dz > r * r
