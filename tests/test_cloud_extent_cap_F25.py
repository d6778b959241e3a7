"""A sparse cloud's default radius does not depend on its pose (issue 29, fuzz_api 512/16).

A default radius is capped at ``CLOUD_EXTENT_CAP`` (a quarter) of the cloud's extent, taken as the diagonal of its
bounding box along the coordinate axes, which a rotation changes: three unit spheres in a row, sparse enough for the
cap to bind, get a radius of 1.78 in the axes and 1.89 turned by 45 degrees about two axes (512/16: three noisy
spheres in five near copies, `jets`, 1.98 and 2.08; no point valid there, 755 reasons changed). Open: the extent
must be one that a rigid motion keeps (2 max |p - centroid|, for instance).

Oracle: the invariance: a rotation leaves the cloud's geometry, so its radius and its curvatures.
"""

import warnings

import numpy as np
import pytest

from meshcurv._backend import use_backend
from meshcurv.pointcloud import point_cloud_curvatures


def three_spheres():
    """60 random points on each of three unit spheres whose centres are 2.3 apart along x."""
    rng = np.random.default_rng(3)
    parts = []
    for x in (0.0, 2.3, 4.6):
        unit = rng.normal(size=(60, 3))
        parts.append(unit / np.linalg.norm(unit, axis=1, keepdims=True) + np.array([x, 0.0, 0.0]))
    return np.vstack(parts)


def turn():
    """A quarter of a half turn about z, then about x."""
    c = s = np.sqrt(0.5)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ np.array(
        [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]
    )


@pytest.mark.xfail(strict=True, reason="open (issue 29, fuzz_api 512/16): the extent cap reads the axis-aligned box")
@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_a_turned_sparse_cloud_keeps_its_default_radius(backend):
    if backend == "numba":
        pytest.importorskip("numba")
    points = three_spheres()
    with use_backend(backend), warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the sparse cloud's notes: not the point here
        axes = point_cloud_curvatures(points, method="corrected_measures")
        turned = point_cloud_curvatures(points @ turn().T, method="corrected_measures")
    assert axes.valid.any()
    np.testing.assert_allclose(turned.parameters["radius"], axes.parameters["radius"], rtol=1e-9)
    np.testing.assert_array_equal(turned.valid, axes.valid)
    largest = np.abs(axes.k_max[axes.valid]).max()
    np.testing.assert_allclose(turned.k_max[axes.valid], axes.k_max[axes.valid], rtol=0, atol=1e-6 * largest)
