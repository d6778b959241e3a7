"""The orientation's forest over each edge of the graph taken one way (issue 31, P23).

A k nearest graph holds most of its edges both ways, ``i -> j`` and ``j -> i``, of equal weights: in the forest's
stable order of the weights the one of the earlier row comes first, and when Kruskal's walk reaches the other its
ends are one tree already. :func:`meshcurv._kernels.pointcloud_graph._single_edges` drops those later ways; the
walk over what is left must make the same unions (the same signs, roots and sheets, to the bit), on lattices too,
whose weights tie by the thousand.
"""

from __future__ import annotations

import numpy as np
import pytest


def graph_of(points):
    """The inputs of the orientation's forest as :func:`meshcurv._pointcloud_normals.oriented_signs` forms them."""
    from scipy.spatial import cKDTree

    from meshcurv._backend import numba_kernels
    from meshcurv._pointcloud_normals import (
        FACING_COSINE,
        GRAPH_NEIGHBOURS,
        STACKED_OFFSET,
        _supported,
        knn,
        local_spacing,
        pca_normals,
    )

    distances, indices = knn(cKDTree(points), points)
    normals = pca_normals(points, indices)
    spacing = local_spacing(distances)
    usable = np.ones(points.shape[0], dtype=bool)
    usable[::97] = False  # (some points left out: rows of fewer edges)
    graph = np.ascontiguousarray(indices[:, :GRAPH_NEIGHBOURS])
    compiled = numba_kernels("pointcloud")
    rows, cols, kept, ahead, behind, cosine, slope = compiled.graph_edges(points, normals, graph, usable)
    flat = _supported(slope <= 0.4, slope, rows, cols, kept, graph)
    stacked, weights, opposite = compiled.edge_weights(
        flat, ahead, behind, cosine, slope, spacing, rows, cols, STACKED_OFFSET, FACING_COSINE
    )
    return graph, rows, cols, kept, flat, flat | stacked, weights, opposite


def clouds():
    rng = np.random.default_rng(23)
    sphere = rng.normal(size=(3000, 3))
    sphere /= np.linalg.norm(sphere, axis=1, keepdims=True)
    noisy = sphere * (1.0 + 0.01 * rng.normal(size=(3000, 1)))
    x, y = np.meshgrid(np.arange(40.0), np.arange(40.0))  # a lattice dome: ties everywhere
    dome = np.column_stack([x.ravel(), y.ravel(), 0.002 * ((x - 20) ** 2 + (y - 20) ** 2).ravel()])
    two = np.concatenate([sphere, sphere * 0.9])  # two sheets, stacked edges between them
    return {"sphere": sphere, "noisy": noisy, "dome": dome, "two": two}


@pytest.mark.parametrize("name", ["sphere", "noisy", "dome", "two"])
def test_single_edges_leave_the_forest_unchanged(name):
    pytest.importorskip("numba")
    from meshcurv._kernels import pointcloud_graph
    from meshcurv._pointcloud_normals import PART_MIN_POINTS, _forest_order

    points = clouds()[name]
    graph, rows, cols, kept, flat, used, weights, opposite = graph_of(points)
    n = points.shape[0]
    single = pointcloud_graph._single_edges(graph, kept, used, weights)
    # the edges dropped: exactly the later ways of edges used both ways at equal weights
    edge = {(int(i), int(j)): e for e, (i, j) in enumerate(zip(rows, cols))}
    wanted = used.copy()
    for (i, j), e in edge.items():
        back = edge.get((j, i))
        if j < i and used[e] and back is not None and used[back] and weights[back] == weights[e]:
            wanted[e] = False
    np.testing.assert_array_equal(single, wanted)
    assert (~single & used).sum() > 0.2 * used.sum()  # (most edges of a k nearest graph go both ways)
    outputs = []
    for chosen in (used, single):
        position = np.flatnonzero(chosen)
        order = position[_forest_order(weights[chosen])]
        n_flat = int(np.count_nonzero(flat[chosen]))
        outputs.append(
            pointcloud_graph.spanning_sheets(n, rows, cols, opposite.view(np.int8), order, n_flat, PART_MIN_POINTS)
        )
    for got, expected in zip(outputs[1], outputs[0]):
        np.testing.assert_array_equal(got, expected)


@pytest.mark.parametrize("k", [1, 5, 8, 10, 17])
def test_neighbour_spacing_is_numpys_mean(k):
    # the radius classes' mean spacing over each centre and its neighbours: NumPy's sum(axis=1) to the bit (its
    # pairwise sum from 8 terms on), on spacings of many magnitudes (where the order of the additions shows)
    pytest.importorskip("numba")
    from meshcurv._kernels import pointcloud

    rng = np.random.default_rng(k)
    n = 20_000
    spacing = rng.random(n) * 10.0 ** rng.integers(-6, 6, n)
    usable = rng.random(n) < 0.9
    indices = rng.integers(0, n, (n, k))
    centres = np.flatnonzero(usable)
    values = np.where(usable, spacing, 0.0)
    rows = indices[centres]
    wanted = (values[centres] + values[rows].sum(axis=1)) / (1.0 + np.count_nonzero(usable[rows], axis=1))
    np.testing.assert_array_equal(pointcloud._neighbour_spacing(values, usable, indices, centres), wanted)
