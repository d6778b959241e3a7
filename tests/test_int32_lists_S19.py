"""The edge neighbour lists in int32 where the mesh fits (issue 31): half the memory the walks of the balls read.

:attr:`MeshTopology.neighbour_lists` gives ``indices`` of the type of the topology's edge arrays (int32 below
``2**31``, :func:`meshcurv.topology.index_dtype`) on both backends, and the fits over surface-connected balls
take them as they are (:func:`meshcurv.neighborhoods.checked_adjacency` keeps int32): the same neighbours, and
the same fits to the bit as with int64 lists (the type of the indices is no part of the answer), which are
the sphere's own normals.
"""

from __future__ import annotations

import numpy as np
import pytest

from meshcurv import jets, shapes
from meshcurv._backend import use_backend
from meshcurv.neighborhoods import checked_adjacency
from meshcurv.topology import MeshTopology


def _sphere():
    sphere = shapes.icosphere(12)
    return np.asarray(sphere.vertices, float), np.asarray(sphere.faces, np.int64)


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_neighbour_lists_take_the_edges_type(backend):
    if backend == "numba":
        pytest.importorskip("numba")
    vertices, faces = _sphere()
    with use_backend(backend):
        topology = MeshTopology.from_faces(faces, vertices.shape[0])
        indptr, indices = topology.neighbour_lists
    assert topology.edges.dtype == np.int32  # a small mesh: int32 edge arrays
    assert indices.dtype == np.int32
    assert indptr.dtype == np.int64
    # every edge once from each end, each list increasing
    expected = [[] for _ in range(vertices.shape[0])]
    for p, q in topology.edges.tolist():
        expected[p].append(q)
        expected[q].append(p)
    for v, neighbours in enumerate(expected):
        assert indices[indptr[v] : indptr[v + 1]].tolist() == sorted(neighbours)


def test_checked_adjacency_keeps_int32_and_widens_the_rest():
    indptr = np.array([0, 1, 2])
    for given, kept in ((np.int32, np.int32), (np.int64, np.int64), (np.int16, np.int64), (np.uint32, np.int64)):
        _, indices = checked_adjacency((indptr, np.array([1, 0], dtype=given)), 2)
        assert indices.dtype == kept
        assert indices.flags.c_contiguous


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_fits_do_not_depend_on_the_type_of_the_lists(backend):
    if backend == "numba":
        pytest.importorskip("numba")
    vertices, faces = _sphere()
    radial = vertices / np.linalg.norm(vertices, axis=1, keepdims=True)
    with use_backend(backend):
        topology = MeshTopology.from_faces(faces, vertices.shape[0])
        indptr, indices = topology.neighbour_lists
        radius = 3.0 * float(np.mean(np.linalg.norm(np.diff(vertices[topology.edges], axis=1)[:, 0], axis=1)))
        narrow = jets.fit_jet_normals(vertices, radial, radius, adjacency=(indptr, indices))
        wide = jets.fit_jet_normals(vertices, radial, radius, adjacency=(indptr, indices.astype(np.int64)))
        fitted_narrow = jets.fit_jets(vertices, radial, radius, degree=2, adjacency=(indptr, indices))
        fitted_wide = jets.fit_jets(vertices, radial, radius, degree=2, adjacency=(indptr, indices.astype(np.int64)))
    np.testing.assert_array_equal(narrow, wide)
    for a, b in zip(fitted_narrow, fitted_wide):
        np.testing.assert_array_equal(a, b)
    # the sphere's normals: a jet of its vertices is the sphere to the fit's precision (a unit sphere of edges
    # about 0.1: the fitted normals within 1e-3 rad of the radial ones)
    assert np.all(np.einsum("ij,ij->i", narrow, radial) > 1.0 - 1e-6)
