"""The nearest neighbours of a point cloud are decided by its geometry (issue 29, K24).

A k-nearest-neighbour query cuts a group of neighbours at one distance by the order in which the search met
them (the input's, the k-d tree's, the grid's), which a rigid motion changes by round-off: fandisk's vertices
read as a cloud have 43 points whose 10th and 11th neighbours are at one distance, and turned or shifted some
of them got another set of neighbours (their curvatures moved by up to 7.7e-4 of the largest). A group tied
at the cut is now dropped whole. Oracles: invariance of the neighbour sets under rotation, translation,
uniform scaling and re-indexing, on fandisk's vertices and on grids of a torus and a sphere (exact ties by
symmetry), on both backends and on the grid search of large clouds.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from meshcurv._backend import use_backend

DATA = Path(__file__).parent / "data" / "matgeom"
TURN = Rotation.from_euler("xyz", [0.3, 1.1, -0.7]).as_matrix()
SHIFT = np.array([3.3, -1.7, 0.9])


def _fandisk() -> np.ndarray:
    with np.load(DATA / "fandisk.npz") as fandisk:
        return fandisk["vertices"].astype(np.float64)


def _torus_grid(n_around: int, n_along: int) -> np.ndarray:
    """Points of a torus (radii 1 and 0.4) on a grid of its angles: every point sees the same neighbours,
    at distances tied in pairs by the torus's mirror symmetries."""
    u, v = np.meshgrid(np.arange(n_around) * 2 * np.pi / n_around, np.arange(n_along) * 2 * np.pi / n_along)
    u, v = u.ravel(), v.ravel()
    return np.column_stack([(1 + 0.4 * np.cos(v)) * np.cos(u), (1 + 0.4 * np.cos(v)) * np.sin(u), 0.4 * np.sin(v)])


def _sphere_grid(n: int) -> np.ndarray:
    """Points of the unit sphere on a grid of latitude and longitude (poles left out): ties by symmetry."""
    theta, phi = np.meshgrid(np.arange(1, n) * np.pi / n, np.arange(2 * n) * np.pi / n)
    theta, phi = theta.ravel(), phi.ravel()
    return np.column_stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)])


def _neighbour_sets(points: np.ndarray) -> np.ndarray:
    """(N, k) each point's neighbours (itself where a tied group was dropped), sorted: the set, not the order."""
    from meshcurv import pointcloud

    _, indices = pointcloud._knn(cKDTree(points), points)
    return np.sort(indices, axis=1)


def _poses(points: np.ndarray, permutation: np.ndarray):
    """The cloud turned, shifted, scaled and re-indexed (and the map back to the input's indices)."""
    identity = np.arange(points.shape[0])
    yield "turned", points @ TURN.T, identity
    yield "shifted", points + SHIFT, identity
    yield "scaled", points * 3.7, identity
    yield "re-indexed", points[permutation], permutation
    yield "all", (points[permutation] @ TURN.T) * 0.29 - SHIFT, permutation


def _assert_same_sets(points: np.ndarray) -> None:
    reference = _neighbour_sets(points)
    permutation = np.random.default_rng(3).permutation(points.shape[0])
    for name, moved, back in _poses(points, permutation):
        found = np.sort(back[_neighbour_sets(moved)], axis=1)
        other = int((found != reference[back]).any(axis=1).sum())
        assert other == 0, f"{name}: {other} points got another set of neighbours"


@pytest.mark.parametrize("backend", ["numba", "numpy"])
@pytest.mark.parametrize("cloud", ["fandisk", "torus", "sphere"])
def test_neighbour_sets_follow_the_geometry(backend, cloud):
    if backend == "numba":
        pytest.importorskip("numba")
    points = {"fandisk": _fandisk, "torus": lambda: _torus_grid(48, 20), "sphere": lambda: _sphere_grid(30)}[cloud]()
    with use_backend(backend):
        _assert_same_sets(points)


@pytest.mark.slow
def test_neighbour_sets_follow_the_geometry_on_the_grid_search():
    # 65,536 points: at KNN_GRID_POINTS, the compiled grid search (its tied rows from the k-d tree)
    from meshcurv import pointcloud

    pytest.importorskip("numba")
    points = _torus_grid(512, 128)
    assert points.shape[0] >= pointcloud.KNN_GRID_POINTS
    with use_backend("numba"):
        _assert_same_sets(points)


def test_a_group_tied_at_the_cut_is_dropped_whole():
    # a square grid: 4 neighbours at 1, 4 at sqrt(2), 4 at 2; the 10th and 11th nearest are among those at 2
    from meshcurv import _pointcloud_normals as normals

    x, y = np.meshgrid(np.arange(7.0), np.arange(7.0))
    points = np.column_stack([x.ravel(), y.ravel(), np.zeros(49)])
    centre = 24  # (3, 3)
    distances, indices = normals.knn(cKDTree(points), points, k=10)
    expected = np.r_[np.ones(4), np.full(4, np.sqrt(2.0)), np.full(2, 2.0)]
    np.testing.assert_allclose(distances[centre], expected, rtol=1e-15)
    kept = indices[centre, :8]
    assert set(np.hypot(*(points[kept, :2] - points[centre, :2]).T).round(12)) == {1.0, round(np.sqrt(2), 12)}
    assert (indices[centre, 8:] == centre).all()  # the four at 2 do not fit: none is taken


def test_ties_are_read_within_round_off_only():
    from meshcurv import _pointcloud_normals as normals

    distances = np.array([[1.0, 2.0, 2.5, 3.0 * (1 - 1e-12), 3.0], [1.0, 2.0, 2.5, 3.0, 3.0 * (1 + 1e-6)]])
    indices = np.array([[5, 6, 7, 8, 9], [5, 6, 7, 8, 9]])
    cut_distances, cut_indices = normals.whole_ties(distances, indices, 4)
    np.testing.assert_array_equal(cut_indices, [[5, 6, 7, 0], [5, 6, 7, 8]])
    np.testing.assert_array_equal(cut_distances, [[1.0, 2.0, 2.5, 3.0], [1.0, 2.0, 2.5, 3.0]])


def test_a_ring_of_ties_keeps_the_query_cut():
    # the poles of a grid of latitude and longitude: their 60 nearest at one distance (TIE_LEAST)
    from meshcurv import _pointcloud_normals as normals

    points = np.concatenate([_sphere_grid(30), [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]]])
    distances, indices = normals.knn(cKDTree(points), points, k=10)
    poles = np.arange(points.shape[0] - 2, points.shape[0])
    assert (indices[poles] != poles[:, None]).all()
    np.testing.assert_allclose(distances[poles], 2 * np.sin(np.pi / 60), rtol=1e-12)
