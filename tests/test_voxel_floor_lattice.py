"""A voxel surface's least radius off the lattice (issue 29; fuzz_labels round 25, seed 7 case 3).

icc's radius on a voxel surface is at least its largest voxel size. At exactly that size, the balls' rims lay on
the vertices one voxel apart, and the last bits of the coordinates decided which were in: a label of 2 x 4 x 3
voxels (spacing 6624 x 4216 x 7332) scaled by 30 gave normals 0.4 apart and curvatures 10-14% of the largest
apart. The floor is :data:`meshcurv.radius.VOXEL_FLOOR` voxels, off every lattice distance: the curvatures scale
as 1 / the factor, to round-off.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import radius
from meshcurv.volume import label_curvatures

pytest.importorskip("skimage")

SPACING = (6623.983988319892, 4215.954868209475, 7331.616207694069)


def _surface():
    image = np.zeros((6, 8, 7), dtype=np.uint8)
    image[2:4, 2:6, 2:5] = 1
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        _, surfaces = label_curvatures(image, spacing=SPACING, return_meshes=True)
    return np.asarray(surfaces[1].vertices, dtype=np.float64), np.asarray(surfaces[1].faces)


def _curvatures(vertices, faces):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return meshcurv.principal_curvatures(vertices, faces)


def test_the_floor_is_off_the_lattice():
    # squared lattice distances of a binary marching-cubes surface are quarters of whole numbers of voxels squared
    for ratio in (radius.VOXEL_FLOOR, radius.VOXEL_FLOOR * radius.VOXEL_NORMAL_VOXELS):
        quarters = 4.0 * ratio**2
        assert abs(quarters - round(quarters)) > 0.05


@pytest.mark.parametrize("factor", [30.0, 1e-6, 1000.0, 0.7])
def test_a_small_voxel_surface_scales(factor):
    vertices, faces = _surface()
    base = _curvatures(vertices, faces)
    assert np.any(base.radius <= radius.VOXEL_FLOOR * max(SPACING) * (1 + 1e-12))  # balls at the floor
    scaled = _curvatures(vertices * factor, faces)
    np.testing.assert_array_equal(base.valid, scaled.valid)
    largest = np.nanmax(np.abs(base.k_max[base.valid]))
    for name in ("k_min", "k_max"):
        apart = np.abs(getattr(base, name) - factor * getattr(scaled, name))[base.valid]
        assert np.max(apart, initial=0.0) <= 1e-9 * largest, name
    np.testing.assert_allclose(scaled.radius, factor * base.radius, rtol=1e-12)
