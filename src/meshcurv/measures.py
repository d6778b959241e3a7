"""The interpolated corrected curvature measures of a triangle mesh (Lachaud, Romon, Thibert, Coeurjolly 2020).

Given unit normals ``u_i`` at the vertices, interpolated linearly over each
triangle ``(x_i, x_j, x_k)``, the curvature measures of the corrected normal
current have closed forms per face, with ``ū = (u_i + u_j + u_k) / 3``:

.. math::

    \\mu_0 &= \\tfrac12 \\langle ū \\mid (x_j - x_i) \\times (x_k - x_i) \\rangle
    \\quad\\text{(corrected area)}\\\\
    \\mu_1 &= \\tfrac12 \\langle ū \\mid (u_k - u_j) \\times x_i + (u_i - u_k) \\times x_j
    + (u_j - u_i) \\times x_k \\rangle \\quad (2H\\,dA)\\\\
    \\mu_2 &= \\tfrac12 \\langle u_i \\mid u_j \\times u_k \\rangle \\quad (K\\,dA)\\\\
    \\mu^{X,Y} &= \\tfrac12 \\langle ū \\mid \\langle Y \\mid u_k - u_i \\rangle X \\times (x_j - x_i)
    - \\langle Y \\mid u_j - u_i \\rangle X \\times (x_k - x_i) \\rangle

Summed over a region and divided by its corrected area they give the mean
and Gaussian curvature and the shape operator there. The estimator
``method="icc"`` (:mod:`meshcurv.estimators.icc`) sums them over balls; the
integrals of :mod:`meshcurv.integrals`, point clouds and label images use them
too.

References
----------
J.-O. Lachaud, P. Romon, B. Thibert, D. Coeurjolly (2020). Interpolated
corrected curvature measures for polygonal surfaces. Computer Graphics Forum
39(5), 41-54. https://doi.org/10.1111/cgf.14067
"""

from __future__ import annotations

import numpy as np

from . import _measures
from ._validation import checked_indices, checked_mesh
from .errors import InvalidMeshError

__all__ = ["face_measures", "corrected_areas", "curvatures_from_measures", "principal_from_measures"]


def _shaped(array, name: str, shape: tuple, kinds: str = "fiu") -> np.ndarray:
    """``array`` as an ndarray of ``shape`` (None: any length) and a dtype kind of ``kinds``, else an InvalidMeshError.

    Shapes and dtypes only (O(1)): the indices of the faces are the caller's
    to check (the public functions that build a mesh validate it once).
    """
    out = np.asarray(array)
    if out.ndim != len(shape) or any(n is not None and n != m for n, m in zip(shape, out.shape)):
        expected = ", ".join("N" if n is None else str(n) for n in shape)
        raise InvalidMeshError(f"`{name}` must have shape ({expected}); got {out.shape}")
    if out.dtype.kind not in kinds:
        raise InvalidMeshError(
            f"`{name}` must hold {'integers' if kinds == 'iu' else 'numbers'}; got dtype {out.dtype}"
        )
    return out


def face_measures(vertices: np.ndarray, faces: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """The corrected curvature measures of every face (formulas: the module's docstring).

    Written relative to the first corner, so that a translation of the mesh
    changes nothing (the sum ``(u_k - u_j) + (u_i - u_k) + (u_j - u_i)`` is 0).
    The compiled kernel when numba is there.

    Parameters
    ----------
    vertices : array_like of shape (V, 3)
    faces : array_like of shape (F, 3), int
        0-based indices into ``vertices``.
    normals : array_like of shape (V, 3)
        Unit normals ``u_i`` at the vertices, interpolated linearly over each face.

    Returns
    -------
    ndarray of shape (F, 9), float64
        Columns ``mu_0`` (length^2), ``mu_1`` (length), ``mu_2``
        (dimensionless), then the symmetrized ``mu^{X,Y}`` (xx, yy, zz, xy,
        xz, yz; length). NaN where a corner's coordinates or normal are not finite.

    Raises
    ------
    InvalidMeshError
        Arrays of the wrong shape or dtype, indices out of range.
    """
    vertices = _shaped(vertices, "vertices", (None, 3))
    normals = _shaped(normals, "normals", vertices.shape)
    faces = checked_indices(_shaped(faces, "faces", (None, 3), "iu"), vertices.shape[0])
    return _measures.face_measures(
        np.ascontiguousarray(vertices, dtype=np.float64), faces, np.ascontiguousarray(normals, dtype=np.float64)
    )


def corrected_areas(vertices: np.ndarray, faces: np.ndarray, measures: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The faces' triangle areas, and their corrected areas, the triangle's where the measure is undefined.

    Parameters
    ----------
    vertices : ndarray of shape (V, 3)
        The mesh's vertices.
    faces : ndarray of shape (F, 3)
        Its faces.
    measures : ndarray of shape (F, k)
        The faces' measures (:func:`face_measures`); ``measures[:, 0]`` is the corrected area ``mu_0``.

    Returns
    -------
    triangle : ndarray of shape (F,)
        The area of each triangle.
    corrected : ndarray of shape (F,)
        ``mu_0``, the triangle's area where ``mu_0`` is not finite.

    Raises
    ------
    InvalidMeshError
        Arrays of the wrong shape or dtype, coordinates not finite, indices out of range.
    """
    vertices, faces = checked_mesh(vertices, faces)
    measures = _shaped(measures, "measures", (faces.shape[0], None))
    return _measures.corrected_areas(vertices, faces, measures)


def curvatures_from_measures(summed: np.ndarray, normals: np.ndarray):
    """Principal curvatures and directions of corrected measures summed over regions (balls).

    ``H = mu_1 / (2 mu_0)``, ``K = mu_2 / mu_0``, ``k = H -/+ sqrt(max(H^2 - K, 0))``
    (:func:`meshcurv._tensors.principal_from_mean_gaussian`), and the
    directions of the shape operator ``-sym(mu^{X,Y}) / mu_0`` restricted to
    the plane normal to each row of ``normals``. One pass with the compiled
    kernels.

    Parameters
    ----------
    summed : array_like of shape (N, 9)
        Sums of rows of :func:`face_measures`, one row per region.
    normals : array_like of shape (N, 3)
        The unit normal of each region.

    Returns
    -------
    k_min, k_max : ndarray of shape (N,), float64
        In 1/length, ``k_min <= k_max``.
    dir_min, dir_max : ndarray of shape (N, 3), float64
        Unit, orthogonal to each other and to the normal, defined up to sign.
        All four NaN in a row whose corrected area ``mu_0`` is not positive
        or whose normal is not finite.

    Raises
    ------
    InvalidMeshError
        ``summed`` or ``normals`` of the wrong shape or dtype.
    """
    summed = _shaped(summed, "summed", (None, 9))
    normals = _shaped(normals, "normals", (summed.shape[0], 3))
    return _measures.curvatures_from_measures(
        np.ascontiguousarray(summed, dtype=np.float64), np.ascontiguousarray(normals, dtype=np.float64)
    )


def principal_from_measures(summed: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Principal curvatures of summed measures from their scalar measures alone (no directions).

    ``H = mu_1 / (2 mu_0)``, ``K = mu_2 / mu_0``, ``k = H -/+ sqrt(max(H^2 - K, 0))``.

    Parameters
    ----------
    summed : array_like of shape (..., k), k >= 3
        Sums of :func:`face_measures` (at least ``mu_0, mu_1, mu_2``), any
        leading shape (the rungs of a ladder of balls, say).

    Returns
    -------
    k_min, k_max : ndarray of shape ``summed.shape[:-1]``, float64
        In 1/length, ``k_min <= k_max``; NaN where ``mu_0`` is not positive.

    Raises
    ------
    InvalidMeshError
        ``summed`` a scalar or with fewer than 3 columns.
    """
    summed = np.asarray(summed)
    if summed.ndim == 0 or summed.shape[-1] < 3:
        raise InvalidMeshError(f"`summed` must have shape (..., 9) (at least mu_0, mu_1, mu_2); got {summed.shape}")
    return _measures.principal_from_measures(summed)
