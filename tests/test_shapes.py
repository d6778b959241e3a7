"""The analytic meshes and their exact curvatures, checked against closed forms."""

import numpy as np
import pytest

from meshcurv import geometry, shapes
from meshcurv.topology import MeshTopology

from conftest import DATA


def test_torus_is_matgeoms_torusmesh_default():
    torus = shapes.torus()
    with np.load(DATA / "matgeom" / "torus_tri.npz") as tri, np.load(DATA / "matgeom" / "torus_quads.npz") as quads:
        np.testing.assert_allclose(torus.vertices, tri["vertices"], rtol=0, atol=1e-12)
        np.testing.assert_array_equal(torus.faces, tri["faces"])
        np.testing.assert_array_equal(torus.quads, quads["faces"])


@pytest.mark.parametrize("n", [1, 2, 5, 16])
def test_icosphere_counts_and_closure(n):
    sphere = shapes.icosphere(n, radius=3.0)
    assert sphere.vertices.shape[0] == 10 * n * n + 2
    assert sphere.faces.shape[0] == 20 * n * n
    np.testing.assert_allclose(np.linalg.norm(sphere.vertices, axis=1), 3.0)
    top = MeshTopology.from_faces(sphere.faces)
    assert top.interior_edges.all() and top.euler_characteristic == 2
    assert geometry.signed_volume(sphere.vertices, sphere.faces) > 0


def test_uv_sphere_is_closed_and_outward():
    sphere = shapes.uv_sphere(32, 16)
    assert sphere.vertices.shape[0] == 32 * 15 + 2 == 482
    top = MeshTopology.from_faces(sphere.faces)
    assert top.interior_edges.all() and top.euler_characteristic == 2
    assert geometry.signed_volume(sphere.vertices, sphere.faces) > 0


def test_faces_are_wound_towards_the_exact_normals():
    for mesh in (shapes.torus(), shapes.ellipsoid(), shapes.cylinder(), shapes.saddle(spacing=0.1)):
        normals = geometry.vertex_normals(mesh.vertices, mesh.faces)
        assert np.sum(normals * mesh.normals, axis=1).min() > 0.9, mesh.name


def test_ellipsoid_gaussian_and_mean_match_the_closed_forms():
    a, b, c = 3.0, 2.0, 1.0
    e = shapes.ellipsoid((a, b, c), subdivisions=6)
    x, y, z = e.vertices.T
    s = x**2 / a**4 + y**2 / b**4 + z**2 / c**4
    gaussian = 1 / (a * b * c) ** 2 / s**2
    mean = (x**2 + y**2 + z**2 - a * a - b * b - c * c) / (2 * (a * b * c) ** 2 * s**1.5)
    np.testing.assert_allclose(e.gaussian, gaussian, rtol=1e-10)
    np.testing.assert_allclose(e.mean, -mean, rtol=1e-10)  # outward normals: convex is positive
    assert (e.k_min > 0).all()


def test_saddle_matches_the_height_field_formulas():
    s = shapes.saddle(spacing=0.1)
    x, y, _ = s.vertices.T
    w2 = 1 + 4 * x**2 + 4 * y**2
    np.testing.assert_allclose(s.gaussian, -4 / w2**2, rtol=1e-10)
    np.testing.assert_allclose(s.mean, 4 * (x**2 - y**2) / w2**1.5, atol=1e-12)
    centre = np.argmin(np.hypot(x, y))
    assert s.k_min[centre] == pytest.approx(-2) and s.k_max[centre] == pytest.approx(2)
    np.testing.assert_allclose(np.abs(s.dir_min[centre]), [1, 0, 0], atol=1e-12)


def test_torus_and_cylinder_closed_forms():
    t = shapes.torus(major_radius=3.0, minor_radius=1.0, n_major=24, n_minor=16)
    outer = np.argmax(np.linalg.norm(t.vertices[:, :2], axis=1))
    assert t.k_min[outer] == pytest.approx(1 / 4) and t.k_max[outer] == pytest.approx(1.0)
    inner = np.argmin(np.linalg.norm(t.vertices[:, :2], axis=1))
    assert t.k_min[inner] == pytest.approx(-1 / 2)
    c = shapes.cylinder(radius=2.0)
    assert (c.k_max == 0.5).all() and (c.k_min == 0).all()
    assert np.isnan(shapes.icosphere(2).dir_min).all()  # umbilic everywhere
