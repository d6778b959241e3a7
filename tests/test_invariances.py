"""The same invariance tests for every method: face flip, scale, rigid motion, re-indexing.

Curvatures are functions of the surface, so none of these may change them
beyond the stated law; tolerances are round-off, relative to the curvature scale.
"""

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv.errors import MeshQualityWarning
from meshcurv import shapes
from meshcurv.estimators import ESTIMATORS

from conftest import random_rotation

METHODS = [name for name in ESTIMATORS if name != "matgeom"]


@pytest.fixture(scope="module")
def mesh():
    # irregular, so that no symmetry of the grid hides a mistake
    return shapes.torus(3.0, 1.0, 36, 18, jitter=0.3, seed=5)


#: quadric's warning on this torus since its smaller balls take quadrics over points spread across the tube
#: (e459c2c): 6 default balls reach round the tube, no smaller one holds a fit, NaN (10-33% of the largest |k| off
#: before); the vertices' NaN and reasons are part of what the invariances compare
REACH_WARNING = r"quadric: 6 vertices have a default ball that reaches round the surface"


def run(vertices, faces, method, **options):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        warnings.filterwarnings("ignore", REACH_WARNING, MeshQualityWarning)
        return meshcurv.principal_curvatures(vertices, faces, method=method, **options)


def close_directions(a, b, atol):
    finite = np.isfinite(a).all(axis=1)
    np.testing.assert_array_equal(finite, np.isfinite(b).all(axis=1))
    np.testing.assert_allclose(np.abs(np.sum(a[finite] * b[finite], axis=1)), 1, atol=atol)


@pytest.mark.parametrize("method", METHODS)
def test_reversing_every_face_flips_signs_and_keeps_gaussian(method, mesh):
    # orient="keep": the literal convention (the default would turn the faces back outward)
    base = run(mesh.vertices, mesh.faces, method, orient="keep")
    flipped = run(mesh.vertices, mesh.faces[:, ::-1], method, orient="keep")
    np.testing.assert_allclose(flipped.k_min, -base.k_max, atol=1e-10)
    np.testing.assert_allclose(flipped.k_max, -base.k_min, atol=1e-10)
    np.testing.assert_allclose(flipped.gaussian, base.gaussian, atol=1e-10)
    np.testing.assert_allclose(flipped.normals, -base.normals, atol=1e-10)
    close_directions(flipped.dir_max, base.dir_min, 1e-8)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("s", [1e-3, 7.5, 1e4])
def test_scaling_divides_curvature_by_the_factor(method, s, mesh):
    base = run(mesh.vertices, mesh.faces, method)
    scaled = run(mesh.vertices * s, mesh.faces, method)
    np.testing.assert_allclose(scaled.k_min * s, base.k_min, atol=1e-9)
    np.testing.assert_allclose(scaled.k_max * s, base.k_max, atol=1e-9)
    np.testing.assert_allclose(scaled.normals, base.normals, atol=1e-9)
    if "radius" in ESTIMATORS[method].options:
        assert scaled.parameters["radius"] == pytest.approx(s * base.parameters["radius"])
        explicit = run(mesh.vertices * s, mesh.faces, method, radius=s * 1.0)
        again = run(mesh.vertices, mesh.faces, method, radius=1.0)
        np.testing.assert_allclose(explicit.k_max * s, again.k_max, atol=1e-9)


@pytest.mark.parametrize("method", METHODS)
def test_rigid_motion_rotates_directions_only(method, mesh):
    base = run(mesh.vertices, mesh.faces, method)
    rotation = random_rotation(1)
    moved = run(mesh.vertices @ rotation.T + [3.0, -40.0, 12.5], mesh.faces, method)
    np.testing.assert_allclose(moved.k_min, base.k_min, atol=1e-9)
    np.testing.assert_allclose(moved.k_max, base.k_max, atol=1e-9)
    np.testing.assert_allclose(moved.normals, base.normals @ rotation.T, atol=1e-9)
    close_directions(moved.dir_max, base.dir_max @ rotation.T, 1e-6)
    close_directions(moved.dir_min, base.dir_min @ rotation.T, 1e-6)


@pytest.mark.parametrize("method", METHODS)
def test_reindexing_vertices_and_faces_permutes_the_result(method, mesh):
    base = run(mesh.vertices, mesh.faces, method)
    rng = np.random.default_rng(2)
    perm = rng.permutation(mesh.vertices.shape[0])
    inverse = np.argsort(perm)
    faces = inverse[mesh.faces][rng.permutation(mesh.faces.shape[0])]
    shuffled = run(mesh.vertices[perm], np.roll(faces, 1, axis=1), method)
    np.testing.assert_allclose(shuffled.k_min, base.k_min[perm], atol=1e-10)
    np.testing.assert_allclose(shuffled.k_max, base.k_max[perm], atol=1e-10)
    np.testing.assert_allclose(shuffled.normals, base.normals[perm], atol=1e-10)
    close_directions(shuffled.dir_max, base.dir_max[perm], 1e-8)
