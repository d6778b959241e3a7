"""The default scale of each vertex from its own sampling, and normal fits of dense surfaces (issue 30).

Oracles: the unit sphere (H = 1 everywhere) sampled 30 times more densely on its upper half than on
its lower (edge lengths about 5.5:1; a convex hull of random points); invariances (scale, re-indexing);
the twin backends; the analytic curvature 1/R of a marching-cubes sphere.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.spatial import ConvexHull

import meshcurv
from meshcurv import shapes
from meshcurv._backend import use_backend
from meshcurv.errors import InvalidMeshError
from meshcurv.geometry import vertex_edge_lengths
from meshcurv.jets import fit_jets
from meshcurv.radius import LOCAL_EVEN, local_scale_ratios
from meshcurv.topology import MeshTopology

BACKENDS = [
    "numpy",
    pytest.param(
        "numba",
        marks=pytest.mark.skipif(__import__("importlib").util.find_spec("numba") is None, reason="numba not installed"),
    ),
]


def _half_refined_sphere(n_coarse=150, ratio=30.0, seed=7):
    """Unit sphere through random points ``ratio`` times denser on z > 0, outward faces; (fine, coarse) masks."""
    rng = np.random.default_rng(seed)

    def draw(count, sign):
        p = rng.normal(size=(count, 3))
        p[:, 2] = sign * np.abs(p[:, 2])
        return p / np.linalg.norm(p, axis=1, keepdims=True)

    points = np.concatenate([draw(int(n_coarse * ratio), 1.0), draw(n_coarse, -1.0)])
    faces = ConvexHull(points).simplices.astype(np.int64)
    a, b, c = (points[faces[:, k]] for k in range(3))
    inward = np.einsum("ij,ij->i", np.cross(b - a, c - a), a + b + c) < 0
    faces[inward] = faces[inward][:, ::-1]
    return points, faces, points[:, 2] > 0.2, points[:, 2] < -0.2


def _default(vertices, faces):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", meshcurv.MeshQualityWarning)
        return meshcurv.principal_curvatures(vertices, faces)


def test_radius_follows_the_local_edge_length_on_a_mesh_refined_on_one_side():
    vertices, faces, fine, coarse = _half_refined_sphere()
    result = _default(vertices, faces)
    assert result.parameters["scale"] == "local"
    local = vertex_edge_lengths(vertices, MeshTopology.from_faces(faces, vertices.shape[0]).edges)
    # the radius grows with the local edge length: the ratio of the halves' radii is that of their edges
    edge_ratio = np.median(local[coarse]) / np.median(local[fine])
    radius_ratio = np.median(result.radius[coarse]) / np.median(result.radius[fine])
    assert edge_ratio > 4
    assert radius_ratio == pytest.approx(edge_ratio, rel=0.25)
    # the fine half keeps the component's radius (its sampling is the median's)
    assert np.median(result.radius[fine]) == pytest.approx(result.parameters["radius"], rel=1e-12)


def test_the_half_refined_sphere_has_mean_curvature_one_on_both_halves():
    # one radius for the whole surface left the coarse half at 17% (median |H - 1|) on a 100:1 sphere
    vertices, faces, fine, coarse = _half_refined_sphere()
    result = _default(vertices, faces)
    for part in (fine, coarse):
        keep = part & result.valid
        assert keep.sum() > 0.9 * part.sum()
        assert np.median(np.abs(result.mean[keep] - 1.0)) < 0.02


def test_an_evenly_sampled_mesh_keeps_one_radius():
    # random points on a sphere: local edge lengths within LOCAL_EVEN of the median on most vertices,
    # an icosphere everywhere: one radius, the call as before
    sphere = shapes.icosphere(16)
    result = _default(sphere.vertices, sphere.faces)
    assert "scale" not in result.parameters
    assert np.all(result.radius == result.parameters["radius"])
    topology = MeshTopology.from_faces(sphere.faces, sphere.vertices.shape[0])
    np.testing.assert_array_equal(local_scale_ratios(sphere.vertices, topology), 1.0)
    assert LOCAL_EVEN > 1


def test_local_radius_scales_with_the_mesh_and_follows_a_reindexing():
    vertices, faces, _, _ = _half_refined_sphere(n_coarse=100, ratio=20.0)
    first = _default(vertices, faces)
    scaled = _default(3.0 * vertices + 2.0, faces)
    np.testing.assert_allclose(scaled.radius, 3.0 * first.radius, rtol=1e-9)
    np.testing.assert_allclose(3.0 * scaled.mean, first.mean, rtol=0, atol=1e-6 * np.nanmax(np.abs(first.mean)))
    order = np.random.default_rng(4).permutation(vertices.shape[0])
    inverse = np.argsort(order)
    moved = _default(vertices[order], inverse[faces][np.random.default_rng(5).permutation(faces.shape[0])])
    np.testing.assert_allclose(moved.radius, first.radius[order], rtol=1e-9)
    np.testing.assert_allclose(moved.mean, first.mean[order], rtol=0, atol=1e-6 * np.nanmax(np.abs(first.mean)))


def test_local_scale_ratios_are_clipped_and_one_without_edges():
    vertices, faces, fine, coarse = _half_refined_sphere()
    topology = MeshTopology.from_faces(faces, vertices.shape[0])
    ratios = local_scale_ratios(vertices, topology)
    assert np.all((ratios >= 1 / 16) & (ratios <= 16))
    assert np.median(ratios[fine]) == 1.0 and np.median(ratios[coarse]) > 4
    lonely = np.vstack([vertices, [[5.0, 5.0, 5.0]]])  # a vertex in no face
    ratios = local_scale_ratios(lonely, MeshTopology.from_faces(faces, lonely.shape[0]))
    assert ratios[-1] == 1.0


@pytest.mark.parametrize("backend", BACKENDS)
def test_both_backends_give_the_local_scale_alike(backend):
    vertices, faces, _, _ = _half_refined_sphere(n_coarse=60, ratio=20.0)
    with use_backend("numpy"):
        reference = _default(vertices, faces)
    with use_backend(backend):
        result = _default(vertices, faces)
    np.testing.assert_allclose(result.radius, reference.radius, rtol=1e-12)
    scale = np.nanmax(np.abs(reference.mean))
    np.testing.assert_allclose(result.mean, reference.mean, rtol=0, atol=1e-6 * scale)


def test_area_weights_must_be_one_finite_number_per_vertex():
    sphere = shapes.icosphere(4)
    with pytest.raises(InvalidMeshError, match="`areas` must hold one finite number >= 0 per vertex"):
        fit_jets(sphere.vertices, sphere.vertices, 0.5, areas=np.ones(3))
    with pytest.raises(InvalidMeshError, match="`areas`"):
        fit_jets(sphere.vertices, sphere.vertices, 0.5, areas=np.full(sphere.vertices.shape[0], np.nan))


def test_area_weights_of_equal_areas_change_no_fit():
    # a common factor of the weights leaves the least-squares solution as it is (to round-off, amplified by
    # the condition number of the degree-3 normal equations: about 1e-8 of the coefficients here)
    sphere = shapes.ellipsoid(subdivisions=5)
    normals = sphere.vertices / np.linalg.norm(sphere.vertices, axis=1, keepdims=True)
    plain, _, _ = fit_jets(sphere.vertices, normals, 0.8, degree=3)
    weighted, _, _ = fit_jets(sphere.vertices, normals, 0.8, degree=3, areas=np.full(sphere.vertices.shape[0], 7.0))
    np.testing.assert_allclose(weighted, plain, rtol=0, atol=1e-6 * np.nanmax(np.abs(plain)))


@pytest.mark.parametrize("backend", [pytest.param("numpy", marks=pytest.mark.slow), *BACKENDS[1:]])
def test_a_dense_voxel_sphere_is_fitted_on_a_coarser_level_within_one_percent(backend):
    # balls of about 35 edge lengths: the normal fits run on clusters of vertices; H of 1/R within 1%
    sphere = shapes.voxel_sphere(2.0, (0.2, 0.1, 0.1), seed=3)
    faces = sphere.faces[:, ::-1]  # marching cubes winds them inward
    with use_backend(backend):
        result = _default(sphere.vertices, faces)
    error = np.abs(result.mean - 0.5)[result.valid] / 0.5
    assert result.valid.mean() > 0.99
    assert np.median(error) < 0.01


@pytest.mark.slow
@pytest.mark.skipif(__import__("importlib").util.find_spec("numba") is None, reason="numba not installed")
def test_both_backends_fit_a_dense_surface_on_the_same_coarser_level():
    # measured: H within 6e-15 of its largest value, radii within 2e-14
    sphere = shapes.voxel_sphere(2.0, (0.2, 0.1, 0.1), seed=3)
    faces = sphere.faces[:, ::-1]
    results = {}
    for backend in ("numba", "numpy"):
        with use_backend(backend):
            results[backend] = _default(sphere.vertices, faces)
    compiled, reference = results["numba"], results["numpy"]
    np.testing.assert_array_equal(compiled.valid, reference.valid)
    np.testing.assert_allclose(compiled.radius, reference.radius, rtol=1e-12)
    np.testing.assert_allclose(compiled.mean, reference.mean, rtol=0, atol=1e-9 * np.nanmax(np.abs(reference.mean)))
