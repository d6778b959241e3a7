"""Voxel clouds read on their grid in every pose: its axes, not the diagonals between them (issue 29).

``benchmarks/fuzz_api.py --point-clouds --cloud-relations 0.5 --real-meshes 0.5 --radius-forms 0.3
--cloud-shapes 0.3 --seed 811 --replay 48``: the vertices of a voxel ellipsoid read as a cloud, 2,577 points valid
along the axes and none after a rigid motion. Marching cubes over unit voxels puts every vertex on the grid of half
voxels, whose planes at right angles to each axis lie 0.5 apart; the planes at right angles to the bisector of two
axes hold every vertex too, 0.5 / sqrt(2) apart. The turned grid was read in a frame of two such bisectors (steps
0.35, 0.5, 0.35), whose steps then said that the staircase's stacked treads were sheets turned inside out, and the
undecided side spread over the whole part.

The same on a voxel sphere under noise of 0.03 voxels, turned. The oracles: the grid of unit voxels (0.5 along each of the rotation's axes) and the invariance of the valid set and
its reasons under a rigid motion.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from meshcurv import point_cloud_curvatures, shapes
from meshcurv._backend import use_backend
from meshcurv.lattice import read_lattice

pytest.importorskip("skimage")

BACKENDS = ["numba", "numpy"]


def _rotation(seed: int) -> np.ndarray:
    """A proper rotation drawn uniformly (QR of a Gaussian matrix) from the stream ``seed``."""
    q, r = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else q[:, [1, 0, 2]]


def _sphere() -> np.ndarray:
    """A voxel sphere's vertices under Gaussian noise of 0.03 voxels (a clean one is read along its axes in the
    poses tried here; noise moves the facet normals the frame is sought from)."""
    points = np.asarray(shapes.voxel_sphere(10.5, spacing=(1, 1, 1), seed=1).vertices, float)
    return points + np.random.default_rng(1).normal(scale=0.03, size=points.shape)


def _lattice(points: np.ndarray):
    from scipy.spatial import cKDTree

    from meshcurv import pointcloud
    from meshcurv._pointcloud_normals import local_spacing

    distances, indices = pointcloud._knn(cKDTree(points), points)
    return read_lattice(points, float(np.median(local_spacing(distances))), neighbours=indices)


@pytest.mark.parametrize("seed", [11, 13])
def test_turned_voxel_grid_read_on_its_axes(seed):
    turn = _rotation(seed)
    lattice = _lattice(_sphere() @ turn.T)
    # half voxels along each axis of the turned grid (the bisectors' planes are 0.5 / sqrt(2) apart)
    np.testing.assert_allclose(lattice.steps, 0.5, rtol=1e-3)
    # the frame's rows are the turned axes, up to order and sign
    np.testing.assert_allclose(np.sort(np.abs(lattice.frame @ turn), axis=1), [[0, 0, 1]] * 3, atol=1e-3)


@pytest.mark.slow
@pytest.mark.parametrize("backend", BACKENDS)
def test_turned_voxel_cloud_same_validity(backend):
    points = _sphere()
    with use_backend(backend), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        axis = point_cloud_curvatures(points)
        turned = point_cloud_curvatures(points @ _rotation(11).T + 3.0)
    assert axis.valid.sum() > 0.3 * points.shape[0]
    np.testing.assert_array_equal(axis.valid, turned.valid)
    np.testing.assert_array_equal(axis.invalid_reason, turned.invalid_reason)
    largest = max(np.abs(axis.k_min[axis.valid]).max(), np.abs(axis.k_max[axis.valid]).max())
    for name in ("k_min", "k_max", "mean", "gaussian"):
        first, second = getattr(axis, name)[axis.valid], getattr(turned, name)[axis.valid]
        scale = largest**2 if name == "gaussian" else largest
        np.testing.assert_allclose(second, first, rtol=0, atol=1e-6 * scale)
