"""The numbers do not depend on the thread count: every reduction adds in a fixed order."""

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes

numba = pytest.importorskip("numba")

pytestmark = pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="needs numba with 2 threads or more")


def _with_threads(n, call):
    before = numba.get_num_threads()
    numba.set_num_threads(n)
    try:
        return call()
    finally:
        numba.set_num_threads(before)


@pytest.mark.parametrize("method", ["icc", "normal_cycle", "quadric"])
def test_results_are_the_same_on_one_and_two_threads(method):
    # a noisy irregular sphere: its default radius comes from the mean edge length (a sum over all edges), and a
    # face on a ball's rim goes in or out with the radius's last bit
    mesh = shapes.with_normal_noise(shapes.random_sphere(3000, seed=3), level=0.1, seed=4)

    def call():
        with warnings.catch_warnings():  # the noise is the point: quadric reports the balls too small for it
            warnings.simplefilter("ignore", meshcurv.MeshQualityWarning)
            return meshcurv.principal_curvatures(mesh.vertices, mesh.faces, method=method)

    one, two = _with_threads(1, call), _with_threads(2, call)
    np.testing.assert_array_equal(one.valid, two.valid)
    for name in ("k_min", "k_max", "normals"):
        np.testing.assert_array_equal(getattr(one, name), getattr(two, name), err_msg=name)
    if one.radius is not None:
        np.testing.assert_array_equal(one.radius, two.radius)


def test_mean_edge_length_is_the_same_on_any_thread_count():
    mesh = shapes.random_sphere(20000, seed=5)
    topology = meshcurv.topology.MeshTopology.from_faces(mesh.faces, mesh.vertices.shape[0])
    lengths = [
        _with_threads(n, lambda: meshcurv.geometry.mean_edge_length(mesh.vertices, topology.edges)) for n in (1, 2)
    ]
    assert lengths[0] == lengths[1]
    exact = np.linalg.norm(mesh.vertices[topology.edges[:, 0]] - mesh.vertices[topology.edges[:, 1]], axis=1)
    assert lengths[0] == pytest.approx(exact.mean(), rel=1e-12)
