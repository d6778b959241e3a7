"""``quadric`` at the default radius of a voxel surface: the fits that the steps bent (issue 29; helper Q25).

On 8a9367a each fit on a staircase was checked against a quadric over a ball twice as wide, and those that departed
from it were grown until their spread under the noise of their residuals met the reach; the grown balls followed the
steps too. Valid and off the exact H by more than half of the largest ``|k|`` (default pose): voxel spheres of radius
3, 4, 6, 8 and 15: 16 (of 16 valid), 12 (of 32), 1, 4 and 24; ``voxel_torus(15, 6)`` 6; a sphere in 0.5 x 1 x 1
voxels 12 and in 1 x 1 x 2 voxels 2. Now the steps' pull is taken as coherent over the ball (a departure of half a
spread follows them, the balls grow as for 1.5 times the spread), and every fit kept is checked against a quadric
over twice its default ball and held within the radius of curvature of its largest ``|k|``: none is left, and the
spheres' median H error fell (``voxel_sphere(15)`` 9.6 -> 6.3%).
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
    "sphere_3": lambda: shapes.voxel_sphere(3.0),
    "sphere_4": lambda: shapes.voxel_sphere(4.0),
    "sphere_6": lambda: shapes.voxel_sphere(6.0),
    "sphere_8": lambda: shapes.voxel_sphere(8.0),
    "sphere_15": lambda: shapes.voxel_sphere(15.0),
    "sphere_7_seed_3": lambda: shapes.voxel_sphere(7.0, seed=3),
    "sphere_8_05x1x1": lambda: shapes.voxel_sphere(8.0, (0.5, 1.0, 1.0), seed=2),
    "sphere_10_1x1x2": lambda: shapes.voxel_sphere(10.0, (1.0, 1.0, 2.0), seed=1),
    "torus_15_6": lambda: shapes.voxel_torus(15.0, 6.0, seed=2),
}


def _quadric(mesh, pose=None):
    vertices = np.asarray(mesh.vertices, dtype=np.float64)
    if pose is not None:
        vertices = (vertices - vertices.mean(axis=0)) @ random_rotation(pose).T
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the staircase's and the undefined vertices' warnings
        return meshcurv.principal_curvatures(vertices, mesh.faces, method="quadric")


@pytest.mark.parametrize("pose", [None, 11])
@pytest.mark.parametrize("name", sorted(MESHES))
def test_no_valid_vertex_is_off_by_half_of_the_largest_curvature(name, pose):
    mesh = MESHES[name]()
    result = _quadric(mesh, pose)
    # the exact H at each vertex's closest point of the analytic surface (outward: a ball's is 1 / radius)
    largest = np.max(np.abs(np.column_stack([mesh.k_min, mesh.k_max])))
    off = result.valid & (np.abs(result.mean - mesh.mean) > 0.5 * largest)
    assert off.sum() == 0, (int(off.sum()), int(result.valid.sum()))
    # and not by leaving everything undefined: a ball of 6 voxels or more is resolved at most of its vertices (the
    # balls of 3 and 4 voxels are left undefined, their fits no steadier than the steps)
    if name not in ("sphere_3", "sphere_4"):
        assert result.valid.mean() > 0.6


@pytest.mark.parametrize(
    ("make", "share"),
    [
        # on 8a9367a 99.6%, 99.8% and 79.4% of the vertices were valid; now 99.2%, 98.3% and 68.6%
        (lambda: shapes.voxel_sphere(10.0), 0.97),
        (lambda: shapes.voxel_sphere(15.0), 0.97),
        (lambda: shapes.voxel_torus(), 0.6),
    ],
    ids=["sphere_10", "sphere_15", "torus"],
)
def test_the_check_keeps_the_coverage(make, share):
    result = _quadric(make())
    assert result.valid.mean() > share


def test_larger_balls_on_a_sphere_read_its_curvature_closer():
    # H = 1 / 15 on the ball of radius 15; the median relative error of the valid vertices was 9.6% on 8a9367a (balls
    # grown for independent noise, which the steps pull further)
    mesh = shapes.voxel_sphere(15.0)
    result = _quadric(mesh)
    error = np.abs(result.mean[result.valid] * 15.0 - 1.0)
    assert np.median(error) < 0.08
