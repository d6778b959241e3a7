"""Integrals of curvature over a triangle mesh: area, total mean and Gaussian curvature, Willmore energy.

Pointwise curvatures averaged over balls do not integrate to the totals (a
ball average spreads a sharp fold over a larger area and clips it), so the
totals are taken from curvature *measures* of the surface with the
estimator's vertex normals ``u_i`` interpolated over each face (Lachaud,
Romon, Thibert and Coeurjolly 2020), which add up over faces:

- ``"area"``: the barycentric vertex areas (a third of each incident face),
  whose sum is the area of the mesh;
- ``"mean"``, the total mean curvature ``int H dA`` with ``H = (k_min + k_max) / 2``:
  half the corrected measure ``mu_1`` of each face,
  ``mu_1 = 1/2 <ū | (u_k - u_j) x x_i + (u_i - u_k) x x_j + (u_j - u_i) x x_k>``
  (:func:`meshcurv.measures.face_measures`);
- ``"gaussian"``, the total Gaussian curvature ``int K dA``: the signed area
  of the spherical triangle ``(u_i, u_j, u_k)`` of each face, the image of the
  face under the normals (Van Oosterom and Strackee 1983,
  ``tan(Omega / 2) = <u_i | u_j x u_k> / (1 + <u_i|u_j> + <u_j|u_k> + <u_k|u_i>)``).
  It is the spherical form of the corrected measure ``mu_2 = 1/2 <u_i | u_j x u_k>``
  (equal to it to first order) and, unlike ``mu_2``, sums over a closed mesh
  to ``2 pi chi`` exactly whenever the normals are nowhere opposite to the
  faces (Gauss-Bonnet: the degree of the normal map; a normal that points
  away from its faces is replaced by the area-weighted face normal); on an open mesh it is
  the area of the image of the normals, the integral of ``K`` over the patch;
- ``"willmore"``, the Willmore energy ``int H^2 dA``: the estimator's
  pointwise ``mean**2`` times the vertex areas (``4 pi`` on a sphere of any
  radius).

Each face's measure goes a third to each of its corners, so that per-vertex
shares (:func:`vertex_integrals`) add up over any set of vertices.
Measured figures (Gauss-Bonnet on spot.obj and rocker-arm.obj, ``mu_1``
against dihedral angles): ``benchmarks/docstring_figures.md``.

References
----------
J.-O. Lachaud, P. Romon, B. Thibert, D. Coeurjolly (2020). Interpolated
corrected curvature measures for polygonal surfaces. Computer Graphics Forum
39(5), 41-54. https://doi.org/10.1111/cgf.14067

A. Van Oosterom and J. Strackee (1983). The solid angle of a plane triangle.
IEEE Transactions on Biomedical Engineering 30(2), 125-126.
https://doi.org/10.1109/TBME.1983.325207
"""

from __future__ import annotations

import numpy as np

from ._geometry import face_areas, vertex_normals
from ._validation import check_choice, checked_indices, checked_mesh
from .errors import InvalidMeshError, InvalidOptionError
from ._measures import face_measures

__all__ = ["INTEGRALS", "vertex_integrals", "face_solid_angles", "weighted_percentiles", "weighted_statistics"]

#: The fields :func:`vertex_integrals` and :meth:`meshcurv.CurvatureResult.integral` integrate.
INTEGRALS = ("area", "mean", "gaussian", "willmore")


def face_solid_angles(normals: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Signed area of the spherical triangle of the unit normals at each face's corners.

    ``tan(Omega / 2) = <u_i | u_j x u_k> / (1 + <u_i|u_j> + <u_j|u_k> + <u_k|u_i>)``
    (Van Oosterom and Strackee 1983).

    Parameters
    ----------
    normals : array_like of shape (V, 3)
        Unit normals at the vertices.
    faces : array_like of shape (F, 3), int
        0-based indices into ``normals``.

    Returns
    -------
    ndarray of shape (F,), float64
        In steradians, in ``(-2 pi, 2 pi]``: positive where the normals turn
        as the corners do (a convex face of an outward-wound mesh), 0 where a
        corner's normal is not finite.

    Raises
    ------
    InvalidMeshError
        Arrays of the wrong shape, ``faces`` not integers in range.
    """
    normals, faces = np.asarray(normals), np.asarray(faces)
    if normals.ndim != 2 or normals.shape[1] != 3 or faces.ndim != 2 or faces.shape[1] != 3:
        raise InvalidMeshError(
            f"`normals` and `faces` must have shapes (V, 3) and (F, 3); got {normals.shape} and {faces.shape}"
        )
    faces = checked_indices(faces, normals.shape[0])
    u0, u1, u2 = (normals[faces[:, k]] for k in range(3))
    triple = np.einsum("ij,ij->i", u0, np.cross(u1, u2))
    cosines = 1.0 + np.einsum("ij,ij->i", u0, u1) + np.einsum("ij,ij->i", u1, u2) + np.einsum("ij,ij->i", u2, u0)
    with np.errstate(invalid="ignore"):
        angles = 2.0 * np.arctan2(triple, cosines)
    return np.where(np.isfinite(angles), angles, 0.0)


def _face_mean_measures(vertices: np.ndarray, faces: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """(F,) ``mu_1 / 2`` of each face (the corrected total mean curvature), 0 where a normal is not finite."""
    measures = face_measures(vertices, faces, normals)[:, 1] / 2
    return np.where(np.isfinite(measures), measures, 0.0)


def _unit_normals(vertices: np.ndarray, faces: np.ndarray, normals) -> np.ndarray:
    """The given unit normals; the area-weighted face normals where they are missing or point away from the faces."""
    fallback = vertex_normals(vertices, faces)
    if normals is None:
        return fallback
    normals = np.asarray(normals, dtype=np.float64)
    if normals.shape != vertices.shape:
        raise InvalidMeshError(f"`normals` must have shape {vertices.shape} (one per vertex); got {normals.shape}")
    with np.errstate(invalid="ignore", divide="ignore"):
        unit = normals / np.linalg.norm(normals, axis=1, keepdims=True)
    with np.errstate(invalid="ignore"):
        kept = np.isfinite(unit).all(axis=1) & (np.einsum("ij,ij->i", unit, fallback) > 0)
    return np.where(kept[:, None], unit, fallback)


def vertex_integrals(vertices, faces, field: str, *, normals=None, pointwise=None) -> np.ndarray:
    """(V,) the share of each vertex in the integral of ``field`` over the mesh.

    Their sum is the integral over the whole mesh, their sum over a set of
    vertices that over the region those vertices stand for.

    Parameters
    ----------
    vertices : array_like of shape (V, 3)
    faces : array_like of shape (F, 3)
        0-based vertex indices, consistently oriented, one side: the faces of
        a double-sided mesh (each face twice, with opposite windings) are all
        counted (:func:`meshcurv.weld.drop_double_sided` keeps one side;
        :meth:`meshcurv.CurvatureResult.integral` integrates over the mesh
        :func:`~meshcurv.principal_curvatures` computed on, one-sided already).
    field : {'area', 'mean', 'gaussian', 'willmore'}
        - ``'area'``: barycentric vertex areas (a third of each incident face);
        - ``'mean'``: total mean curvature ``int H dA`` from the corrected
          measure ``mu_1 / 2`` of each face;
        - ``'gaussian'``: total Gaussian curvature ``int K dA``, the signed area of
          the spherical image of each face under the normals;
        - ``'willmore'``: ``int H^2 dA`` as ``pointwise**2`` times the vertex areas.
    normals : array_like of shape (V, 3), optional
        Vertex normals to interpolate (an estimator's, e.g.
        ``CurvatureResult.normals``); the area-weighted face normals where
        missing, not finite, or pointing away from the faces (a negative
        cosine with the area-weighted normal: a failed fit, which would wrap
        the spherical image once more around the sphere).
    pointwise : array_like of shape (V,), optional
        The pointwise mean curvature, for ``'willmore'`` (required there).

    Returns
    -------
    ndarray of shape (V,)
        In length^2 (``'area'``), length (``'mean'``), or dimensionless.
        Unreferenced vertices get 0; ``'willmore'`` is NaN where
        ``pointwise`` is NaN at a referenced vertex.

    Notes
    -----
    The rules and the measurements behind them are in the module docstring
    (:mod:`meshcurv.integrals`).

    Examples
    --------
    Gauss-Bonnet on a sphere (Euler characteristic 2):

    >>> import numpy as np, meshcurv
    >>> from meshcurv.integrals import vertex_integrals
    >>> s = meshcurv.shapes.icosphere(subdivisions=8, radius=2.0)
    >>> print(f"{vertex_integrals(s.vertices, s.faces, 'gaussian').sum() / np.pi:.6f}")
    4.000000
    """
    check_choice(field, "field", INTEGRALS)
    vertices, faces = checked_mesh(vertices, faces)
    n_vertices = vertices.shape[0]
    if field == "willmore":
        if pointwise is None:
            raise InvalidMeshError("`pointwise` (the mean curvature at each vertex) is needed for 'willmore'")
        pointwise = np.asarray(pointwise, dtype=np.float64)
        if pointwise.shape != (n_vertices,):
            raise InvalidMeshError(f"`pointwise` must have shape ({n_vertices},); got {pointwise.shape}")
    if field in ("area", "willmore"):
        per_face = face_areas(vertices, faces)
    elif field == "mean":
        per_face = _face_mean_measures(vertices, faces, _unit_normals(vertices, faces, normals))
    else:
        per_face = face_solid_angles(_unit_normals(vertices, faces, normals), faces)
    shares = np.bincount(faces.ravel(), weights=np.repeat(per_face / 3.0, 3), minlength=n_vertices)
    if field == "willmore":
        with np.errstate(invalid="ignore"):
            shares = np.where(shares > 0, pointwise**2 * shares, 0.0)
    return shares


def weighted_percentiles(values, weights, percentiles) -> np.ndarray:
    """Percentiles of ``values`` where each value counts by its weight (e.g. its vertex area).

    The ``p``-th percentile is the smallest value whose cumulative weight
    (values in increasing order) reaches ``p / 100`` of the total: a value of
    weight 2 counts as the value twice, a value holding more than half the
    weight is the median, and equal weights give numpy's
    ``method="inverted_cdf"``. Values that are not finite and weights that
    are not positive are left out; NaN when nothing is left.

    Parameters
    ----------
    values, weights : array_like of shape (N,)
    percentiles : array_like of floats in [0, 100]

    Returns
    -------
    ndarray of the shape of ``percentiles``

    Raises
    ------
    InvalidMeshError
        ``values`` and ``weights`` not of one shape (N,).
    InvalidOptionError
        A percentile that is not a number in [0, 100].
    """
    try:
        wanted = np.asarray(percentiles, dtype=np.float64) / 100.0
    except (TypeError, ValueError):
        raise InvalidOptionError(f"`percentiles` must be numbers in [0, 100]; got {percentiles!r}") from None
    if not ((wanted >= 0) & (wanted <= 1)).all():  # NaN fails too
        raise InvalidOptionError(f"`percentiles` must be numbers in [0, 100]; got {percentiles!r}")
    values = np.asarray(values, dtype=np.float64)
    weights = np.asarray(weights, dtype=np.float64)
    if values.shape != weights.shape or values.ndim != 1:
        raise InvalidMeshError(
            f"`values` and `weights` must have one shape (N,); got {values.shape} and {weights.shape}"
        )
    kept = np.isfinite(values) & np.isfinite(weights) & (weights > 0)
    if not kept.any():
        return np.full(wanted.shape, np.nan)
    order = np.argsort(values[kept], kind="stable")
    ranked, share = values[kept][order], weights[kept][order]
    running = np.cumsum(share)
    reached = np.searchsorted(running, wanted * running[-1] * (1 - 1e-12), side="left")
    return ranked[np.minimum(reached, ranked.size - 1)]


def weighted_statistics(values, weights) -> dict[str, float]:
    """Weighted mean and percentiles of ``values`` (see :func:`weighted_percentiles`).

    Parameters
    ----------
    values, weights : array_like of shape (N,)
        Values not finite and weights not positive are left out.

    Returns
    -------
    dict of str to float
        ``mean`` (``sum(w v) / sum(w)``), ``median``, ``p5``, ``p25``,
        ``p75``, ``p95``; all NaN when nothing is left.

    Raises
    ------
    InvalidMeshError
        ``values`` and ``weights`` not of one shape (N,).
    """
    values = np.asarray(values, dtype=np.float64)
    weights = np.asarray(weights, dtype=np.float64)
    names = ("p5", "p25", "median", "p75", "p95")
    figures = dict(zip(names, weighted_percentiles(values, weights, [5, 25, 50, 75, 95]).tolist()))
    kept = np.isfinite(values) & np.isfinite(weights) & (weights > 0)
    mean = float(np.sum(values[kept] * weights[kept]) / np.sum(weights[kept])) if kept.any() else np.nan
    return {"mean": mean, **{name: figures[name] for name in ("median", "p5", "p25", "p75", "p95")}}
