"""The voxel reading of voxel meshes whose vertices moved by a few hundredths to a tenth of a voxel (issue 29, fuzz
415/108).

A marching-cubes mesh whose every vertex moved by 0.03 to 0.1 voxel in a random direction is the same voxel
surface to well within a voxel, but :func:`meshcurv.lattice.voxel_grid` took a coordinate as on its plane only
within :data:`meshcurv.lattice.VOXEL_SNAP` (0.05) of the half voxels' distance, 0.025 voxel: from 0.03 on, fewer
than 95% of the vertices kept two coordinates on the grid, the mesh was read as smooth, and ``method="quadric"``
measured its staircase (75-80 of the 1,890 vertices of ``voxel_sphere(10)`` off the clean H by more than half the
largest |k|). Meshes on a grid along some axes only (a cylinder's axis, a height field's x and y) must stay
unread.
"""

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes
from meshcurv.errors import MeshQualityWarning
from meshcurv.lattice import voxel_grid

pytest.importorskip("skimage")

PENDING = pytest.mark.xfail(
    strict=True, reason="issue 29: the voxel reading tolerant to a tenth of a voxel of noise (L21's patch) not applied"
)


def moved(vertices, gap, seed):
    """Every vertex moved by ``gap`` voxels in a random direction (each coordinate by up to ``gap``)."""
    directions = np.random.default_rng(seed).normal(size=vertices.shape)
    return vertices + gap * directions / np.linalg.norm(directions, axis=1, keepdims=True)


@PENDING
@pytest.mark.parametrize("gap", [0.03, 0.05, 0.1])
@pytest.mark.parametrize("radius", [6.0, 10.0])
def test_a_noisy_voxel_sphere_is_on_the_grid_of_its_image(radius, gap):
    mesh = shapes.voxel_sphere(radius=radius)
    grid = voxel_grid(moved(mesh.vertices, gap, 1), mesh.faces)
    assert grid is not None
    # the image's voxel, to the noise over the sphere's span (a tenth of a voxel over 20 voxels: 5e-3)
    np.testing.assert_allclose(grid.spacing, mesh.spacing, rtol=5e-3)


def test_a_grid_along_some_axes_only_is_no_voxel_surface():
    # a cylinder: its axis sampled on a grid, its circles not; a height field: x and y on a grid, z = 0.5 sin(3 x)
    cylinder = shapes.cylinder()
    assert voxel_grid(np.asarray(cylinder.vertices, float), cylinder.faces) is None
    saddle = shapes.saddle()
    heights = np.array(saddle.vertices, dtype=float)
    heights[:, 2] = 0.5 * np.sin(3 * heights[:, 0])
    assert voxel_grid(heights, saddle.faces) is None


@PENDING
@pytest.mark.parametrize("gap", [0.05, 0.1])
def test_quadric_on_a_noisy_voxel_sphere_never_lies(gap):
    mesh = shapes.voxel_sphere(radius=10.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshQualityWarning)
        clean = meshcurv.principal_curvatures(mesh.vertices, mesh.faces, method="quadric")
        noisy = meshcurv.principal_curvatures(moved(mesh.vertices, gap, 2), mesh.faces, method="quadric")
    assert noisy.parameters["surface"] == "voxel"
    both = noisy.valid & clean.valid
    assert both.sum() > 0.95 * both.size
    # the analytic H of the ball is 1/10; each vertex against its clean self, to a fifth of the largest |k| (the
    # staircase read as the surface: up to 1.3 of it)
    largest = np.nanmax(np.abs(np.c_[clean.k_min, clean.k_max]))
    assert np.max(np.abs(noisy.mean[both] - clean.mean[both])) < 0.2 * largest
