"""Voxel surfaces read as clouds: their valid points and values do not depend on the pose (issue 29, fuzz_api 491/8).

The vertices of a marching-cubes surface lie on a lattice, where many decisions meet exact ties: neighbours at one
distance at the cut of a k-nearest query, planes of heights evenly spaced. A rigid motion turns those ties into
round-off, which then chose: a voxel ellipsoid's cloud turned and moved 10 sizes away had no valid point (its
turned grid was read with steps of round-off), a voxel torus 44 of 3,388 points valid in one pose only and H 20%
apart on points valid in both (the two-sheets reading at 24 of a turned sphere's points). The oracle is the
invariance: a rigid motion, a shift and a scaling by a power of two (exact in floating point) leave the cloud's
geometry, so its valid points and its curvatures to round-off, and a clean voxel sphere's points are nearly all
valid.
"""

import warnings

import numpy as np
import pytest

from meshcurv import point_cloud_curvatures, shapes

pytest.importorskip("skimage")

SURFACES = {
    "sphere": lambda: shapes.voxel_sphere(16.0, seed=5),
    "ellipsoid": lambda: shapes.voxel_ellipsoid((14.0, 10.0, 7.0), seed=2),
    "torus": lambda: shapes.voxel_torus(12.0, 5.0, seed=1),
    "anisotropic sphere": lambda: shapes.voxel_sphere(12.0, spacing=(1.5, 1.0, 1.0), seed=4),
}


def _rotation(rng: np.random.Generator) -> np.ndarray:
    """A proper rotation drawn uniformly (QR of a Gaussian matrix)."""
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else q[:, [1, 0, 2]]


def _curvatures(points):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the staircase's notes: not the point here
        return point_cloud_curvatures(points)


#: Open: the voxel torus turned measures another noise level (0.064324 against 0.064387 in the image's axes): the
#: degree-2 jets of ``radius._cloud_noise_level`` fit at two of its points in the axes and at neither turned (the same
#: sample, normals, usable points and facing rows: a decision of the jets' kernel), so another default radius.
OPEN_NOISE = pytest.mark.xfail(strict=True, reason="open: the noise level's jets differ turned at 2 points (torus)")


@pytest.mark.parametrize("name", [pytest.param(n, marks=OPEN_NOISE) if n == "torus" else n for n in SURFACES])
@pytest.mark.parametrize("seed", [0, 1])
def test_voxel_cloud_moved_keeps_its_valid_points_and_values(name, seed):
    points = np.asarray(SURFACES[name]().vertices, float)
    rng = np.random.default_rng(seed)
    scale = 2.0 ** rng.integers(-12, 12)  # (exact: the cloud's own ties stay ties)
    size = float(np.ptp(points)) * scale
    moved = (points * scale) @ _rotation(rng).T + rng.uniform(-10.0, 10.0, size=3) * size
    axes, turned = _curvatures(points), _curvatures(moved)
    np.testing.assert_array_equal(turned.valid, axes.valid)
    both = axes.valid
    assert both.mean() > 0.5
    # curvature scales as 1 / length; round-off of coordinates 10 sizes away: a few 1e-14 of the largest |k|
    largest = np.abs(np.r_[axes.k_min[both], axes.k_max[both]]).max()
    np.testing.assert_allclose(turned.k_min[both] * scale, axes.k_min[both], rtol=0, atol=1e-9 * largest)
    np.testing.assert_allclose(turned.k_max[both] * scale, axes.k_max[both], rtol=0, atol=1e-9 * largest)


@pytest.mark.parametrize("name", ["sphere", "ellipsoid"])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_voxel_cloud_valid_in_any_pose(name, seed):
    # any scale (not only powers of two: ties of the axes' pose become round-off) and any rigid motion: the valid
    # points of the image's axes stay valid (the ellipsoid scaled by 1.18, turned and shifted had none on 27c2539),
    # nearly all of a clean voxel sphere's, and H at 1 / R on it
    points = np.asarray(SURFACES[name]().vertices, float)
    rng = np.random.default_rng(seed)
    scale = 10.0 ** rng.uniform(-3.0, 3.0)
    moved = (points * scale) @ _rotation(rng).T + rng.uniform(-10.0, 10.0, size=3) * float(np.ptp(points)) * scale
    axes, turned = _curvatures(points), _curvatures(moved)
    assert turned.valid.sum() >= 0.98 * axes.valid.sum()
    assert (axes.valid & turned.valid).sum() >= 0.98 * axes.valid.sum()
    if name == "sphere":
        assert turned.valid.mean() > 0.9
        h = 0.5 * (turned.k_min + turned.k_max)[turned.valid]
        assert abs(np.median(h) * 16.0 * scale - 1.0) < 0.05
