"""Point-cloud jets by the rim of a thin plate (issue 29, class 3; fuzz round 20, seed 350 case 15).

A flat ellipsoid (1, 1, c) under noise along its normal, curvatures at a given radius: the ball of a point
near the rim holds the plate's other face, the fit shrinks off it, and the smaller ball still holds the rim's
turn, where the curvature grows several times within the ball. Such a fit gave H 1.8 times the exact one,
valid. Expected values: the ellipsoid's exact curvature, from its equation.
"""

import numpy as np
import pytest
from scipy.spatial import cKDTree

from meshcurv.pointcloud import point_cloud_curvatures

#: A valid H within this share of the largest |k|: below the fuzzer's bound (``benchmarks/fuzz_api.py``, "cloud
#: truth": half of it), which the band by the rim reached (0.536 in the fuzz case; 0.47-0.50 on these samples, at
#: a few points), and above the error of the estimates kept by the rim (up to 0.3; the faces' median is 0.02-0.05).
TOLERANCE = 0.4


def _plate(thickness, n_points, noise, seed):
    """Points of the ellipsoid (1, 1, ``thickness``) spread by area (rejection on the area element), moved along
    the exact normal by uniform noise of ``noise`` spacings; their exact outward normals, H and largest |k| (at
    least 1, the part's size), and the spacing."""
    rng = np.random.default_rng(seed)
    axes = np.array([1.0, 1.0, thickness])
    unit = rng.normal(size=(6 * n_points, 3))
    unit /= np.linalg.norm(unit, axis=1, keepdims=True)
    weight = np.linalg.norm(unit / axes, axis=1)  # the area element of the map from the unit sphere, up to a factor
    points = (unit[rng.random(unit.shape[0]) < weight / weight.max()][:n_points]) * axes
    # the shape operator of F = sum x_i^2 / a_i^2 - 1: P diag(2 / a^2) P / |grad F| on the tangent plane
    gradient = 2 * points / axes**2
    length = np.linalg.norm(gradient, axis=1)
    normals = gradient / length[:, None]
    projector = np.eye(3)[None] - normals[:, :, None] * normals[:, None, :]
    shape = projector @ np.diag(2 / axes**2)[None] @ projector / length[:, None, None]
    mean = 0.5 * np.trace(shape, axis1=1, axis2=2)
    largest = np.maximum(np.abs(np.linalg.eigvalsh(shape)).max(axis=1), 1.0)
    # the spacing as the library measures it: the 8th neighbour's distance times sqrt(pi / 8), median
    spacing = float(np.median(cKDTree(points).query(points, k=9)[0][:, 8]) * np.sqrt(np.pi / 8))
    points = points + rng.uniform(-noise * spacing, noise * spacing, size=(n_points, 1)) * normals
    return points, normals, mean, largest, spacing


@pytest.mark.filterwarnings("ignore")
@pytest.mark.parametrize(("seed", "radius"), [(5, 0.2332), (6, 0.2332), (7, 0.2332)])
def test_jets_by_a_thin_rim_are_right_or_invalid(seed, radius):
    points, normals, mean, largest, spacing = _plate(0.2, 4000, 0.1, seed)
    result = point_cloud_curvatures(points, method="jets", radius=radius)
    side = np.sign(np.einsum("ij,ij->i", result.normals, normals))
    error = np.abs(result.mean - side * mean) / largest
    # the points whose radius of curvature is below 4 spacings (the rim itself) are resolved by no estimator
    resolved = largest * spacing <= 0.25
    checked = result.valid & resolved
    assert checked.sum() > 0.25 * resolved.sum()  # the faces stay measured
    assert np.all(error[checked] <= TOLERANCE), np.sort(error[checked])[-5:]
