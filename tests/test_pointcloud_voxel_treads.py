"""Inward normals on the treads of a voxel surface in anisotropic voxels, read as a cloud (issue 29).

Found by helper V12's voxel-cloud fuzz strategy (``fuzz_api.py --point-clouds``, seed 29, case 429): the
marching-cubes torus (26.2, 8.87) in voxels of 0.7 x 1 x 1.3, read as a point cloud, keeps 9 points of a flat
tread near its top valid with their normal inward (H 0 where the exact torus has 0.028, the sign of the normal wrong).
Present before this stop's changes. The 9 points belong to a part of 124 points (two treads and their riser)
that the orientation's graph cut off from the rest; :func:`meshcurv._pointcloud_normals.outward_signs` turned it
by the flux about its own centroid, which on a piece of a saddle or a tread says nothing, and the winding number
did not correct it. Such fragments now have no side of their own (``undecided_fragments``): NaN.
The truth: the analytic torus's outward normal at each vertex (``shapes.voxel_torus``).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from meshcurv import shapes
from meshcurv.pointcloud import point_cloud_curvatures


def test_every_valid_normal_of_a_voxel_torus_faces_out():
    pytest.importorskip("skimage")  # (marching cubes: the volume extra)
    mesh = shapes.voxel_torus(26.2, 8.87, spacing=(0.7, 1.0, 1.3), seed=436)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the staircase's notes: one warning, not what is tested
        result = point_cloud_curvatures(mesh.vertices, method="corrected_measures")
    inward = result.valid & (np.einsum("ij,ij->i", result.normals, mesh.normals) < 0)
    assert result.valid.mean() > 0.5
    assert not inward.any(), f"{int(inward.sum())} valid points with their normal inward"
