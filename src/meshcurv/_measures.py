"""The cores of :mod:`meshcurv.measures`: the same quantities over arrays already checked.

Each function here has the name, the arguments and the result of the public
function of :mod:`meshcurv.measures` that checks its input and calls it (its
docstring holds the contract; the module's, the formulas). They trust their
input: C-contiguous float64 ``vertices``, ``normals`` and sums, C-contiguous
int64 faces of indices in range. The estimators call them on the arrays of a
:class:`~meshcurv._prepared.PreparedMesh`, checked once.
"""

from __future__ import annotations

import numpy as np

from ._backend import twin
from ._geometry import face_areas
from ._tensors import principal_from_mean_gaussian, principal_from_shape_operator


@twin("icc")
def face_measures(vertices: np.ndarray, faces: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """(F, 9) the corrected curvature measures of every face (:func:`meshcurv.measures.face_measures`)."""
    x0, x1, x2 = (vertices[faces[:, k]] for k in range(3))
    u0, u1, u2 = (normals[faces[:, k]] for k in range(3))
    x01, x02 = x1 - x0, x2 - x0
    u01, u02 = u1 - u0, u2 - u0
    um = (u0 + u1 + u2) / 3
    mu0 = 0.5 * np.einsum("ij,ij->i", um, np.cross(x01, x02))
    mu1 = 0.5 * np.einsum("ij,ij->i", um, np.cross(u0 - u2, x01) + np.cross(u1 - u0, x02))
    mu2 = 0.5 * np.einsum("ij,ij->i", u0, np.cross(u1, u2))
    # mu^{X,Y} = X^T M Y with M = 1/2 [ (x01 x um) (u02)^T - (x02 x um) (u01)^T ]
    a, b = np.cross(x01, um), np.cross(x02, um)
    m = 0.5 * (a[:, :, None] * u02[:, None, :] - b[:, :, None] * u01[:, None, :])
    rows, columns = [0, 1, 2, 0, 0, 1], [0, 1, 2, 1, 2, 2]  # xx, yy, zz, xy, xz, yz
    sym = 0.5 * (m[:, rows, columns] + m[:, columns, rows])
    return np.column_stack([mu0, mu1, mu2, sym])


def corrected_areas(vertices: np.ndarray, faces: np.ndarray, measures: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(F,) triangle areas and corrected areas (:func:`meshcurv.measures.corrected_areas`)."""
    triangle = face_areas(vertices, faces)
    return triangle, np.where(np.isfinite(measures[:, 0]), measures[:, 0], triangle)


@twin("icc")
def curvatures_from_measures(summed: np.ndarray, normals: np.ndarray):
    """k_min, k_max, dir_min, dir_max of summed measures (:func:`meshcurv.measures.curvatures_from_measures`)."""
    area = summed[:, 0]
    good = (area > 0) & np.isfinite(normals).all(axis=1)
    k_min, k_max = principal_from_measures(summed)
    with np.errstate(invalid="ignore", divide="ignore"):
        shape_operator = -summed[:, 3:] / area[:, None]
    _, _, dir_min, dir_max = principal_from_shape_operator(
        np.where(good[:, None], shape_operator, 0.0), np.where(good[:, None], normals, [0.0, 0.0, 1.0])
    )
    for field in (k_min, k_max, dir_min, dir_max):
        field[~good] = np.nan
    return k_min, k_max, dir_min, dir_max


def principal_from_measures(summed: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """k_min, k_max from the scalar measures alone (:func:`meshcurv.measures.principal_from_measures`)."""
    area = summed[..., 0]
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(area > 0, summed[..., 1] / (2 * area), np.nan)
        gaussian = np.where(area > 0, summed[..., 2] / area, np.nan)
    return principal_from_mean_gaussian(mean, gaussian)
