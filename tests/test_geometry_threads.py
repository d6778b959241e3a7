"""The geometry passes that run compiled chunks on threads give the same bits on one thread and on two (issue 31:
plain chunks on ``run_chunks`` threads instead of ``parallel=True`` kernels)."""

from __future__ import annotations

import numpy as np
import pytest

from meshcurv import shapes
from meshcurv._backend import SERIAL_ROWS, numba_kernels
from meshcurv.topology import MeshTopology

numba = pytest.importorskip("numba")


def _on_threads(function, threads):
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(threads)
        return function()
    finally:
        numba.set_num_threads(before)


@pytest.fixture(scope="module")
def sphere():
    mesh = shapes.with_normal_noise(shapes.icosphere(48), 0.01, seed=5)  # 23,042 vertices: above SERIAL_ROWS
    assert mesh.vertices.shape[0] >= SERIAL_ROWS
    return mesh, MeshTopology.from_faces(mesh.faces)


def test_the_geometry_chunks_give_the_same_bits_on_one_and_two_threads(sphere):
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("one thread only")
    mesh, topology = sphere
    geometry = numba_kernels("geometry")
    if geometry is None:  # MESHCURV_BACKEND=numpy: no compiled kernels to compare
        pytest.skip("the NumPy backend is forced")
    vertices, faces, edges = mesh.vertices, np.ascontiguousarray(mesh.faces, dtype=np.int64), topology.edges
    scales = np.full(vertices.shape[0], 0.05)
    summed = geometry.face_cross_products(vertices, faces)[: vertices.shape[0]] * 1e-3

    def every_pass():
        cross, degenerate = geometry.cross_and_degenerate(vertices, faces, scales, 0.1)
        return (
            geometry.mean_edge_length(vertices, edges),
            geometry.face_cross_products(vertices, faces),
            cross,
            degenerate,
            geometry.normalize_normal_sums(summed),
        )

    one, two = _on_threads(every_pass, 1), _on_threads(every_pass, 2)
    for a, b in zip(one, two, strict=True):
        np.testing.assert_array_equal(a, b)
    # the mean of positive lengths lies between the shortest and the longest
    lengths = np.linalg.norm(vertices[edges[:, 1]] - vertices[edges[:, 0]], axis=1)
    assert lengths.min() <= one[0] <= lengths.max()
    np.testing.assert_array_equal(one[1], one[2])  # the same cross products by both passes
