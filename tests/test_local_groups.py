"""A group of points with its own radius (issue 31): computed on the points within its reach only.

Oracle: the same call computed over the whole cloud (``LOCAL_SHARE`` below 0 turns the local path off). The
local path finds the same balls (every point within reach of the group is in its box grown by the reach), so
the results agree to the rounding of sums taken in another order (1e-12 relative).
"""

import warnings

import numpy as np
import pytest

from meshcurv import pointcloud
from meshcurv._backend import use_backend
from meshcurv.errors import MeshQualityWarning
from meshcurv.pointcloud import POINT_CLOUD_METHODS, point_cloud_curvatures


def plane_and_line():
    """A random sample of a gently waved unit square and a line of 80 points 2 spacings above it (scan-line
    points: groups of their own radius, a few per cent of the cloud)."""
    rng = np.random.default_rng(5)
    g = rng.random((2500, 2))
    plane = np.column_stack([g, 0.01 * np.sin(6 * g[:, 0])])
    line = np.column_stack([np.linspace(0.2, 0.8, 80), np.full(80, 0.5), np.full(80, 0.04)])
    return np.vstack([plane, line])


def curvatures(points, method):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshQualityWarning)
        return point_cloud_curvatures(points, method=method)


@pytest.mark.parametrize("backend", ["numpy", "numba"])
@pytest.mark.parametrize("method", POINT_CLOUD_METHODS)
def test_a_small_group_is_computed_on_its_neighbourhood_alone(method, backend, monkeypatch):
    if backend == "numba":
        pytest.importorskip("numba")
    points = plane_and_line()
    used = []

    def spy(*args):
        near = within_reach(*args)
        used.append(near is not None and near.size < points.shape[0])
        return near

    within_reach = pointcloud._within_reach
    with use_backend(backend):
        monkeypatch.setattr(pointcloud, "_within_reach", spy)
        local = curvatures(points, method)
        monkeypatch.setattr(pointcloud, "LOCAL_SHARE", -1.0)
        whole = curvatures(points, method)
    assert len(local.parameters["radii"]) > 1 and any(used)
    np.testing.assert_array_equal(local.valid, whole.valid)
    np.testing.assert_array_equal(local.invalid_reason, whole.invalid_reason)
    for field in ("k_min", "k_max", "normals"):
        np.testing.assert_allclose(getattr(local, field), getattr(whole, field), rtol=1e-12, atol=1e-12)
    for field in ("dir_min", "dir_max"):  # directions up to sign
        np.testing.assert_allclose(np.abs(getattr(local, field)), np.abs(getattr(whole, field)), rtol=1e-12, atol=1e-12)


def test_a_group_over_most_of_the_cloud_is_not_cut_out():
    points = plane_and_line()
    assert pointcloud._within_reach(points, np.arange(points.shape[0] // 2), 0.01) is None
    assert pointcloud._within_reach(points, np.zeros(0, dtype=np.int64), 0.01) is None
    near = pointcloud._within_reach(points, np.array([2500]), 0.05)
    inside = np.flatnonzero(np.linalg.norm(points - points[2500], axis=1) <= 0.05)
    assert np.isin(inside, near).all() and near.size < 0.1 * points.shape[0]


def test_the_near_copies_are_found_in_the_rows_with_a_gap_only():
    """``_copy_pairs`` looks at the rows whose first distance is below ``COPY_GAP`` times their last: the pairs
    of the whole (rows, neighbours) array, each row's neighbours before its last gap."""
    rng = np.random.default_rng(2)
    distances = np.sort(rng.random((500, 10)), axis=1)
    distances[::7, :3] *= 1e-6  # three copies before a gap
    distances[::11, 0] = 0.0  # one copy at distance 0 (kept: a gap from 0 to the next)
    distances[::13] = 1e-200  # all below MIN_SPACING: no gap counts
    indices = rng.integers(0, 10_000, size=(500, 10))
    centres = np.arange(500) + 20_000
    rows, cols = pointcloud._copy_pairs(centres, distances, indices)
    gap = (distances[:, :-1] <= pointcloud.COPY_GAP * distances[:, 1:]) & (distances[:, 1:] > pointcloud.MIN_SPACING)
    expected = [
        (centres[r], indices[r, j]) for r in range(500) if gap[r].any() for j in range(9 - int(np.argmax(gap[r, ::-1])))
    ]
    assert list(zip(rows, cols)) == expected and len(expected) > 50


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_the_nearest_neighbours_on_a_grid_are_the_k_d_trees(backend, monkeypatch):
    """``_knn`` (a grid with the compiled kernels) gives the k-d tree's arrays to the bit: on a random sample,
    on a lattice (every neighbour tied with another: its order is the tree's) and on sparse outliers."""
    from scipy.spatial import cKDTree

    from meshcurv import _pointcloud_normals

    if backend == "numba":
        pytest.importorskip("numba")
    monkeypatch.setattr(pointcloud, "KNN_GRID_POINTS", 0)
    rng = np.random.default_rng(4)
    x, y = np.meshgrid(np.arange(30.0), np.arange(20.0))
    lattice = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)]) / 30.0 + [2.0, 0.0, 0.0]
    far = rng.normal(size=(10, 3)) * 10.0
    cloud = np.concatenate([plane_and_line(), lattice, far])
    tree = cKDTree(cloud)
    with use_backend(backend):
        distances, indices = pointcloud._knn(tree, cloud)
    expected_distances, expected_indices = _pointcloud_normals.knn(tree, cloud)
    np.testing.assert_array_equal(indices, expected_indices)
    np.testing.assert_array_equal(distances, expected_distances)
