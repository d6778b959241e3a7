"""A mesh in a scattered vertex order is computed in a local one (meshcurv._locality), with the same numbers.

The oracle is re-indexing invariance: a shuffled mesh (vertices and faces) must
give the results of the mesh in its own order, permuted, to round-off (the
sums run in another order); the reordering itself is checked against its
definition (Morton codes, stable sorts) on both backends; the compiled path
against the NumPy one is a row of tests/test_kernel_twins.py.
"""

import logging
import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import _locality, shapes
from meshcurv._backend import use_backend
from meshcurv.errors import MeshQualityWarning

try:
    import numba  # noqa: F401
except ImportError:
    HAS_NUMBA = False
else:
    HAS_NUMBA = True


@pytest.fixture(scope="module")
def torus():
    # irregular and above MIN_VERTICES: 300 x 120 = 36,000 vertices
    mesh = shapes.torus(3.0, 1.0, 300, 120, jitter=0.3, seed=7)
    assert mesh.vertices.shape[0] >= _locality.MIN_VERTICES
    return mesh


def shuffle(vertices, faces, seed, block=None):
    """The mesh with its vertices permuted (within blocks of ``block``, or all) and its faces shuffled."""
    rng = np.random.default_rng(seed)
    n = vertices.shape[0]
    if block is None:
        order = rng.permutation(n)
    else:
        order = np.concatenate([start + rng.permutation(min(block, n - start)) for start in range(0, n, block)])
    index = np.empty_like(order)
    index[order] = np.arange(n)
    return vertices[order], index[faces][rng.permutation(faces.shape[0])], order


def run(vertices, faces, method, **options):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        if method == "matgeom":  # (the jittered torus's circles of K = 0: a tangent eigenvalue ties the normal's, and
            # matGeom's normal there is round-off's choice: a few vertices undefined, with a warning)
            warnings.filterwarnings("ignore", category=MeshQualityWarning, message="matgeom: .* have no normal")
        return meshcurv.principal_curvatures(vertices, faces, method=method, **options)


def test_orders_that_are_local_in_one_direction_are_not_scattered(torus):
    # rows of a grid (the torus), an icosphere's triangles: one short side per face however long the others
    assert not _locality.is_scattered(torus.vertices.shape[0], torus.faces)
    sphere = shapes.icosphere(64)
    assert _locality.median_side_span(sphere.faces) <= 2
    assert not _locality.is_scattered(sphere.vertices.shape[0], sphere.faces)
    # a shuffle within blocks of 64 vertices stays within a few cache lines
    _, faces, _ = shuffle(torus.vertices, torus.faces, 1, block=64)
    assert not _locality.is_scattered(torus.vertices.shape[0], faces)


def test_a_shuffled_mesh_is_scattered_when_large(torus):
    _, faces, _ = shuffle(torus.vertices, torus.faces, 1)
    assert _locality.median_side_span(faces) > 1000
    assert _locality.is_scattered(torus.vertices.shape[0], faces)
    small = shapes.torus(3.0, 1.0, 60, 30)
    _, small_faces, _ = shuffle(small.vertices, small.faces, 1)
    assert not _locality.is_scattered(small.vertices.shape[0], small_faces)  # stays in the caches


@pytest.mark.parametrize(
    "backend", ["numpy", pytest.param("numba", marks=pytest.mark.skipif(not HAS_NUMBA, reason="numba not installed"))]
)
def test_the_reordering_is_the_morton_order_and_its_faces_by_first_corner(backend, torus):
    vertices, faces, _ = shuffle(torus.vertices, torus.faces, 3)
    with use_backend(backend):
        local = _locality.reordering(vertices, faces)
    n = vertices.shape[0]
    np.testing.assert_array_equal(np.sort(local.order), np.arange(n))
    np.testing.assert_array_equal(local.index[local.order], np.arange(n))
    np.testing.assert_array_equal(local.vertices, vertices[local.order])
    np.testing.assert_array_equal(local.faces, local.index[faces][local.face_order])
    # Morton codes by their definition: bit i of axis a's cell at bit 3 i + a
    lo = vertices.min(axis=0)
    cells = ((vertices - lo) * ((2**21 - 1) / (vertices.max(axis=0) - lo).max())).astype(np.int64)
    codes = np.zeros(n, dtype=object)
    for bit in range(21):
        for axis in range(3):
            codes += ((cells[:, axis] >> bit) & 1) << (3 * bit + axis)
    assert all(codes[local.order][:-1] <= codes[local.order][1:])
    first = local.faces.min(axis=1)
    assert (np.diff(first) >= 0).all()
    ties = np.flatnonzero(np.diff(first) == 0)
    assert (local.face_order[ties] < local.face_order[ties + 1]).all()  # stable
    np.testing.assert_array_equal(local.original_faces(local.faces), faces)
    assert _locality.median_side_span(local.faces) <= 2


@pytest.mark.parametrize("method", ["icc", "normal_cycle", "matgeom"])
def test_a_scattered_mesh_gives_the_numbers_of_the_mesh_in_its_own_order(method, torus, caplog):
    base = run(torus.vertices, torus.faces, method)
    vertices, faces, order = shuffle(torus.vertices, torus.faces, 2)
    with caplog.at_level(logging.INFO, logger="meshcurv._locality"):
        shuffled = run(vertices, faces, method)
    assert "scattered order" in caplog.text
    scale = np.abs(base.k_max).max()
    for name in ("k_min", "k_max", "normals"):
        np.testing.assert_allclose(
            getattr(shuffled, name), getattr(base, name)[order], rtol=0, atol=1e-10 * scale, err_msg=name
        )
    np.testing.assert_array_equal(shuffled.valid, base.valid[order])
    for name in ("dir_min", "dir_max"):
        np.testing.assert_allclose(
            np.abs(np.sum(getattr(shuffled, name) * getattr(base, name)[order], axis=1)), 1, atol=1e-8
        )
    # the mesh kept for the integrals is the caller's, in the caller's order
    np.testing.assert_allclose(shuffled.vertex_areas, base.vertex_areas[order], rtol=1e-12)
    assert shuffled.integral("gaussian") == pytest.approx(base.integral("gaussian"), abs=1e-9)
    np.testing.assert_array_equal(shuffled._surface.vertices, vertices)
    assert shuffled._surface.index is None
    if method == "icc":
        assert shuffled.parameters["radius"] == pytest.approx(base.parameters["radius"], rel=1e-12)


@pytest.mark.slow
def test_a_scattered_soup_is_welded_and_put_back_in_the_callers_order(torus):
    # split the torus along one ring of vertices (a seam): the faces of the last ring take copies
    n = torus.vertices.shape[0]
    seam = np.arange(120)  # ring 0 (vertex i * n_minor + j, i = 0)
    last_ring = (torus.faces >= (300 - 1) * 120).any(axis=1)
    faces = torus.faces.copy()
    faces[last_ring] = np.where(faces[last_ring] < 120, faces[last_ring] + n, faces[last_ring])
    split = np.vstack([torus.vertices, torus.vertices[seam]])
    with pytest.warns(meshcurv.MeshQualityWarning, match="welded 120"):
        base = meshcurv.principal_curvatures(split, faces)
    vertices, shuffled_faces, order = shuffle(split, faces, 5)
    assert _locality.is_scattered(vertices.shape[0], shuffled_faces)
    with pytest.warns(meshcurv.MeshQualityWarning, match="welded 120"):
        shuffled = meshcurv.principal_curvatures(vertices, shuffled_faces)
    np.testing.assert_allclose(shuffled.k_max, base.k_max[order], rtol=0, atol=1e-10)
    np.testing.assert_allclose(shuffled.k_min, base.k_min[order], rtol=0, atol=1e-10)
    copies = np.flatnonzero(order >= n)  # the caller's rows of the copies, and of their originals
    originals = np.argsort(order)[order[copies] - n]
    np.testing.assert_array_equal(shuffled.k_max[copies], shuffled.k_max[originals])  # copies share their values
    # a welded vertex's area is on the first of its rows (another copy once shuffled): the pairs' sums agree
    areas, base_areas = shuffled.vertex_areas, base.vertex_areas[order]
    np.testing.assert_allclose(areas[copies] + areas[originals], base_areas[copies] + base_areas[originals], rtol=1e-12)
    others = np.setdiff1d(np.arange(order.size), np.concatenate([copies, originals]))
    np.testing.assert_allclose(areas[others], base_areas[others], rtol=1e-12)


def test_a_given_topology_of_a_scattered_mesh_is_rebuilt_in_the_local_order(torus):
    vertices, faces, order = shuffle(torus.vertices, torus.faces, 6)
    topology = meshcurv.MeshTopology.from_faces(faces, vertices.shape[0])
    base = run(torus.vertices, torus.faces, "normal_cycle")
    again = run(vertices, topology, "normal_cycle")
    np.testing.assert_allclose(again.k_max, base.k_max[order], rtol=0, atol=1e-10)
    np.testing.assert_array_equal(topology.faces, faces)  # the caller's topology is not changed


def test_a_scattered_mesh_wider_than_the_float_range_is_computed_as_given(torus):
    # its bounding box overflows: no Morton codes; the computation in the given order is still defined
    vertices, faces, _ = shuffle(torus.vertices, torus.faces, 9)
    vertices = vertices * 3e307  # within the float range, but -4 to 4 apart: 2.4e308
    points, topology, local = _locality.local_topology(vertices, faces)
    assert local is None and points is vertices
    np.testing.assert_array_equal(topology.faces, faces)
