"""Compiled twin of :mod:`meshcurv.smoothing`: repeated averages over the neighbour lists."""

from __future__ import annotations

import numba as nb
import numpy as np

from ._common import _JIT


@nb.njit(parallel=True, **_JIT)
def smooth_over_neighbours(values, indptr, indices, steps):
    """``steps`` passes of the 1-ring mean (neighbours + self) / (degree + 1), by gathering: the sums of
    ``smoothing.smooth_over_neighbours`` in its order (the sparse product from 0 over the neighbours in
    list order, then the vertex's own value), so that both backends smooth to the bit."""
    n_vertices, n_columns = values.shape
    current = values.copy()
    following = np.empty_like(current)
    for _ in range(steps):
        for i in nb.prange(n_vertices):
            start, stop = indptr[i], indptr[i + 1]
            scale = 1.0 / (stop - start + 1.0)
            for c in range(n_columns):
                following[i, c] = 0.0
            for j in range(start, stop):  # neighbours outside, columns inside: each row read once
                w = indices[j]
                for c in range(n_columns):
                    following[i, c] += current[w, c]
            for c in range(n_columns):
                following[i, c] = (following[i, c] + current[i, c]) * scale
        current, following = following, current
    return current
