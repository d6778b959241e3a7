"""Parts of very different scales in one mesh (issue 29, "never lie"; fuzz round 16, seed 274 case 172).

A saddle 2 units wide beside a voxel sphere scaled by 1e12 and moved by 5e12: the weld's tolerance came
from the median edge of the whole mesh (the sphere's, 1e12: a tolerance of 1e7), which welded the
saddle's whole boundary into one point; and the sphere's voxel grid held the saddle "on" it (within the
grid's tolerance of a lattice point), so the voxel rule gave it a radius of at least a voxel (1e12): its
valid vertices were off the exact saddle by 1.0 of their |k|, and the two backends apart by 6.5e-4. Each
part is now welded within its own tolerance, and a mesh with a part off its grid's scale is measured as
an ordinary mesh, each group of components of one scale at its own radius.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import MeshTopology, shapes
from meshcurv._backend import use_backend
from meshcurv.weld import drop_closed_copies, weld_vertices

#: The saddle measured alone (icc, default radius) is within this share of each vertex's largest |k| of the
#: exact values (0.23 at worst); a ball over the whole saddle gives 1.0 and more.
SADDLE_TOLERANCE = 0.3

try:
    import numba  # noqa: F401

    BACKENDS = ("numpy", "numba")
except ImportError:  # pragma: no cover - the no-extras job
    BACKENDS = ("numpy",)


def _saddle_beside(big_vertices, big_faces, scale: float):
    saddle = shapes.saddle(spacing=0.2)
    vertices = np.concatenate([saddle.vertices, big_vertices * scale + 5 * scale])
    faces = np.concatenate([saddle.faces, big_faces + len(saddle.vertices)])
    return saddle, vertices, faces


def _saddle_errors(saddle, result) -> tuple[np.ndarray, np.ndarray]:
    n = len(saddle.vertices)
    largest = np.maximum(np.abs(saddle.k_min), np.abs(saddle.k_max))
    error = np.maximum(np.abs(result.k_max[:n] - saddle.k_max), np.abs(result.k_min[:n] - saddle.k_min)) / largest
    return result.valid[:n], error


@pytest.mark.parametrize("scale", [1e6, 1e12])
def test_a_small_part_is_welded_at_its_own_scale(scale):
    sphere = shapes.icosphere(subdivisions=4)
    saddle, vertices, faces = _saddle_beside(sphere.vertices, sphere.faces, scale)
    welding = weld_vertices(vertices, MeshTopology.from_faces(faces))
    assert welding.n_welded == 0  # nothing coincides: the saddle's boundary is its own
    # a small soup beside the large part is still welded back (within its own tolerance)
    soup = saddle.vertices[saddle.faces.ravel()]
    vertices = np.concatenate([soup, sphere.vertices * scale + 5 * scale])
    faces = np.concatenate([np.arange(soup.shape[0]).reshape(-1, 3), sphere.faces + soup.shape[0]])
    welding = weld_vertices(vertices, MeshTopology.from_faces(faces))
    assert welding.vertices.shape[0] == len(saddle.vertices) + len(sphere.vertices)
    assert welding.topology.boundary_edges.sum() == MeshTopology.from_faces(saddle.faces).boundary_edges.sum()


def test_two_small_parts_apart_are_no_copies_beside_a_large_one():
    small = shapes.icosphere(subdivisions=2)
    large = shapes.icosphere(subdivisions=5)
    n = len(small.vertices)
    shifted = small.vertices + [1e-3, 0.0, 0.0]  # 1e-2 of its edges: another sphere, not a copy
    vertices = np.concatenate([small.vertices, shifted, large.vertices * 1e9 + 5e9])
    faces = np.concatenate([small.faces, small.faces + n, large.faces + 2 * n])
    assert drop_closed_copies(vertices, MeshTopology.from_faces(faces)).n_welded == 0
    # an exact copy is still one
    vertices[n : 2 * n] = small.vertices
    assert drop_closed_copies(vertices, MeshTopology.from_faces(faces)).n_welded == n


@pytest.mark.parametrize("scale", [1e9, 1e12])
def test_a_small_part_beside_a_voxel_surface_is_measured_at_its_own_scale(scale):
    pytest.importorskip("skimage")
    sphere = shapes.voxel_sphere(radius=4.0)
    saddle, vertices, faces = _saddle_beside(sphere.vertices, sphere.faces, scale)
    results = {}
    for backend in BACKENDS:
        with use_backend(backend), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            results[backend] = meshcurv.principal_curvatures(vertices, faces, method="icc")
        valid, error = _saddle_errors(saddle, results[backend])
        assert valid.sum() >= 0.9 * valid.size
        assert np.all(error[valid] <= SADDLE_TOLERANCE)
        assert results[backend].parameters["n_welded_vertices"] == 0
    if len(results) == 2:
        a, b = results["numba"], results["numpy"]
        both = a.valid & b.valid
        size = np.abs(a.k_max[both]).max()
        np.testing.assert_allclose(a.k_max[both] / size, b.k_max[both] / size, rtol=0, atol=1e-6)
        np.testing.assert_allclose(a.k_min[both] / size, b.k_min[both] / size, rtol=0, atol=1e-6)


@pytest.mark.parametrize("method", ["quadric", "normal_cycle_ball"])
def test_the_other_ball_methods_measure_the_small_part_too(method):
    pytest.importorskip("skimage")
    sphere = shapes.voxel_sphere(radius=4.0)
    saddle, vertices, faces = _saddle_beside(sphere.vertices, sphere.faces, 1e12)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = meshcurv.principal_curvatures(vertices, faces, method=method)
        alone = meshcurv.principal_curvatures(saddle.vertices, saddle.faces, method=method)
    valid, error = _saddle_errors(saddle, result)
    valid_alone, error_alone = _saddle_errors(saddle, alone)
    assert valid.sum() >= valid_alone.sum()
    # the saddle's own accuracy, not that of a ball of 1e12 over all of it
    assert np.median(error[valid]) <= 2 * np.median(error_alone[valid_alone]) + 0.05


def test_a_voxel_surface_alone_keeps_its_voxel_rule():
    pytest.importorskip("skimage")
    sphere = shapes.voxel_sphere(radius=6.0)
    for scale in (1.0, 1e12):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            result = meshcurv.principal_curvatures(sphere.vertices * scale + 5 * scale, sphere.faces)
        assert result.parameters["surface"] == "voxel"
