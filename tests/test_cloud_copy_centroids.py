"""Near copies of a cloud's points are measured at their centroid (issue 29; fuzz_api round 29, seed 550 case 60).

Points closer to another than :data:`meshcurv.pointcloud.COPY_GAP` times the distance to their next neighbour are
merged as copies of one point. The merged point stood at the first copy in the points' Morton order, which the pose
chooses: a nested cloud (a sphere inside another) holding two copies 2.8e-5 apart (1e-3 spacings) read, turned,
curvatures 1.2e-4 of the largest |k| apart at 46 points, both backends. The expected values come from the
invariance: a rigid motion moves no curvature beyond round-off.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from conftest import chosen_backend, random_rotation
from meshcurv.pointcloud import point_cloud_curvatures


def _sphere_with_near_copies(seed: int) -> np.ndarray:
    """A unit sphere of 3,000 points and near copies of 60 of them, each 5e-4 spacings off in a random direction."""
    rng = np.random.default_rng(seed)
    points = rng.normal(size=(3000, 3))
    points /= np.linalg.norm(points, axis=1, keepdims=True)
    spacing = np.sqrt(4 * np.pi / 3000)
    picked = rng.choice(3000, 60, replace=False)
    offsets = rng.normal(size=(60, 3))
    offsets *= 5e-4 * spacing / np.linalg.norm(offsets, axis=1, keepdims=True)
    return np.concatenate([points, points[picked] + offsets])


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_near_copies_merge_where_no_pose_chooses(backend):
    points = _sphere_with_near_copies(5)
    turn = random_rotation(11)
    shift = np.array([3.0, -7.0, 2.0])
    with chosen_backend(backend), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        before = point_cloud_curvatures(points)
        after = point_cloud_curvatures(points @ turn.T + shift)
    np.testing.assert_array_equal(before.valid, after.valid)
    assert before.valid.mean() > 0.9
    largest = np.abs(before.k_max[before.valid]).max()
    for field in ("k_min", "k_max"):
        a, b = getattr(before, field)[before.valid], getattr(after, field)[after.valid]
        assert np.abs(a - b).max() <= 1e-9 * largest, field
