"""Batched eigen-decomposition of symmetric 3x3 tensors stored as six components."""

from __future__ import annotations

import numpy as np


_ROWS = np.array([0, 3, 4, 3, 1, 5, 4, 5, 2])  # (xx, yy, zz, xy, xz, yz) -> 3x3, row-major


def sorted_by_magnitude(tensors: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eigenpairs of (N, 6) symmetric tensors, ordered by absolute eigenvalue.

    Returns ``values`` (N, 3) and ``vectors`` (N, 3, 3) (``vectors[i, :, k]`` goes
    with ``values[i, k]``), with ``|values[:, 0]| <= |values[:, 1]| <= |values[:, 2]|``.
    The sort is stable over LAPACK's ascending order, as matGeom's ``sort(abs(d))``
    over Octave's ``eig``. Rows with a non-finite component are NaN. (The
    compiled path of matGeom's estimator does the same per vertex in
    ``_kernels.matgeom.matgeom_principal``.)
    """
    n = tensors.shape[0]
    values = np.full((n, 3), np.nan)
    vectors = np.full((n, 3, 3), np.nan)
    finite = np.isfinite(tensors).all(axis=1)
    matrices = tensors[finite][:, _ROWS].reshape(-1, 3, 3)
    if matrices.shape[0]:
        w, v = np.linalg.eigh(matrices)
        order = np.argsort(np.abs(w), axis=1, kind="stable")
        values[finite] = np.take_along_axis(w, order, axis=1)
        vectors[finite] = np.take_along_axis(v, order[:, None, :], axis=2)
    return values, vectors
