"""The shape index of flat vertices (issue 29; fuzz_labels round 25, seed 444 case 3).

On the flat sides of a voxel blob the curvatures are the round-off of their sums (about 1e-14 of 1/h) and
their ratio, the shape index, any number in [-1, 1]: a label's shape-index columns moved from 0.644 to 0.563
when the spacing was scaled by 0.7, while its area and mean curvature agreed to 1e-9. A flat vertex's shape
index is NaN (``result.FLAT_CURVEDNESS``), so the table is invariant under a scaling, as every other column.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv.result import FLAT_CURVEDNESS, shape_index
from meshcurv.statistics import curvature_statistics
from meshcurv.volume import label_curvatures

pytest.importorskip("skimage")


def _box_image() -> np.ndarray:
    """A plate of 6 x 1 x 6 voxels (two flat sides, rounded rims) in a zero margin: the fuzzer's 4 x 1 x 4 blob has
    no vertex farther than the least radius (``radius.VOXEL_FLOOR`` voxels) from its rims."""
    image = np.zeros((10, 5, 10), dtype=np.uint8)
    image[2:8, 2, 2:8] = 1
    return image


def _table(spacing):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return label_curvatures(_box_image(), spacing=spacing, return_meshes=True)


@pytest.mark.parametrize("factor", [0.7, 3.0])
def test_a_label_tables_shape_index_columns_do_not_move_under_a_scaling(factor):
    spacing = np.array([0.0843, 0.0843, 0.0843])
    (table, surfaces), (scaled, scaled_surfaces) = _table(tuple(spacing)), _table(tuple(spacing * factor))
    row, other = table.iloc[0], scaled.iloc[0]
    # the invariance the other columns hold: area by factor^2, H by 1/factor
    assert other["area"] == pytest.approx(row["area"] * factor**2, rel=1e-9)
    columns = [c for c in table.columns if c.startswith("shape_index_")]
    assert columns
    for column in columns:
        assert other[column] == pytest.approx(row[column], rel=1e-9, abs=1e-12, nan_ok=True), column
    a, b = surfaces[1].result, scaled_surfaces[1].result
    both = a.valid & b.valid
    np.testing.assert_array_equal(np.isnan(a.shape_index[both]), np.isnan(b.shape_index[both]))
    same = both & np.isfinite(a.shape_index)
    np.testing.assert_allclose(a.shape_index[same], b.shape_index[same], atol=1e-9)


def test_the_flat_sides_of_a_plate_have_no_shape_index():
    _, surfaces = _table((1.0, 1.0, 1.0))
    result = surfaces[1].result
    flat = result.valid & (result.curvedness * result.radius < FLAT_CURVEDNESS)
    assert flat.sum() > 0  # the sides' inner vertices: a plane, to round-off
    assert np.isnan(result.shape_index[flat]).all()
    curved = result.valid & ~flat
    assert np.isfinite(result.shape_index[curved]).all()


@pytest.mark.parametrize("factor", [0.7, 3.0])
def test_the_mesh_statistics_do_not_move_under_a_scaling(factor):
    # the plate's surface as a mesh, through principal_curvatures and curvature_statistics
    _, surfaces = _table((1.0, 1.0, 1.0))
    vertices, faces = surfaces[1].vertices, surfaces[1].faces
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        row = curvature_statistics(meshcurv.principal_curvatures(vertices, faces))
        scaled = curvature_statistics(meshcurv.principal_curvatures(vertices * factor, faces))
    for column in [c for c in row if c.startswith("shape_index_")]:
        assert scaled[column] == pytest.approx(row[column], rel=1e-9, abs=1e-12, nan_ok=True), column


def test_shape_index_scale_rule():
    k_min = np.array([1e-15, 0.0, -1.0, 1e-15, 2e-9])
    k_max = np.array([2e-15, 0.0, 1.0, 2e-15, 2e-9])
    scale = np.array([1.0, 1.0, 1.0, np.nan, 1.0])
    index = shape_index(k_min, k_max, scale)
    # round-off curvatures at a scale of 1: flat; exact zeros: flat; a saddle: 0; no scale: only zeros are flat
    assert np.isnan(index[0]) and np.isnan(index[1]) and index[2] == 0.0
    assert index[3] == pytest.approx((2 / np.pi) * np.arctan2(3e-15, 1e-15))
    assert index[4] == pytest.approx(1.0)  # 2e-9 of 1/scale is above the floor: an umbilic cap
    np.testing.assert_array_equal(np.isnan(shape_index(k_min, k_max)), [False, True, False, False, False])
