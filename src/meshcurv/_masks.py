"""Masks before marching cubes: label images from probability maps, and each object's mask smoothed.

:mod:`meshcurv.volume` measures the objects of a label image. Segmentations
do not always come as one: a network gives a probability map, a membrane
segmentation in an MRC file is often a float32 mask. This module turns those
into label images (a float image without a threshold is refused: whether it
holds labels or probabilities is the user's to say), and blurs an object's
mask before its surface is extracted, as biologists do to take the voxel
staircase away.

Probability maps (``threshold``)
--------------------------------
The voxels whose value is greater than ``threshold`` are the foreground; its
connected components, with **6-connectivity** (voxels that share a face;
:func:`scipy.ndimage.label`'s default structure), are the objects, numbered
1, 2, ... in the order of their first voxel (C order). 6-connectivity is
chosen because marching cubes at level 0.5 separates two voxels that touch
only along an edge or at a corner: each object is then exactly the voxels its
surface encloses, with no pinched vertex where two blobs touch diagonally (the
cost: a single voxel touching an object only diagonally is an object of its
own, a ``too_small`` row). NaN voxels are background (one warning gives their
count).

Smoothing (``smooth``)
----------------------
Each object's mask, on its bounding box padded by ``ceil(3 sigma / h) + 1``
voxels along each axis (``h`` the voxel size there) and clipped to the image,
is blurred by :func:`scipy.ndimage.gaussian_filter` with the standard
deviation ``sigma / h`` voxels per axis (``sigma`` in physical units, as the
spacing), and its surface is marching cubes at level 0.5 of the blurred
mask. Along an image face the object touches, the mask is continued beyond
the image by its last plane (``mode="nearest"``: the object is taken to go on
as it was), and the surface is closed there by a flat cap in the plane of the
image's outer voxel faces, as for an unsmoothed mask, so that
:mod:`meshcurv.volume` leaves the cap out of the area and the statistics.
The level set of a blurred convex object lies inside the object, by about
``sigma^2 H`` (``H`` the mean curvature; Gaussian smoothing moves a level set
as mean curvature flow does for a time ``sigma^2 / 2``): ``sigma^2 / R`` on
a ball of radius ``R``, so area and volume shrink by about
``2 sigma^2 / R^2`` and ``3 sigma^2 / R^2`` (1% and 1.5% for ``R = 10
sigma``).
"""

from __future__ import annotations

import itertools
import math
import warnings

import numpy as np

from ._validation import check_positive_float
from .errors import InvalidMeshError, InvalidOptionError, MeshcurvWarning

__all__ = [
    "check_threshold",
    "check_smooth",
    "labels_from_image",
    "smooth_padding",
    "smoothed_crop",
    "smoothed_surface",
    "canonical_pose",
    "posed",
    "unposed",
    "posed_marching_cubes",
    "POSES",
    "CONNECTIVITY",
    "SMOOTH_TRUNCATE",
]

#: Connectivity of the components of a thresholded probability map: 6 (voxels sharing a face).
CONNECTIVITY = 6

#: The crop around each object reaches this many standard deviations beyond its box (plus one voxel).
SMOOTH_TRUNCATE = 3.0


def check_threshold(threshold) -> float | None:
    """``threshold`` as a finite float, or None."""
    if threshold is None:
        return None
    if (
        isinstance(threshold, bool)
        or not isinstance(threshold, (int, float, np.integer, np.floating))
        or not np.isfinite(threshold)
    ):
        raise InvalidOptionError(
            f"`threshold` must be a finite number (voxels greater than it are objects); got {threshold!r}"
        )
    return float(threshold)


def check_smooth(smooth) -> float | None:
    """``smooth`` (sigma in physical units) as a positive finite float, or None."""
    if smooth is None:
        return None
    return check_positive_float(smooth, "smooth")


def labels_from_image(image: np.ndarray, threshold: float | None, *, caller: str, stacklevel: int) -> np.ndarray:
    """The label image of ``image``: its components above ``threshold``, or ``image`` itself.

    Without ``threshold``: an integer or boolean image is returned as it is;
    a float image is an error that says to pass a threshold (or to cast
    labels stored as floats). With ``threshold``: the components
    (:data:`CONNECTIVITY`) of ``image > threshold``, as int32 (or int64
    beyond 2**31 - 1 components).

    Raises
    ------
    InvalidMeshError
        A float image without ``threshold``; an image of another kind
        (complex, text) with one.
    """
    if threshold is None:
        if image.dtype.kind == "f":
            raise InvalidMeshError(
                f"`labels` must be an integer label image or a boolean mask; got dtype {image.dtype}: for a "
                "probability map pass threshold=T (--threshold T), the voxels greater than T are the objects, split "
                "into connected components; labels stored as floats: cast them first (.astype(int))"
            )
        return image
    if image.dtype.kind not in "biuf":
        raise InvalidMeshError(
            f"`labels` with `threshold` must be an image of real numbers (a probability map); got dtype {image.dtype}"
        )
    from scipy import ndimage

    foreground = image > threshold  # NaN > t is False: background
    if image.dtype.kind == "f":
        n_nan = int(np.count_nonzero(np.isnan(image)))
        if n_nan:
            warnings.warn(
                f"{caller}: {n_nan} voxels of the image are NaN; they are taken as background",
                MeshcurvWarning,
                stacklevel=stacklevel + 1,
            )
    structure = ndimage.generate_binary_structure(3, 1) if foreground.ndim == 3 else None  # 6-connectivity
    try:
        labels, _ = ndimage.label(foreground, structure=structure, output=np.int32)
    except RuntimeError:  # more components than int32 holds
        labels, _ = ndimage.label(foreground, structure=structure, output=np.int64)
    return labels


def smooth_padding(spacing: np.ndarray, sigma: float) -> np.ndarray:
    """(3,) int: the voxels added around an object's box before it is blurred, ``ceil(3 sigma / h) + 1`` per axis."""
    return np.array(
        [math.ceil(SMOOTH_TRUNCATE * sigma / h) + 1 for h in np.asarray(spacing, dtype=float)], dtype=np.int64
    )


def smoothed_crop(image: np.ndarray, label: int, box, spacing: np.ndarray, sigma: float):
    """``(mask, origin, starts, stops)``: the object's mask on its box padded by :func:`smooth_padding`.

    ``mask`` is bool, clipped to the image; ``origin`` the image index of its
    first voxel; ``starts``, ``stops`` the object's box (int64 arrays).
    """
    starts = np.array([part.start for part in box], dtype=np.int64)
    stops = np.array([part.stop for part in box], dtype=np.int64)
    pad = smooth_padding(spacing, sigma)
    low = np.maximum(starts - pad, 0)
    high = np.minimum(stops + pad, np.array(image.shape, dtype=np.int64))
    region = tuple(slice(int(a), int(b)) for a, b in zip(low, high))
    return image[region] == label, low, starts, stops


def smoothed_surface(
    mask: np.ndarray,
    origin: np.ndarray,
    starts: np.ndarray,
    stops: np.ndarray,
    image_shape,
    spacing: np.ndarray,
    sigma: float,
    marching_cubes,
):
    """Vertices (in voxels), outward faces, voxel count, centroid and touching faces of a blurred mask.

    ``mask``, ``origin``: :func:`smoothed_crop`. The blurred mask is padded by
    one voxel of 0 and cut at 0.5 by ``marching_cubes``; the vertices between
    an image face and that padding (strictly within the outer half voxel
    beyond the face's voxel centres, and a voxel beyond) are put on the face,
    ``-0.5`` or ``shape - 0.5``, the plane of the cap of an unsmoothed mask.
    ``touching`` (3, 2) bool: the low and high image face of each axis that
    the surface reaches (the object's box touches it, or its blur reaches
    0.5 there).
    The mask is blurred and cut in its :func:`canonical_pose`, and the surface
    turned back (:func:`posed_marching_cubes`): every mirror and permutation of
    the image's axes gets the same blur, bit for bit, and the same triangles.
    """
    from scipy import ndimage

    shape = np.asarray(image_shape, dtype=np.int64)
    n_voxels = int(np.count_nonzero(mask))
    centroid = (np.array([np.mean(axis) for axis in np.nonzero(mask)]) + origin) * spacing
    pose = canonical_pose(mask, spacing)
    order, _ = pose
    posed_blur = ndimage.gaussian_filter(
        posed(mask, pose).astype(np.float32),
        sigma / np.asarray(spacing, dtype=float)[list(order)],
        mode="nearest",
        truncate=4.0,
    )
    blurred = unposed(posed_blur, pose)
    end = origin + np.array(mask.shape)
    touching = np.zeros((3, 2), dtype=bool)
    for axis in range(3):
        first = np.take(blurred, 0, axis=axis)
        last = np.take(blurred, -1, axis=axis)
        touching[axis, 0] = origin[axis] == 0 and (starts[axis] == 0 or bool((first > 0.5).any()))
        touching[axis, 1] = end[axis] == shape[axis] and (stops[axis] == shape[axis] or bool((last > 0.5).any()))
    index, faces = posed_marching_cubes(np.pad(posed_blur, 1), pose, marching_cubes)
    index += origin - 1
    for axis in range(3):
        column = index[:, axis]
        if touching[axis, 0]:
            column[(column > -1.0) & (column < 0.0)] = -0.5
        if touching[axis, 1]:
            column[(column > shape[axis] - 1.0) & (column < shape[axis])] = shape[axis] - 0.5
    return index, faces, n_voxels, centroid, touching


Pose = tuple[tuple[int, ...], tuple[bool, ...]]

#: The 48 symmetries of a voxel grid (with its spacing permuted along): ``(order, flips)``, the image
#: ``np.transpose(np.flip(mask, axes flipped), order)``.
POSES: tuple[Pose, ...] = tuple(
    (order, flips) for order in itertools.permutations(range(3)) for flips in itertools.product((False, True), repeat=3)
)


def posed(array: np.ndarray, pose) -> np.ndarray:
    """``array`` (3D) in ``pose`` (:data:`POSES`): flipped along the axes of ``flips``, then its axes in ``order``."""
    order, flips = pose
    return np.transpose(np.flip(array, axis=tuple(a for a in range(3) if flips[a])), order)


def unposed(array: np.ndarray, pose) -> np.ndarray:
    """The inverse of :func:`posed`: ``array`` in ``pose`` turned back to the image's axes."""
    order, flips = pose
    return np.flip(np.transpose(array, np.argsort(order)), axis=tuple(a for a in range(3) if flips[a]))


def canonical_pose(mask: np.ndarray, spacing) -> Pose:
    """The pose (:data:`POSES`) that puts ``mask`` (3D bool) and its ``spacing`` first of all 48 poses.

    The poses are ordered by the spacing they put along axes 0, 1, 2, then the
    shape, then the count of the mask's voxels in each plane along axes 0, 1
    and 2, then the mask's voxels in C order. Every mirror and permutation of
    the axes of a mask (the spacing permuted along) has the same first posed
    mask; where the object is symmetric, several poses give it, and the first
    is taken (they give the same array, hence the same surface in that pose).

    Marching cubes is not equivariant: its tables split the same polygon of a
    cube by another diagonal once the cube is mirrored or its axes swapped, and
    on a binary mask every saddle of a face lies exactly on the level. The
    same object transposed was another triangulation of the same vertices, whose
    default radius moved by 0.09% (4.003 to 3.9998 voxels), across the lattice
    distance (4 voxels) of a shell of 31 vertices near the image border:
    ``total_mean`` 6% apart (issue 29, fuzz_labels seed 773 case 483). Its
    surface cut in this pose and turned back (:func:`posed_marching_cubes`)
    is the same mesh in every pose of the image, moved rigidly.
    """
    spacing = np.asarray(spacing, dtype=float)
    shape = np.array(mask.shape)
    # the voxels per plane along each image axis: a pose's profile along its axis k is that of axis order[k]
    profiles = [np.count_nonzero(mask, axis=tuple(b for b in range(3) if b != a)).tolist() for a in range(3)]

    def summary(pose):
        order, flips = pose
        along = [profiles[a][::-1] if flips[a] else profiles[a] for a in order]
        return (spacing[list(order)].tolist(), shape[list(order)].tolist(), along)

    summaries = [summary(pose) for pose in POSES]
    first = min(summaries)
    candidates = [pose for pose, key in zip(POSES, summaries) if key == first]
    if len(candidates) == 1:
        return candidates[0]
    return min(candidates, key=lambda pose: np.packbits(np.ascontiguousarray(posed(mask, pose))).tobytes())


def posed_marching_cubes(field: np.ndarray, pose, marching_cubes) -> tuple[np.ndarray, np.ndarray]:
    """``(vertices, faces)``: marching cubes at 0.5 of ``field`` posed by :func:`posed`, in ``field``'s axes.

    ``field`` is given in the pose already (``posed(image field, pose)``);
    the vertices (float64, in voxels of the unposed field, exact: a posed
    vertex on whole and half voxels stays there) are turned back, and the
    faces wound outward (marching cubes winds a bright object inward; a pose
    that is a mirror winds it the other way once turned back).
    """
    order, flips = pose
    vertices, faces, _, _ = marching_cubes(np.ascontiguousarray(field), 0.5, method="lewiner", allow_degenerate=False)
    index = np.zeros((vertices.shape[0], 3), dtype=np.float64)
    index[:, list(order)] = vertices
    shape = np.array(field.shape)[np.argsort(order)]  # the unposed field's shape
    for axis in range(3):
        if flips[axis]:
            index[:, axis] = (shape[axis] - 1) - index[:, axis]
    mirror = (np.linalg.det(np.eye(3)[list(order)]) < 0) != (sum(flips) % 2 == 1)
    faces = np.ascontiguousarray(faces if mirror else faces[:, ::-1], dtype=np.int64)
    return index, faces
