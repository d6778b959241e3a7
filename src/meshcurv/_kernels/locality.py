"""Compiled twins of :mod:`meshcurv._locality`: a local order of a mesh's vertices and faces."""

from __future__ import annotations

import numba as nb
import numpy as np

from ._common import _JIT
from .topology import _bucket_starts


@nb.njit(parallel=True, **_JIT)
def morton_reordering(vertices, faces, lo, scale, bits, spread):
    """``_locality.morton_reordering``: ``(order, index, face_order, new_vertices, new_faces)``.

    The vertices in the order of their Morton codes (``bits`` bits per axis of
    ``(x - lo) * scale``, spread to every third bit by the (steps, 2) uint64
    ``(shift, mask)`` rows of ``spread``; stable), the faces renumbered and sorted by their smallest new
    corner (a stable counting sort).
    """
    n = vertices.shape[0]
    n_faces = faces.shape[0]
    codes = np.zeros(n, np.uint64)
    top = np.uint64(2**bits - 1)
    for k in nb.prange(n):
        code = np.uint64(0)
        for a in range(3):
            x = np.uint64((vertices[k, a] - lo[a]) * scale) & top
            for step in range(spread.shape[0]):
                x = (x | (x << spread[step, 0])) & spread[step, 1]
            code |= x << np.uint64(a)
        codes[k] = code
    order = _radix_order(codes, 3 * bits)
    index = np.empty(n, np.int64)
    new_vertices = np.empty((n, 3))
    for k in nb.prange(n):
        index[order[k]] = k
        for a in range(3):
            new_vertices[k, a] = vertices[order[k], a]
    renumbered = np.empty((n_faces, 3), np.int64)
    for f in nb.prange(n_faces):
        for a in range(3):
            renumbered[f, a] = index[faces[f, a]]
    cursor = np.zeros((1, n), np.int64)  # faces by smallest corner, then where the next one goes
    for f in range(n_faces):
        cursor[0, min(renumbered[f, 0], renumbered[f, 1], renumbered[f, 2])] += 1
    _bucket_starts(cursor)
    face_order = np.empty(n_faces, np.int64)
    for f in range(n_faces):
        low = min(renumbered[f, 0], renumbered[f, 1], renumbered[f, 2])
        face_order[cursor[0, low]] = f
        cursor[0, low] += 1
    new_faces = np.empty((n_faces, 3), np.int64)
    for j in nb.prange(n_faces):
        for a in range(3):
            new_faces[j, a] = renumbered[face_order[j], a]
    return order, index, face_order, new_vertices, new_faces


@nb.njit(**_JIT)
def _radix_order(codes, bits):
    """(N,) indices of ``codes`` (uint64 of ``bits`` bits) in ascending order, stable: a radix sort
    of 16-bit digits, least significant first (``np.argsort(kind="stable")``)."""
    n = codes.shape[0]
    order = np.arange(n)
    keys = codes.copy()
    next_order = np.empty(n, np.int64)
    next_keys = np.empty(n, np.uint64)
    mask = np.uint64(0xFFFF)
    for shift in range(0, bits, 16):
        starts = np.zeros(65537, np.int64)
        for i in range(n):
            starts[np.int64((keys[i] >> np.uint64(shift)) & mask) + 1] += 1
        for d in range(65536):
            starts[d + 1] += starts[d]
        for i in range(n):
            digit = np.int64((keys[i] >> np.uint64(shift)) & mask)
            at = starts[digit]
            starts[digit] += 1
            next_order[at] = order[i]
            next_keys[at] = keys[i]
        order, next_order = next_order, order
        keys, next_keys = next_keys, keys
    return order
