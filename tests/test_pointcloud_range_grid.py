"""A surface sampled on a grid of two axes (a range image, a terrain model) is no voxel staircase (issue 29).

The rules for voxel surfaces read as clouds (their facets and single steps, see
:func:`meshcurv._pointcloud_normals.lattice_treads`) read a grid from the coordinates; a plane sampled on an
(x, y) grid with heights off any grid has two axes of one, and is measured flat: H 0 at every point (a first
version of the facet and step rules made every point of such planes NaN).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from meshcurv import point_cloud_curvatures
from meshcurv.errors import MeshcurvWarning


@pytest.mark.parametrize("method", ["corrected_measures", "jets"])
@pytest.mark.parametrize("slope", [(0.3137, 0.2219), (2.7183, 0.1)])
def test_a_plane_sampled_on_a_grid_of_two_axes_is_flat_and_measured(method, slope):
    x, y = np.meshgrid(np.arange(60.0), np.arange(60.0))
    points = np.column_stack([x.ravel(), y.ravel(), (slope[0] * x + slope[1] * y).ravel()])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshcurvWarning)
        result = point_cloud_curvatures(points, method=method)
    assert result.valid.mean() > 0.9
    assert np.abs(result.mean[result.valid]).max() < 1e-9
