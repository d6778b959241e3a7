"""Fuzz label images: ``python benchmarks/fuzz_labels.py --minutes N [--seed S] [--timeout T]``.

Random label images for :func:`meshcurv.volume.label_curvatures`, checked
against analytic geometry:

- ``ball``: a ball of radius 2.5-14 voxels (of the largest voxel size),
  placed anywhere from well inside the image to cut by one, two or three of
  its faces (on its equator, off centre, in a corner, at the far faces),
  voxels anisotropic up to 4:1 and scaled by 1e-4 to 1e4. Truths: the area of
  the sphere inside the image box (the fraction of 200,000 Fibonacci points
  of the sphere inside it) and the volume of the ball inside it (a 160^3
  midpoint grid over their common box); ``mean_weighted`` against ``1 / R``.
- ``box``: a box of voxels touching 0-3 faces of the image (a face, an edge,
  a corner, the far side). Truths: the area of its faces not on the image's
  faces, its volume ``a b c``.
- ``cylinder``: a cylinder across the image along a random axis. Truths: its
  lateral area ``2 pi R L`` and volume ``pi R^2 L``.
- ``many``: 20-150 blobs of 1-60 voxels (one-voxel labels included) with
  random label values in odd dtypes (bool, int8 ... uint64, up to the dtype's
  largest value), some touching the border. Checks: one row per label present,
  in order, the right voxel counts, ``too_small`` exactly for surfaces of
  fewer than 16 vertices, the volume within half a voxel layer of the voxel
  count's.

- ``shell`` and ``torus`` (``--shapes P``, a share of the cases from a stream of
  their own; 0 by default, the draws of earlier rounds): a hollow ball (a cavity
  of radius 5-12 voxels inside a wall of 3-8, its wall facing into it) or a solid
  torus turned at random (tube 4-8 voxels), inside the image. Truths: area,
  volume, the Euler characteristic (4, 0), ``total_gaussian`` ``2 pi chi``
  (within 0.1 of 4 pi), ``total_mean`` (``4 pi (R1 - R2)``, ``2 pi^2 R``: 15%),
  ``mean_median`` ``1 / R1`` (the outer sphere's, the larger area) and the
  torus's ``mean_weighted`` ``1 / (2 r)``: a cavity's wall read with the outer
  sphere's sign, or a handle closed, is far beyond them.

Every case also checks: finite area and volume on ``ok`` rows; the curvature
columns NaN exactly when no vertex was used (and then, for a label cut by the
border, the reason in ``warnings``); ``area <= area_mesh`` up to the
corrected area's rounding; exactly one ``no `spacing``` warning when the call
gives no spacing (a quarter of the cases), none otherwise; and, for one case
in eight, the same table from a Fortran-ordered, read-only copy of the image.

Tolerances (from the measurements in :mod:`meshcurv.volume` and
``tests/test_volume_border.py``): area 3% of the truth plus 0.5 h per unit length of
the rim where a cut surface meets the image face (marching cubes' chamfer
there, and the refit's extrapolation) plus, for boxes, 0.8 h per unit length
of their edges inside (the corrected area rounds them: 0.42-0.52 h measured)
plus two thirds of the digitisation's own volume error (``|n_voxels v - V| / V``
of the area: the voxels of a ball of 4.4 voxels hold 2.5% less than the ball,
and its area follows, 0.99 correlated over 30 centre offsets; seed 93 case 1322);
volume 2% plus ``1.5 h / R`` (the half-voxel rounding of a digitised ball)
plus ``h^2 / 8`` per unit length of rims and box edges (the chamfers).
``h`` is the largest voxel size. Areas are checked from ``R >= 4 h`` (boxes of
3 voxels a side); ``mean_weighted`` and ``mean_median``, wherever they are not
NaN, within 15% of ``1 / R`` (balls) or ``1 / (2 R)`` (cylinders) from ``R >= 5 h``
(at 17f1386 the check asked for 30 vertices used: it let wrong values of smaller
patches through). A label cut by the border whose curvature columns are NaN must
say why in its ``warnings``.

Each case runs in a forked child with a wall-clock limit (``--timeout``) and
an address-space cap; a case that reaches the limit with less than half of it as
CPU time (starved by the machine's load) runs once more with 5 times the limit. A finding is an exception other than the documented
ones, a crash, a timeout, or a broken check. One JSON line per finding in
``--log``; a summary on stdout (counts per kind and outcome).
``--replay I --seed S`` runs case ``I`` in this process and prints it.

``--relations P`` (default 0: the draws of earlier rounds): a share ``P`` of
the cases (drawn from a stream of their own) is computed again under an
invariance of the image, and every row must agree with its related row within
1e-6 of ``max(|value|, R^e)`` (``R`` the label's equivalent radius, ``e`` the
column's power of length), with the same status, counts and Euler
characteristic: ``scale`` (the spacing times 2^-8, 2^8, 1e-3, 1e3 or 0.7, given
as an array or a list: areas by s^2, volumes by s^3, curvatures by 1/s, ...),
``pad`` (1-3 zero voxels on each face: the labels off the border unchanged,
their centroids shifted), ``relabel`` (the label values renumbered at random in
their dtype), ``flip`` (mirrored along an axis) and ``transpose`` (the axes
permuted with the spacing): these two within 2% (:data:`MIRROR_RTOL`: marching
cubes draws other diagonals on the same staircase) on the balls and cylinders
of 4 voxels of equivalent radius or more, their volume and triangle area within
1e-6; on the shells and tori of ``--shapes`` the curvature columns in their
smallest radius of curvature (the cavity's, the tube's), their extremes left
out, and on shells the split into ``k_min`` and ``k_max`` (umbilic spheres:
:data:`UMBILIC_SPLIT`).
"""

from __future__ import annotations

import os

os.environ.setdefault("NUMBA_THREADING_LAYER", "workqueue")  # forked children after parallel regions (fuzz_api.py)

import argparse  # noqa: E402
import collections  # noqa: E402
import json  # noqa: E402
import pickle  # noqa: E402
import re  # noqa: E402
import resource  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
import traceback  # noqa: E402
import warnings  # noqa: E402

import numpy as np  # noqa: E402
from _forked import collect, vsize  # noqa: E402

from meshcurv.errors import (
    InvalidMeshError,
    InvalidOptionError,
    MeshcurvWarning,
    MeshFileError,  # noqa: E402
    MissingDependencyError,
)
from meshcurv.volume import MIN_VERTICES, label_curvatures  # noqa: E402

DOCUMENTED = (InvalidMeshError, InvalidOptionError, MeshFileError, MissingDependencyError)
KINDS = ("ball", "box", "cylinder", "many")
DTYPES = ("bool", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "uint64")
CURVATURE_COLUMNS = (
    "mean_weighted",
    "mean_median",
    "gaussian_weighted",
    "k_min_p5",
    "k_max_p95",
    "total_mean",
    "total_gaussian",
    "willmore",
    "shape_index_fraction_cap",
)


# ---- the cases -------------------------------------------------------------------------------------------------------


def _spacing(rng, unit: bool) -> np.ndarray:
    if unit:
        return np.ones(3)
    ratios = np.exp(rng.uniform(np.log(0.25), 0, 3)) if rng.random() < 0.6 else np.ones(3)
    scale = 10.0 ** rng.choice([0.0, 0.0, 0.0, rng.uniform(-4, 4)])
    return ratios / ratios.max() * scale  # the largest voxel size is ``scale``


def _fibonacci_sphere(n: int) -> np.ndarray:
    index = np.arange(n) + 0.5
    polar = np.arccos(1 - 2 * index / n)
    azimuth = np.pi * (1 + 5**0.5) * index
    return np.column_stack([np.cos(polar), np.sin(polar) * np.cos(azimuth), np.sin(polar) * np.sin(azimuth)])


_SPHERE = _fibonacci_sphere(200_000)


def _ball_case(rng, unit):
    spacing = _spacing(rng, unit)
    h = spacing.max()
    radius = rng.uniform(2.5, 14.0) * h
    extent = np.ceil((2 * radius + rng.uniform(2, 8) * h) / spacing).astype(int)
    center = (extent - 1) * spacing / 2 + rng.uniform(-0.3, 0.3, 3) * spacing
    for axis in range(3):  # cut by 0-3 image faces, low or high, at any depth (the equator included)
        if rng.random() < 0.6:
            depth = rng.choice([0.0, rng.uniform(-0.8, 0.8)]) * radius
            low_face = -0.5 * spacing[axis]
            if rng.random() < 0.5:
                center[axis] = low_face + depth
            else:
                center[axis] = (extent[axis] - 0.5) * spacing[axis] - depth
    axes = np.meshgrid(*[np.arange(n) * s - c for n, s, c in zip(extent, spacing, center)], indexing="ij", sparse=True)
    image = sum(a**2 for a in axes) <= radius**2
    box_low, box_high = -0.5 * spacing, (extent - 0.5) * spacing
    points = center + radius * _SPHERE
    area = 4 * np.pi * radius**2 * np.mean(((points >= box_low) & (points <= box_high)).all(axis=1))
    low, high = np.maximum(box_low, center - radius), np.minimum(box_high, center + radius)
    volume, rim = 0.0, 0.0
    if (high > low).all():
        grid = np.meshgrid(
            *[low[k] + (np.arange(160) + 0.5) * (high[k] - low[k]) / 160 - center[k] for k in range(3)],
            indexing="ij",
            sparse=True,
        )
        volume = float(np.count_nonzero(sum(g**2 for g in grid) <= radius**2)) * np.prod(high - low) / 160**3
        for axis in range(3):  # an upper bound of the rims' length: whole circles where a face cuts the ball
            for face in (box_low[axis], box_high[axis]):
                distance = abs(face - center[axis])
                if distance < radius:
                    rim += 2 * np.pi * np.sqrt(radius**2 - distance**2)
    truth = {
        "area": area,
        "volume": volume,
        "rim": rim,
        "radius": radius,
        "h": h,
        "check_area": radius >= 4 * h,
        "mean": 1 / radius,
    }
    return image.astype(np.uint8), spacing, truth


def _box_case(rng, unit):
    spacing = _spacing(rng, unit)
    sides = rng.integers(2, 14, 3)
    extent = sides + rng.integers(2, 8, 3)
    start = np.array([rng.choice([0, extent[k] - sides[k], rng.integers(1, extent[k] - sides[k])]) for k in range(3)])
    image = np.zeros(extent, dtype=np.uint8)
    image[tuple(slice(s, s + n) for s, n in zip(start, sides))] = 1
    size = sides * spacing
    on_border = np.column_stack([start == 0, start + sides == extent])  # (axis, low/high)
    area = sum(np.prod(np.delete(size, axis)) for axis in range(3) for side in range(2) if not on_border[axis, side])
    inner_edges, rims, chamfered = 0.0, 0.0, 0.0
    for a in range(3):
        for b in range(a + 1, 3):
            length = size[3 - a - b]
            for sa in range(2):
                for sb in range(2):
                    border = int(on_border[a, sa]) + int(on_border[b, sb])
                    inner_edges += length * (border == 0)
                    rims += length * (border == 1)
                    chamfered += length * spacing[a] * spacing[b] / 8
    truth = {
        "area": area,
        "volume": float(np.prod(size)),
        "rim": rims,
        "edges": inner_edges,
        "chamfer_volume": chamfered,
        "h": spacing.max(),
        "check_area": sides.min() >= 3,
        "box": True,
    }
    return image, spacing, truth


def _cylinder_case(rng, unit):
    spacing = _spacing(rng, unit)
    h = spacing.max()
    axis = int(rng.integers(3))
    radius = rng.uniform(4.0, 10.0) * h
    extent = np.ceil((2 * radius + rng.uniform(2, 6) * h) / spacing).astype(int)
    extent[axis] = int(rng.integers(8, 40))
    center = (extent - 1) * spacing / 2 + rng.uniform(-0.3, 0.3, 3) * spacing
    axes = np.meshgrid(*[np.arange(n) * s - c for n, s, c in zip(extent, spacing, center)], indexing="ij", sparse=True)
    image = np.broadcast_to(sum(a**2 for k, a in enumerate(axes) if k != axis) <= radius**2, tuple(extent))
    length = extent[axis] * spacing[axis]
    truth = {
        "area": 2 * np.pi * radius * length,
        "volume": np.pi * radius**2 * length,
        "rim": 4 * np.pi * radius,
        "radius": radius,
        "h": h,
        "check_area": True,
        "mean": 1 / (2 * radius),
    }
    return np.ascontiguousarray(image, dtype=np.uint8), spacing, truth


def _many_case(rng, unit):
    spacing = _spacing(rng, unit)
    dtype = np.dtype(str(rng.choice(DTYPES)))
    extent = rng.integers(12, 40, 3)
    n_blobs = 1 if dtype.kind == "b" else int(rng.integers(20, 150))
    image = np.zeros(extent, dtype=dtype)
    top = 1 if dtype.kind == "b" else int(np.iinfo(dtype).max)
    values = rng.choice([1, top, None], p=[0.1, 0.1, 0.8], size=n_blobs)
    for value in values:
        value = int(rng.integers(1, top, endpoint=True, dtype=np.uint64)) if value is None else int(value)
        side = rng.integers(1, 5, 3)
        start = rng.integers(0, extent - side + 1)
        image[tuple(slice(s, s + n) for s, n in zip(start, side))] = value
    return image, spacing, {"h": spacing.max(), "many": True}


def _rotation(rng) -> np.ndarray:
    """A random rotation (the QR of a Gaussian matrix, its determinant made 1)."""
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def _shell_case(rng, unit):
    """A hollow ball (a cavity of radius ``R2`` inside a ball of radius ``R1``, inside the image): two closed
    surfaces, the inner one facing into the cavity (H = -1 / R2 with the label's outward normals)."""
    spacing = _spacing(rng, unit)
    h = spacing.max()
    inner = rng.uniform(5.0, 12.0) * h
    outer = inner + rng.uniform(3.0, 8.0) * h
    extent = np.ceil((2 * outer + rng.uniform(3, 8) * h) / spacing).astype(int)
    center = (extent - 1) * spacing / 2 + rng.uniform(-0.3, 0.3, 3) * spacing
    axes = np.meshgrid(*[np.arange(n) * s - c for n, s, c in zip(extent, spacing, center)], indexing="ij", sparse=True)
    distance = sum(a**2 for a in axes)
    image = (distance <= outer**2) & (distance > inner**2)
    area = 4 * np.pi * (outer**2 + inner**2)
    volume = 4 / 3 * np.pi * (outer**3 - inner**3)
    total_mean = 4 * np.pi * (outer - inner)  # the cavity's wall counts -1 / R2 over 4 pi R2^2
    truth = {
        "area": area,
        "volume": volume,
        "volume_tolerance": 0.02 * volume + 0.5 * h * area,  # the half-voxel rounding on both walls
        "rim": 0.0,
        "radius": inner,
        "h": h,
        "check_area": True,
        "euler": 4,
        # a cavity's wall read with the outer sphere's sign (turned outward) gives 4 pi (R1 + R2): 2 R2 / (R1 + R2)
        # of the scale away; a mean weighted by area is the outer sphere's value (its share 0.5-0.85)
        "expect": {
            "total_mean": (total_mean, 0.15 * 4 * np.pi * (outer + inner)),
            "mean_median": (1 / outer, 0.15 / outer),
        },
    }
    return image.astype(np.uint8), spacing, truth


def _torus_case(rng, unit):
    """A solid torus turned at random, inside the image (genus 1: Euler characteristic 0, total K 0); its
    ``total_mean`` is ``2 pi^2 R`` and ``mean_weighted`` ``1 / (2 r)`` exactly."""
    spacing = _spacing(rng, unit)
    h = spacing.max()
    tube = rng.uniform(4.0, 8.0) * h
    ring = tube + rng.uniform(3.0, 12.0) * h
    extent = np.ceil((2 * (ring + tube) + rng.uniform(3, 8) * h) / spacing).astype(int)
    center = (extent - 1) * spacing / 2 + rng.uniform(-0.3, 0.3, 3) * spacing
    turn = _rotation(rng)
    grid = np.stack(
        np.meshgrid(*[np.arange(n) * s - c for n, s, c in zip(extent, spacing, center)], indexing="ij"), axis=-1
    )
    local = grid @ turn  # the torus's own frame: its axis along the third coordinate
    image = (np.hypot(local[..., 0], local[..., 1]) - ring) ** 2 + local[..., 2] ** 2 <= tube**2
    area = 4 * np.pi**2 * ring * tube
    volume = 2 * np.pi**2 * ring * tube**2
    truth = {
        "area": area,
        "volume": volume,
        "volume_tolerance": 0.02 * volume + 0.5 * h * area,
        "rim": 0.0,
        "radius": tube,
        "h": h,
        "check_area": True,
        "euler": 0,
        "expect": {
            "total_mean": (2 * np.pi**2 * ring, 0.15 * 2 * np.pi**2 * ring),
            "mean_weighted": (1 / (2 * tube), 0.15 / (2 * tube)),
        },
    }
    return image.astype(np.uint8), spacing, truth


CASES = {
    "ball": _ball_case,
    "box": _box_case,
    "cylinder": _cylinder_case,
    "many": _many_case,
    "shell": _shell_case,
    "torus": _torus_case,
}

#: Share of the cases that are a hollow ball (a cavity inside, its wall facing into it) or a turned solid torus
#: (``--shapes``; a stream of its own; 0 by default, so that the cases of earlier rounds replay as drawn).
SHAPES = 0.0
#: The random stream of the shapes (beside the case's own ``[seed, index]``).
SHAPE_STREAM = 67

#: Share of the cases computed again under an invariance of the image (``--relations``): 0 by default, so that the
#: cases of earlier rounds replay as drawn (the relation comes from a stream of its own).
RELATIONS = 0.0
#: The random stream of the relations (beside the case's own ``[seed, index]``).
RELATION_STREAM = 61
#: The invariances: the spacing scaled (areas by s^2, volumes by s^3, curvatures by 1/s, ...), zeros padded around
#: the image (the rows of the labels off the border unchanged), the label values renumbered, the image mirrored
#: along an axis, its axes permuted with the spacing.
RELATION_KINDS = ("scale", "scale", "pad", "relabel", "flip", "transpose")
#: Relative agreement of a row and its related row, in ``max(|value|, R^e)`` (``R`` the label's equivalent radius,
#: ``e`` the column's power of length): the last bits of a change of units, not a change of the estimate.
RELATION_RTOL = 1e-6
#: ... for a mirrored or transposed image: marching cubes triangulates the same staircase with other diagonals
#: (seed 7 case 0 with ``--relations 1``: a box's vertices the same, the fitted normals of its edges apart by
#: 0.16, the corrected area by 1.7e-5), so its counts of vertices used and its values move with them; within this
#: share (a pose that reads another surface, as the turned voxel surfaces did: 100-200% of H, is far beyond it),
#: the volume and the triangles' area within :data:`RELATION_RTOL`. The diagonals alone move a ball's tails by about
#: 1% (seed 460 case 30, a ball of 12.5 voxels flipped: k_min's 5th percentile 0.0386 and 0.0383 on the two
#: triangulations in one pose); the 20% it broke by (0.045 -> 0.054) was ``icc``'s cubes anchored at the lowest
#: corner, which a mirror moves (the same mesh and its mirror image: 0.0386 and 0.0491), not this tolerance
#: (fuzz_labels.md, round 26: the cubes laid out from the middle of the surface's box).
MIRROR_RTOL = 0.02
#: ... on the smooth solids (ball, cylinder) of an equivalent radius of this many voxels (of the largest size) at
#: least; on smaller ones, on boxes (their curvature lives on their edges, where the diagonals change: seed 452 cases
#: 129 and 207, k_max_p25 of a mirrored box 15% apart) and on the blobs of ``many`` (a label of many blobs of a few
#: voxels has a large equivalent radius; seed 444 case 21: a blob transposed, its median k_min 4.6% apart; case 45:
#: several blobs mirrored, k_max_p95 5.7%) the other diagonals are a share of the surface, and only the counts, the
#: volume and the triangles' area are compared.
MIRROR_MIN_RADIUS = 4.0
#: ... on the shapes of ``--shapes`` (a hollow ball, a turned torus) the curvature columns are measured in the
#: shape's smallest radius of curvature (``truth["radius"]``: the cavity's, the tube's), not in its equivalent radius
#: (that of its volume, two to four times larger, which made the bar of a curvature column 2% of a value far below
#: the shape's curvatures: 662/330, a torus transposed, ``k_min_max`` 9.6e-6 -> 9.9e-6 where 1 / r is 3.4 times
#: more); and their extremes (``_min``, ``_max``: one vertex's value each) are left out, as on boxes: the other
#: diagonals move single vertices of a torus by up to 12% of 1 / r (F31's probe, seed 800, 52 mirrored shapes:
#: ``shape_index_max``, ``k_min_max``, ``k_max_min`` 9-20% apart on tori of tube 6.7 voxels, ``k_min_min`` 2.6% on
#: shells; their percentiles within 1%).
MIRROR_SHAPES = ("shell", "torus")
#: ... and on a shell (two spheres: umbilic everywhere, ``k_min = k_max``) the columns of the split of the curvature
#: into ``k_min`` and ``k_max`` are left out too: ``k_max - k_min = 2 sqrt(H^2 - K)`` is ill-conditioned where it is
#: 0, and the other diagonals move it where H and K do not move (662/98, a shell of cavity 10.8 voxels flipped: the
#: cavity's ``k_min_p5`` -0.0936 -> -0.0956 and ``k_max_p5`` -0.0927 -> -0.0905, opposite ways, ``folding_index``
#: 0.019 -> 0.067, while every ``mean_``, ``gaussian_`` and ``curvedness_`` percentile agreed within 0.2%).
UMBILIC_SPLIT = ("k_min_", "k_max_", "shape_index_", "folding_index")


def _relation(seed: int, index: int, image, give_spacing: bool):
    """``(name, value)`` of case ``index``'s relation, or None (:data:`RELATIONS`)."""
    if not RELATIONS:
        return None
    rng = np.random.default_rng([seed, index, RELATION_STREAM])
    if rng.random() >= RELATIONS:
        return None
    name = RELATION_KINDS[int(rng.integers(len(RELATION_KINDS)))]
    if name == "relabel" and image.dtype == bool:
        name = "flip"
    if name == "scale":
        # (given as a NumPy array or a list, the unit spacing of a call without one as the scale itself)
        return name, (float(rng.choice([2.0**-8, 2.0**8, 1e-3, 1e3, 0.7])), ["array", "list"][int(rng.integers(2))])
    if name == "pad":
        return name, rng.integers(1, 4, size=(3, 2))
    if name == "flip":
        return name, int(rng.integers(3))
    if name == "transpose":
        return name, [(1, 0, 2), (2, 1, 0), (0, 2, 1), (1, 2, 0), (2, 0, 1)][int(rng.integers(5))]
    return name, int(rng.integers(2**31))


def make_case(seed: int, index: int):
    """``(kind, image, spacing, give_spacing, truth, twin)`` of case ``index``: a quarter without spacing (1 x 1 x 1)."""
    rng = np.random.default_rng([seed, index])
    kind = KINDS[int(rng.choice(4, p=[0.4, 0.25, 0.15, 0.2]))]
    shapes = np.random.default_rng([seed, index, SHAPE_STREAM])
    if SHAPES and shapes.random() < SHAPES:
        kind = ["shell", "torus"][int(shapes.integers(2))]
    give_spacing = bool(rng.random() >= 0.25)
    image, spacing, truth = CASES[kind](rng, unit=not give_spacing)
    twin = bool(rng.random() < 0.125)
    return kind, image, spacing, give_spacing, truth, twin


def _length_power(column: str) -> int | None:
    """The power of length of a numeric column of the table (None: not compared, a count or a text)."""
    if column in ("area", "area_mesh"):
        return 2
    if column == "volume":
        return 3
    if column in ("equivalent_radius", "radius", "total_mean") or column.startswith(("centroid_", "mean_integral")):
        return 1
    if column.startswith(("gaussian_integral", "shape_index", "ici_")) or column in (
        "total_gaussian",
        "willmore",
        "bending_energy",
        "folding_index",
    ):
        return 0
    if column.startswith(("mean_", "k_min_", "k_max_", "curvedness_")):
        return -1
    if column.startswith("gaussian_"):
        return -2
    return None


def related_image(image, spacing, relation):
    """``(image, spacing, rows)`` of the related call; ``rows(table)`` maps its table back to the original's labels."""
    name, value = relation
    spacing = np.asarray(spacing, float)
    if name == "scale":
        factor, form = value
        scaled = spacing * factor
        return image, (scaled if form == "array" else scaled.tolist()), None
    if name == "pad":
        return np.pad(image, value), spacing, None
    if name == "flip":
        return np.flip(image, axis=value), spacing, None
    if name == "transpose":
        return np.transpose(image, value), spacing[list(value)], None
    present = np.unique(image)
    present = present[present != 0]
    top = int(np.iinfo(image.dtype).max)
    rng = np.random.default_rng(value)
    new = (
        np.sort(rng.choice(np.arange(1, top + 1, dtype=np.uint64), size=len(present), replace=False))
        if top < 2**20
        else None
    )
    if new is None:  # (a wide dtype: distinct values drawn until there are enough)
        drawn = set()
        while len(drawn) < len(present):
            drawn.add(int(rng.integers(1, top, endpoint=True, dtype=np.uint64)))
        new = np.array(sorted(drawn), dtype=np.uint64)
    new = rng.permutation(new).astype(image.dtype)
    lookup = dict(zip((int(v) for v in present), (int(v) for v in new)))
    renumbered = np.zeros_like(image)
    for old, value_new in lookup.items():
        renumbered[image == old] = value_new
    return renumbered, spacing, lookup


def relation_broken(kind, table, other, image, spacing, relation, lookup, smallest=None) -> list[str]:
    """The rows of ``table`` and of the related call's ``other`` that should agree and do not. ``smallest``: the
    shape's smallest radius of curvature (:data:`MIRROR_SHAPES`), the scale of its curvature columns when mirrored."""
    name, value = relation
    label = f"relation {name}"
    spacing = np.asarray(spacing, float)
    by_label = {int(row.label): row for row in other.itertuples()}
    factor = value[0] if name == "scale" else 1.0
    broken = []
    for row in table.itertuples():
        if name == "pad" and row.touches_border:  # (padded, the label is closed there: another surface)
            continue
        twin = by_label.get(lookup[int(row.label)] if lookup else int(row.label))
        if twin is None:
            broken.append(f"{label}: label {row.label} has no row")
            continue
        mirror = name in ("flip", "transpose")
        for column in ("status", "n_voxels", "n_vertices", "n_faces", "n_used", "n_invalid", "euler_characteristic"):
            if not (mirror and column in ("n_used", "n_invalid")) and getattr(row, column) != getattr(twin, column):
                broken.append(f"{label}: label {row.label} {column} {getattr(row, column)} -> {getattr(twin, column)}")
        if name in ("pad", "flip", "transpose") and row.touches_border != twin.touches_border:
            broken.append(f"{label}: label {row.label} touches_border {row.touches_border} -> {twin.touches_border}")
        radius = row.equivalent_radius if np.isfinite(row.equivalent_radius) and row.equivalent_radius > 0 else 1.0
        exact = ("volume", "area_mesh") + (("area",) if not mirror else ())
        small = mirror and (kind in ("many", "box") or radius < MIRROR_MIN_RADIUS * float(spacing.max()))
        centroid = np.array([row.centroid_0, row.centroid_1, row.centroid_2])
        if name == "pad":
            centroid = centroid + value[:, 0] * spacing
        elif name == "flip":
            centroid[value] = (image.shape[value] - 1) * spacing[value] - centroid[value]
        elif name == "transpose":
            centroid = centroid[list(value)]
        shape = mirror and kind in MIRROR_SHAPES and smallest is not None
        for column in table.columns:
            power = _length_power(column)
            if power is None or (small and column not in exact):
                continue
            if shape and column.endswith(("_min", "_max")):  # (one vertex's value: :data:`MIRROR_SHAPES`)
                continue
            if shape and kind == "shell" and column.startswith(UMBILIC_SPLIT):  # (:data:`UMBILIC_SPLIT`)
                continue
            scale = smallest if shape and power < 0 else radius
            mine = centroid[int(column[-1])] if column.startswith("centroid_") else getattr(row, column)
            theirs = getattr(twin, column) / factor**power
            if np.isnan(mine) != np.isnan(theirs) and not (mirror and column not in exact):
                broken.append(f"{label}: label {row.label} {column} {mine:.6g} -> {theirs:.6g} (NaN in one)")
            elif np.isfinite(mine) and abs(mine - theirs) > (
                MIRROR_RTOL if mirror and column not in exact else RELATION_RTOL
            ) * max(abs(mine), scale**power):
                broken.append(f"{label}: label {row.label} {column} {mine:.9g} -> {theirs:.9g}")
    return broken


# ---- the checks ------------------------------------------------------------------------------------------------------


def check_table(kind, image, spacing, truth, table) -> list[str]:
    broken = []
    present = np.unique(image.view(np.uint8) if image.dtype == bool else image)
    present = [int(v) for v in present if v != 0]
    if [int(v) for v in table.label] != present:
        broken.append(f"labels: {len(table)} rows for {len(present)} labels present")
        return broken
    flat = image.view(np.uint8) if image.dtype == bool else image
    for row in table.itertuples():
        n_voxels = int(np.count_nonzero(flat == row.label)) if len(table) < 40 else row.n_voxels
        if row.n_voxels != n_voxels:
            broken.append(f"n_voxels: {row.n_voxels} for {n_voxels}")
        if row.status not in ("ok", "too_small"):
            broken.append(f"status {row.status}: {row.error[:100]}")
            continue
        if row.status == "too_small":
            if row.n_vertices >= MIN_VERTICES:
                broken.append(f"too_small with {row.n_vertices} vertices")
            if np.isfinite(row.area) or np.isfinite(row.mean_weighted):
                broken.append("too_small with a finite area or curvature")
            continue
        if row.n_vertices < MIN_VERTICES:
            broken.append(f"ok with {row.n_vertices} vertices")
        if not (np.isfinite(row.area) and np.isfinite(row.volume) and row.area > 0 and row.volume > 0):
            broken.append(f"area {row.area}, volume {row.volume}: not finite and positive")
            continue
        if not 0 <= row.n_used <= row.n_vertices:
            broken.append(f"n_used {row.n_used} of {row.n_vertices}")
        nan = [np.isnan(getattr(row, column)) for column in CURVATURE_COLUMNS]
        if row.n_used == 0 and not all(nan):
            broken.append(
                "curvature columns finite with no vertex used: "
                + ", ".join(c for c, n in zip(CURVATURE_COLUMNS, nan) if not n)
            )
        if row.n_used > 0 and any(nan[:2]):
            broken.append("mean_weighted or mean_median NaN with vertices used")
        if row.touches_border and row.n_used == 0 and "curvature columns NaN" not in row.warnings:
            broken.append("cut by the border, curvature columns NaN without a reason in `warnings`")
        if row.area > 1.05 * row.area_mesh:
            broken.append(f"area {row.area:.6g} above the triangles' {row.area_mesh:.6g}")
        voxel_volume = row.n_voxels * float(np.prod(spacing))
        if abs(row.volume - voxel_volume) > 0.5 * truth["h"] * row.area_mesh + 1e-9 * voxel_volume:
            broken.append(
                f"volume {row.volume:.6g} farther than half a voxel layer from the voxels' {voxel_volume:.6g}"
            )
    if truth.get("many") or len(table) != 1 or table.status[0] != "ok":
        return broken
    row = table.iloc[0]
    h = truth["h"]
    # the volume
    if truth.get("box"):
        loss = truth["volume"] - row.volume
        if not -1e-9 * truth["volume"] <= loss <= 1.2 * truth["chamfer_volume"] + 1e-9 * truth["volume"]:
            broken.append(
                f"box volume {row.volume:.6g} for {truth['volume']:.6g} (chamfers {truth['chamfer_volume']:.3g})"
            )
    else:
        tolerance = truth.get(
            "volume_tolerance", (0.02 + 1.5 * h / truth["radius"]) * truth["volume"] + h * h / 8 * truth["rim"]
        )
        if abs(row.volume - truth["volume"]) > tolerance:
            broken.append(f"{kind} volume {row.volume:.6g} for {truth['volume']:.6g} (tolerance {tolerance:.3g})")
    # the area of the surface inside the image
    if truth["check_area"] and truth["area"] > 0:
        voxels = row.n_voxels * float(np.prod(spacing))
        digitised = abs(voxels - truth["volume"]) / truth["volume"] if truth["volume"] > 0 else 0.0
        tolerance = (
            (0.03 + 2 / 3 * digitised) * truth["area"] + 0.5 * h * truth["rim"] + 0.8 * h * truth.get("edges", 0.0)
        )
        if abs(row.area - truth["area"]) > tolerance:
            broken.append(
                f"{kind} area {row.area:.6g} for {truth['area']:.6g} (tolerance {tolerance:.3g}; "
                f"touches_border {row.touches_border})"
            )
    # the topology, Gauss-Bonnet and the columns whose exact value is known (shell, torus: inside the image)
    if "euler" in truth:
        if row.euler_characteristic != truth["euler"]:
            broken.append(f"{kind} euler_characteristic {row.euler_characteristic} for {truth['euler']}")
        elif np.isfinite(row.total_gaussian) and abs(row.total_gaussian - 2 * np.pi * truth["euler"]) > 0.1 * 4 * np.pi:
            broken.append(f"{kind} total_gaussian {row.total_gaussian:.6g} for {2 * np.pi * truth['euler']:.6g}")
    for column, (value, tolerance) in truth.get("expect", {}).items():
        mine = getattr(row, column)
        if np.isfinite(mine) and abs(mine - value) > tolerance:
            broken.append(
                f"{kind} {column} {mine:.6g} for {value:.6g} (tolerance {tolerance:.3g}; {row.n_used} vertices used "
                f"of {row.n_vertices})"
            )
    # H wherever it is given (not NaN), on the curved solids
    if "mean" in truth and truth["radius"] >= 5 * h:
        for column in ("mean_weighted", "mean_median"):
            value = getattr(row, column)
            if np.isfinite(value) and abs(value / truth["mean"] - 1) > 0.15:
                broken.append(
                    f"{kind} {column} {value:.6g} for {truth['mean']:.6g} "
                    f"({row.n_used} vertices used of {row.n_vertices})"
                )
    return broken


def run_case(seed, index) -> dict:
    kind, image, spacing, give_spacing, truth, twin = make_case(seed, index)
    options = {"spacing": tuple(spacing)} if give_spacing else {}
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            table = label_curvatures(image, **options)
    except DOCUMENTED as exc:
        return {"kind": kind, "status": "documented", "type": type(exc).__name__, "message": str(exc)[:200]}
    except Exception as exc:  # noqa: BLE001
        frame = traceback.extract_tb(exc.__traceback__)[-1]
        return {
            "kind": kind,
            "status": "exception",
            "type": type(exc).__name__,
            "message": str(exc)[:300],
            "where": f"{os.path.basename(frame.filename)}:{frame.lineno}",
        }
    broken = check_table(kind, image, spacing, truth, table)
    spacing_warnings = [
        w for w in caught if issubclass(w.category, MeshcurvWarning) and "no `spacing`" in str(w.message)
    ]
    if len(spacing_warnings) != (0 if give_spacing else 1):
        broken.append(
            f"{len(spacing_warnings)} spacing warnings with spacing {'given' if give_spacing else 'not given'}"
        )
    if twin:
        other = np.asfortranarray(image)
        other.flags.writeable = False
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            again = label_curvatures(other, spacing=tuple(spacing))
        numbers = [c for c in table.columns if table[c].dtype.kind == "f"]
        if not np.allclose(table[numbers].to_numpy(), again[numbers].to_numpy(), rtol=1e-9, atol=0, equal_nan=True):
            broken.append("a Fortran-ordered read-only copy gives another table")
    relation = _relation(seed, index, image, give_spacing)
    if relation is not None:
        other_image, other_spacing, lookup = related_image(image, spacing, relation)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                other = label_curvatures(other_image, spacing=other_spacing)
        except DOCUMENTED as exc:
            broken.append(
                f"relation {relation[0]}: {type(exc).__name__} where the original succeeded: {str(exc)[:150]}"
            )
        else:
            broken += relation_broken(kind, table, other, image, spacing, relation, lookup, truth.get("radius"))
    return {
        "kind": kind,
        "relation": relation[0] if relation is not None else None,
        "status": "invariant" if broken else "ok",
        "broken": broken,
        "labels": len(table),
        "touches_border": bool(table.touches_border.any()) if len(table) else False,
    }


# ---- the runner ------------------------------------------------------------------------------------------------------


#: A case that reaches ``--timeout`` having had less than half of it as CPU time was starved by
#: the machine's other work (4 s of CPU in 60 s at load 12: seed 102 case 129), not busy: it is
#: run once more with this many times the wall-clock limit, and a finding only if that too runs out.
STARVED_WALL = 5


def _children_cpu() -> float:
    """CPU seconds of the reaped children so far (user and system)."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def run_forked(seed, index, timeout, memory_mib) -> tuple[dict, float, float]:
    """Case ``index`` in a forked child: ``(outcome, elapsed, cpu)``, ``cpu`` the child's CPU seconds."""
    base = vsize()
    cpu_before = _children_cpu()
    read_end, write_end = os.pipe()
    pid = os.fork()
    if pid == 0:  # child
        os.close(read_end)
        code = 0
        try:
            resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
            limit = base + memory_mib * 2**20
            resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
            try:
                outcome = run_case(seed, index)
            except MemoryError:
                outcome = {"kind": "?", "status": "memory", "message": "MemoryError"}
            with os.fdopen(write_end, "wb") as fh:
                fh.write(pickle.dumps(outcome))
        except BaseException:  # noqa: BLE001
            code = 3
        os._exit(code)
    os.close(write_end)
    data, status, timed_out, elapsed = collect(pid, read_end, timeout)
    cpu = _children_cpu() - cpu_before
    if timed_out:
        message = f"no answer within {timeout:g} s ({cpu:.1f} s of CPU)"
        return {"kind": "?", "status": "timeout", "message": message}, elapsed, cpu
    if os.WIFSIGNALED(status):
        return {"kind": "?", "status": "crash", "message": f"killed by signal {os.WTERMSIG(status)}"}, elapsed, cpu
    try:
        return pickle.loads(data), elapsed, cpu
    except Exception:  # noqa: BLE001
        return (
            {
                "kind": "?",
                "status": "crash",
                "message": f"child exit {os.WEXITSTATUS(status)} without an answer",
            },
            elapsed,
            cpu,
        )


def _key(outcome) -> str:
    if outcome["status"] == "invariant":
        first = re.sub(r"[-+]?\d[\d.e+-]*", "#", outcome["broken"][0])
        return f"{outcome['kind']} | {first.split(' for ')[0].split(' (')[0]}"
    if outcome["status"] == "exception":
        return f"{outcome['kind']} | {outcome['type']} at {outcome['where']}"
    return f"{outcome['kind']} | {outcome['status']}"


def main(argv=None) -> int:
    global RELATIONS, SHAPES
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=5.0)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--timeout", type=float, default=120.0, help="seconds per case")
    parser.add_argument("--memory", type=int, default=1536, help="MiB above the parent's address space")
    parser.add_argument("--start", type=int, default=0, help="first case index")
    parser.add_argument("--log", default=os.path.join(tempfile.gettempdir(), "fuzz_labels.jsonl"))
    parser.add_argument("--replay", type=int, default=None, help="run case I in this process and show it")
    parser.add_argument(
        "--relations",
        type=float,
        default=RELATIONS,
        help="share of the cases computed again under an invariance of the image: the spacing scaled (given as an "
        "array or a list), zeros padded around it, the labels renumbered, mirrored along an axis, its axes permuted "
        "(default: 0: the draws of earlier rounds)",
    )
    parser.add_argument(
        "--shapes",
        type=float,
        default=SHAPES,
        help="share of the cases that are a hollow ball (a cavity inside, its wall facing into it) or a turned solid "
        "torus, inside the image, checked against their area, volume, Euler characteristic, total Gaussian and "
        "mean curvature (default: 0: the draws of earlier rounds)",
    )
    options = parser.parse_args(argv)
    RELATIONS = options.relations
    SHAPES = options.shapes

    if options.replay is not None:
        kind, image, spacing, give_spacing, truth, twin = make_case(options.seed, options.replay)
        print(
            f"case {options.replay} seed {options.seed}: {kind}, image {image.shape} {image.dtype}, spacing "
            f"{tuple(spacing.tolist())} ({'given' if give_spacing else 'not given'}), truth {truth}"
        )
        relation = _relation(options.seed, options.replay, image, give_spacing)
        if relation is not None:
            print(f"relation: {relation[0]} {relation[1]}")
        for key, value in run_case(options.seed, options.replay).items():
            print(f"{key}: {value}")
        return 0

    with warnings.catch_warnings():  # compile the kernels once, before the children fork
        warnings.simplefilter("ignore")
        warm = np.zeros((12, 12, 12), dtype=np.uint8)
        warm[:6, 3:9, 3:9] = 1
        label_curvatures(warm, spacing=(1.0, 1.0, 1.0))
    deadline = time.monotonic() + options.minutes * 60
    counts: collections.Counter = collections.Counter()
    first_seen: dict = {}
    slowest = []
    index = options.start
    with open(options.log, "a") as log:
        log.write(
            json.dumps({"run": time.strftime("%Y-%m-%d %H:%M:%S"), "seed": options.seed, "minutes": options.minutes})
            + "\n"
        )
        while time.monotonic() < deadline:
            outcome, elapsed, cpu = run_forked(options.seed, index, options.timeout, options.memory)
            if outcome["status"] == "timeout" and cpu < options.timeout / 2:
                # starved by the machine's load rather than busy: once more with STARVED_WALL x the time
                counts[("?", "timeout under load, rerun")] += 1
                outcome, elapsed, cpu = run_forked(options.seed, index, STARVED_WALL * options.timeout, options.memory)
            counts[(outcome["kind"], outcome["status"])] += 1
            if outcome.get("relation"):
                counts[(outcome["kind"], f"relation {outcome['relation']}: {outcome['status']}")] += 1
            if outcome["status"] == "ok" and outcome.get("touches_border"):
                counts[(outcome["kind"], "ok, cut by the border")] += 1
            slowest.append((elapsed, index))
            if outcome["status"] not in ("ok", "documented"):
                key = _key(outcome)
                log.write(
                    json.dumps(
                        {"index": index, "seed": options.seed, "key": key, "elapsed": round(elapsed, 2), **outcome},
                        default=str,
                    )
                    + "\n"
                )
                log.flush()
                if key not in first_seen:
                    first_seen[key] = index
                    detail = "; ".join(outcome.get("broken", [])) or outcome.get("message", "")
                    print(f"[{index}] NEW {key}: {detail[:200]}", flush=True)
                counts[("finding", key)] += 1
            index += 1
            if index % 200 == 0:
                print(f"... {index - options.start} cases, {len(first_seen)} distinct findings", flush=True)
    print(f"\n{index - options.start} cases in {options.minutes:g} min (seed {options.seed})")
    for (kind, status), n in sorted(counts.items()):
        if kind != "finding":
            print(f"  {kind:10s} {status:24s} {n}")
    print(f"\n{len(first_seen)} distinct findings:")
    for key, first in first_seen.items():
        print(f"  {counts[('finding', key)]:5d}x  first case {first}: {key}")
    slowest.sort(reverse=True)
    print("slowest cases:", ", ".join(f"{i} ({t:.1f}s)" for t, i in slowest[:5]))
    return 1 if first_seen else 0


if __name__ == "__main__":
    sys.exit(main())
