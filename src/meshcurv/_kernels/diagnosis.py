"""Compiled twin of :mod:`meshcurv.diagnosis`: the facts of a mesh in one pass."""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ._common import _JIT, _UNSIGNED, _degenerate, _edge_length, _face_cross


@nb.njit(**_JIT)  # serial: as fast as the parallel reductions (bound by memory), 1.4 s less to compile
def mesh_facts(vertices, faces, edges, referenced, scales, area_ratio, zero_length_ratio):
    """The measured facts of :func:`meshcurv.diagnose`, in one pass over vertices, faces and edges.

    Returns ``(lower, upper, area, six_volume, mean_length, n_degenerate, n_zero_length)``:
    the bounding box of the referenced vertices, the total area, the sum over
    faces of ``(a - centre) . cross(b - a, c - a)`` (``centre`` the mean of the
    referenced vertices), the mean edge length, the faces that repeat a vertex or
    whose area is at most ``area_ratio`` x ``scales[a]^2``, the edges no longer
    than ``zero_length_ratio`` x ``scales`` at their first end (``scales``: the
    length scale of each vertex, ``geometry.vertex_length_scales``).
    """
    lower = np.empty(3)  # inf, -inf and zeros: numba's np.full and np.zeros compile more functions (issue 31)
    upper = np.empty(3)
    centre = np.empty(3)
    for k in range(3):
        lower[k], upper[k], centre[k] = np.inf, -np.inf, 0.0
    used = 0
    for v in range(vertices.shape[0]):
        if not referenced[v]:
            continue
        used += 1
        for k in range(3):
            x = vertices[v, k]
            centre[k] += x
            lower[k] = x if x < lower[k] else lower[k]  # min(lower[k], x): numba compiles min and max once per
            upper[k] = x if x > upper[k] else upper[k]  # caller's options (issue 31)
    if used:
        for k in range(3):  # not centre /= used: numba types and lowers the array operation as a ufunc
            centre[k] /= used
    n_edges = edges.shape[0]
    total = 0.0
    n_zero_length = 0
    for e in range(n_edges):  # one pass, no (E,) array of the lengths (24 MB at a million vertices)
        p = _UNSIGNED(edges[e, 0])
        length = _edge_length(vertices, p, _UNSIGNED(edges[e, 1]))
        total += length
        n_zero_length += 1 if length <= zero_length_ratio * scales[p] else 0
    mean = total / n_edges if n_edges else 0.0
    area = 0.0
    six_volume = 0.0
    n_degenerate = 0
    for f in range(faces.shape[0]):
        a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
        nx, ny, nz = _face_cross(vertices, a, b, c)
        half = 0.5 * math.sqrt(nx * nx + ny * ny + nz * nz)
        area += half
        n_degenerate += 1 if _degenerate(a, b, c, half, area_ratio * scales[a] * scales[a]) else 0
        six_volume += (
            (vertices[a, 0] - centre[0]) * nx + (vertices[a, 1] - centre[1]) * ny + (vertices[a, 2] - centre[2]) * nz
        )
    return lower, upper, area, six_volume, mean, n_degenerate, n_zero_length


@nb.njit(**_JIT)
def long_edges(vertices, edges, reach):
    """(E,) bool: the edges longer than the smaller ``reach`` of their two ends (the NumPy path of
    :func:`meshcurv.defects.needle_vertices`: the same squared lengths, x + y + z in that order)."""
    out = np.empty(edges.shape[0], np.bool_)
    for e in range(edges.shape[0]):
        a, b = edges[e, 0], edges[e, 1]
        dx, dy, dz = vertices[b, 0] - vertices[a, 0], vertices[b, 1] - vertices[a, 1], vertices[b, 2] - vertices[a, 2]
        ra, rb = reach[a], reach[b]
        r = rb if rb < ra else ra  # min(ra, rb)
        out[e] = dx * dx + dy * dy + dz * dz > r * r
    return out
