"""Recognising meshes of voxel images: the grid their vertices lie on.

A mesh extracted from a 3D image by marching cubes (scikit-image's
``measure.marching_cubes``, VTK's ``vtkMarchingCubes`` / flying edges,
ITK, ...) has every vertex on an edge of the voxel grid: two of its three
coordinates are grid coordinates ``origin + i * spacing``, the third is
interpolated. A blocky (cuberille) surface built from voxel faces has all three
on the grid. Such surfaces carry a staircase of the grid's size that a
curvature estimator must average out over a few voxels; :func:`voxel_grid`
finds the grid so that the default radius can take it into account.

The test is exact, not statistical: grid coordinates come from the same
``i * spacing`` (plus the same offset) for every vertex on a grid plane, so they
repeat bit for bit, while interpolated coordinates are almost all distinct.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

__all__ = ["VoxelGrid", "voxel_grid", "GRID_FRACTION"]

#: Share of the vertices that must have at least two coordinates on the grid.
GRID_FRACTION = 0.95

#: A coordinate value counts as a grid plane when this many vertices share it.
_PLANE_MULTIPLICITY = 3

#: The grid planes of an axis: its most populated repeated values, taken until they hold this share of
#: the repeated values (a plane of the grid holds dozens to thousands of vertices, a repeated interpolated
#: coordinate a few).
_GRID_SHARE = 0.5

#: Share of those planes that must lie on one lattice (a few busy interpolated values may not).
_PLANES_ON_GRID = 0.8

#: The origin of the lattice is sought among this many of the busiest planes.
_ORIGIN_CANDIDATES = 64

#: Grid coordinates within this fraction of the spacing of a plane of the lattice lie on it.
_ON_GRID = 1e-6


class VoxelGrid(NamedTuple):
    """The grid found by :func:`voxel_grid`.

    Attributes
    ----------
    spacing : ndarray of shape (3,)
        Distance between grid planes along x, y and z (the vertices' own axes).
    origin : ndarray of shape (3,)
        One grid coordinate per axis.
    fraction : float
        Share of the vertices with at least two coordinates on the grid.
    """

    spacing: np.ndarray
    origin: np.ndarray
    fraction: float


def _plane_lattice(planes: np.ndarray, candidates: np.ndarray, share: float):
    """``(spacing, origin)`` of the lattice that holds ``share`` of the sorted ``planes``, or None.

    The spacing is the smallest gap common among the planes (wider gaps are
    multiples of it), or, where small gaps are rare (a few busy interpolated
    values among the grid planes), the median gap. The origin is the one of
    ``candidates`` whose lattice holds the most planes.
    """
    if planes.size < 3:
        return None
    gaps = np.diff(planes)
    gaps = gaps[gaps > 0]
    if gaps.size == 0:
        return None
    smallest = float(np.min(gaps))
    near = gaps[gaps < 1.5 * smallest]
    spacing = float(np.median(near if near.size >= 0.5 * gaps.size else gaps))
    # one candidate at a time: no (candidates, planes) temporaries (64 rows of a large mesh's planes each)
    held = np.zeros(candidates.size)
    with np.errstate(over="ignore", invalid="ignore"):  # a subnormal spacing (coordinates of 1e-310): no grid
        for j, candidate in enumerate(candidates):
            steps = (planes - candidate) / spacing
            held[j] = np.count_nonzero(np.abs(steps - np.round(steps)) <= 1e3 * _ON_GRID) / planes.size
    if held.max() < share:
        return None  # the repeated values are not evenly spaced: not a grid (a symmetric height field, say)
    return spacing, float(candidates[np.argmax(held)])


def _axis_lattice(values: np.ndarray):
    """``(spacing, origin, on_grid)`` of one coordinate axis, or None when its repeated values form no lattice.

    The lattice of every repeated value (a binary mask's isosurface: the grid
    planes and the middles between them), or else that of the busiest ones:
    the interpolated coordinates of a smoothed mask's isosurface repeat too, a
    few times each (a symmetric solid, float32 coordinates), where a plane of
    the grid holds every vertex on the grid edges that lie in it.
    """
    planes, counts = np.unique(values, return_counts=True)
    repeated = counts >= _PLANE_MULTIPLICITY
    planes, counts = planes[repeated], counts[repeated]
    found = _plane_lattice(planes, planes[:1], 1.0)
    if found is None and planes.size:
        busiest = np.argsort(counts, kind="stable")[::-1]
        enough = int(np.searchsorted(np.cumsum(counts[busiest]), _GRID_SHARE * counts.sum())) + 1
        found = _plane_lattice(np.sort(planes[busiest[:enough]]), planes[busiest[:_ORIGIN_CANDIDATES]], _PLANES_ON_GRID)
    if found is None:
        return None
    spacing, origin = found
    with np.errstate(over="ignore", invalid="ignore"):
        steps = (values - origin) / spacing
    if not np.isfinite(steps).all() or np.abs(steps).max() > 2.0**52:
        return None  # a coordinate billions of voxels away (a spike): not a voxel image
    whole = np.round(steps)
    on_grid = np.abs(steps - whole) <= _ON_GRID * max(1.0, np.abs(steps).max() * 1e-9)
    return spacing, origin, on_grid, whole.astype(np.int64) % 2


def voxel_grid(vertices: np.ndarray) -> VoxelGrid | None:
    """The voxel grid a mesh's vertices lie on, or None.

    Parameters
    ----------
    vertices : ndarray of shape (V, 3)
        Vertex coordinates (of the referenced vertices).

    Returns
    -------
    VoxelGrid or None
        The spacing and origin of the grid when at least :data:`GRID_FRACTION`
        of the vertices have two or more coordinates on it along every axis
        (marching cubes: exactly two; voxel faces: three); None otherwise.

    Examples
    --------
    >>> import numpy as np
    >>> from meshcurv.lattice import voxel_grid
    >>> voxel_grid(np.random.default_rng(0).normal(size=(500, 3))) is None
    True
    """
    if vertices.shape[0] < 16:
        return None
    found = []
    for k in range(3):  # an axis without a lattice settles it: the others are not sorted (most meshes)
        axis = _axis_lattice(vertices[:, k])
        if axis is None:
            return None
        found.append(axis)
    on_grid = np.column_stack([axis[2] for axis in found])
    fraction = float((on_grid.sum(axis=1) >= 2).mean())
    if fraction < GRID_FRACTION:
        return None
    spacing = np.array([axis[0] for axis in found])
    origin = np.array([axis[1] for axis in found])
    # a binary mask cut at 0.5 puts the interpolated coordinate at the middle of its grid edge: every
    # coordinate is then on the half grid, and the voxel grid is every other plane of it along each axis,
    # the choice of planes (one of eight) that puts two coordinates of every vertex on the grid
    parity = np.column_stack([axis[3] for axis in found])
    for pattern in np.ndindex(2, 2, 2):
        on_voxel_grid = on_grid & (parity == np.array(pattern))
        voxel_fraction = float((on_voxel_grid.sum(axis=1) >= 2).mean())
        if voxel_fraction >= GRID_FRACTION:
            return VoxelGrid(2 * spacing, origin + np.array(pattern) * spacing, voxel_fraction)
    return VoxelGrid(spacing, origin, fraction)
