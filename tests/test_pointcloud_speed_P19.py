"""What the point-cloud speed changes of issue 31 (P19) must keep: the same balls, sums and checks.

The ball search (of ``pointcloud.measured_balls``) sorts each ball's points by a bucket sort and one insertion
pass instead of inserting them one by one: the rows must be those of the definition, the points closer than the radius in the order of
``(squared distance, index)`` (ties by index: a lattice's), cut to the ``k`` nearest. The measures' kernels
read the balls' rows in place (``rows``) instead of gathered copies: the same sums and flat-ball tests as over
the copies. The check of unsteady estimates compares the pairs of curvatures without stacking them: NaN on
either side is unsteady, as before.
"""

from __future__ import annotations

import numpy as np
import pytest

from meshcurv._pointcloud_estimators import AGREEMENT, FLAT_TURN, unsteady


def lattice_dome(side: int = 30) -> np.ndarray:
    """A ``side`` x ``side`` unit lattice, every point at the same height but a ring of them raised by 1: many
    equal distances (a lattice's ties) and some that differ."""
    x, y = np.meshgrid(np.arange(side, dtype=float), np.arange(side, dtype=float))
    z = np.where((x - side / 2) ** 2 + (y - side / 2) ** 2 < (side / 4) ** 2, 1.0, 0.0)
    return np.column_stack([x.ravel(), y.ravel(), z.ravel()])


def brute_balls(points, centres, radius, k):
    """The definition: the points strictly closer than ``radius``, ordered by (squared distance, index), the
    first ``k``; padded with ``N`` (index) and inf (squared distance)."""
    n = points.shape[0]
    index = np.full((centres.size, k), n, dtype=np.int64)
    squared = np.full((centres.size, k), np.inf)
    counts = np.zeros(centres.size, dtype=np.int64)
    for row, c in enumerate(centres):
        step = points - points[c]
        d = step[:, 0] * step[:, 0] + step[:, 1] * step[:, 1] + step[:, 2] * step[:, 2]
        inside = np.flatnonzero(d < radius * radius)
        inside = inside[np.lexsort((inside, d[inside]))][:k]
        index[row, : inside.size], squared[row, : inside.size], counts[row] = inside, d[inside], inside.size
    return index, squared, counts


@pytest.mark.parametrize(("radius", "k"), [(3.0, 40), (3.0, 12), (4.5, 96), (0.5, 8)])
def test_ball_search_rows_are_the_definitions(radius, k):
    pytest.importorskip("numba")
    from test_kernel_twins import searched_balls

    points = lattice_dome()
    rng = np.random.default_rng(7)
    points = np.concatenate([points, rng.uniform(0, 29, size=(300, 3))])  # and points at distinct distances
    centres = np.arange(0, points.shape[0], 7)
    # the search of the measures' balls (pointcloud.measured_balls) alone: no normals, no tie tolerance
    got = searched_balls(points, centres, radius, k)
    expected = brute_balls(points, centres, radius, k)
    np.testing.assert_array_equal(got[0], expected[0])
    np.testing.assert_array_equal(got[1], expected[2])
    # and smaller balls than the search's: the prefixes of its rows closer than the radius
    got = searched_balls(points, centres, radius, k, wide=1.5 * radius, k_wide=2 * k)
    np.testing.assert_array_equal(got[0], expected[0])
    np.testing.assert_array_equal(got[1], expected[2])


def test_measures_kernels_read_the_rows_in_place():
    pytest.importorskip("numba")
    from meshcurv._backend import numba_kernels
    from meshcurv._pointcloud_estimators import EDGE_ON, TRIANGLES, _rank_pattern, flat_balls
    from test_kernel_twins import searched_balls

    kernels = numba_kernels("pointcloud")
    rng = np.random.default_rng(3)
    u = rng.normal(size=(3000, 3))
    points = u / np.linalg.norm(u, axis=1, keepdims=True)  # unit sphere: normals = points
    normals = points.copy()
    centres = np.arange(0, 3000, 3)
    radius = 0.2
    index, counts, _, _ = searched_balls(points, centres, radius, 40)
    counts[::5] = 2  # rows too small to measure, and rows left out, in the selection or not
    rows = np.flatnonzero(np.arange(centres.size) % 3 != 1)
    pattern = _rank_pattern(TRIANGLES)
    in_place = kernels.ball_triangle_sums(points, normals, index, counts, pattern, EDGE_ON, rows)
    gathered = kernels.ball_triangle_sums(points, normals, index[rows], counts[rows], pattern, EDGE_ON)
    np.testing.assert_array_equal(in_place, gathered)
    np.testing.assert_array_equal(
        flat_balls(points, centres, index, counts, rows), flat_balls(points, centres[rows], index[rows], counts[rows])
    )
    # H = mu_1 / (2 mu_0) of a unit sphere with outward normals: +1 (the triangles' sums are a measurement)
    full = counts[rows] > 3
    mean = in_place[full, 1] / (2 * in_place[full, 0])
    assert np.median(mean) == pytest.approx(1.0, abs=0.05)


def test_unsteady_compares_the_pairs_and_flags_nan():
    radius = 1.0
    found = (np.array([1.0, 1.0, np.nan, 0.0, -2.0, 0.01]), np.array([2.0, 2.0, 1.0, 0.0, -1.0, 0.02]))
    larger = (np.array([1.1, 1.0, 1.0, 0.0, -2.0, 0.015]), np.array([2.2, 3.0, 1.0, np.nan, -1.5, 0.025]))
    flagged = unsteady(found, larger, np.arange(6), radius)
    # row 0: off by 0.2 of 2 (<= AGREEMENT); row 1: k_max off by 1 of 2 (> AGREEMENT); rows 2 and 3: NaN on
    # one side; row 4: off by 0.5 of 2 (<= 0.4 * 2); row 5: |k| below FLAT_TURN / radius, the scale is
    # FLAT_TURN (off by 0.005 <= 0.4 * 0.05)
    assert AGREEMENT == 0.4 and FLAT_TURN == 0.05
    np.testing.assert_array_equal(flagged, [False, True, True, True, False, False])
    # centres not checked stay False; an agreement per centre
    per_centre = unsteady(found, larger, np.array([0, 4]), radius, np.array([0.01, 0.3]))
    np.testing.assert_array_equal(per_centre, [True, False, False, False, False, False])
