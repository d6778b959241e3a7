"""``quadric`` at the default radius of a voxel surface (issue 29; helper Q24's measurement).

At a voxel surface's default radius (1.86 voxels on ``voxel_torus()``) every ball holds the staircase, and the
noise checks were skipped there: the degree-4 jets followed the steps and were valid. ``voxel_torus()``: 1,564 of
its 2,710 valid vertices off the exact H by more than half of the largest ``|k|`` (median error 103%), in every
pose. Each fit is now checked against one over a ball twice as wide, as over a crack, and a ball on a
staircase takes no fit as structure (residuals that grow over the wider ball are the steps'): the sphere and the
ellipsoid have no valid vertex that far off; the torus 21 (see :data:`OPEN`).
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

#: Still off (strict xfail): the grown balls the wider-ball check takes (about 3 voxels on the torus) follow the
#: steps too. Before / now: torus 1,564 / 21 of 2,177 valid, the 2 x 1 x 1 sphere 119 / 6, the 2 x 0.5 x 0.5
#: ellipsoid 182 / 3. Taking no grown ball on a staircase leaves 0-3 off but the torus and ellipsoids undefined
#: and 32% of the sphere valid (tests/test_noisy_voxel_L21.py asks for 95%): not chosen.
OPEN = {"torus", "sphere_2x1x1", "ellipsoid_2x05x05"}


def _cases():
    for name in sorted(MESHES):
        marks = [pytest.mark.xfail(strict=True, reason="open: grown balls on the staircase")] if name in OPEN else []
        yield pytest.param(name, marks=marks, id=name)


@pytest.mark.parametrize("turned", [False, True])
@pytest.mark.parametrize("name", list(_cases()))
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
