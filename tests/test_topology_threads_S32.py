"""The topology build's passes over the faces in ranges on threads (issue 31, S32) give the arrays of one pass over
all the faces, and matGeom's fused smoothing of its traces and floors gives the bits of the separate smoothing."""

from __future__ import annotations

import numpy as np
import pytest

from meshcurv import shapes
from meshcurv.topology import MeshTopology, _bucket_template

numba = pytest.importorskip("numba")


def _on_threads(function, threads):
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
        return function()
    finally:
        numba.set_num_threads(before)


def _awkward_faces():
    """An icosphere's faces with every defect the first pass records: faces repeating a corner (some the only
    face of a vertex, some first at a vertex with proper faces later), flipped faces, a third face on an edge, a
    face stored twice, and unreferenced vertices at the end."""
    sphere = shapes.icosphere(24)
    faces = np.array(sphere.faces, dtype=np.int64)
    n = sphere.vertices.shape[0]
    faces[::41] = faces[::41, ::-1]  # flipped
    faces[7] = [faces[7, 0], faces[7, 0], faces[7, 1]]  # repeats a corner
    faces[-3] = [faces[-3, 2], faces[-3, 2], faces[-3, 2]]  # a single point
    extra = np.array(
        [
            [n, n, 5],  # vertex n held by a face repeating a corner only
            [faces[100, 0], faces[100, 1], faces[2000, 2]],  # a third face on an edge
            faces[300],  # a face stored twice
            [n + 1, n + 1, n + 2],  # repeats, then a proper face at n + 1 in the last range
            [n + 1, n + 3, n + 2],
        ]
    )
    head = np.array([[n + 4, n + 4, 9], [n + 5, n + 5, n + 5]])  # a first range's vertex of repeated corners only
    return np.vstack([head, faces, extra]), n + 8  # n + 6, n + 7: unreferenced


def _build(faces, n_vertices):
    from meshcurv._kernels import topology as kernels

    return kernels.build_topology(faces, n_vertices, _bucket_template(n_vertices, faces.shape[0]), True)


@pytest.mark.parametrize("threads", [2, 3, 4])
def test_the_build_on_threads_gives_the_arrays_of_one_pass(threads):
    faces, n_vertices = _awkward_faces()
    one = _on_threads(lambda: _build(faces, n_vertices), 1)
    several = _on_threads(lambda: _build(faces, n_vertices), threads)
    names = ("edges", "face_edges", "edge_faces", "counts", "forward", "twins", "corners", "first")
    for name, a, b in zip(names, one, several, strict=True):
        assert a.dtype == b.dtype, name
        np.testing.assert_array_equal(a, b, err_msg=name)


def test_the_first_pass_reads_as_defined():
    """corners, first and the edges of the threaded build against their definitions, written out."""
    faces, n_vertices = _awkward_faces()
    edges, face_edges, _, counts, _, _, corners, first = _on_threads(lambda: _build(faces, n_vertices), 2)
    proper = (faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 2] != faces[:, 0])
    expected_corners = np.bincount(faces[proper].ravel(), minlength=n_vertices)
    np.testing.assert_array_equal(corners, expected_corners)
    expected_first = np.full(n_vertices, -1)
    for f in range(faces.shape[0] - 1, -1, -1):  # backwards: the first face's value stays
        for k in range(3):
            if not proper[f] and expected_first[faces[f, k]] < 0:
                expected_first[faces[f, k]] = -2
    for f in range(faces.shape[0] - 1, -1, -1):
        if proper[f]:
            for k in range(2, -1, -1):
                expected_first[faces[f, k]] = 3 * f + k
    np.testing.assert_array_equal(first, expected_first)
    assert (first == -2).sum() >= 2 and (first == -1).sum() == 2
    sides = np.stack([faces.ravel(), np.roll(faces, -1, axis=1).ravel()], axis=1)
    keys = np.unique(np.sort(sides[sides[:, 0] != sides[:, 1]], axis=1), axis=0)
    np.testing.assert_array_equal(edges, keys)
    assert counts.sum() == (sides[:, 0] != sides[:, 1]).sum()
    assert (face_edges.ravel()[sides[:, 0] == sides[:, 1]] == -1).all()


def test_the_faces_sorted_by_their_smallest_corner_on_threads():
    from meshcurv._kernels import topology as kernels

    faces, n_vertices = _awkward_faces()
    rng = np.random.default_rng(3)
    faces = faces[rng.permutation(faces.shape[0])]
    order = np.argsort(faces.min(axis=1), kind="stable")
    for threads in (1, 2, 4):
        got_order, got = _on_threads(lambda: kernels._faces_by_smallest_corner(faces, n_vertices), threads)
        np.testing.assert_array_equal(got_order, order)
        np.testing.assert_array_equal(got, faces[order])
        assert got.dtype == np.int64 and got_order.dtype == np.int64


@pytest.mark.parametrize("steps", [0, 1, 2, 3, 4])
def test_matgeom_smooths_its_fields_in_the_finish_kernel_to_the_bit(steps):
    from meshcurv._kernels import matgeom as kernels
    from meshcurv._kernels.smoothing import smooth_over_neighbours

    mesh = shapes.with_normal_noise(shapes.icosphere(12), 0.02, seed=2)
    topology = MeshTopology.from_faces(mesh.faces)
    indptr, indices = topology.neighbour_lists
    rng = np.random.default_rng(4)
    tensors = rng.standard_normal((mesh.vertices.shape[0], 6))
    fields = rng.standard_normal((mesh.vertices.shape[0], 2))
    fields[5, 1] = np.nan
    expected_fields = smooth_over_neighbours(fields, indptr, indices, steps) if steps else fields.copy()
    expected = kernels.matgeom_finish(tensors.copy(), indptr, indices, steps)
    for threads in (1, 2):
        got_fields = fields.copy()
        got = _on_threads(
            lambda: kernels.matgeom_finish(tensors.copy(), indptr, indices, steps, kernels.NORMAL_GAP, got_fields),
            threads,
        )
        np.testing.assert_array_equal(got_fields, expected_fields)
        for a, b in zip(got, expected, strict=True):
            np.testing.assert_array_equal(a, b)
