"""The orientation's stacked edges weigh at least 3 even where the cosine of two unit normals rounds past 1.

Two unit normals a row of voxels apart can have a dot product of ``1 + 4.4e-16`` in floating point. A stacked
edge weighs ``3 + (1 - |cos|)``, so it came out ``3 - 4.4e-16``: below the flat edges' ceiling of 3, which broke
the forest's ordering (an ``AssertionError`` on voxel clouds in 1 x 1 x 2.5 voxels, fuzz 340/14).
"""

import numpy as np
import pytest

from meshcurv import _pointcloud_normals as normals_module

ABOVE_ONE = np.nextafter(np.nextafter(1.0, 2.0), 2.0)  # 1 + 4.4e-16, as fuzz 340/14 read


def _stacked_edge_inputs():
    # one edge between two points on parallel planes one spacing apart, normals facing the same way
    flat = np.array([False, False])
    ahead = np.array([1.0, 1.0])
    behind = np.array([1.0, 1.0])
    cosine = np.array([ABOVE_ONE, -ABOVE_ONE])
    slope = np.array([1.0, 1.0])
    spacing = np.array([1.0, 1.0])
    rows = np.array([0, 0])
    cols = np.array([1, 1])
    return flat, ahead, behind, cosine, slope, spacing, rows, cols


def test_numpy_stacked_weight_not_below_three():
    stacked, weights, _ = normals_module._edge_weights(*_stacked_edge_inputs())
    assert stacked[0]
    assert weights[0] >= 3.0


def test_compiled_stacked_weight_not_below_three():
    pytest.importorskip("numba")
    from meshcurv._kernels import pointcloud as kernels

    stacked, weights, _ = kernels.edge_weights(
        *_stacked_edge_inputs(), normals_module.STACKED_OFFSET, normals_module.FACING_COSINE
    )
    assert stacked[0]
    assert weights[0] >= 3.0
