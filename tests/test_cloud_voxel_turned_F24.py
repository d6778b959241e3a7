"""A voxel sphere's vertices read as a cloud keep their valid points when turned (issue 29, fuzz_api 491/8).

The vertices of a marching-cubes sphere (radius 28 voxels, scaled by 1000) lie on a lattice. Turned and shifted
10 sizes away by the fuzzer's motion, every point's side was undecided ("between two sheets closer than the
spacing" and "facing the same way as a sheet stacked on theirs"): 14,205 valid points in the image's axes, 0 turned
(the same on 8a9367a). The turned grid's axes, refined by least squares over coordinates of 5e5 with a column of
ones (condition about 1e9), were off by 2e-10 rad: each plane spread over 1e-5 and was read as planes 6e-7 apart,
a "lattice" of steps far below the spacing, so that no stacked neighbour was put down to the staircase's steps.
The oracle is the invariance: a rigid motion leaves the cloud's geometry, so its valid points and its H.
"""

import warnings

import numpy as np
import pytest

from meshcurv import point_cloud_curvatures, shapes

SEED = 308923312  # the fuzzer's motion


def _rotation(seed: int) -> np.ndarray:
    """A proper rotation of the stream ``seed`` (QR of a Gaussian matrix, as benchmarks/fuzz_api.py draws it)."""
    q, r = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else q[:, [1, 0, 2]]


def test_turned_voxel_sphere_cloud_keeps_its_valid_points():
    pytest.importorskip("skimage")
    mesh = shapes.voxel_sphere(28.0, seed=47)
    points = np.asarray(mesh.vertices, float) * 1000.0
    size = float(np.ptp(points))
    moved = points @ _rotation(SEED).T + np.random.default_rng(SEED).uniform(-10.0, 10.0, size=3) * size
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the staircase's notes: not the point here
        axes, turned = point_cloud_curvatures(points), point_cloud_curvatures(moved)
    assert axes.valid.mean() > 0.9
    assert turned.valid.sum() >= 0.98 * axes.valid.sum()
    both = axes.valid & turned.valid
    h = 0.5 * (turned.k_min + turned.k_max)[both]
    # outward on the sphere of radius 28,000: H = 1 / R at the median
    assert abs(np.median(h) * 28000.0 - 1.0) < 0.05
