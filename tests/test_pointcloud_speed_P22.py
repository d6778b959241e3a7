"""What the point-cloud speed changes of issue 31 (P22) must keep: the same triangle sums and flat-ball tests.

The measures' kernel draws each ball's triangles from a table of ranks per count of points instead of drawing
them triangle by triangle, and turns a triangle of negative corrected area by negating its measures instead of
swapping its corners: the sums must be those of the definition, to the bit (each triangle's measures as
``_triangle_measures`` with ``turn`` gives them, summed in the pattern's order, edge-on ones left out). The flat
balls' test keeps the offsets it divided: the same decisions as the NumPy path's, on balls that hold a surface
and balls that hold a line.
"""

from __future__ import annotations

import numpy as np
import pytest


def definition_sums(points, normals, index, counts, pattern, edge_on, rows):
    """The sums of the definition, one triangle at a time: the ranks ``floor(u c)``, ``floor(u' (c - 1))``,
    ``floor(u'' (c - 2))`` moved past the ones before, ``_triangle_measures`` with ``turn``."""
    from meshcurv._kernels.icc import _triangle_measures
    from meshcurv._kernels.pointcloud import _edge_on

    out = np.zeros((rows.size, 9))
    for r, row in enumerate(rows):
        c = int(counts[row])
        total = [0.0] * 9
        for u, v, w in pattern:
            a = int(np.floor(u * c))
            b = int(np.floor(v * (c - 1)))
            b += b >= a
            z = int(np.floor(w * (c - 2)))
            z += z >= min(a, b)
            z += z >= max(a, b)
            assert len({a, b, z}) == 3 and max(a, b, z) < c
            i, j, k = index[row, a], index[row, b], index[row, z]
            if _edge_on(points, normals, i, j, k, edge_on):
                continue
            total = [s + m for s, m in zip(total, _triangle_measures(points, normals, i, j, k, True))]
        out[r] = total
    return out


def test_triangle_sums_are_the_definitions():
    pytest.importorskip("numba")
    from meshcurv._backend import numba_kernels
    from meshcurv._pointcloud_estimators import EDGE_ON, _rank_pattern

    rng = np.random.default_rng(22)
    n = 400
    points = rng.normal(size=(n, 3))
    normals = rng.normal(size=(n, 3))  # any signs: about half the triangles have a negative corrected area
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    normals[:40] = [0.0, 0.0, 1.0]  # and edge-on triangles: points of a vertical plane, normals along it
    points[:40, 2] = rng.normal(size=40)
    points[:40, 1] = 0.0
    k = 60
    index = np.stack([rng.permutation(n)[:k] for _ in range(120)])
    index[:20, :30] = rng.permuted(np.tile(np.arange(40), (20, 1)), axis=1)[:, :30]
    counts = rng.integers(3, k + 1, size=120)
    counts[:20] = 30
    pattern = _rank_pattern(32)
    rows = np.arange(0, 120, 3)
    got = numba_kernels("pointcloud").ball_triangle_sums(points, normals, index, counts, pattern, EDGE_ON, rows)
    wanted = definition_sums(points, normals, index, counts, pattern, EDGE_ON, rows)
    np.testing.assert_array_equal(got, wanted)
    every = numba_kernels("pointcloud").ball_triangle_sums(points, normals, index, counts, pattern, EDGE_ON)
    np.testing.assert_array_equal(every[rows], got)


def test_flat_balls_decide_as_the_numpy_path():
    pytest.importorskip("numba")
    from meshcurv._backend import numba_kernels, use_backend
    from meshcurv._pointcloud_estimators import flat_balls

    rng = np.random.default_rng(5)
    plane = np.column_stack([rng.random(600), rng.random(600), np.zeros(600)])
    line = np.column_stack([np.linspace(0, 1, 200), np.full(200, 2.0), rng.normal(scale=1e-3, size=200)])
    points = np.concatenate([plane, line])
    centres = np.concatenate([np.arange(0, 600, 11), 600 + np.arange(0, 200, 7)])
    step = points[centres][:, None, :] - points[None, :, :]
    squared = np.einsum("mnd,mnd->mn", step, step)
    order = np.argsort(squared, axis=1, kind="stable")[:, :80]
    counts = (np.take_along_axis(squared, order, axis=1) < 0.15**2).sum(axis=1)
    index = np.where(np.arange(80)[None, :] < counts[:, None], order, points.shape[0])
    got = flat_balls(points, centres, index, counts)
    assert numba_kernels("pointcloud") is not None
    with use_backend("numpy"):
        wanted = flat_balls(points, centres, index, counts)
    assert got.any() and not got.all()  # (both kinds of balls)
    np.testing.assert_array_equal(got, wanted)
    rows = np.arange(1, centres.size, 2)
    np.testing.assert_array_equal(flat_balls(points, centres, index, counts, rows), wanted[rows])
