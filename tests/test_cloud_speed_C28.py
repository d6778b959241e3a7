"""What the point-cloud speed changes of issue 31 (C28) must keep: the same orders, signs and checks.

The orientation's forest takes its edges from a radix sort that now carries the edges themselves through its
passes (no gather of them in the sorted order afterwards): the values must be those of the stable order. The
check of unsteady estimates now keeps no directions of its larger balls: the curvatures it compares are the same.
"""

from __future__ import annotations

import numpy as np
import pytest


@pytest.mark.parametrize("n", [0, 1, 7, 5000])
def test_stable_order_carries_the_values_in_the_stable_order(n):
    pytest.importorskip("numba")
    from meshcurv._kernels import pointcloud_graph

    rng = np.random.default_rng(n)
    # codes with many ties (a stable order keeps them in their order) and some large bytes
    codes = (rng.integers(0, 50, n).astype(np.uint64) << np.uint64(rng.integers(0, 40))) + rng.integers(0, 3, n).astype(
        np.uint64
    )
    values = rng.integers(-(2**40), 2**40, n)
    given = values.copy()
    order = np.argsort(codes, kind="stable")
    carried, ordered = pointcloud_graph.stable_order(codes, values)
    np.testing.assert_array_equal(carried, values[order])
    np.testing.assert_array_equal(ordered, codes[order])
    np.testing.assert_array_equal(pointcloud_graph.stable_order(codes)[0], order)
    np.testing.assert_array_equal(values, given)  # (the input not changed)


@pytest.mark.parametrize("backend", ["numba", "numpy"])
def test_the_check_of_larger_balls_flags_as_with_their_directions(backend, monkeypatch):
    # corrected_measures' details["unsteady"]: computed from the larger balls' curvatures only; the same flags as
    # when the larger balls' directions are kept (a _measured that writes every field)
    from conftest import chosen_backend

    from meshcurv import _pointcloud_estimators as estimators

    rng = np.random.default_rng(3)
    u = rng.normal(size=(4000, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    points = u * [3.0, 2.0, 1.0] + 0.02 * rng.standard_normal((4000, 3))  # noisy: some estimates unsteady
    normals = u / [3.0, 2.0, 1.0]
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    from scipy.spatial import cKDTree

    tree, usable, centres = cKDTree(points), np.ones(4000, dtype=bool), np.arange(4000)
    found = {}
    with chosen_backend(backend):
        details: dict = {}
        found["new"] = estimators.corrected_measures(
            tree, points, normals, 0.3, centres, usable, spacing=0.06, details=details
        )
        flagged = details["unsteady"]
        measured = estimators._measured
        seen = []

        def every_field(out, *args, **kwargs):
            if out[2] is None:  # the larger balls: their directions written too, as before
                out[2], out[3] = np.full((4000, 3), np.nan), np.full((4000, 3), np.nan)
                seen.append(out)
            return measured(out, *args, **kwargs)

        monkeypatch.setattr(estimators, "_measured", every_field)
        details = {}
        found["old"] = estimators.corrected_measures(
            tree, points, normals, 0.3, centres, usable, spacing=0.06, details=details
        )
    assert seen and np.isfinite(seen[0][2]).any()
    np.testing.assert_array_equal(details["unsteady"], flagged)
    assert 0 < flagged.sum() < 4000
    for a, b in zip(found["new"], found["old"]):
        np.testing.assert_array_equal(a, b)
