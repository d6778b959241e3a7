"""Smoothing of per-vertex fields over the mesh graph (vertices never move)."""

from __future__ import annotations

import numpy as np

from ._backend import numba_kernels
from .topology import MeshTopology

__all__ = ["smooth_vertex_field"]


def smooth_vertex_field(values, topology: MeshTopology, steps: int) -> np.ndarray:
    """Average a per-vertex field over 1-rings, ``steps`` times.

    One pass replaces the value at each vertex by the plain mean of its own value
    and the values at its distinct edge neighbours, each with weight
    ``1 / (degree + 1)``: matGeom's ``smoothMeshFunction``. A vertex with no edge
    keeps its value.

    Parameters
    ----------
    values : array_like of shape (V,) or (V, k)
        The field; all ``k`` columns are smoothed at once.
    topology : MeshTopology
        The mesh connectivity (its ``adjacency``).
    steps : int
        Number of passes; 0 returns a copy.

    Returns
    -------
    ndarray of the same shape as ``values``, float64.

    Notes
    -----
    NaN spreads one ring per pass, as in matGeom (the sparse product only
    touches neighbours).
    """
    field = np.array(values, dtype=np.float64, copy=True)
    if steps <= 0:
        return field
    kernels = numba_kernels()
    if kernels is not None:
        flat = np.ascontiguousarray(field.reshape(field.shape[0], -1))
        indptr, indices = topology.neighbour_lists
        return kernels.smooth_over_neighbours(flat, indptr, indices, steps).reshape(field.shape)
    adjacency = topology.adjacency
    scale = 1.0 / (topology.vertex_degrees + 1.0)
    if field.ndim == 2:
        scale = scale[:, None]
    for _ in range(steps):
        field = (adjacency @ field + field) * scale
    return field
