"""A flat cloud has no outside: its side is the same on both backends (issue 29, fuzz round 14, seed 246 case 3042).

The vertices of an icosphere flattened onto a coordinate plane: the orientation turns each part outward by its
flux about its centroid, exactly 0 on a plane up to round-off, whose sign differed between the NumPy and the
numba paths (every normal opposite, H 0 on both). A part with no volume now faces ``PCA_SIGN``.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from meshcurv import shapes
from meshcurv._backend import use_backend
from meshcurv._pointcloud_normals import PCA_SIGN
from meshcurv.pointcloud import point_cloud_curvatures

pytest.importorskip("numba")


# (onto x = 0 too: its y and z coordinates repeat with round-off differences, which the grid reader read as a grid of
# step 2.8e-17, and every point was NaN "on a flat tread of a voxel staircase")
@pytest.mark.parametrize("axis", [0, 1, 2])
def test_a_flat_cloud_faces_the_same_side_on_both_backends(axis):
    points = np.array(shapes.icosphere(6).vertices, dtype=float)
    points[:, axis] = 0.0
    normals = {}
    for backend in ("numba", "numpy"):
        with use_backend(backend), warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the merged mirror points: one warning, not what is tested
            result = point_cloud_curvatures(points)
        assert result.valid.mean() > 0.9 and np.abs(result.mean[result.valid]).max() < 1e-9  # a plane
        normals[backend] = result.normals
    np.testing.assert_allclose(normals["numba"], normals["numpy"], atol=1e-9)
    # the plane's normal, on the side of PCA_SIGN
    expected = np.eye(3)[axis] * np.sign(PCA_SIGN[axis])
    np.testing.assert_allclose(normals["numpy"], np.broadcast_to(expected, normals["numpy"].shape), atol=1e-9)
