"""Ring methods on a voxel surface in a turned frame (issue 29; the lead's review of R22's 6c745a3).

The ring methods cannot measure a staircase: on a voxel surface read on its grid every vertex is undefined. The
grid is read in the coordinate axes only: a marching-cubes mesh turned by a rotation (a segmentation's affine with
a rotation, as NIfTI headers often have) is not read as one, and ``rusinkiewicz`` and ``meyer`` give valid numbers
off by 100-200% of H (``voxel_sphere(10)`` turned: 1,461 and 1,890 of its 1,890 vertices off by more than half).
Strict xfails until the voxel reading finds the grid's own frame.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes

from conftest import random_rotation

OPEN = pytest.mark.xfail(strict=True, reason="open: the voxel grid is read in the coordinate axes only")


@pytest.mark.parametrize("turned", [False, pytest.param(True, marks=OPEN)])
@pytest.mark.parametrize("method", ["rusinkiewicz", "meyer"])
def test_no_valid_vertex_of_a_voxel_sphere_is_off_by_half_of_h(method, turned):
    pytest.importorskip("skimage")
    sphere = shapes.voxel_sphere(10)
    vertices = np.asarray(sphere.vertices, dtype=np.float64)
    if turned:
        vertices = (vertices - vertices.mean(axis=0)) @ random_rotation(3).T
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = meshcurv.principal_curvatures(vertices, sphere.faces, method=method)
    off = np.abs(result.mean[result.valid] - 0.1) > 0.05  # a sphere of radius 10: H = 0.1
    assert off.sum() == 0, (int(off.sum()), int(result.valid.sum()))
