"""A large mesh whose faces lie apart around its vertices is computed with its faces sorted (issue 31).

The oracle is face re-indexing invariance: the curvatures of a mesh do not
depend on the order of its faces beyond the order of floating-point sums, so a
mesh with its faces shuffled (the vertices kept) must give the numbers of the
mesh in its own order to round-off. One exception is written out: where the
principal curvatures nearly meet (a sphere's umbilics) ``k = H -/+ sqrt(H^2 -
K)`` moves by the square root of the round-off of ``H^2 - K`` (a perturbation
``d`` of a non-negative ``x`` moves ``sqrt(x)`` by at most ``sqrt(|d|)``), while
``H`` and ``K`` themselves stay within round-off. The sort itself is checked
against its definition (``np.argsort`` of the smallest corner, stable) on both
backends.
"""

import logging
import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import _locality, _prepared, shapes
from meshcurv._backend import use_backend
from meshcurv.errors import MeshQualityWarning

try:
    import numba  # noqa: F401
except ImportError:
    HAS_NUMBA = False
else:
    HAS_NUMBA = True

BACKENDS = ["numpy", pytest.param("numba", marks=pytest.mark.skipif(not HAS_NUMBA, reason="numba not installed"))]


@pytest.fixture(scope="module")
def torus():
    # irregular and above MIN_VERTICES: 300 x 120 = 36,000 vertices, its faces in rows of the grid (local)
    mesh = shapes.torus(3.0, 1.0, 300, 120, jitter=0.3, seed=7)
    assert mesh.vertices.shape[0] >= _locality.MIN_VERTICES
    return mesh


def shuffled_faces(faces, seed):
    """``faces`` in a random order, each keeping its corners (and their order), and that order."""
    order = np.random.default_rng(seed).permutation(faces.shape[0])
    return faces[order], order


def run(vertices, faces, method="icc"):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        if method == "matgeom":  # (the jittered torus's circles of K = 0: a tangent eigenvalue ties the normal's, and
            # matGeom's normal there is round-off's choice: a few vertices undefined, with a warning)
            warnings.filterwarnings("ignore", category=MeshQualityWarning, message="matgeom: .* have no normal")
        return meshcurv.principal_curvatures(vertices, faces, method=method)


@pytest.mark.parametrize("backend", BACKENDS)
def test_faces_apart_are_sorted_by_their_smallest_corner(backend, torus):
    faces, _ = shuffled_faces(torus.faces, 1)
    n = torus.vertices.shape[0]
    with use_backend(backend):
        mesh = _prepared.prepare_mesh(torus.vertices, faces, orient="keep", weld=False)
        kept = _prepared.prepare_mesh(torus.vertices, torus.faces, orient="keep", weld=False)
        assert not _prepared._faces_apart(n, torus.faces)  # rows of a grid: a vertex's faces a row apart
        assert _prepared._faces_apart(n, faces)
    expected = faces[np.argsort(faces.min(axis=1), kind="stable")]
    np.testing.assert_array_equal(mesh.topology.faces, expected)
    np.testing.assert_array_equal(mesh.vertices, torus.vertices)  # the vertices as given (no Morton order)
    assert mesh.index is None
    np.testing.assert_array_equal(mesh.surface.faces, faces)  # the caller's faces, in the caller's rows
    np.testing.assert_array_equal(kept.topology.faces, torus.faces)  # faces near each other: as given


@pytest.mark.parametrize("backend", BACKENDS)
def test_small_meshes_and_a_given_topology_keep_their_face_order(backend, torus):
    small = shapes.torus(3.0, 1.0, 60, 30)
    faces, _ = shuffled_faces(small.faces, 2)
    with use_backend(backend):
        assert not _prepared._faces_apart(small.vertices.shape[0], faces)  # below MIN_VERTICES: in the caches
        mesh = _prepared.prepare_mesh(small.vertices, faces, orient="keep", weld=False)
        np.testing.assert_array_equal(mesh.topology.faces, faces)
        big, _ = shuffled_faces(torus.faces, 3)
        topology = meshcurv.MeshTopology.from_faces(big)
        given = _prepared.prepare_mesh(torus.vertices, topology, orient="keep", weld=False)
    np.testing.assert_array_equal(given.topology.faces, big)


@pytest.mark.parametrize("backend", BACKENDS)
def test_the_compiled_sort_and_spans_are_their_definitions(backend):
    # random faces with many ties of their smallest corner: the sort must be stable
    rng = np.random.default_rng(4)
    n = 5000
    faces = rng.integers(0, n, size=(40000, 3)).astype(np.int64)
    shift = 4
    sampled = np.arange(0, n, 2**shift)
    rows = [np.flatnonzero((faces == v).any(axis=1)) for v in sampled]
    expected_spans = np.array([r[-1] - r[0] if r.size else -1 for r in rows])
    with use_backend(backend):
        np.testing.assert_array_equal(_prepared._face_spans(faces, n, shift), expected_spans)
    order = np.argsort(faces.min(axis=1), kind="stable")
    if backend == "numba":
        from meshcurv._kernels import topology as kernels

        compiled_order, ordered = kernels._faces_by_smallest_corner(faces, n)
        np.testing.assert_array_equal(compiled_order, order)
        np.testing.assert_array_equal(ordered, faces[order])


@pytest.mark.parametrize("method", ["icc", "normal_cycle", "matgeom"])
def test_a_mesh_with_its_faces_apart_gives_the_numbers_of_the_mesh_in_its_own_order(method, torus, caplog):
    base = run(torus.vertices, torus.faces, method)
    faces, _ = shuffled_faces(torus.faces, 5)
    with caplog.at_level(logging.INFO, logger="meshcurv._prepared"):
        shuffled = run(torus.vertices, faces, method)
    assert "sorted by their smallest corner" in caplog.text
    # the same faces summed in another order: round-off of sums of a few dozen terms, amplified at most by the
    # conditioning of the fits (the torus has no umbilic: k_max - k_min >= 1 / 3 everywhere)
    scale = np.abs(base.k_max).max()
    for name, power in (("k_min", 1), ("k_max", 1), ("mean", 1), ("gaussian", 2), ("normals", 0)):
        np.testing.assert_allclose(
            getattr(shuffled, name), getattr(base, name), rtol=0, atol=1e-10 * scale**power, err_msg=name
        )
    np.testing.assert_array_equal(shuffled.valid, base.valid)
    for name in ("dir_min", "dir_max"):
        np.testing.assert_allclose(np.abs(np.sum(getattr(shuffled, name) * getattr(base, name), axis=1)), 1, atol=1e-8)
    np.testing.assert_allclose(shuffled.vertex_areas, base.vertex_areas, rtol=1e-12)
    np.testing.assert_array_equal(shuffled._surface.faces, faces)  # the mesh kept for integrals: the caller's
    if method == "icc":
        assert shuffled.parameters["radius"] == pytest.approx(base.parameters["radius"], rel=1e-12)


def test_at_umbilics_the_face_order_moves_k_by_the_root_of_the_round_off_alone():
    # every vertex of a sphere is an umbilic: k_max - k_min is round-off's, and k = H -/+ sqrt(H^2 - K) moves by
    # sqrt(|d(H^2 - K)|) when the sums' order moves H^2 - K by d; H and K themselves stay within round-off
    sphere = shapes.icosphere(58)  # 33,642 vertices
    assert sphere.vertices.shape[0] >= _locality.MIN_VERTICES
    faces, _ = shuffled_faces(sphere.faces, 6)
    base, shuffled = run(sphere.vertices, sphere.faces), run(sphere.vertices, faces)
    np.testing.assert_array_equal(shuffled.valid, base.valid)
    tolerance = 1e-12  # relative to 1 / r^2 (r = 1): sums of a few dozen terms, mu_2's cancellation on small faces
    np.testing.assert_allclose(shuffled.mean, base.mean, rtol=0, atol=tolerance)
    np.testing.assert_allclose(shuffled.gaussian, base.gaussian, rtol=0, atol=tolerance)
    # |d(H^2 - K)| <= 2 |H| |dH| + |dK| <= 3 tolerance, so |dk| <= tolerance + sqrt(3 tolerance)
    bound = tolerance + np.sqrt(3 * tolerance)
    for name in ("k_min", "k_max"):
        np.testing.assert_allclose(getattr(shuffled, name), getattr(base, name), rtol=0, atol=bound, err_msg=name)


@pytest.mark.slow
def test_the_numpy_backend_gives_the_numbers_of_the_mesh_in_its_own_order(torus):
    faces, _ = shuffled_faces(torus.faces, 5)
    with use_backend("numpy"):
        base, shuffled = run(torus.vertices, torus.faces), run(torus.vertices, faces)
    scale = np.abs(base.k_max).max()
    for name in ("k_min", "k_max", "normals"):
        np.testing.assert_allclose(
            getattr(shuffled, name), getattr(base, name), rtol=0, atol=1e-10 * scale, err_msg=name
        )
    np.testing.assert_array_equal(shuffled.valid, base.valid)


def test_the_faces_kept_for_the_integrals_are_oriented_in_the_callers_rows(torus):
    # a tenth of the shuffled faces reversed: orient="outward" turns them back, and the surface kept for the
    # integrals and the plots holds the caller's rows (the torus's own winding is outward)
    faces, _ = shuffled_faces(torus.faces, 8)
    reversed_rows = np.random.default_rng(9).random(faces.shape[0]) < 0.1
    given = faces.copy()
    given[reversed_rows] = given[reversed_rows][:, [0, 2, 1]]
    mesh = _prepared.prepare_mesh(torus.vertices, given, orient="outward", weld=False)
    assert mesh.n_flipped == reversed_rows.sum()
    assert (np.diff(mesh.topology.faces.min(axis=1)) >= 0).all()  # computed sorted
    np.testing.assert_array_equal(mesh.surface.faces, faces)
