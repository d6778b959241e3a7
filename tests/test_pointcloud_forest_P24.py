"""The orientation's forest with fewer serial passes (issue 31, P24).

:func:`meshcurv._kernels.pointcloud_graph._single_edge_keys` hands the forest its single edges compacted with
their sort keys and their count of flat edges (the NumPy lines ``flatnonzero``, ``weights[single]``,
``flat[single]`` and the keys of ``_forest_order`` before); :func:`~meshcurv._kernels.pointcloud_graph.stable_order`
counts and places the codes on every core; the walk of
:func:`~meshcurv._kernels.pointcloud_graph.spanning_sheets` holds 32-bit indices and reads the roots on every
core. Each must give what the serial NumPy lines give, to the bit.
"""

from __future__ import annotations

import numpy as np
import pytest

from test_pointcloud_forest_P23 import clouds, graph_of


@pytest.mark.parametrize("name", ["sphere", "noisy", "dome", "two"])
def test_single_edge_keys_are_the_numpy_lines(name):
    pytest.importorskip("numba")
    from meshcurv._kernels import pointcloud_graph
    from meshcurv._pointcloud_normals import PART_MIN_POINTS, TIE_RESOLUTION, _forest_order

    points = clouds()[name]
    graph, rows, cols, kept, flat, used, weights, opposite = graph_of(points)
    single = pointcloud_graph._single_edges(graph, kept, used, weights)
    positions, codes, n_flat, fits = pointcloud_graph._single_edge_keys(
        graph, kept, used, flat, weights, 1.0 / TIE_RESOLUTION
    )
    np.testing.assert_array_equal(positions, np.flatnonzero(single))
    assert n_flat == np.count_nonzero(flat[single])
    assert fits
    np.testing.assert_array_equal(codes, np.rint(weights[single] * (1.0 / TIE_RESOLUTION)).astype(np.uint64))
    order = pointcloud_graph.stable_order(codes)[0]
    np.testing.assert_array_equal(order, _forest_order(weights[single]))
    # the forest over them: the signs, roots and sheets of the walk over every used edge
    n = points.shape[0]
    expected = pointcloud_graph.spanning_sheets(
        n,
        rows,
        cols,
        opposite.view(np.int8),
        np.flatnonzero(used)[_forest_order(weights[used])],
        int(np.count_nonzero(flat)),
        PART_MIN_POINTS,
    )
    got = pointcloud_graph.spanning_sheets(
        n, rows, cols, opposite.view(np.int8), positions[order], n_flat, PART_MIN_POINTS
    )
    for a, b in zip(got, expected):
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("bad", [np.nan, -1.0, 1e30])
def test_single_edge_keys_say_when_a_weight_does_not_fit(bad):
    pytest.importorskip("numba")
    from meshcurv._kernels import pointcloud_graph
    from meshcurv._pointcloud_normals import TIE_RESOLUTION

    graph, rows, cols, kept, flat, used, weights, opposite = graph_of(clouds()["sphere"])
    weights = weights.copy()
    assert pointcloud_graph._single_edge_keys(graph, kept, used, flat, weights, 1.0 / TIE_RESOLUTION)[3]
    weights[np.flatnonzero(used)[7]] = bad  # (a used edge of the first rows: single, the earlier way)
    assert not pointcloud_graph._single_edge_keys(graph, kept, used, flat, weights, 1.0 / TIE_RESOLUTION)[3]


@pytest.mark.parametrize("n", [1, 2, 63, 64, 65, 1000, 100_003])
def test_stable_order_on_every_core_is_argsorts(n):
    pytest.importorskip("numba")
    from meshcurv._kernels import pointcloud_graph

    rng = np.random.default_rng(n)
    for codes in (
        rng.integers(0, 2**63, n, dtype=np.uint64),
        rng.integers(0, 5, n, dtype=np.uint64) << np.uint64(24),  # ties by the thousand, three bytes zero
        np.sort(rng.integers(0, 300, n, dtype=np.uint64))[::-1].copy(),  # descending runs across the ranges
    ):
        order, ordered = pointcloud_graph.stable_order(codes)
        np.testing.assert_array_equal(order, np.argsort(codes, kind="stable"))
        np.testing.assert_array_equal(ordered, codes[order])


def test_spanning_sheets_on_a_chain_of_long_paths():
    # unions that hang long chains before any root is read: the roots read on every core are the serial ones
    pytest.importorskip("numba")
    from meshcurv._kernels import pointcloud, pointcloud_graph

    n = 5000
    rng = np.random.default_rng(24)
    rows = np.concatenate([np.arange(n - 1), rng.integers(0, n, 3000)])
    cols = np.concatenate([np.arange(1, n), rng.integers(0, n, 3000)])
    opposite = (rng.random(rows.size) < 0.5).astype(np.int8)
    order = np.concatenate([np.arange(0, n - 1, 2), np.arange(1, n - 1, 2), np.arange(n - 1, rows.size)])
    for n_flat in (0, n // 2, n - 1, rows.size):
        signs, roots, sheets = pointcloud_graph.spanning_sheets(n, rows, cols, opposite, order, n_flat, 10)
        expected_signs, expected_roots = pointcloud.spanning_signs(n, rows, cols, opposite, order)
        np.testing.assert_array_equal(signs, expected_signs)
        np.testing.assert_array_equal(roots, expected_roots)
        assert roots.dtype == np.int64
