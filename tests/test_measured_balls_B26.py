"""The measures' balls in one pass (issue 31): ``pointcloud.measured_balls`` against its NumPy twin.

:func:`meshcurv._kernels.pointcloud.measured_balls` searches each centre's ball once for both radii of
:func:`meshcurv._pointcloud_estimators.corrected_measures` (the estimate and its check) and cuts the ties and the
points facing away in the thread that found the row. Its balls must be those of the search, the tie cut and the
side filter run one after the other: the NumPy twin (``_measured_balls``: k-d tree queries, ``_whole_ties``,
``_own_side``), to the bit. The clouds: an ellipsoid with noise (no ties) beside a square lattice (its points at
one distance in fours and eights: cuts through tied runs, runs ordered by their keys), some normals turned (points
facing away), some NaN, and sheets.
"""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("numba")


def _cloud():
    rng = np.random.default_rng(26)
    # an ellipsoid (3, 2, 1) by random angles (denser at its poles), its outward normals, noise of 0.01
    z, phi = rng.uniform(-1.0, 1.0, 3000), rng.uniform(0.0, 2.0 * np.pi, 3000)
    ring = np.sqrt(1.0 - z * z)
    points = np.column_stack([3.0 * ring * np.cos(phi), 2.0 * ring * np.sin(phi), z])
    normals = points / np.array([9.0, 4.0, 1.0])
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    points += 0.01 * rng.standard_normal(points.shape)
    x, y = (grid.ravel() for grid in np.meshgrid(np.arange(20.0), np.arange(20.0)))
    lattice = np.column_stack([x, y, np.zeros(x.size)]) * 0.05 + 5.0
    lattice_normals = np.column_stack([0.1 * np.sin(x), 0.05 * y, np.ones(x.size)])
    lattice_normals /= np.linalg.norm(lattice_normals, axis=1, keepdims=True)
    lattice_normals[::9] = np.nan
    points = np.concatenate([points, lattice])
    normals = np.concatenate([normals, lattice_normals])
    turned = rng.random(points.shape[0]) < 0.1
    normals[turned] *= -1.0
    return np.ascontiguousarray(points), np.ascontiguousarray(normals), rng


@pytest.mark.parametrize("with_sheets", [False, True])
@pytest.mark.parametrize(("k", "k_wide"), [(11, 0), (11, 24), (24, 48), (40, 96)])
def test_measured_balls_are_the_steps_to_the_bit(k, k_wide, with_sheets):
    from scipy.spatial import cKDTree

    from meshcurv._kernels.neighborhoods import pool_grid
    from meshcurv._kernels.pointcloud import measured_balls
    from meshcurv._pointcloud_estimators import (
        FACING_MARGIN,
        LARGER,
        MIN_BALL_POINTS,
        SQUARED_TIE,
        _measured_balls,
        _usable_tree,
    )

    points, normals, rng = _cloud()
    n = points.shape[0]
    radius = 0.12  # the lattice's step 0.05: 2.4 steps; the wide balls 3.4 steps (rings of 4 and 8 tied points)
    wide = radius * LARGER
    usable = rng.random(n) > 0.15
    chunk = np.flatnonzero(rng.random(n) > 0.4)
    sheets = rng.integers(-1, 3, n) if with_sheets else None
    own_sheets = np.zeros(0, dtype=np.int64) if sheets is None else sheets.astype(np.int64)
    grid = pool_grid(points, np.flatnonzero(usable), float(wide if k_wide else radius))
    got = measured_balls(
        points,
        normals,
        chunk,
        radius,
        k,
        wide,
        k_wide,
        *grid,
        own_sheets,
        SQUARED_TIE,
        MIN_BALL_POINTS,
        FACING_MARGIN,
        8,
    )
    twin = _measured_balls(
        _usable_tree(cKDTree(points), points, usable), points, normals, chunk, radius, k, wide, k_wide, sheets
    )
    names = ("index", "counts", "wide_index", "wide_counts")
    for name, a, b in zip(names, got, twin):
        np.testing.assert_array_equal(a, b, err_msg=f"{name} against the NumPy twin")
    assert got[0].shape == (chunk.size, k) and got[2].shape == (chunk.size, k_wide)
    # the inputs meant something: cuts and balls less points facing away
    assert (got[1] < k).any() and (got[1] > 0).any()
    if k_wide:
        assert (got[3] >= got[1]).mean() > 0.9  # (the larger balls hold more points, but for their own cuts)


def test_measured_balls_on_a_lattice_cut_ties_whole():
    """On a square lattice the rings of points at one distance are taken or dropped whole: every count is a sum of
    whole rings (1, 4, 4, 4, 8, ...), never a ring cut by the index or the round-off."""
    from meshcurv._kernels.neighborhoods import pool_grid
    from meshcurv._kernels.pointcloud import measured_balls
    from meshcurv._pointcloud_estimators import FACING_MARGIN, MIN_BALL_POINTS, SQUARED_TIE

    x, y = (grid.ravel() for grid in np.meshgrid(np.arange(30.0), np.arange(30.0)))
    points = np.ascontiguousarray(np.column_stack([x, y, np.zeros(x.size)]))
    normals = np.ascontiguousarray(np.tile([0.0, 0.0, 1.0], (x.size, 1)))
    inside = np.flatnonzero((x >= 5) & (x < 25) & (y >= 5) & (y < 25))
    grid = pool_grid(points, np.arange(x.size), 3.5)
    # the offsets' squared lengths within 3.5: 0 (1), 1 (4), 2 (4), 4 (4), 5 (8), 8 (4), 9 (4), 10 (8)
    rings = np.cumsum([1, 4, 4, 4, 8, 4, 4, 8])
    none = np.zeros(0, dtype=np.int64)
    for k, k_wide in ((10, 0), (16, 30), (21, 37)):
        index, counts, wide_index, wide_counts = measured_balls(
            points, normals, inside, 2.5, k, 3.5, k_wide, *grid, none, SQUARED_TIE, MIN_BALL_POINTS, FACING_MARGIN, 4
        )
        assert np.isin(counts, rings).all(), k
        # 2.5: 21 points within the radius; at most k of them, whole rings
        assert (counts == rings[rings <= min(k, 21)].max()).all(), k
        if k_wide:
            assert (wide_counts == rings[rings <= k_wide].max()).all(), k_wide


@pytest.mark.parametrize("with_centres", [False, True])
def test_cut_neighbours_is_its_numpy_twin_to_the_bit(with_centres):
    """``pointcloud.cut_neighbours`` (the k nearest cut whole at a tie, compiled) against
    ``_pointcloud_normals._cut_neighbours`` on a lattice's neighbours (rings of tied distances, cut through) and
    on rows with ties built in: within round-off of the cut, NaN and infinite distances, ties too long to drop."""
    from scipy.spatial import cKDTree

    from meshcurv._kernels.pointcloud import cut_neighbours
    from meshcurv._pointcloud_normals import TIE_LEAST, TIE_TOLERANCE, _cut_neighbours

    x, y = (grid.ravel() for grid in np.meshgrid(np.arange(15.0), np.arange(15.0)))
    lattice = np.column_stack([x, y, np.zeros(x.size)]) * 0.3
    rng = np.random.default_rng(31)
    rows = [cKDTree(lattice).query(lattice, k=k + 2) for k in (4, 6, 10)]
    built = np.sort(rng.random((400, 11)), axis=1)
    tie = rng.random(400) < 0.5
    built[tie, 9] = built[tie, 10] * (1 - 0.5 * rng.random(tie.sum()) * TIE_TOLERANCE)  # within the tolerance
    built[tie, 7:9] = built[tie, 10, None]
    built[:3, 2:] = built[:3, 10, None]  # a tie over most of the row: kept as the query cut it
    built[3:6, 10] = np.nan
    built[6:9, 8:] = np.inf
    cases = [(d[:, 1:], i[:, 1:]) for d, i in rows] + [(built, rng.integers(0, 1000, built.shape))]
    for distances, indices in cases:
        k = distances.shape[1] - 1
        centres = rng.permutation(distances.shape[0]) if with_centres else None
        expected = _cut_neighbours(distances, indices, k, centres)
        got = cut_neighbours(
            np.ascontiguousarray(distances),
            np.ascontiguousarray(indices, dtype=np.int64),
            k,
            np.zeros(0, dtype=np.int64) if centres is None else centres.astype(np.int64),
            TIE_TOLERANCE,
            TIE_LEAST,
        )
        np.testing.assert_array_equal(got[0], expected[0], err_msg=f"distances, k={k}")
        np.testing.assert_array_equal(got[1], expected[1], err_msg=f"indices, k={k}")
        assert (expected[1] != indices[:, :k]).any(), k  # (some groups dropped whole)
