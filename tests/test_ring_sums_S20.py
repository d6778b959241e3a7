"""The sums and largest values over rings of edge neighbours (issue 31: the default radius's noisy patches took
them through a SciPy sparse matrix, 0.12-0.17 CPU s of a default call at 1M vertices; compiled since S20).

Oracles: the definition written out vertex by vertex (the sum over the closed 1-ring, repeated; the largest over
the vertices within k edges, found by a breadth-first walk), the degrees of a closed icosphere (1 + 6 at most
vertices, 1 + 5 at the 12 of the icosahedron), and the NumPy path to the bit.
"""

from __future__ import annotations

import numpy as np
import pytest

import meshcurv
from meshcurv import neighborhoods
from meshcurv._backend import use_backend


def _mesh(subdivisions=6, holes=False):
    mesh = meshcurv.shapes.icosphere(subdivisions)
    faces = mesh.faces
    n = mesh.vertices.shape[0]
    if holes:  # vertices without any edge (the faces around vertex 0 removed), boundary loops
        faces = faces[~(faces == 0).any(axis=1)]
    return meshcurv.MeshTopology.from_faces(faces, n).neighbour_lists, n


def _by_definition_sums(lists, rings, values):
    indptr, indices = lists
    out = np.array(values, dtype=np.float64)
    for _ in range(rings):
        previous = out.copy()
        for v in range(indptr.size - 1):
            out[v] = previous[v] + previous[indices[indptr[v] : indptr[v + 1]]].sum(axis=0)
    return out


def _within(lists, v, rings):
    indptr, indices = lists
    seen, front = {v}, [v]
    for _ in range(rings):
        front = [int(u) for w in front for u in indices[indptr[w] : indptr[w + 1]] if int(u) not in seen]
        seen.update(front)
    return sorted(seen)


def _bits_equal(a, b):
    assert a.dtype == b.dtype == np.float64 and a.shape == b.shape
    nan = np.isnan(a)
    np.testing.assert_array_equal(nan, np.isnan(b))
    np.testing.assert_array_equal(a[~nan].view(np.uint64), b[~nan].view(np.uint64))


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_one_ring_of_ones_is_one_plus_the_degree(backend):
    if backend == "numba":
        pytest.importorskip("numba")
    lists, n = _mesh(6)
    with use_backend(backend):
        (counted,) = neighborhoods.ring_sums(lists, 1, np.ones(n))
    degrees = np.sort(counted)
    # an icosphere: the 12 vertices of the icosahedron have 5 neighbours, every other one 6
    np.testing.assert_array_equal(degrees[:12], 6.0)
    np.testing.assert_array_equal(degrees[12:], 7.0)


@pytest.mark.parametrize("backend", ["numpy", "numba"])
@pytest.mark.parametrize("holes", [False, True])
def test_ring_sums_and_largest_follow_their_definition(backend, holes):
    if backend == "numba":
        pytest.importorskip("numba")
    lists, n = _mesh(4, holes)
    rng = np.random.default_rng(1)
    values, weights = rng.normal(size=(n, 3)), rng.random(n)
    with use_backend(backend):
        sums = neighborhoods.ring_sums(lists, 2, values, weights)
        largest = neighborhoods.ring_max(lists, 2, weights)
    # sums: to round-off (the definition adds in another order)
    np.testing.assert_allclose(sums[0], _by_definition_sums(lists, 2, values), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(sums[1], _by_definition_sums(lists, 2, weights), rtol=1e-12, atol=1e-12)
    assert sums[0].shape == (n, 3) and sums[1].shape == (n,)
    # the largest: exact
    expected = np.array([weights[_within(lists, v, 2)].max() for v in range(n)])
    np.testing.assert_array_equal(largest, expected)


def test_the_compiled_rings_are_the_numpy_ones_to_the_bit():
    pytest.importorskip("numba")
    rng = np.random.default_rng(2)
    for subdivisions, holes in ((3, False), (8, True), (60, False)):
        lists, n = _mesh(subdivisions, holes)
        values = rng.normal(size=(n, 3))
        values[rng.random(n) < 0.01] = np.nan
        values[rng.random((n, 3)) < 0.05] = -0.0
        values[rng.random((n, 3)) < 0.05] = 0.0
        column = np.ascontiguousarray(values[:, 2])
        for rings in range(4):
            got = {}
            for backend in ("numpy", "numba"):
                with use_backend(backend):
                    got[backend] = [
                        *neighborhoods.ring_sums(lists, rings, values, column, np.ones(n)),
                        neighborhoods.ring_max(lists, rings, column),
                    ]
            for expected, found in zip(got["numpy"], got["numba"]):
                _bits_equal(expected, found)
            # a largest value 0 is 0.0 on both backends (np.maximum keeps either of 0.0 and -0.0, by its loop)
            assert not np.signbit(got["numba"][-1][got["numba"][-1] == 0]).any()


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_a_nan_within_the_rings_makes_the_largest_nan(backend):
    if backend == "numba":
        pytest.importorskip("numba")
    lists, n = _mesh(4)
    values = np.zeros(n)
    values[0] = np.nan
    with use_backend(backend):
        largest = neighborhoods.ring_max(lists, 2, values)
    near = np.zeros(n, dtype=bool)
    near[_within(lists, 0, 2)] = True
    assert np.isnan(largest[near]).all() and (largest[~near] == 0).all()
