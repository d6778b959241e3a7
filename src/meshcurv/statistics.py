"""Per-object curvature statistics as FreeSurfer's ``mris_curvature_stats`` reports them: :func:`curvature_statistics`.

For one surface (a mesh, or one object of a label image, where
:func:`meshcurv.label_curvatures` calls the same code on each label), the
statistics are:

- for each field of :data:`FIELDS` (``k_min``, ``k_max``, H = ``mean``,
  K = ``gaussian``, ``shape_index``, ``curvedness``): its area-weighted mean,
  standard deviation, minimum and maximum, ``<field>_mean``, ``<field>_std``,
  ``<field>_min``, ``<field>_max`` (FreeSurfer's "mean +- std, min, max",
  each vertex weighted by its area ``A_i``);
- for H and K, the natural, rectified, positive and negative surface
  integrals (FreeSurfer's ``-m`` output): ``mean_integral = int H dA``,
  ``mean_integral_rectified = int |H| dA``, ``mean_integral_positive =
  int H+ dA``, ``mean_integral_negative = int H- dA`` (``<= 0``), and the same
  ``gaussian_integral*`` for K;
- ``bending_energy``, ``BE = int (k1^2 + k2^2) dA`` (Pienaar et al. 2008,
  FreeSurfer's ``BE``; ``= 4 int H^2 dA - 2 int K dA``, 8 pi on any sphere);
- ``folding_index``, ``FI = 1 / (4 pi) int |k1| (|k1| - |k2|) dA`` with
  ``|k1| >= |k2|`` (Van Essen and Drury 1997; FreeSurfer's ``FI``; Shimony et
  al. 2016, Table 1): 0 on a sphere, ``>= 0`` everywhere;
- ``ici_positive`` and ``ici_negative``, the intrinsic curvature indices
  ``ICIp = int K+ dA / 4 pi`` and ``ICIn = int |K-| dA / 4 pi`` (Van Essen and
  Drury 1997; FreeSurfer's ``ICIp``, ``ICIn``): 1 and 0 on a sphere, 1 and 1 on
  a torus.

See :data:`COLUMNS`.

How each is computed
--------------------
The weights ``A_i`` are a third of the *corrected area* ``mu_0`` of each face
around vertex ``i`` (Lachaud et al. 2020; :func:`meshcurv.measures.face_measures`
with the result's normals), the ``area`` of :func:`meshcurv.label_curvatures`.
The moments are over the valid vertices (and those of ``where``).

The integrals of H and K are the curvature measures of the surface with the
estimator's normals interpolated over each face (:mod:`meshcurv.integrals`):
``int H dA`` is the sum of ``mu_1 / 2`` over the faces, ``int K dA`` the sum of
the signed areas of the spherical triangles of the normals (the Gauss image,
``2 pi chi`` on a closed surface), a third of each to each corner.
``<field>_mean`` of H and K are these integrals over the corrected area.
The positive and negative integrals split those measures by the sign of the
pointwise estimate where they lie (a face's ``mu_1 / 2`` by the pointwise H
averaged over its corners, a vertex's share of the Gauss image by the
pointwise K there; the measure's own sign where the estimate is NaN):
``positive + negative = natural`` and ``rectified = positive - negative``.
When the Gauss image folds (``int |K| dA`` from it above the sum of the
pointwise ``|K| A_i`` by more than :data:`FOLD_TOLERANCE`), a note says so.
``bending_energy`` and ``folding_index`` are sums of the pointwise ``k_min``,
``k_max`` times ``A_i`` over the valid vertices, as FreeSurfer's. Measured
figures: ``benchmarks/label_statistics.py``.

References
----------
FreeSurfer, ``mris_curvature_stats`` (R. Pienaar):
https://surfer.nmr.mgh.harvard.edu/fswiki/mris_curvature_stats

R. Pienaar, B. Fischl, V. Caviness, N. Makris, P. E. Grant (2008). A
methodology for analyzing curvature in the developing brain from preterm to
adult. International Journal of Imaging Systems and Technology 18(1), 42-68.
https://pmc.ncbi.nlm.nih.gov/articles/PMC2779548

D. C. Van Essen and H. A. Drury (1997). Structural and functional analyses of
human cerebral cortex using a surface-based atlas. Journal of Neuroscience
17(18), 7079-7102. https://doi.org/10.1523/JNEUROSCI.17-18-07079.1997

J. S. Shimony et al. (2016). Comparison of cortical folding measures for
evaluation of developing human brain. NeuroImage 125, 780-790.

J.-O. Lachaud, P. Romon, B. Thibert, D. Coeurjolly (2020). Interpolated
corrected curvature measures for polygonal surfaces. Computer Graphics Forum
39(5), 41-54. https://doi.org/10.1111/cgf.14067
"""

from __future__ import annotations

import warnings

import numpy as np

from .errors import InvalidOptionError, MeshQualityWarning
from .integrals import _unit_normals, face_solid_angles
from ._measures import corrected_areas, face_measures
from .result import CurvatureResult, _where_mask

__all__ = ["curvature_statistics", "FIELDS", "MOMENTS", "INTEGRALS", "COLUMNS"]

#: The per-vertex fields summarised (attributes of :class:`~meshcurv.CurvatureResult`): H, K, k_min, ...
FIELDS = ("mean", "gaussian", "k_min", "k_max", "shape_index", "curvedness")

#: The area-weighted moments of each field: ``<field>_mean``, ``<field>_std``, ``<field>_min``, ``<field>_max``.
MOMENTS = ("mean", "std", "min", "max")

#: The integrals over the surface (see the module's documentation).
INTEGRALS = (
    "mean_integral",
    "mean_integral_rectified",
    "mean_integral_positive",
    "mean_integral_negative",
    "gaussian_integral",
    "gaussian_integral_rectified",
    "gaussian_integral_positive",
    "gaussian_integral_negative",
    "bending_energy",
    "folding_index",
    "ici_positive",
    "ici_negative",
)

#: The keys of :func:`curvature_statistics`, in order (columns of :func:`meshcurv.label_curvatures` too).
COLUMNS = (*(f"{field}_{moment}" for field in FIELDS for moment in MOMENTS), *INTEGRALS)


def _moments(values: np.ndarray, weights: np.ndarray, keep: np.ndarray) -> tuple[float, float, float, float]:
    """Area-weighted ``mean, std, min, max`` of ``values[keep]`` (NaN when nothing is kept)."""
    keep = keep & np.isfinite(values) & (weights > 0)
    if not keep.any():
        return (np.nan,) * 4
    v, w = values[keep], weights[keep]
    mean = float(np.sum(v * w) / np.sum(w))
    std = float(np.sqrt(np.sum(w * (v - mean) ** 2) / np.sum(w)))
    return mean, std, float(v.min()), float(v.max())


def _split(masses: np.ndarray, signs: np.ndarray) -> tuple[float, float, float, float]:
    """``natural, rectified, positive, negative``: ``masses`` summed by the sign of ``signs`` (their own where NaN or 0)."""
    if masses.size == 0:
        return (np.nan,) * 4
    side = np.where(np.isfinite(signs) & (signs != 0), signs, masses)
    positive = float(masses[side > 0].sum())
    negative = float(masses[~(side > 0)].sum())
    return positive + negative, positive - negative, positive, negative


def _region_statistics(
    k_min, k_max, shape_index, used, weights, face_measures_in, face_mean_sign, gaussian_shares, gaussian_sign
) -> dict[str, float]:
    """The :data:`COLUMNS` of one region of a surface, from its pieces (shared by the mesh and the label table).

    ``k_min, k_max`` (V,) pointwise, NaN where invalid, and ``shape_index`` (V,) theirs
    (:attr:`meshcurv.CurvatureResult.shape_index`: NaN where flat); ``used`` (V,) the
    vertices of the moments, ``weights`` (V,) their areas; ``face_measures_in``
    (F', 2) ``mu_0, mu_1`` of the faces of the region, ``face_mean_sign`` (F',)
    the pointwise H averaged over their corners; ``gaussian_shares`` (V',) the
    shares of the Gauss image of the region's vertices, ``gaussian_sign`` (V',)
    the pointwise K there.
    """
    k_min = np.asarray(k_min, dtype=np.float64)
    k_max = np.asarray(k_max, dtype=np.float64)
    mean, gaussian = (k_min + k_max) / 2, k_min * k_max
    curvedness = np.sqrt((k_min**2 + k_max**2) / 2)
    shape_index = np.asarray(shape_index, dtype=np.float64)
    fields = dict(zip(FIELDS, (mean, gaussian, k_min, k_max, shape_index, curvedness), strict=True))
    row: dict[str, float] = {}
    for name in FIELDS:
        row.update(zip((f"{name}_{moment}" for moment in MOMENTS), _moments(fields[name], weights, used)))
    mean_integral = _split(0.5 * face_measures_in[:, 1], face_mean_sign)
    gaussian_integral = _split(gaussian_shares, gaussian_sign)
    for name, figures in (("mean_integral", mean_integral), ("gaussian_integral", gaussian_integral)):
        row.update(zip((name, f"{name}_rectified", f"{name}_positive", f"{name}_negative"), figures))
    area = float(face_measures_in[:, 0].sum())
    # H and K averaged over the area: the ratios of the measures (see the module's documentation)
    if area > 0:  # else the pointwise moments' means stand
        row["mean_mean"] = mean_integral[0] / area
        row["gaussian_mean"] = gaussian_integral[0] / area
    keep = used & np.isfinite(k_min) & np.isfinite(k_max) & (weights > 0)
    if keep.any():
        w = weights[keep]
        major = np.maximum(np.abs(k_min[keep]), np.abs(k_max[keep]))
        minor = np.minimum(np.abs(k_min[keep]), np.abs(k_max[keep]))
        row["bending_energy"] = float(np.sum((k_min[keep] ** 2 + k_max[keep] ** 2) * w))
        row["folding_index"] = float(np.sum(major * (major - minor) * w) / (4 * np.pi))
    else:
        row["bending_energy"] = row["folding_index"] = np.nan
    row["ici_positive"] = gaussian_integral[2] / (4 * np.pi)
    row["ici_negative"] = 0.0 - gaussian_integral[3] / (4 * np.pi)
    return {name: float(row[name]) for name in COLUMNS}


#: ``gaussian_integral_rectified`` above the sum of the pointwise ``|K| A_i`` by more than this fraction: the
#: Gauss image of the normals folds, and the split integrals of K are questionable (a note says so; the
#: figures behind the value: ``benchmarks/label_statistics.py``).
FOLD_TOLERANCE = 0.15


def _fold_note(row: dict, k_min, k_max, used, weights) -> str:
    """A note when the Gauss image folds (:data:`FOLD_TOLERANCE`), else ``""``."""
    gaussian = np.asarray(k_min, dtype=np.float64) * np.asarray(k_max, dtype=np.float64)
    keep = used & np.isfinite(gaussian) & (weights > 0)
    pointwise = float(np.sum(np.abs(gaussian[keep]) * weights[keep]))
    measured = row["gaussian_integral_rectified"]
    if not (pointwise > 0 and measured > (1 + FOLD_TOLERANCE) * pointwise):
        return ""
    return (
        f"ici_positive, ici_negative and the rectified, positive and negative integrals of K are questionable: "
        f"the Gauss image of the fitted normals folds (int |K| dA from it is {measured:.4g}, "
        f"{100 * (measured / pointwise - 1):.0f}% above the {pointwise:.4g} of the pointwise |K| times the "
        "areas): the normals wobble at a scale below the estimator's radius"
    )


def _face_average(field: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(F,) ``field`` (V,) averaged over the finite values at each face's corners (NaN when none is finite)."""
    values = np.asarray(field, dtype=np.float64)[faces]
    finite = np.isfinite(values)
    count = finite.sum(axis=1)
    total = np.where(finite, values, 0.0).sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count > 0, total / np.maximum(count, 1), np.nan)


def curvature_statistics(result, *, where=None) -> dict[str, float]:
    """FreeSurfer's per-object curvature statistics of a mesh's :class:`~meshcurv.CurvatureResult`.

    Area-weighted mean, standard deviation, minimum and maximum of each field
    of :data:`FIELDS`; the natural, rectified, positive and negative integrals
    of H and K from the corrected curvature measures; bending energy, folding
    index and the intrinsic curvature indices. The same numbers as the columns
    of :func:`meshcurv.label_curvatures` for each label (which calls this code
    on each object's surface).

    Parameters
    ----------
    result : CurvatureResult
        From :func:`meshcurv.principal_curvatures` (which keeps the mesh the
        integrals need).
    where : array_like of shape (V,), bool, optional
        The vertices of the region to summarise (default: all): the moments
        and the Gauss image are over these vertices, ``int H dA`` over the
        faces all of whose corners are in it.

    Returns
    -------
    dict
        ``{column: float}`` for each of :data:`COLUMNS`; NaN where nothing
        is left (no valid vertex in ``where``, with a warning).

    Raises
    ------
    InvalidOptionError
        ``result`` not a CurvatureResult, or one without a mesh (a point
        cloud's, or one built directly); ``where`` not a bool array of one
        value per vertex.

    Warns
    -----
    MeshQualityWarning
        When no valid vertex is left to summarise: the statistics are NaN.
        When the Gauss image of the normals folds (the rectified integral of
        K from it more than :data:`FOLD_TOLERANCE` above the sum of the
        pointwise ``|K| A_i``): the split integrals of K are then too high.

    Notes
    -----
    With ``k1 >= k2`` in magnitude (``|k1| = max(|k_min|, |k_max|)``):

    .. math::

        BE = \\int (k_{min}^2 + k_{max}^2)\\,dA, \\quad
        FI = \\frac{1}{4\\pi}\\int |k_1|\\,(|k_1| - |k_2|)\\,dA, \\quad
        ICI_\\pm = \\frac{1}{4\\pi}\\int K_\\pm\\,dA

    The integrals of H and K are sums of the corrected curvature measures
    (Lachaud et al. 2020) and of the Gauss image, split into positive and
    negative parts by the sign of the pointwise estimate; the rules, their
    measurements and the sources (FreeSurfer's ``mris_curvature_stats``, Van
    Essen and Drury 1997) are in :mod:`meshcurv.statistics`.

    Examples
    --------
    >>> import numpy as np, meshcurv
    >>> from meshcurv.statistics import curvature_statistics
    >>> sphere = meshcurv.shapes.icosphere(subdivisions=16, radius=2.0)
    >>> stats = curvature_statistics(meshcurv.principal_curvatures(sphere.vertices, sphere.faces))
    >>> print(f"{stats['bending_energy'] / (8 * np.pi):.3f} {stats['ici_positive']:.3f} {stats['ici_negative']:.3f}")
    0.998 1.000 0.000
    >>> print(f"{stats['mean_integral'] / (4 * np.pi * 2.0):.3f} {stats['shape_index_mean']:.3f}")
    0.998 1.000
    """
    if not isinstance(result, CurvatureResult):
        raise InvalidOptionError(
            f"`result` must be a CurvatureResult (from meshcurv.principal_curvatures); got {type(result).__name__}"
        )
    surface = result._surface
    if surface is None:
        raise InvalidOptionError(
            f"curvature_statistics needs the triangles of a mesh; this {result.method!r} result "
            "has none (a point cloud's, or one built directly): compute it with "
            "meshcurv.principal_curvatures on a mesh"
        )
    region = _where_mask(where, result.n_vertices)
    vertices, faces = np.asarray(surface.vertices), np.asarray(surface.faces)
    rows = surface.rows
    valid = np.asarray(result.valid)[rows]
    k_min, k_max = np.asarray(result.k_min)[rows], np.asarray(result.k_max)[rows]
    shape_index = np.asarray(result.shape_index)[rows]
    region = region[rows]
    normals = None if result.method == "matgeom" else np.where(valid[:, None], np.asarray(result.normals)[rows], np.nan)
    normals = _unit_normals(vertices, faces, normals)
    measures = face_measures(vertices, faces, normals)[:, :2]
    _, corrected = corrected_areas(vertices, faces, measures)
    weights = np.bincount(faces.ravel(), np.repeat(np.maximum(corrected, 0.0) / 3.0, 3), minlength=vertices.shape[0])
    used = region & valid
    if not used.any():
        warnings.warn(
            f"curvature_statistics: no valid vertex to summarise ({int(region.sum())} in `where`, "
            f"{int(valid.sum())} valid): the statistics are NaN",
            MeshQualityWarning,
            stacklevel=2,
        )
    inside = region[faces].all(axis=1) & np.isfinite(measures).all(axis=1)
    gaussian_shares = np.bincount(
        faces.ravel(), np.repeat(face_solid_angles(normals, faces) / 3.0, 3), minlength=vertices.shape[0]
    )
    mean_integrand = (measures[inside], _face_average((k_min + k_max) / 2, faces[inside]))
    gaussian_integrand = (gaussian_shares[region], (k_min * k_max)[region])
    row = _region_statistics(k_min, k_max, shape_index, used, weights, *mean_integrand, *gaussian_integrand)
    note = _fold_note(row, k_min, k_max, used, weights)
    if note:
        warnings.warn(f"curvature_statistics: {note}", MeshQualityWarning, stacklevel=2)
    return row
