"""The kernels of :mod:`meshcurv._kernels.pointcloud_graph` against their NumPy twins (issue 31).

Each kernel computes what its NumPy twin computes, to the bit: the Morton codes
and their stable order of :func:`meshcurv.pointcloud._spatial_order` (a stable
order is unique), the spanning forest of
:func:`meshcurv._kernels.pointcloud.spanning_signs` (the same unions in the same
order) with the sheets of :func:`meshcurv._pointcloud_normals._sheets` read off
its union-find (numbered as :func:`scipy.sparse.csgraph.connected_components`
numbers them: by their first point), and the torn edges of
:func:`meshcurv._pointcloud_normals.oriented_signs`.
"""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("numba")

from meshcurv._backend import use_backend  # noqa: E402
from meshcurv._kernels import pointcloud as cloud_kernels  # noqa: E402
from meshcurv._kernels import pointcloud_graph  # noqa: E402
from meshcurv._pointcloud_normals import (  # noqa: E402
    PARALLEL_COSINE,
    PART_MIN_POINTS,
    _sheets,
    knn,
    local_spacing,
    oriented_signs,
    pca_normals,
)
from meshcurv.pointcloud import MORTON_BITS, _morton_codes  # noqa: E402

TOP = np.uint64(2**MORTON_BITS - 1)


def sphere_cloud(n: int = 3000, seed: int = 0) -> np.ndarray:
    """``n`` points drawn uniformly on the unit sphere."""
    u = np.random.default_rng(seed).normal(size=(n, 3))
    return u / np.linalg.norm(u, axis=1, keepdims=True)


def morton_inputs(points):
    low = points.min(axis=0)
    return low, (2.0**MORTON_BITS - 1) / float((points.max(axis=0) - low).max())


@pytest.mark.parametrize("kind", ["sphere", "lattice", "clipped"])
def test_morton_codes_and_their_order_are_numpys(kind):
    points = sphere_cloud(5000)
    if kind == "lattice":  # many equal codes (coincident points): the stable order keeps their input order
        points = np.round(points * 4.0) / 4.0
    low, scale = morton_inputs(points)
    if kind == "clipped":  # cells beyond the top one are clipped to it
        scale *= 1.5
    expected = _morton_codes(points, low, scale)
    got = pointcloud_graph.morton_codes(points, low, scale, TOP)
    np.testing.assert_array_equal(got, expected)
    order, ordered = pointcloud_graph.stable_order(got)
    np.testing.assert_array_equal(order, np.argsort(expected, kind="stable"))
    np.testing.assert_array_equal(ordered, expected[order])


def test_stable_order_of_any_codes():
    rng = np.random.default_rng(3)
    for codes in (
        rng.integers(0, 2**63, 4000, dtype=np.uint64),  # every byte used
        rng.integers(0, 8, 4000, dtype=np.uint64) << np.uint64(40),  # most bytes zero, many ties
        np.zeros(7, dtype=np.uint64),
        np.zeros(0, dtype=np.uint64),
    ):
        order, ordered = pointcloud_graph.stable_order(codes)
        np.testing.assert_array_equal(order, np.argsort(codes, kind="stable"))
        np.testing.assert_array_equal(ordered, np.sort(codes))


def random_forest_inputs(seed: int, n: int = 600, e: int = 1500, flat_share: float = 0.8):
    """A random graph: edges, opposite relations, a flat mask and an order with every flat edge first."""
    rng = np.random.default_rng(seed)
    rows, cols = rng.integers(0, n, e), rng.integers(0, n, e)
    flat = rng.random(e) < flat_share
    opposite = (rng.random(e) < 0.3).astype(np.int8)
    # weights as oriented_signs gives them: flat edges below 3, the others at 3 or more; ties among both
    weights = np.where(flat, np.round(rng.random(e), 1), 3.0 + np.round(rng.random(e), 1))
    return n, rows, cols, opposite, np.argsort(weights), int(flat.sum()), flat


@pytest.mark.parametrize(("seed", "flat_share"), [(0, 0.8), (1, 0.8), (2, 0.8), (3, 1.0)])
def test_spanning_sheets_is_spanning_signs_and_the_sheets(seed, flat_share):
    n, rows, cols, opposite, order, n_flat, flat = random_forest_inputs(seed, flat_share=flat_share)
    signs, roots, sheets = pointcloud_graph.spanning_sheets(n, rows, cols, opposite, order, n_flat, PART_MIN_POINTS)
    expected_signs, expected_roots = cloud_kernels.spanning_signs(n, rows, cols, opposite, order)
    np.testing.assert_array_equal(signs, expected_signs)
    np.testing.assert_array_equal(roots, expected_roots)
    # the components of the flat edges, numbered by their first point as scipy's connected_components does
    with use_backend("numpy"):
        np.testing.assert_array_equal(sheets, _sheets(n, rows[flat], cols[flat]))
    assert (sheets >= 0).any() and (sheets < 0).any()  # (large sheets and small ones)


def test_spanning_sheets_numbers_the_sheets_as_scipy_does():
    # a chain per sheet: sheets 0..k-1 whose first points come in that order, PART_MIN_POINTS points and more
    n = 4 * PART_MIN_POINTS + 10
    perm = np.random.default_rng(4).permutation(n)
    groups = np.array_split(perm, 4)
    rows = np.concatenate([g[:-1] for g in groups] + [groups[0][:1]])
    cols = np.concatenate([g[1:] for g in groups] + [groups[1][:1]])  # last edge: stacked, joins two sheets
    flat = np.ones(rows.size, dtype=bool)
    flat[-1] = False
    order = np.arange(rows.size)
    _, _, sheets = pointcloud_graph.spanning_sheets(
        n, rows, cols, np.zeros(rows.size, dtype=np.int8), order, rows.size - 1, PART_MIN_POINTS
    )
    with use_backend("numpy"):
        np.testing.assert_array_equal(sheets, _sheets(n, rows[flat], cols[flat]))
    # re-indexing the points moves the sheets with them: the same partition
    inverse = np.argsort(perm)
    _, _, moved = pointcloud_graph.spanning_sheets(
        n, inverse[rows], inverse[cols], np.zeros(rows.size, dtype=np.int8), order, rows.size - 1, 1
    )
    pairs = np.unique(np.column_stack([sheets[perm], moved[inverse[perm]]]), axis=0)
    assert pairs.shape[0] == 4


def test_torn_ends_are_numpys():
    rng = np.random.default_rng(6)
    n, e = 500, 3000
    rows, cols = rng.integers(0, n, e), rng.integers(0, n, e)
    flat = rng.random(e) < 0.7
    cosine = rng.uniform(-1.0, 1.0, e)
    signs = np.where(rng.random(n) < 0.5, -1.0, 1.0)
    torn = flat & (np.abs(cosine) >= PARALLEL_COSINE) & (signs[rows] * signs[cols] * cosine < 0)
    expected = np.zeros(n, dtype=bool)
    expected[rows[torn]] = expected[cols[torn]] = True
    got = pointcloud_graph.torn_ends(flat, cosine, signs, rows, cols, PARALLEL_COSINE, np.zeros(n, dtype=bool))
    np.testing.assert_array_equal(got, expected)


def test_the_sheets_are_the_same_on_both_backends():
    # three unit spheres 3 apart, their points shuffled: three sheets, numbered by their first point on both
    # backends (the compiled one numbered them by the union-find's roots: 0, 2, 1 here)
    rng = np.random.default_rng(0)
    u = sphere_cloud(6000, seed=0)
    points = np.concatenate([u[:2000], u[2000:4000] + [3.0, 0.0, 0.0], u[4000:] + [0.0, 3.0, 0.0]])
    points = points[rng.permutation(points.shape[0])]
    from scipy.spatial import cKDTree

    tree = cKDTree(points)
    distances, indices = knn(tree, points)
    usable = np.ones(points.shape[0], dtype=bool)
    spacing = local_spacing(distances)
    results = {}
    for backend in ("numpy", "numba"):
        with use_backend(backend):
            normals = pca_normals(points, indices)
            results[backend] = oriented_signs(points, normals, indices, usable, spacing, tree), normals
    (expected, expected_normals), (got, got_normals) = results["numpy"], results["numba"]
    first = np.unique(got[3], return_index=True)[1]
    assert np.unique(got[3]).tolist() == [0, 1, 2] and (np.diff(first) > 0).all()
    np.testing.assert_array_equal(got[3], expected[3])
    np.testing.assert_array_equal(got[2], expected[2])  # doubtful
    # outward on both: the oriented normals agree
    agree = np.einsum("ij,ij->i", got_normals * got[0][:, None], expected_normals * expected[0][:, None])
    assert (agree > 0).all()


def test_gathered_results_are_numpys():
    from meshcurv.pointcloud import _UNDEFINED, _gathered_results

    rng = np.random.default_rng(10)
    n, m = 400, 1000
    take = rng.integers(0, n, m)
    k_min, k_max = rng.normal(size=n), rng.normal(size=n)
    k_min[rng.random(n) < 0.1] = np.nan  # (a valid point with a NaN curvature becomes invalid)
    k_max[rng.random(n) < 0.05] = np.inf
    dir_min, dir_max, normals = rng.normal(size=(n, 3)), rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    valid = rng.random(n) < 0.8
    reason = rng.integers(0, 4, n).astype(np.int8)
    expected = _gathered_results(take, k_min, k_max, dir_min, dir_max, normals, valid, reason)
    got = pointcloud_graph.gathered_results(take, k_min, k_max, dir_min, dir_max, normals, valid, reason, _UNDEFINED)
    for value, reference in zip(got, expected):
        assert value.dtype == reference.dtype and value.shape == reference.shape
        np.testing.assert_array_equal(value, reference)
