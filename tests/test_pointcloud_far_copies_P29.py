"""A cloud far from the origin gives the results of the same cloud near it (issue 29; fuzz_api 574/56).

A shift of 2^20 sizes rounds every coordinate to its last bits; the fuzzer compares the moved cloud with the
moved cloud brought back exactly (``moved - shift``, exact: each coordinate within a factor 2 of the shift), an
exact translation of it. Before, the centroid of near copies (round-off copies of each point, merged and measured
at their centroid) was summed in absolute coordinates, rounded at the far cloud's magnitude: ``jets`` on a torus
held 5 times, 1e-9 apart, read k 1.05e-6 of the largest |k| apart at the copies; the normals of any far cloud
differed in their last bits. Expected from the invariance: an exact translation moves no value, to the last bit.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from conftest import chosen_backend
from meshcurv.pointcloud import point_cloud_curvatures

FIELDS = ("k_min", "k_max", "dir_min", "dir_max", "normals", "valid", "invalid_reason")


def _sphere(n: int, seed: int, copies: int) -> np.ndarray:
    """A unit sphere of ``n`` random points, held ``copies`` times with round-off differences of 1e-9."""
    rng = np.random.default_rng(seed)
    points = rng.normal(size=(n, 3))
    points /= np.linalg.norm(points, axis=1, keepdims=True)
    if copies == 1:
        return points
    return np.concatenate([points + rng.normal(size=points.shape) * 1e-9 for _ in range(copies)])


def _moved_and_back(points: np.ndarray, shift: float) -> tuple[np.ndarray, np.ndarray]:
    moved = points + shift
    back = moved - shift
    assert np.all(moved / shift >= 0.5) and np.all(moved / shift <= 2.0)  # (so that ``back`` is exact: Sterbenz)
    assert not np.array_equal(back, points)  # (the shift rounded the points: the case this file is about)
    return moved, back


@pytest.mark.parametrize("backend", ["numpy", "numba"])
@pytest.mark.parametrize(
    ("copies", "method", "shift"),
    [(5, "jets", -(2.0**21)), (5, None, -(2.0**21)), (1, None, 2.0**21), (3, "corrected_measures", -3.0 * 2.0**20)],
)
def test_far_cloud_reads_as_near(backend, copies, method, shift):
    points = _sphere(1200, 7, copies)
    moved, back = _moved_and_back(points, shift)
    options = {} if method is None else {"method": method}
    with chosen_backend(backend), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        far = point_cloud_curvatures(moved, **options)
        near = point_cloud_curvatures(back, **options)
    assert near.valid.mean() > 0.9
    for field in FIELDS:
        np.testing.assert_array_equal(getattr(far, field), getattr(near, field), err_msg=field)
