"""Copies merged into one point keep the mean of their given normals, not the normal of the copy the pose or the
order put first (issue 29, fuzz_api 522/117).

Duplicates, near copies and copies a registration error apart are merged into one point, computed once; the point
kept is its group's first in the Morton order (coincident points: in the input's order), which a rotation (or a
permutation) changes. When the copies' given normals differ (two points of one scan close enough to be merged as
copies of one), the kept point took the normal of either: 522/117 (three spheres in five registered copies, given
normals, turned) had normals 0.0046 apart at 20 points and k apart by 3.1e-4 of the largest |k| at 270 of 5,055.

Oracle: the invariances. The input reversed is the same cloud; a half turn about z negates x and y exactly (no
round-off) and reverses the Morton order of two points apart along x: the same cloud in another pose. Either gives
the same curvatures, to the round-off of the sums that take the points in another order.
"""

import warnings

import numpy as np
import pytest

from meshcurv._backend import use_backend
from meshcurv.pointcloud import point_cloud_curvatures

HALF_TURN = np.diag([-1.0, -1.0, 1.0])


def sphere(n, rng):
    """``n`` random points on the unit sphere (their outward normals are the points themselves)."""
    unit = rng.normal(size=(n, 3))
    return unit / np.linalg.norm(unit, axis=1, keepdims=True)


def computed(backend, *calls):
    with use_backend(backend), warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the merge's note: not the point here
        return [point_cloud_curvatures(points, normals=normals) for points, normals in calls]


def assert_same(first, other, order, tolerance):
    """``other``'s values at the rows ``order`` are ``first``'s, to ``tolerance`` of the largest |k|."""
    np.testing.assert_array_equal(other.valid[order], first.valid)
    assert first.valid.mean() > 0.9
    valid = first.valid
    largest = np.abs(first.k_max[valid]).max()
    for field in ("k_min", "k_max"):
        a, b = getattr(first, field)[valid], getattr(other, field)[order][valid]
        np.testing.assert_allclose(b, a, rtol=0, atol=tolerance * largest)


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_a_duplicate_with_its_own_normal_is_read_alike_in_either_order(backend):
    # a duplicate of point 0 (the same coordinates) given a normal tilted by 0.1 rad: merged, the point kept is the
    # first in the input's order; the input reversed keeps the other
    if backend == "numba":
        pytest.importorskip("numba")
    points = sphere(800, np.random.default_rng(5))
    tilted = points[0] + 0.1 * np.cross(points[0], [0.0, 0.0, 1.0])
    points = np.vstack([points, points[:1]])
    normals = np.vstack([points[:-1], tilted / np.linalg.norm(tilted)])
    back = np.arange(points.shape[0])[::-1]
    first, reversed_ = computed(backend, (points, normals), (points[back], normals[back]))
    assert_same(first, reversed_, back, 1e-12)


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_registered_copies_of_close_points_are_read_alike_in_both_poses(backend):
    # 522/117's form: five copies of a sphere, each moved whole by 0.01 spacings (merged as a registration error),
    # the exact normals given; two points of the sphere 0.03 spacings apart along x, whose copies make one group
    # holding both normals (0.004 rad apart)
    if backend == "numba":
        pytest.importorskip("numba")
    rng = np.random.default_rng(7)
    points = sphere(1000, rng)
    spacing = np.sqrt(4.0 * np.pi / 1000)
    close = points[0] + [0.03 * spacing, 0.0, 0.0]
    points = np.vstack([points, close / np.linalg.norm(close)])
    copies = [points]
    for _ in range(4):
        direction = rng.normal(size=3)
        copies.append(points + 0.01 * spacing * direction / np.linalg.norm(direction))
    copies = np.vstack(copies)
    normals = np.vstack([points] * 5)  # each copy given the original's exact normals
    rows = np.arange(copies.shape[0])
    first, turned = computed(backend, (copies, normals), (copies @ HALF_TURN.T, normals @ HALF_TURN.T))
    # (to 1e-6 of the largest |k|: this sphere's k move by 3e-8 when its points move by one ulp)
    assert_same(first, turned, rows, 1e-6)
