"""A second side stored with vertices of its own, on a mesh that is not welded (issue 29, class 7).

``method='matgeom'`` (and any call with ``weld=False``) did not weld, so a double-sided mesh whose second side has
vertices of its own (each face's copy on copies of its corners, as STL and some exporters write them) was two
surfaces: every copy valid with the other side's curvature (H = -1/R on a sphere of radius R), no warning, and the
integrals counting the surface twice (area twice, total Gaussian curvature 8 pi). fuzz_api's double-sided relation
shared the vertices and left matgeom out; found by F30's probe, session 64. The oracles: the one-sided mesh's own
result (the same faces and vertices, so the same numbers, bit for bit: matGeom's on the side kept), Gauss-Bonnet
(4 pi) and the re-indexing invariance (each copy gets its twin's values).
"""

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes

from conftest import chosen_backend
from test_double_sided import one_warning as _one_warning


def _second_side_apart(vertices, faces, seed=None):
    """``vertices`` twice, the second side's faces reversed on the copies (shuffled with ``seed``)."""
    n = vertices.shape[0]
    second = faces[:, ::-1] + n
    both = np.vstack([faces, second])
    if seed is not None:
        both = both[np.random.default_rng(seed).permutation(both.shape[0])]
    return np.vstack([vertices, vertices]), both


@pytest.mark.parametrize("backend", ["numba", "numpy"])
@pytest.mark.parametrize("seed", [None, 3])
@pytest.mark.parametrize(
    "mesh", [shapes.icosphere(3, radius=2.0), shapes.torus(3.0, 1.0, 32, 16)], ids=lambda mesh: mesh.name
)
def test_matgeom_measures_a_second_side_with_vertices_of_its_own_once(mesh, seed, backend):
    with chosen_backend(backend):
        one = meshcurv.principal_curvatures(mesh.vertices, mesh.faces, method="matgeom")
        vertices, faces = _second_side_apart(mesh.vertices, mesh.faces, seed)
        both, message = _one_warning(vertices, faces, method="matgeom")
    n = mesh.vertices.shape[0]
    assert f"dropped {mesh.faces.shape[0]} faces" in message and "double-sided" in message
    assert both.parameters["n_double_sided_faces"] == mesh.faces.shape[0]
    # the side kept is the given one (outward): matGeom's numbers on it, and each copy its twin's
    for name in ("k_min", "k_max", "mean", "gaussian"):
        np.testing.assert_array_equal(getattr(both, name)[:n], getattr(one, name))
        np.testing.assert_array_equal(getattr(both, name)[n:], getattr(one, name))
    assert both.valid.all()
    # the surface counted once: its area, and Gauss-Bonnet's 2 pi chi (4 pi for the sphere, 0 for the torus)
    assert both.integral("area") == pytest.approx(one.integral("area"), rel=1e-12)
    total = 4 * np.pi if mesh.name.startswith("icosphere") else 0.0
    assert both.integral("gaussian") == pytest.approx(total, abs=1e-9)


def test_any_unwelded_call_finds_the_second_side():
    sphere = shapes.icosphere(3)
    vertices, faces = _second_side_apart(sphere.vertices, sphere.faces)
    one = meshcurv.principal_curvatures(sphere.vertices, sphere.faces, method="normal_cycle", weld=False)
    both, _ = _one_warning(vertices, faces, method="normal_cycle", weld=False)
    np.testing.assert_array_equal(both.mean[sphere.vertices.shape[0] :], one.mean)
    assert both.integral("gaussian") == pytest.approx(4 * np.pi, abs=1e-9)


def test_a_part_stored_twice_with_one_winding_is_not_taken_for_two_sides():
    # every vertex has a copy at its point, but the copy's faces have the same winding: a closed part stored
    # twice, not a second side (the weld's closed copies; without a weld, two parts as given)
    sphere = shapes.icosphere(3)
    n = sphere.vertices.shape[0]
    vertices = np.vstack([sphere.vertices, sphere.vertices])
    faces = np.vstack([sphere.faces, sphere.faces + n])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = meshcurv.principal_curvatures(vertices, faces, method="matgeom")
    one = meshcurv.principal_curvatures(sphere.vertices, sphere.faces, method="matgeom")
    assert result.parameters["n_double_sided_faces"] == 0
    np.testing.assert_allclose(result.mean[n:], one.mean, rtol=1e-12)
