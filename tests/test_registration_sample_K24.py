"""The registration error of a cloud of copies is read on a sample that the pose does not choose (issue 29, K24).

``pointcloud._registration_gap`` read the copies' spread on 2,048 points spread evenly over the internal Morton
order, which a rotation reorders: 5 registered copies of a 4,000-point ellipsoid, turned, read a spacing 3e-4
of itself apart, and curvatures up to 0.04 of the largest apart. Oracle: rigid motions, uniform scaling and
re-indexing change nothing but round-off.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import meshcurv
from meshcurv._backend import use_backend

TURN = Rotation.from_euler("xyz", [0.3, 1.1, -0.7]).as_matrix()


def _copies(n: int = 4000, copies: int = 5) -> np.ndarray:
    """An ellipsoid (axes 1, 1, 0.6) sampled ``copies`` times, each copy off by 0.01 spacings."""
    rng = np.random.default_rng(451)
    unit = rng.normal(size=(n, 3))
    unit /= np.linalg.norm(unit, axis=1, keepdims=True)
    surface = unit * np.array([1.0, 1.0, 0.6])
    spacing = np.sqrt(4 * np.pi / n)
    return np.concatenate([surface + 0.01 * spacing * rng.normal(size=surface.shape) for _ in range(copies)])


def _curvatures(points: np.ndarray):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", meshcurv.MeshQualityWarning)
        return meshcurv.point_cloud_curvatures(points)


@pytest.mark.parametrize("backend", ["numba", pytest.param("numpy", marks=pytest.mark.slow)])
def test_registered_copies_read_alike_in_every_pose(backend):
    if backend == "numba":
        pytest.importorskip("numba")
    points = _copies()
    permutation = np.random.default_rng(5).permutation(points.shape[0])
    with use_backend(backend):
        reference = _curvatures(points)
        largest = np.nanmax(np.abs(reference.k_max))
        poses = {
            "turned": (points @ TURN.T, np.arange(points.shape[0]), 1.0),
            "shifted": (points + np.array([3.3, -1.7, 0.9]), np.arange(points.shape[0]), 1.0),
            "scaled": (points * 3.7, np.arange(points.shape[0]), 3.7),
            "re-indexed, turned": (points[permutation] @ TURN.T, permutation, 1.0),
        }
        for name, (moved, back, scale) in poses.items():
            found = _curvatures(moved)
            assert found.parameters["spacing"] / scale == pytest.approx(reference.parameters["spacing"], rel=1e-12)
            np.testing.assert_array_equal(found.valid, reference.valid[back], err_msg=name)
            for field in ("k_min", "k_max"):
                moved_k = getattr(found, field) * scale
                np.testing.assert_allclose(
                    moved_k, getattr(reference, field)[back], rtol=0, atol=1e-9 * largest, err_msg=f"{name} {field}"
                )
