"""Smoothing of per-vertex fields over the mesh graph (vertices never move)."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

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
    operator = _averaging_operator(topology)
    for _ in range(steps):
        field = operator @ field
    return field


def _averaging_operator(topology: MeshTopology) -> sp.csr_matrix:
    """(V, V) row-stochastic sparse matrix ``D^-1 (A + I)``."""
    matrix = (topology.adjacency + sp.identity(topology.n_vertices, format="csr")).tocsr()
    row_sums = np.asarray(matrix.sum(axis=1)).ravel()
    return sp.diags(1.0 / row_sums) @ matrix
