"""From 3D label images to one row of curvature statistics per object: :func:`label_curvatures`.

Each label of an integer image (or the ``True`` voxels of a boolean mask) is
cut out on its bounding box (:func:`scipy.ndimage.find_objects`) padded by one
voxel of background, so the image is never copied per label and every surface
is closed, even for an object cut by the image border. Its surface is
scikit-image's marching cubes of the binary crop at level 0.5, placed in
physical units (``index * spacing``, image axes 0, 1, 2, often called z, y,
x) and wound outward (marching cubes winds the faces of a bright object
inward: they are reversed, so that the outer surface of a cell and the wall of
a cavity inside it both face away from the object). Marching cubes is not
equivariant (a mirrored cube's polygon is split by the other diagonal), so
each crop is cut in the first of its 48 mirrors and axis permutations
(:func:`meshcurv._masks.canonical_pose`) and its surface turned back: every
mirror and permutation of the image's axes, the spacing permuted along, gets
the same mesh moved rigidly, and the same row. The curvatures are those
of :func:`meshcurv.principal_curvatures` with its default method (``icc``),
whose default radius recognises the voxel grid of the mesh
(``result.parameters["surface"] == "voxel"``: a radius of a few voxels that
averages the staircase out).

Area, and the staircase
-----------------------
The triangles of binary marching cubes follow the voxel staircase, so their
area overestimates that of the smooth object by a factor that depends on the
voxel shape (spheres of radius 6-20: +8% with cubic voxels, +19% with voxels
of 1 x 0.25 x 0.25). The area reported is instead the *corrected area*
``mu_0`` of the interpolated corrected curvature measures (Lachaud et al.
2020), ``sum over faces of <u_bar, face area vector>``, with the normals ``u``
fitted by ``icc`` over a few voxels: it is the area of the smooth surface those
normals describe (the same spheres: -1.1% to +0.6%). Smoothing the mask with a
Gaussian before marching cubes (``smooth=sigma``, below) is not the default:
it removes most of the staircase's bias but shrinks the objects, the level
set moving inward by about ``sigma^2 H``. Measured on spheres (3 random
centres each, voxels 1 x 1 x 1 and 1 x 0.5 x 0.5, the worst of the 6):
sigma 0.5 area -2.4%, volume -3.2% at radius 6, -0.8% and -1.1% at radius
10, -0.3% and -0.3% at radius 20; sigma 1 area -6.9%, volume -9.6% at
radius 6, -2.9% and -4.1% at radius 10, -0.7% and -0.9% at radius 20
(without smoothing: -1.4% and -1.7% at radius 6, within 0.5% beyond); the
blurred surface is recognised as a voxel surface, and total K stays 4 pi.
The raw triangle area stays in the table as ``area_mesh``.

Each vertex carries a third of the corrected area of its faces (the
barycentric cell, with ``mu_0`` in place of the triangle area); these are the
weights of every area-weighted statistic.

Columns of the table
--------------------
``label, status, error, n_voxels, touches_border, n_vertices, n_faces,
n_used, n_invalid, euler_characteristic, area, area_mesh, volume,
equivalent_radius, centroid_0, centroid_1, centroid_2, radius, surface``;
then for each field of :data:`FIELDS` (``mean`` is H, ``gaussian`` is K,
``k_min``, ``k_max``, ``shape_index``, ``curvedness``): ``<field>_weighted``
(the area-weighted mean; ``mean_weighted`` is the area-weighted mean of H, see below),
``<field>_median``, ``<field>_p5``, ``<field>_p25``, ``<field>_p75``,
``<field>_p95`` (area-weighted percentiles: a value counts by its vertex
area, :func:`meshcurv.integrals.weighted_percentiles`); then ``total_mean`` (the integral
of H dA), ``total_gaussian`` (the integral of K dA), ``willmore`` (the integral
of H^2 dA), then FreeSurfer's per-object statistics of
:func:`meshcurv.statistics.curvature_statistics` (:data:`meshcurv.statistics.COLUMNS`:
``<field>_mean``, ``_std``, ``_min``, ``_max`` of each field; the natural,
rectified, positive and negative integrals ``mean_integral*`` and
``gaussian_integral*``; ``bending_energy``, ``folding_index``,
``ici_positive``, ``ici_negative``), computed by the same code over the same
vertices and faces as the columns above, then the area fractions of the nine
shape-index categories of Koenderink and van Doorn
(``shape_index_fraction_cup`` ... ``_cap``: of the area of the vertices that
have a shape index, the flat ones left out, :attr:`meshcurv.CurvatureResult.shape_index`)
and ``warnings``. See
:data:`COLUMNS`. ``<field>_mean`` is ``<field>_weighted`` and
``mean_integral``, ``gaussian_integral`` are ``total_mean``,
``total_gaussian``, under FreeSurfer's names.

- ``mean_weighted`` and ``gaussian_weighted`` are ``total_mean / A`` and
  ``total_gaussian / A`` (``A`` the corrected area of the same faces): the
  area-weighted means of H and K as ratios of the corrected measures. Measured
  on 50 rotated spheres and ellipsoids of semi-axes 6-20 with voxels 1 x 0.25
  x 0.25 (``benchmarks/volume.py``), the ratio is within 2.6% of the exact
  ``int H dA / area`` on every label (median 0.2%), where the sum
  ``sum_i H_i A_i / sum_i A_i`` of the vertex estimates is off by up to 5.7%
  (median 0.7%) on flat ellipsoids. The other ``<field>_weighted`` columns
  are ``sum_i f_i A_i / sum_i A_i`` over the vertices used.
- ``total_mean`` is the sum over the faces of the corrected curvature measure
  ``mu_1 / 2`` (the integral of H dA of the surface with the fitted normals).
  ``total_gaussian`` is the integral of K dA as :mod:`meshcurv.integrals`
  computes it: the area of the image of the fitted normals, a third of each
  face's spherical triangle to each corner, summed over the vertices used.
  On a closed label it is ``2 pi chi`` exactly, by Gauss-Bonnet (the
  earlier sum of ``mu_2`` was 0.8% off at the median and 7.9% at worst on the
  50 labels above, the sum of the vertex values ``K_i A_i`` 2.7% and 11.9%);
  on a label cut by the border, the total curvature of its part away from it.
- ``willmore`` is ``sum_i H_i^2 A_i``, the Willmore energy ``W = int H^2 dA``
  (4 pi on a sphere, more on any other closed surface; ``int (H^2 - K) dA``
  is ``willmore - total_gaussian``).
- ``volume`` is the divergence theorem on the closed mesh,
  ``sum over faces of x_0 . (x_1 x x_2) / 6``; for a label cut by the image
  border, that of the part inside the image.
- ``euler_characteristic`` is ``V - E + F`` of the label's mesh (2 for one
  closed surface of genus 0; 2 per component, minus 2 per handle).
- ``touches_border``: the label has a voxel on a face of the image; see
  below for what each column then measures.
- ``status``: ``ok``; ``empty`` (a label of ``labels_to_use`` with no voxel);
  ``too_small`` (a surface of fewer than :data:`MIN_VERTICES` vertices, where
  no voxel grid can be recognised and no curvature estimated: one or a few
  voxels); ``failed`` (anything else: ``error`` says what). One label that
  fails never stops the others.

Objects cut by the image border
-------------------------------
The mesh of a label with a voxel on a face of the image is closed by a flat
cap along that face (and chamfers along the image's edges and corners where
two such faces meet), which is not the object's surface. Each column then
measures:

- ``area``, ``area_mesh``: the surface of the object inside the image, the
  cap left out (its faces are those whose corners all lie on the image faces
  the label touches). The normals of the corrected area are fitted again
  without the cap within the estimator's reach of it (on the open surface,
  same method and radius): the normals fitted with the cap turn towards it and
  shrank the area (a hemisphere of radius 12 voxels measured 10% of its
  curved area; a box in a corner 0). Measured: hemispheres of radius 6, 12,
  20 voxels cut on their equator within 1.3%, 0.7%, 0.2% of ``2 pi R^2``
  (the same balls whole: 0.5%, 0.01%, 0.05% of ``4 pi R^2``); a cylinder
  across the image within 0.6% of its lateral area; a cube of side 10
  voxels in a corner 2.7% under its three inner faces, as the cube of side
  20 whole is 4.2% under its six (the corrected area rounds the voxel edges).
  ``python benchmarks/fuzz_labels.py`` checks these on random cuts.
- ``volume``, ``equivalent_radius``, ``n_voxels``, ``centroid_*``: those of
  the part inside the image (the volume closed by the cap).
- ``euler_characteristic``: that of the mesh closed by its cap (2 for a
  hemisphere).
- The curvature columns (``<field>_<statistic>``, ``total_mean``,
  ``total_gaussian``, ``willmore``, FreeSurfer's statistics, the shape-index
  fractions): over the
  part of the surface beyond the reach of the estimator from the cap, where
  the estimates do not see it: the vertices farther than the radius over
  which ``icc`` fits its normals (``3 r``,
  ``result.parameters["normal_radius"]``; the ball radius ``r`` for the
  other methods) from the image faces the label touches (``n_used`` counts
  them), and for ``total_mean`` the faces all of whose corners are such
  vertices (the integrals of K: the vertices off the border). On a ball of
  radius 12 voxels cut by the image border, H is 5-7%
  too high at 2 r from the cap and right beyond 3 r. ``mean_weighted`` and
  ``gaussian_weighted`` divide by the corrected area of those same faces
  (not by ``area``): they are means over that part.
- ``radius``: the default radius of a label cut by the border is chosen by
  the voxel rule (:func:`meshcurv.radius.voxel_radius`) from a pilot on its
  surface without the cap, over the vertices farther than
  :data:`CUT_PILOT_RIM` voxels from the image faces, and is at least
  :data:`CUT_RADIUS_FLOOR` voxels (``surface`` is ``voxel``). Chosen on the
  capped mesh, the creases along the cap's rim read as curvature and gave
  about one voxel, which does not average the staircase out: slivers of
  balls cut by two or three image faces had ``mean_weighted`` 15-92% off,
  marked valid (``benchmarks/fuzz_labels.md``).
- A label cut by the border that keeps less than :data:`CUT_MIN_AREA_BALLS`
  ``pi r^2`` of surface beyond that reach (a sliver, a small object, a
  hemisphere of a few radii ``r``) has NaN curvature columns (not 0, not
  an estimate of too few vertices), ``n_used`` 0, and the reason in
  ``warnings``; its area and volume are those of the part inside.

Probability maps, smoothing, images larger than memory
-------------------------------------------------------
- ``threshold=T``: the image is a probability map; the voxels greater than
  ``T`` are the foreground and its connected components (6-connectivity) the
  labels, numbered 1, 2, ... (:func:`meshcurv._masks.labels_from_image`). A
  float image without ``threshold`` is refused with a message saying so.
- ``smooth=sigma`` (the unit of ``spacing``): each object's mask, on its box
  padded by ``ceil(3 sigma / h) + 1`` voxels, is blurred by a Gaussian of
  ``sigma / h`` voxels along each axis before marching cubes at 0.5; along
  an image face it touches, the mask goes on beyond the face and the surface
  is closed by a flat cap on the face, left out as above
  (:mod:`meshcurv._masks`). The radius is the default rules' (:mod:`meshcurv.radius`).
- A label image read by slicing (Zarr, Dask, :class:`meshcurv._lazy.LazyImage`,
  what :func:`meshcurv.io._images.read_image` returns for a ``.zarr`` store)
  is never loaded whole: the labels' boxes are found one chunk at a time,
  then each label's box is read from the store, in this process, and sent to
  the workers as below (:mod:`meshcurv._lazy`).

Many labels on several processes
--------------------------------
With ``workers=N`` (a local Dask cluster, :func:`meshcurv.batch.local_cluster`,
started and closed by the call) or ``client=`` (a cluster of one's own), each
label, or a group of small ones (:data:`TASK_VOXELS` voxels of boxes), is one
task. A task receives its labels' crops (the box padded by one voxel, as a
boolean mask), their offsets, the image's shape and the spacing: never the
image, which stays in the calling process; a few tasks per worker are sent
ahead, so the crops in flight are bounded too. The rows are those of the
serial run, in the same order, up to the order of floating-point sums. A task
whose worker process dies (out of memory, a crash in a compiled library) or
that raises is run again label by label; the label that still kills its worker
gets a ``failed`` row (``WorkerDied: ...``), the others are computed.

References
----------
J.-O. Lachaud, P. Romon, B. Thibert, D. Coeurjolly (2020). Interpolated
corrected curvature measures for polygonal surfaces. Computer Graphics Forum
39(5), 41-54. https://doi.org/10.1111/cgf.14067

J. J. Koenderink and A. J. van Doorn (1992). Surface shape and curvature
scales. Image and Vision Computing 10(8), 557-564.
https://doi.org/10.1016/0262-8856(92)90076-F

W. E. Lorensen and H. E. Cline (1987). Marching cubes: a high resolution 3D
surface construction algorithm. SIGGRAPH 87. https://doi.org/10.1145/37402.37422
"""

from __future__ import annotations

import contextlib
import functools
import logging
import warnings
from typing import NamedTuple
from collections.abc import Callable

import numpy as np

from ._validation import check_int_option, check_positive_float, checked_spacing
from .curvature import principal_curvatures
from .errors import InvalidMeshError, InvalidOptionError, MeshcurvWarning, MeshQualityWarning, MissingDependencyError
from .measures import corrected_areas, face_measures
from .radius import VOXEL_CURVEDNESS_PERCENTILE, VOXEL_PILOT, voxel_radius
from .integrals import vertex_integrals, weighted_percentiles
from .result import CurvatureResult
from .batch import _driver as driver
from .statistics import COLUMNS as STATISTICS_COLUMNS
from ._lazy import as_lazy, check_lazy_labels, is_lazy, lazy_objects
from ._masks import (
    canonical_pose,
    check_smooth,
    check_threshold,
    labels_from_image,
    posed,
    posed_marching_cubes,
    smoothed_crop,
    smoothed_surface,
)
from .statistics import _face_average, _fold_note, _region_statistics

__all__ = [
    "label_curvatures",
    "label_surfaces",
    "LabelSurface",
    "COLUMNS",
    "FIELDS",
    "STATISTICS",
    "SHAPE_CATEGORIES",
    "MIN_VERTICES",
]

logger = logging.getLogger(__name__)

#: The per-vertex fields summarised (attributes of :class:`~meshcurv.CurvatureResult`).
FIELDS = ("mean", "gaussian", "k_min", "k_max", "shape_index", "curvedness")

#: The statistics of each field, area-weighted: ``weighted`` is the mean, ``p5`` the 5th percentile, ...
STATISTICS = ("weighted", "median", "p5", "p25", "p75", "p95")
_QUANTILES = {"median": 0.5, "p5": 0.05, "p25": 0.25, "p75": 0.75, "p95": 0.95}

#: Koenderink and van Doorn's nine shape categories, as intervals of the shape index (upper bounds).
SHAPE_CATEGORIES = (
    ("cup", -7 / 8),
    ("trough", -5 / 8),
    ("rut", -3 / 8),
    ("saddle_rut", -1 / 8),
    ("saddle", 1 / 8),
    ("saddle_ridge", 3 / 8),
    ("ridge", 5 / 8),
    ("dome", 7 / 8),
    ("cap", 1.0),
)

#: Surfaces of fewer vertices are ``too_small`` (below it :func:`meshcurv.lattice.voxel_grid` sees no grid).
MIN_VERTICES = 16

#: The columns of the table, in order (see the module's documentation).
COLUMNS = (
    "label",
    "status",
    "error",
    "n_voxels",
    "touches_border",
    "n_vertices",
    "n_faces",
    "n_used",
    "n_invalid",
    "euler_characteristic",
    "area",
    "area_mesh",
    "volume",
    "equivalent_radius",
    "centroid_0",
    "centroid_1",
    "centroid_2",
    "radius",
    "surface",
    *(f"{field}_{statistic}" for field in FIELDS for statistic in STATISTICS),
    "total_mean",
    "total_gaussian",
    "willmore",
    *STATISTICS_COLUMNS,
    *(f"shape_index_fraction_{name}" for name, _ in SHAPE_CATEGORIES),
    "warnings",
)

_INTEGER_COLUMNS = ("label", "n_voxels", "n_vertices", "n_faces", "n_used", "n_invalid", "euler_characteristic")
_TEXT_COLUMNS = ("status", "error", "surface", "warnings")

#: Voxels of the labels' boxes gathered into one Dask task (``workers``, ``client``): a label of radius 20
#: voxels (a box of 64k voxels, about a second of work) is a task of its own, many small ones share one.
TASK_VOXELS = 2**16

#: The fewest tasks per worker when there are enough labels, so that no worker waits for another's long task.
TASKS_PER_WORKER = 8

#: Tasks sent ahead per worker: the crops held by the cluster at a time are bounded, whatever the image.
_IN_FLIGHT_PER_WORKER = 3

#: Dask settings of the local cluster of ``workers=N``: a task goes to a worker only when its thread is free
#: (so that a worker that dies takes only its running task with it), and is tried again once after its
#: worker died before it is lost (``KilledWorker``: the labels of a group are then run one by one).
CLUSTER_CONFIG = {"distributed.scheduler.worker-saturation": 1.0, "distributed.scheduler.allowed-failures": 1}

#: Label values up to this are indexed directly by :func:`scipy.ndimage.find_objects` (a list of that length).
_DIRECT_LABELS = 2**24


class LabelSurface(NamedTuple):
    """The surface of one label and its per-vertex results (``return_meshes=True``).

    Attributes
    ----------
    label : int
    vertices : ndarray of shape (V, 3)
        Physical coordinates along image axes 0, 1, 2.
    faces : ndarray of shape (F, 3)
        Wound outward (away from the object).
    result : CurvatureResult
    used : ndarray of shape (V,), bool
        The vertices in the statistics (valid, and away from the image border).
    vertex_areas : ndarray of shape (V,)
        A third of the corrected area of each adjacent face: the weights of the statistics.
    """

    label: int
    vertices: np.ndarray
    faces: np.ndarray
    result: CurvatureResult
    used: np.ndarray
    vertex_areas: np.ndarray


def _check_labels(labels) -> np.ndarray:
    if isinstance(labels, np.ma.MaskedArray):
        raise InvalidMeshError("`labels` must be a plain array; got a masked array (fill it first)")
    image = np.asanyarray(labels)
    if image.dtype == bool:
        image = image.view(np.uint8)
    elif image.dtype.kind not in "iu":
        raise InvalidMeshError(
            f"`labels` must be an integer label image or a boolean mask; got dtype {image.dtype} "
            "(a float image is not a segmentation: threshold or label it first, or cast whole-number "
            "values with .astype(int))"
        )
    if image.ndim != 3:
        raise InvalidMeshError(
            f"`labels` must be a 3D image (axes 0, 1, 2 = z, y, x); got {image.ndim} dimensions, shape {image.shape}"
        )
    if image.size == 0:
        raise InvalidMeshError(f"`labels` is empty; got shape {image.shape}")
    if image.dtype.kind == "i" and image.min() < 0:
        raise InvalidMeshError(f"`labels` must be >= 0 (0 is the background); got the value {int(image.min())}")
    return image


def _check_labels_to_use(labels_to_use):
    if labels_to_use is None:
        return None
    values = np.atleast_1d(np.asarray(labels_to_use))
    if values.ndim != 1 or (values.size and values.dtype.kind not in "iu"):
        raise InvalidOptionError(f"`labels_to_use` must be a sequence of integer labels; got {labels_to_use!r}")
    if values.size and values.min() <= 0:
        raise InvalidOptionError(
            f"`labels_to_use` must hold labels >= 1 (0 is the background); got {int(values.min())}"
        )
    return [int(value) for value in dict.fromkeys(values.tolist())]


def _objects(image: np.ndarray, wanted):
    """``{label: slices or None}`` for the wanted labels (all present ones when None), one pass over the image."""
    from scipy import ndimage

    top = int(image.max())
    if top <= _DIRECT_LABELS:
        found = ndimage.find_objects(image)
        present = {index + 1: box for index, box in enumerate(found) if box is not None}
    else:  # huge label values: number them 1..n first (a full-size index array)
        values, inverse = np.unique(image, return_inverse=True)
        if values[0] != 0:  # code 0 is the background for find_objects: labels from 1 when the image has none
            values = np.concatenate([np.zeros(1, dtype=values.dtype), values])
            inverse += 1
        found = ndimage.find_objects(inverse.reshape(image.shape))
        present = {int(values[index + 1]): box for index, box in enumerate(found) if box is not None}
    if wanted is None:
        return present
    return {label: present.get(label) for label in wanted}


def _marching_cubes():
    try:
        from skimage.measure import marching_cubes
    except ImportError as exc:
        raise MissingDependencyError("label_curvatures needs scikit-image: pip install 'meshcurv[volume]'") from exc
    return marching_cubes


def _field_statistics(result: CurvatureResult, used: np.ndarray, weights: np.ndarray) -> dict:
    row = {}
    for field in FIELDS:
        values = np.asarray(getattr(result, field))
        keep = used & np.isfinite(values) & (weights > 0)
        if keep.any():
            v, w = values[keep], weights[keep]
            # the rule of the batch table and of meshcurv compute: a value counts by its vertex area
            figures = dict(zip(_QUANTILES, weighted_percentiles(v, w, [100.0 * q for q in _QUANTILES.values()])))
            figures["weighted"] = float(np.sum(v * w) / np.sum(w))
        else:
            figures = dict.fromkeys(STATISTICS, np.nan)
        row.update({f"{field}_{statistic}": float(figures[statistic]) for statistic in STATISTICS})
    index = np.asarray(result.shape_index)
    keep = used & np.isfinite(index) & (weights > 0)
    total = weights[keep].sum()
    bounds = np.array([upper for _, upper in SHAPE_CATEGORIES])
    category = np.minimum(np.searchsorted(bounds, index[keep], side="left"), len(bounds) - 1)
    fractions = (
        np.bincount(category, weights[keep], minlength=len(bounds)) / total
        if total > 0
        else np.full(len(bounds), np.nan)
    )
    row.update({f"shape_index_fraction_{name}": float(value) for (name, _), value in zip(SHAPE_CATEGORIES, fractions)})
    return row


def _empty_row(label: int, status: str, error: str, **facts) -> dict:
    row: dict[str, object] = dict.fromkeys(COLUMNS, np.nan)
    row.update(
        {
            "label": label,
            "status": status,
            "error": error,
            "n_voxels": 0,
            "touches_border": False,
            "n_vertices": 0,
            "n_faces": 0,
            "n_used": 0,
            "n_invalid": 0,
            "euler_characteristic": 0,
            "surface": "",
            "warnings": "",
        }
    )
    row.update(facts)
    return row


def _crop(image: np.ndarray, label: int, box) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The label's mask on its box padded by one voxel of background (bool), and the box's start and stop."""
    starts = np.array([part.start for part in box], dtype=np.int64)
    stops = np.array([part.stop for part in box], dtype=np.int64)
    return np.pad(image[box] == label, 1), starts, stops


def _surface(padded: np.ndarray, starts: np.ndarray, spacing: np.ndarray):
    """Vertices (in voxels), outward faces, voxel count and centroid of one label's padded crop.

    The crop is cut in its :func:`meshcurv._masks.canonical_pose` and its
    surface turned back: the same triangles in every mirror and permutation of
    the image's axes.
    """
    marching_cubes = _marching_cubes()
    mask = padded[1:-1, 1:-1, 1:-1]
    n_voxels = int(np.count_nonzero(mask))
    centroid = (np.array([np.mean(axis) for axis in np.nonzero(mask)]) + starts) * spacing
    pose = canonical_pose(padded, spacing)
    # in whole voxels first (exact), then to physical units: grid planes repeat bit for bit (meshcurv.lattice)
    index, faces = posed_marching_cubes(posed(padded, pose).astype(np.float32), pose, marching_cubes)
    index += starts - 1
    return index, faces, n_voxels, centroid


def _divergence_volume(vertices: np.ndarray, faces: np.ndarray) -> float:
    origin = vertices.mean(axis=0)
    x0, x1, x2 = (vertices[faces[:, k]] - origin for k in range(3))
    return float(np.einsum("ij,ij->i", x0, np.cross(x1, x2)).sum() / 6.0)


def _cap_faces(index: np.ndarray, faces: np.ndarray, touching: np.ndarray, shape: np.ndarray) -> np.ndarray:
    """(F,) bool: the faces that close the crop along the image faces the label touches (not its surface).

    ``index``: the vertices in voxels, exact (marching cubes of a binary mask
    puts them on half voxels). A face is part of the cap when each of its
    corners is on an outer face of the image (``-0.5`` or ``shape - 0.5``
    along an axis whose face the label touches): the faces in those planes
    and the chamfers where two of them meet at an edge or corner of the image.
    A face running from one face of an image one voxel thick to the
    opposite one is a wall of the object, not a cap.
    """
    on_low = touching[:, 0] & (index == -0.5)
    on_high = touching[:, 1] & (index == shape - 0.5)
    corners = (on_low | on_high).any(axis=1)[faces]
    across = (on_low[faces].any(axis=1) & on_high[faces].any(axis=1)).any(axis=1)
    return corners.all(axis=1) & ~across


def _area_inside(vertices, faces, cap, border, normals, triangle, corrected, options, radius, messages):
    """(F,) the corrected face areas, those of the faces near the cap with normals fitted without it.

    The estimator's normals within its reach of a cap (``border``) are bent
    towards the cap's; they are fitted again on the surface without its cap
    faces (an open surface, where the fits extrapolate over one side), with
    the same method and radius. The normals of the other vertices are kept
    (the same fits: their balls do not reach the cap). When that fit fails,
    the faces near the cap keep their triangle area, and ``messages`` says so.
    """
    referenced, renumber = _open_surface(faces, cap, vertices.shape[0])
    refit = dict(options)
    if "radius" not in refit and isinstance(radius, float):
        refit["radius"] = radius
    near = border[faces].any(axis=1) & ~cap
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            opened = principal_curvatures(vertices[referenced], renumber[faces[~cap]], orient="consistent", **refit)
    except (InvalidMeshError, InvalidOptionError, ValueError, ArithmeticError) as exc:
        messages.append(
            f"area: the normals near the image border could not be fitted without the cap "
            f"({type(exc).__name__}: {exc}); the {int(near.sum())} faces there count by their "
            "triangle area"
        )
        return np.where(near, triangle, corrected)
    refitted = np.array(normals, dtype=np.float64, copy=True)
    moved = border & referenced
    fitted = np.asarray(opened.normals)[renumber[moved]]
    refitted[moved] = np.where(np.isfinite(fitted).all(axis=1)[:, None], fitted, refitted[moved])
    measures = face_measures(vertices, faces[near], refitted)[:, 0]
    area = np.where(np.isfinite(measures), measures, triangle[near])
    out = np.array(corrected, copy=True)
    out[near] = area
    return out


#: On a label cut by the image border, the default radius is chosen as on any voxel surface
#: (:func:`meshcurv.radius.voxel_surface_radius`) but from the pilot's curvature of its open surface (the
#: cap's faces left out) and of the vertices farther than this many voxels from the image faces it touches:
#: the creases along the cap's rim made the 75th percentile of the pilot's curvedness large, hence a radius
#: of about one voxel (1.1-1.3 h where the same balls whole get 3-5 h), which does not average the staircase
#: out. Measured on the 660 balls of radius 4-14 voxels cut by 1-3 image faces of ``benchmarks/fuzz_labels.py``
#: (seed 7): the radius is 0.81 (median; 5th percentile 0.54) of the rule's radius for the true curvature.
#: 2.01, not 2: off the lattice's distances (marching cubes' vertices lie at whole and half voxels from the image
#: faces; at 2.0 the last bits of the spacing decided which vertices the pilot read: a cut ball's radius 3.9987 at
#: unit spacing, 3.9155 at 1e-3; fuzz_labels round 25, seed 452 case 190).
CUT_PILOT_RIM = 2.01

#: The smallest default radius of a cut voxel label, in voxels (of the largest voxel size): what the voxel
#: rule gives a ball of radius 4 voxels; a sliver whose pilot sees little but its rim gets at least this.
CUT_RADIUS_FLOOR = 2.01  # (off the lattice's distances, as CUT_PILOT_RIM and radius.VOXEL_FLOOR)

#: A label cut by the border must keep this much surface beyond the estimator's reach of the image faces it
#: touches, in areas of one ball (``pi r^2``, ``r`` the ball radius), for its curvature statistics; with less
#: they are NaN and the ``warnings`` column says why. Measured on 24 whole balls of radius 5-14 voxels with
#: the default radius (2.4-5.3 voxels), ``total_mean / area`` over 1,440 random patches: worst 11% below
#: ``0.5 r^2``, 11% over 2-4 ``r^2``, 5.2% over 4-8 ``r^2``, 2.5% over 8-16 ``r^2`` (``1 / R`` the truth).
CUT_MIN_AREA_BALLS = 1.0


def _border_distance(vertices: np.ndarray, touching: np.ndarray, shape: np.ndarray, spacing: np.ndarray) -> np.ndarray:
    """(V,) the distance of each vertex to the nearest image face the label touches (inf when none)."""
    low, high = -0.5 * spacing, (shape - 0.5) * spacing  # the image's outer voxel faces
    distance = np.full(vertices.shape[0], np.inf)
    for axis in range(3):
        if touching[axis, 0]:
            distance = np.minimum(distance, vertices[:, axis] - low[axis])
        if touching[axis, 1]:
            distance = np.minimum(distance, high[axis] - vertices[:, axis])
    return distance


def _open_surface(faces: np.ndarray, cap: np.ndarray, n_vertices: int):
    """``(referenced, renumber)``: the vertices of the surface without its cap, and their new numbers."""
    referenced = np.zeros(n_vertices, dtype=bool)
    referenced[faces[~cap].ravel()] = True
    return referenced, np.cumsum(referenced) - 1


def _takes_radius(method) -> bool:
    """Whether ``method`` (None: the default) is a registered method over balls, that takes a ``radius``."""
    from .estimators import DEFAULT_METHOD, ESTIMATORS

    name = DEFAULT_METHOD if method is None else method
    return isinstance(name, str) and name in ESTIMATORS and "radius" in ESTIMATORS[name].options


def _cut_radius(vertices, faces, cap, distance, spacing) -> float | None:
    """The default radius of a voxel label cut by the border (:data:`CUT_PILOT_RIM`), or None if no pilot ran.

    ``icc`` at :data:`meshcurv.radius.VOXEL_PILOT` voxels on the surface
    without its cap; ``R`` the inverse of the
    :data:`meshcurv.radius.VOXEL_CURVEDNESS_PERCENTILE` th percentile of its
    curvedness over the vertices farther than :data:`CUT_PILOT_RIM` voxels from
    the image faces (``distance``); the radius :func:`meshcurv.radius.voxel_radius`,
    at least :data:`CUT_RADIUS_FLOOR` voxels (that alone when no vertex is that far).
    """
    h = float(np.max(spacing))
    referenced, renumber = _open_surface(faces, cap, vertices.shape[0])
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            pilot = principal_curvatures(
                vertices[referenced], renumber[faces[~cap]], method="icc", orient="consistent", radius=VOXEL_PILOT * h
            )
    except (InvalidMeshError, InvalidOptionError, ValueError, ArithmeticError):
        return None
    curvedness = np.maximum(np.abs(np.asarray(pilot.k_min)), np.abs(np.asarray(pilot.k_max)))
    keep = (
        np.asarray(pilot.valid)
        & np.isfinite(curvedness)
        & (curvedness > 0)
        & (distance[referenced] > CUT_PILOT_RIM * h)
    )
    floor = CUT_RADIUS_FLOOR * h
    if not keep.any():
        return floor
    return max(floor, voxel_radius(spacing, 1.0 / float(np.percentile(curvedness[keep], VOXEL_CURVEDNESS_PERCENTILE))))


def _one_label(image, label, box, spacing, method, radius, smooth=None):
    """``(row, LabelSurface or None)`` of one label (its mask blurred by ``smooth``, sigma, when given)."""
    if box is None:
        return _empty_row(label, "empty", f"label {label} has no voxel in the image"), None
    label, crop, starts, stops, options = _task_crop(image, label, box, spacing, smooth)
    return _crop_label(label, crop, starts, stops, image.shape, spacing, method, radius, **options)


def _task_crop(image, label, box, spacing, smooth):
    """``(label, crop, starts, stops, options)``: what :func:`_crop_label` needs of the image for one label.

    Without ``smooth``: :func:`_crop` and no options. With it: the mask of
    :func:`meshcurv._masks.smoothed_crop` and ``{"smoothing": (sigma, origin)}``.
    """
    if smooth is None:
        return (label, *_crop(image, label, box), {})
    mask, origin, starts, stops = smoothed_crop(image, label, box, spacing, smooth)
    return label, mask, starts, stops, {"smoothing": (smooth, origin)}


def _crop_label(label, padded, starts, stops, image_shape, spacing, method, radius, smoothing=None):
    """``(row, LabelSurface or None)`` of one label from its crop (:func:`_crop`) and the image's shape.

    ``smoothing``: ``(sigma, origin)`` when ``padded`` is the mask of
    :func:`meshcurv._masks.smoothed_crop`, whose first voxel is ``origin``.
    """
    shape = np.array(image_shape)
    if smoothing is None:
        index, faces, n_voxels, centroid = _surface(padded, starts, spacing)
        touching = np.column_stack([starts == 0, stops == shape])  # (3, 2): low and high face of each axis
    else:
        index, faces, n_voxels, centroid, touching = smoothed_surface(
            padded, smoothing[1], starts, stops, shape, spacing, smoothing[0], _marching_cubes()
        )
    facts = {
        "n_voxels": n_voxels,
        "touches_border": bool(touching.any()),
        "n_vertices": int(index.shape[0]),
        "n_faces": int(faces.shape[0]),
        **{f"centroid_{k}": float(centroid[k]) for k in range(3)},
    }
    if index.shape[0] < MIN_VERTICES:
        return _empty_row(
            label,
            "too_small",
            f"label {label} has {n_voxels} voxel(s): a surface of "
            f"{index.shape[0]} vertices is too small to have a curvature (at least {MIN_VERTICES})",
            **facts,
        ), None
    vertices = index * spacing
    options = {} if method is None else {"method": method}
    if radius is not None:
        options["radius"] = radius
    cap = _cap_faces(index, faces, touching, shape)
    distance = _border_distance(vertices, touching, shape, spacing)
    chosen = None  # a cut label's default radius, chosen without its cap
    if radius is None and cap.any() and _takes_radius(method):
        chosen = _cut_radius(vertices, faces, cap, distance, spacing)
        if chosen is not None:
            options["radius"] = chosen
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        # the faces are outward already; 'consistent' keeps that (the wall of a cavity faces into it)
        result = principal_curvatures(vertices, faces, orient="consistent", **options)
    messages = [str(w.message) for w in caught]

    # vertices too near a face of the image the label touches: the cap that closes the crop, and its rim
    parameters = result.parameters
    margin = float(parameters.get("normal_radius", parameters.get("radius", 2.0 * spacing.max())))
    border = distance < margin
    used = np.asarray(result.valid) & ~border

    normals = np.asarray(result.normals)
    measures = face_measures(vertices, faces, normals)[:, :3]
    triangle, corrected = corrected_areas(vertices, faces, measures)
    if cap.any():  # the area of the surface inside the image, with normals that do not see the cap
        corrected = _area_inside(
            vertices, faces, cap, border, normals, triangle, corrected, options, parameters.get("radius"), messages
        )
    surface_faces = ~cap
    vertex_areas = np.bincount(
        faces[surface_faces].ravel(),
        np.repeat(np.maximum(corrected[surface_faces], 0.0) / 3.0, 3),
        minlength=vertices.shape[0],
    )
    on_object = ~border[faces].any(axis=1)
    inside_faces = on_object & np.isfinite(measures[:, 1:]).all(axis=1)
    measured_area = float(measures[inside_faces, 0].sum())
    reason = None
    if touching.any():  # too little surface out of reach of the cap: no statistic rather than a wrong one
        scale = float(parameters.get("radius", margin))
        needed = CUT_MIN_AREA_BALLS * np.pi * scale**2
        if not measured_area >= needed:
            reason = (
                f"curvature columns NaN: the label is cut by the image border and keeps an area of "
                f"{measured_area:.3g} beyond the estimator's reach ({margin:.3g}) of the image faces it "
                f"touches, less than the {needed:.3g} (pi r^2, r = {scale:.3g}) its statistics need; "
                "area and volume are those of its part inside the image"
            )
    if reason is None and not used.any():  # no vertex to stand for the surface: its integrals neither
        # (issue 29, fuzz_labels seed 73 case 772: a label of 11 voxels cut by the border, its 10 vertices
        # beyond the cap's reach all undefined, had finite totals from the faces between them)
        reach = f" beyond the estimator's reach ({margin:.3g}) of the image faces it touches" if touching.any() else ""
        reason = (
            f"curvature columns NaN: no vertex of the label{reach} has a defined estimate "
            f"({int((~np.asarray(result.valid)).sum())} of its {vertices.shape[0]} vertices undefined); "
            "area and volume are measured all the same"
        )
    if reason is not None:
        messages.append(reason)
        used = np.zeros_like(used)
        border = np.ones_like(border)
        inside_faces = np.zeros_like(inside_faces)
        measured_area = 0.0
    volume = _divergence_volume(vertices, faces)
    n_edges = result.diagnosis.n_edges if result.diagnosis is not None else 0
    mean = np.asarray(result.mean)
    keep = used & np.isfinite(mean)
    # the integrals of curvature over the part away from the border (NaN when none is left)
    total_mean = float(0.5 * measures[inside_faces, 1].sum()) if inside_faces.any() else np.nan
    # the area of the image of the normals (meshcurv.integrals): 2 pi chi on a closed surface whatever
    # the estimator's errors; on a label cut by the border, that of its vertices off the border
    gaussian_shares = vertex_integrals(vertices, faces, "gaussian", normals=normals)
    total_gaussian = float(gaussian_shares[~border].sum()) if (~border).any() else np.nan
    # FreeSurfer's statistics (meshcurv.statistics) over the same vertices and faces: the same code as a mesh's
    statistics = _region_statistics(
        result.k_min,
        result.k_max,
        result.shape_index,
        used,
        vertex_areas,
        measures[inside_faces, :2],
        _face_average(mean, faces[inside_faces]),
        gaussian_shares[~border],
        np.asarray(result.gaussian)[~border],
    )
    messages.extend(filter(None, [_fold_note(statistics, result.k_min, result.k_max, used, vertex_areas)]))
    row = {
        "label": label,
        "status": "ok",
        "error": "",
        **facts,
        "n_used": int(used.sum()),
        "n_invalid": int((~np.asarray(result.valid)).sum()),
        "euler_characteristic": int(vertices.shape[0] - n_edges + faces.shape[0]),
        "area": float(corrected[surface_faces].sum()),
        "area_mesh": float(triangle[surface_faces].sum()),
        "volume": volume,
        "equivalent_radius": float(np.cbrt(3.0 * max(volume, 0.0) / (4.0 * np.pi))),
        "radius": float(result.parameters["radius"]) if "radius" in result.parameters else np.nan,
        "surface": "voxel" if chosen is not None else str(result.parameters.get("surface", "")),
        **_field_statistics(result, used, vertex_areas),
        "total_mean": total_mean,
        "total_gaussian": total_gaussian,
        "willmore": float(np.sum(mean[keep] ** 2 * vertex_areas[keep])) if keep.any() else np.nan,
        **statistics,
        "warnings": "; ".join(messages),
    }
    if measured_area > 0:  # H and K weighted by area: the ratios of the corrected measures (see the module)
        row["mean_weighted"] = total_mean / measured_area
        row["gaussian_weighted"] = total_gaussian / measured_area
    return row, LabelSurface(label, vertices, faces, result, used, vertex_areas)


#: What a call without ``spacing`` assumes (and says once, in a warning).
DEFAULT_SPACING = (1.0, 1.0, 1.0)


def _image_and_spacing(labels, spacing):
    """``(array, spacing, assumed)``: an :class:`~meshcurv.io._images.Image` gives its array and its spacing.

    Without ``spacing``, and with no spacing carried by the image, the voxels
    are taken as :data:`DEFAULT_SPACING` (``assumed`` True: the caller warns
    once the inputs are checked, :func:`_warn_spacing`).
    """
    carried = None
    if isinstance(labels, tuple) and hasattr(labels, "spacing"):
        from .io._images import Image

        if isinstance(labels, Image):
            labels, carried = labels.array, labels.spacing
    if spacing is not None:
        return labels, spacing, False
    if carried is not None:
        return labels, carried, False
    return labels, DEFAULT_SPACING, True


def _warn_spacing(caller: str, stacklevel: int) -> None:
    warnings.warn(
        f"{caller}: no `spacing` given (and none carried by the image): the voxels are taken as "
        "1 x 1 x 1, so areas are in voxel faces and curvatures per voxel length; pass spacing=(z, y, x), "
        "the voxel size along image axes 0, 1, 2 in your unit",
        MeshcurvWarning,
        stacklevel=stacklevel + 1,
    )


def _warn_no_object(caller: str, threshold, stacklevel: int) -> None:
    """The image holds no object: an empty table, said once (a wrong threshold or an empty mask)."""
    what = (
        "every voxel is 0 (the background)"
        if threshold is None
        else f"no voxel is greater than threshold={threshold:g}"
    )
    warnings.warn(
        f"{caller}: the image holds no object: {what}; the table has no row",
        MeshcurvWarning,
        stacklevel=stacklevel + 1,
    )


def _plan(
    labels, spacing, labels_to_use, radius, threshold=None, *, caller: str = "label_curvatures", stacklevel: int = 2
):
    """Check the inputs and find the labels' boxes: ``(image, spacing, {label: box or None}, radius)``.

    A lazy image (:func:`meshcurv._lazy.is_lazy`) is read a chunk at a time
    (:func:`meshcurv._lazy.lazy_objects`); an image in memory is first turned
    into labels by ``threshold`` (:func:`meshcurv._masks.labels_from_image`).
    """
    threshold = check_threshold(threshold)
    spacing = checked_spacing(spacing)
    wanted = _check_labels_to_use(labels_to_use)
    if radius is not None:
        radius = check_positive_float(radius, "radius")
    _marching_cubes()
    if is_lazy(labels):
        if threshold is not None:
            raise InvalidOptionError(
                "`threshold` needs the image in memory (its components span chunks); a lazily "
                "read image (Zarr, Dask) must be a label image: label it first"
            )
        lazy = check_lazy_labels(as_lazy(labels))
        return lazy, spacing, lazy_objects(lazy, wanted, _objects), radius
    if isinstance(labels, np.ma.MaskedArray):
        raise InvalidMeshError("`labels` must be a plain array; got a masked array (fill it first)")
    image = _check_labels(labels_from_image(np.asanyarray(labels), threshold, caller=caller, stacklevel=stacklevel + 1))
    return image, spacing, _objects(image, wanted), radius


def _guarded(label, compute, keep_surfaces):
    """``compute()``, or a ``failed`` row when it raises for this label (not for bad options)."""
    try:
        row, surface = compute()
    except (InvalidOptionError, MissingDependencyError):
        raise  # the options are wrong for every label: not this label's failure
    except (ValueError, RuntimeError, ArithmeticError, MemoryError) as exc:
        logger.debug("label %d failed", label, exc_info=True)
        row, surface = _empty_row(label, "failed", f"{type(exc).__name__}: {exc}"), None
    return row, (surface if keep_surfaces else None)


def _iterate(image, spacing, objects, method, radius, keep_surfaces, smooth=None):
    for label, box in objects.items():
        yield _guarded(
            label, functools.partial(_one_label, image, label, box, spacing, method, radius, smooth), keep_surfaces
        )


def _dask():
    try:
        import distributed
    except ImportError:
        raise MissingDependencyError(
            "label_curvatures with `workers` or `client` runs the labels on Dask: pip install 'meshcurv[batch]'"
        ) from None
    return distributed


def _check_parallel(workers, client):
    """``(workers, client)`` checked: None, None for the serial path."""
    if client is not None and workers is not None:
        raise InvalidOptionError("give `workers` (a local cluster of that many processes) or `client`, not both")
    if workers is not None:
        from .batch import MAX_WORKERS

        workers = check_int_option(workers, "workers", minimum=1, maximum=MAX_WORKERS)
        if workers == 1:
            workers = None
    if workers is not None or client is not None:
        distributed = _dask()
        if client is not None and not isinstance(client, distributed.Client):
            raise InvalidOptionError(f"`client` must be a distributed.Client; got {type(client).__name__}")
    return workers, client


def _crop_task(crops, image_shape, spacing, method, radius, keep_surfaces):
    """One Dask task: ``(row, surface)`` of each ``(label, padded, starts, stops, options)`` of ``crops``.

    (:func:`_task_crop`: ``options`` holds the ``smoothing`` of a smoothed crop.)
    """
    return [
        _guarded(
            label,
            functools.partial(
                _crop_label, label, padded, starts, stops, image_shape, spacing, method, radius, **options
            ),
            keep_surfaces,
        )
        for label, padded, starts, stops, options in crops
    ]


def _groups(objects, workers: int) -> list[list]:
    """The labels that have a box, cut into tasks: runs of consecutive labels of about :data:`TASK_VOXELS`.

    The labels are first shared out evenly into :data:`TASKS_PER_WORKER` runs
    per worker (fewer when there are fewer labels); a run is then cut where
    the voxels of its boxes pass :data:`TASK_VOXELS` (one label at least per task).
    """
    labels = [label for label, box in objects.items() if box is not None]
    if not labels:
        return []
    sizes = [int(np.prod([part.stop - part.start + 2 for part in objects[label]])) for label in labels]
    groups: list[list] = []
    for run in np.array_split(np.arange(len(labels)), min(len(labels), TASKS_PER_WORKER * workers)):
        total = TASK_VOXELS + 1
        for position in run.tolist():
            if total + sizes[position] > TASK_VOXELS:
                groups.append([])
                total = 0
            groups[-1].append(labels[position])
            total += sizes[position]
    return groups


def _lost(outcome, distributed) -> str:
    """The error of a label whose task ended without rows (its worker died, or the task raised)."""
    if isinstance(outcome, distributed.KilledWorker):
        return (
            f"WorkerDied: the worker process computing this label died each time it ran (killed by the system: "
            f"out of memory? a crash in a compiled library?) ({type(outcome).__name__}: {outcome})"
        )
    return f"{type(outcome).__name__}: {outcome}"


def _iterate_dask(image, spacing, objects, method, radius, keep_surfaces, client, workers, smooth=None):
    """As :func:`_iterate` (the same rows, in the same order), each group of labels a task on a Dask cluster.

    The driver is batch's (:func:`meshcurv.batch._driver.run_tasks`). Each task
    gets only its labels' crops (the box padded by one voxel, as a boolean
    mask, or its smoothed mask), their offsets, the image's shape and the
    spacing; the crops are made only for the tasks in flight. A task that
    raises or whose worker dies (:class:`distributed.KilledWorker`) is run
    again label by label when it held several; a label whose task alone still
    fails gets a ``failed`` row.
    """
    distributed = _dask()
    fatal = (InvalidOptionError, MissingDependencyError)
    with driver.cluster(client=client, workers=workers, dashboard=False, config=CLUSTER_CONFIG) as (active, owned):
        n_workers = driver._worker_count(active)
        groups = _groups(objects, n_workers)
        logger.info("%d labels in %d tasks on %d workers", len(objects), len(groups), n_workers)

        def submit(chosen):
            return [
                active.submit(
                    _crop_task,
                    [_task_crop(image, label, objects[label], spacing, smooth) for label in group],
                    image.shape,
                    spacing,
                    method,
                    radius,
                    keep_surfaces,
                    pure=False,
                )
                for group in chosen
            ]

        tasks = driver.run_tasks(
            active,
            groups,
            submit,
            owned=owned,
            limit=_IN_FLIGHT_PER_WORKER * n_workers,
            split=lambda outcome: not isinstance(outcome, fatal),
            items="labels",
        )
        with contextlib.closing(tasks):
            done: dict = {}
            for label, box in objects.items():
                if box is None:
                    yield _guarded(
                        label, functools.partial(_one_label, image, label, None, spacing, method, radius), keep_surfaces
                    )
                    continue
                while label not in done:
                    group, outcome = next(tasks)
                    if isinstance(outcome, fatal):
                        raise outcome
                    if isinstance(outcome, BaseException):
                        logger.debug("label %d failed: %r", group[0], outcome)
                        done[group[0]] = (_empty_row(group[0], "failed", _lost(outcome, distributed)), None)
                    else:
                        done.update(zip(group, outcome))
                yield done.pop(label)


def label_surfaces(
    labels,
    *,
    spacing=None,
    labels_to_use=None,
    method: str | None = None,
    radius: float | None = None,
    keep_surfaces: bool = True,
    workers: int | None = None,
    client=None,
    threshold: float | None = None,
    smooth: float | None = None,
):
    """``(total, iterator)``: the number of labels, and ``(row, surface)`` for each, one at a time.

    ``row`` is a dict of :data:`COLUMNS` (see :func:`label_curvatures`);
    ``surface`` a :class:`LabelSurface`, or None when the label has none
    (``row["status"]`` says why) or when ``keep_surfaces`` is False. Only one
    label's crop and mesh are held at a time: this is what
    :func:`label_curvatures` and ``meshcurv volume`` run. The inputs are
    checked, and the labels found, before this returns. With ``workers`` or
    ``client`` (as in :func:`label_curvatures`) the labels are computed on a
    Dask cluster, a few tasks ahead, and yielded in the same order.
    ``threshold``, ``smooth`` and lazy images as in :func:`label_curvatures`.
    """
    return _label_surfaces(
        labels,
        spacing,
        labels_to_use,
        method,
        radius,
        keep_surfaces,
        workers,
        client,
        caller="label_surfaces",
        stacklevel=2,
        threshold=threshold,
        smooth=smooth,
    )


def _label_surfaces(
    labels,
    spacing,
    labels_to_use,
    method,
    radius,
    keep_surfaces,
    workers,
    client,
    *,
    caller: str,
    stacklevel: int,
    threshold=None,
    smooth=None,
):
    """:func:`label_surfaces`; the warning of a missing spacing names ``caller``, ``stacklevel`` frames up."""
    workers, client = _check_parallel(workers, client)
    smooth = check_smooth(smooth)
    labels, spacing, assumed = _image_and_spacing(labels, spacing)
    image, spacing, objects, radius = _plan(
        labels, spacing, labels_to_use, radius, threshold, caller=caller, stacklevel=stacklevel + 1
    )
    if assumed:
        _warn_spacing(caller, stacklevel + 1)
    if not objects and labels_to_use is None:
        _warn_no_object(caller, threshold, stacklevel + 1)
    if (workers is None and client is None) or all(box is None for box in objects.values()):
        return len(objects), _iterate(image, spacing, objects, method, radius, keep_surfaces, smooth)
    return len(objects), _iterate_dask(image, spacing, objects, method, radius, keep_surfaces, client, workers, smooth)


def _table(rows):
    import pandas

    frame = pandas.DataFrame.from_records(rows, columns=list(COLUMNS))
    for name in _INTEGER_COLUMNS:
        huge = name == "label" and len(frame) > 0 and max(map(int, frame[name])) > np.iinfo(np.int64).max
        frame[name] = frame[name].astype(np.uint64 if huge else np.int64)  # uint64 labels beyond 2**63 kept
    frame["touches_border"] = frame["touches_border"].astype(bool)
    for name in _TEXT_COLUMNS:
        frame[name] = frame[name].fillna("").astype(str)
    for name in COLUMNS:
        if name not in _INTEGER_COLUMNS + _TEXT_COLUMNS + ("touches_border",):
            frame[name] = frame[name].astype(np.float64)
    return frame


def _pandas():
    try:
        import pandas
    except ImportError as exc:
        raise MissingDependencyError(
            "label_curvatures returns a pandas DataFrame: pip install 'meshcurv[volume]'"
        ) from exc
    return pandas


def label_curvatures(
    labels,
    *,
    spacing=None,
    labels_to_use=None,
    method: str | None = None,
    radius: float | None = None,
    return_meshes: bool = False,
    progress: Callable[[int, int, int], None] | None = None,
    workers: int | None = None,
    client=None,
    threshold: float | None = None,
    smooth: float | None = None,
):
    """Curvature statistics of every object of a 3D label image, one row per label.

    Each label's surface is extracted by marching cubes on its bounding box
    (padded by one voxel), in physical units, wound outward, and its
    curvatures are computed by :func:`meshcurv.principal_curvatures`; the
    columns are described in :mod:`meshcurv.volume` (:data:`COLUMNS`).

    Parameters
    ----------
    labels : array_like of shape (Z, Y, X), integer, bool or float
        A label image (0 is the background, each positive value one object)
        or a binary mask (one object, label 1); with ``threshold``, a
        probability map; or the ``Image`` that
        ``meshcurv.io._images.read_image`` returns, whose spacing (from the
        file) is used when ``spacing`` is not given. A float image needs
        ``threshold`` (labels stored as floats: cast them first). An array read by slicing, a ``zarr.Array``, a
        ``dask.array.Array`` or a :class:`meshcurv._lazy.LazyImage` (what
        ``read_image`` returns for a ``.zarr`` store), is never loaded
        whole: the objects' boxes are found a chunk at a time, then each
        object's box is read (:mod:`meshcurv._lazy`); it must hold labels.
    spacing : sequence of 3 floats, optional
        Voxel size along image axes 0, 1, 2 (z, y, x), in the unit of the
        results (areas in unit^2, curvatures in 1/unit). Without it (and no
        spacing carried by ``labels``) the voxels are taken as 1 x 1 x 1,
        with a warning.
    labels_to_use : sequence of int, optional
        The labels to measure, in this order; default every label present,
        in increasing order. A label with no voxel gets a row with status
        ``empty``.
    method : str, optional
        The estimator (:data:`meshcurv.METHODS`); default that of
        :func:`meshcurv.principal_curvatures` (``icc``), the one whose
        default radius recognises voxel surfaces and whose fitted normals give
        the corrected area. With another method the area is that of the
        method's normals (``normal_cycle``: close to the staircase's area).
    radius : float, optional
        The ball radius of the estimator, in physical units; default: chosen
        per label from its voxel grid and curvature.
    return_meshes : bool, default: False
        Also return the surfaces: a dict ``{label: LabelSurface}`` (vertices,
        outward faces, the CurvatureResult, the vertices used and their
        areas) of the labels with status ``ok``.
    progress : callable, optional
        Called as ``progress(done, total, label)`` after each label.
    workers : int, optional
        Compute the labels on a local Dask cluster of this many worker
        processes (:func:`meshcurv.batch.local_cluster`, one thread each),
        started and closed by the call; None or 1: one label after the other
        in this process.
    client : distributed.Client, optional
        Compute the labels on this Dask cluster instead (not with ``workers``).

        On a cluster, a label or a group of small ones (:data:`TASK_VOXELS`
        voxels of boxes) is one task, which receives only its labels' crops
        (their boxes padded by one voxel, as boolean masks) with their offsets
        and the spacing, never the image; a few tasks per worker are sent
        ahead. The rows are those of the serial run, in the same order (up to
        the order of floating-point sums). A label whose computation raises
        gets a ``failed`` row, as serially; a label whose worker process dies
        (out of memory, a crash in a compiled library) gets a ``failed`` row
        (``WorkerDied: ...``) after its task was tried again once on the local
        cluster (``distributed.scheduler.allowed-failures`` times on a
        ``client``'s), and the other labels are computed.

    threshold : float, optional
        ``labels`` is a probability map (any real image): the voxels greater
        than ``threshold`` are the foreground, and its connected components
        (6-connectivity: voxels sharing a face) are the objects, numbered 1,
        2, ... in the order of their first voxel; NaN voxels are background
        (with a warning). See :mod:`meshcurv._masks`. Not for lazy images.
    smooth : float, optional
        Blur each object's mask with a Gaussian of this standard deviation,
        in the unit of ``spacing`` (``smooth / spacing`` voxels along each
        axis), on its box padded by ``ceil(3 smooth / h) + 1`` voxels,
        before marching cubes at level 0.5 (:mod:`meshcurv._masks`). The
        staircase is gone from the surface; the level set moves inward by
        about ``smooth^2 H``, so a ball of radius ``R`` loses about
        ``2 smooth^2 / R^2`` of its area and ``3 smooth^2 / R^2`` of its volume.
        The radius is then chosen by the default rules (a blurred mask's
        surface is recognised as a voxel surface).

    Returns
    -------
    pandas.DataFrame
        One row per label (:data:`COLUMNS`), or ``(table, surfaces)`` with
        ``return_meshes=True``.

    Raises
    ------
    InvalidMeshError
        ``labels`` not a 3D integer or boolean array (or, with ``threshold``,
        an array of real numbers), empty, or with negative labels; a float
        image without ``threshold``.
    InvalidOptionError
        ``spacing`` not 3 positive finite numbers; bad ``labels_to_use``,
        ``method``, ``radius``, ``workers``, ``threshold`` or ``smooth``;
        both ``workers`` and ``client``; ``threshold`` with a lazy image.
    MissingDependencyError
        Without scikit-image or pandas (``pip install 'meshcurv[volume]'``);
        ``workers`` or ``client`` without dask.distributed (``pip install
        'meshcurv[batch]'``).

    Warns
    -----
    MeshQualityWarning
        Once per call, when labels had no surface (``empty``, ``too_small``),
        failed, or have invalid vertices: the counts (the rows say which).
    MeshcurvWarning
        When no ``spacing`` was given and the image carries none: what was
        assumed (1 x 1 x 1) and how to pass it. When the image holds no
        object (no label, or no voxel above ``threshold``): the table is
        empty. When a thresholded image has NaN voxels.

    Examples
    --------
    >>> import numpy as np, pytest
    >>> _ = pytest.importorskip("skimage"), pytest.importorskip("pandas")  # the volume extra
    >>> from meshcurv.volume import label_curvatures
    >>> z, y, x = np.ogrid[:40, :40, :40]
    >>> ball = (z - 19.6) ** 2 + (y - 20.3) ** 2 + (x - 19.8) ** 2 <= 12 ** 2
    >>> table = label_curvatures(ball.astype(np.uint8), spacing=(1.0, 1.0, 1.0))
    >>> row = table.iloc[0]
    >>> print(f"{row.area / (4 * np.pi * 144):.2f} {row.mean_weighted * 12:.2f} {row.total_gaussian / np.pi:.1f}")
    1.00 1.00 4.0
    """
    _pandas()
    if progress is not None and not callable(progress):
        raise InvalidOptionError(f"`progress` must be a callable progress(done, total, label); got {progress!r}")
    total, surfaces_and_rows = _label_surfaces(
        labels,
        spacing,
        labels_to_use,
        method,
        radius,
        return_meshes,
        workers,
        client,
        caller="label_curvatures",
        stacklevel=2,
        threshold=threshold,
        smooth=smooth,
    )
    rows, surfaces = [], {}
    for row, surface in surfaces_and_rows:
        rows.append(row)
        if surface is not None:
            surfaces[surface.label] = surface
        if progress is not None:
            progress(len(rows), total, row["label"])
    table = _table(rows)
    message = _problems(table)
    if message:
        warnings.warn(message, MeshQualityWarning, stacklevel=2)
    return (table, surfaces) if return_meshes else table


def _problems(table) -> str:
    parts = []
    counts = table["status"].value_counts()
    bad = {status: int(counts.get(status, 0)) for status in ("empty", "too_small", "failed") if counts.get(status, 0)}
    if bad:
        parts.append(
            f"{sum(bad.values())} of {len(table)} labels have no curvature ("
            + ", ".join(f"{n} {status}" for status, n in bad.items())
            + "; see the status and error columns)"
        )
    invalid = table["n_invalid"]
    if (invalid > 0).any():
        parts.append(
            f"{int(invalid.sum())} invalid vertices (no estimate) in {int((invalid > 0).sum())} labels "
            "(n_invalid, warnings columns)"
        )
    return "label_curvatures: " + "; ".join(parts) if parts else ""
