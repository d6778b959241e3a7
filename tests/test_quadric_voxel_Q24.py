"""``quadric`` at the default radius of a voxel surface (issue 29; helpers Q24 and Q25).

At a voxel surface's default radius (1.86 voxels on ``voxel_torus()``) every ball holds the staircase, and the
noise checks were skipped there: the degree-4 jets followed the steps and were valid. ``voxel_torus()``: 1,564 of
its 2,710 valid vertices off the exact H by more than half of the largest ``|k|`` (median error 103%), in every
pose. Each fit is now checked against one over a ball twice as wide, as over a crack, and a ball on a
staircase takes no fit as structure (residuals that grow over the wider ball are the steps'): Q24 left the sphere
and the ellipsoid with no valid vertex that far off, the torus with 21, the 2 x 1 x 1 sphere 6 and the
2 x 0.5 x 0.5 ellipsoid 3 (strict xfails on 8a9367a); the fits kept are now checked against a quadric over twice
the default ball and held within the radius of curvature of their largest ``|k|`` (Q25: none).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes

from conftest import random_rotation

pytest.importorskip("skimage")

MESHES = {
    "torus": lambda: shapes.voxel_torus(),
    "sphere": lambda: shapes.voxel_sphere(10.0),
    "ellipsoid": lambda: shapes.voxel_ellipsoid(),
    "sphere_2x1x1": lambda: shapes.voxel_sphere(10.0, (2.0, 1.0, 1.0)),
    "ellipsoid_2x05x05": lambda: shapes.voxel_ellipsoid(spacing=(2.0, 0.5, 0.5)),
}


@pytest.mark.parametrize("turned", [False, True])
@pytest.mark.parametrize("name", sorted(MESHES))
def test_no_valid_vertex_is_off_by_half_of_the_largest_curvature(name, turned):
    mesh = MESHES[name]()
    vertices = np.asarray(mesh.vertices, dtype=np.float64)
    if turned:
        vertices = (vertices - vertices.mean(axis=0)) @ random_rotation(7).T
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = meshcurv.principal_curvatures(vertices, mesh.faces, method="quadric")
    largest = np.max(np.abs(np.column_stack([mesh.k_min, mesh.k_max])))
    off = result.valid & (np.abs(result.mean - mesh.mean) > 0.5 * largest)
    assert off.sum() == 0, (int(off.sum()), int(result.valid.sum()))
