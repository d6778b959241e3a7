"""The analytic meshes and their exact curvatures, checked against closed forms."""

import sys

import numpy as np
import pytest

from meshcurv import geometry, shapes
from meshcurv.errors import InvalidMeshError, InvalidOptionError
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


# -- marching-cubes meshes of voxelised solids (the `volume` extra) -------------------


@pytest.fixture
def skimage():
    return pytest.importorskip("skimage")


@pytest.mark.parametrize("spacing", [(1.0, 1.0, 1.0), (2.0, 1.0, 1.0), (0.3, 0.4, 0.5)])
def test_voxel_sphere_vertices_within_half_a_voxel_and_exact_curvature(skimage, spacing):
    m = shapes.voxel_sphere(6.0, spacing, seed=3)
    distance = np.linalg.norm(m.vertices - m.center, axis=1)
    # a vertex is the midpoint of a grid edge joining a voxel centre inside (<= r) and one outside (> r)
    assert np.abs(distance - 6.0).max() <= max(spacing) / 2 + 1e-12
    np.testing.assert_allclose(np.linalg.norm(m.closest_points - m.center, axis=1), 6.0, rtol=1e-12)
    np.testing.assert_allclose(m.mean, 1 / 6.0, rtol=1e-12)
    np.testing.assert_allclose(m.gaussian, 1 / 36.0, rtol=1e-12)
    np.testing.assert_allclose(np.einsum("ij,ij->i", m.normals, m.vertices - m.center), distance, rtol=1e-12)
    assert m.spacing == spacing


def test_voxel_sphere_is_closed_inward_and_has_the_balls_volume(skimage):
    m = shapes.voxel_sphere(10.0, seed=1)
    top = MeshTopology.from_faces(m.faces, m.vertices.shape[0])
    assert top.interior_edges.all() and top.euler_characteristic == 2
    volume = geometry.signed_volume(m.vertices, m.faces)
    # inward as marching cubes returns it; the voxel count of a radius-10 ball is within 1% of 4/3 pi r^3
    assert volume < 0
    assert -volume == pytest.approx(4 / 3 * np.pi * 1000, rel=0.01)
    normals = geometry.vertex_normals(m.vertices, m.faces)
    assert np.median(np.einsum("ij,ij->i", normals, m.normals)) < -0.9  # faces wound against the exact normals


def test_voxel_shapes_centre_is_a_seeded_sub_voxel_offset(skimage):
    a, b, c = (shapes.voxel_sphere(3.0, (0.5, 0.5, 0.5), seed=s) for s in (0, 0, 1))
    np.testing.assert_array_equal(a.vertices, b.vertices)
    assert not np.allclose(a.center, c.center)
    assert np.abs(a.center - c.center).max() < 0.5  # both within half a voxel of the grid's middle


def test_ellipsoid_closest_points_are_on_the_surface_and_along_the_normal():
    axes = np.array([5.0, 3.0, 2.0])
    rng = np.random.default_rng(0)
    directions = rng.normal(size=(500, 3))
    surface = directions / np.linalg.norm(directions / axes, axis=1, keepdims=True)
    points = surface * rng.uniform(0.8, 1.3, size=(500, 1))  # inside and outside, near the surface
    closest = shapes.ellipsoid_closest_points(points, axes)
    np.testing.assert_allclose(np.sum((closest / axes) ** 2, axis=1), 1.0, rtol=1e-12)
    gradient = closest / axes**2  # the normality condition: y - x parallel to the normal at x
    residual = np.cross(points - closest, gradient / np.linalg.norm(gradient, axis=1, keepdims=True))
    assert np.abs(residual).max() < 1e-10
    # no point of a dense sample of the surface is closer
    u, v = np.meshgrid(np.linspace(0, np.pi, 120), np.linspace(0, 2 * np.pi, 240), indexing="ij")
    sample = np.stack([np.sin(u) * np.cos(v), np.sin(u) * np.sin(v), np.cos(u)], axis=-1).reshape(-1, 3) * axes
    from scipy.spatial import cKDTree

    brute, _ = cKDTree(sample).query(points)
    assert (np.linalg.norm(points - closest, axis=1) <= brute + 1e-12).all()


def test_voxel_ellipsoid_exact_values_match_the_closed_forms(skimage):
    a, b, c = 6.0, 4.0, 3.0
    m = shapes.voxel_ellipsoid((a, b, c), (1.0, 0.5, 0.5), seed=2)
    x, y, z = (m.closest_points - m.center).T
    np.testing.assert_allclose(x**2 / a**2 + y**2 / b**2 + z**2 / c**2, 1.0, rtol=1e-12)
    s = x**2 / a**4 + y**2 / b**4 + z**2 / c**4
    np.testing.assert_allclose(m.gaussian, 1 / (a * b * c) ** 2 / s**2, rtol=1e-9)
    mean = (x**2 + y**2 + z**2 - a * a - b * b - c * c) / (2 * (a * b * c) ** 2 * s**1.5)
    np.testing.assert_allclose(m.mean, -mean, rtol=1e-9)
    assert np.abs(np.cross(m.vertices - m.closest_points, m.normals)).max() < 1e-10
    assert np.linalg.norm(m.vertices - m.closest_points, axis=1).max() <= np.linalg.norm(m.spacing) / 2
    assert geometry.signed_volume(m.vertices, m.faces) == pytest.approx(-4 / 3 * np.pi * a * b * c, rel=0.03)


def test_voxel_torus_exact_values(skimage):
    R, r = 8.0, 3.0
    m = shapes.voxel_torus(R, r, (0.5, 0.5, 0.5), seed=4)
    p = m.closest_points - m.center
    np.testing.assert_allclose(p[:, 0] ** 2 + (np.hypot(p[:, 1], p[:, 2]) - R) ** 2, r * r, rtol=1e-12)
    assert (m.k_max == 1 / r).all()
    rho = np.hypot(p[:, 1], p[:, 2])
    np.testing.assert_allclose(m.k_min, (rho - R) / r / rho, rtol=1e-9, atol=1e-15)  # cos(phi) / (R + r cos(phi))
    assert m.k_min.min() == pytest.approx(-1 / (R - r), rel=0.01) and m.k_max.max() == 1 / r
    top = MeshTopology.from_faces(m.faces, m.vertices.shape[0])
    assert top.euler_characteristic == 0
    assert geometry.signed_volume(m.vertices, m.faces) == pytest.approx(-2 * np.pi**2 * R * r * r, rel=0.02)
    assert np.abs(np.einsum("ij,ij->i", m.dir_max, m.normals)).max() < 1e-12


def test_voxel_shapes_reject_bad_options():
    with pytest.raises(InvalidOptionError, match=r"`spacing` must be 3 numbers.*got \(1, 1\)"):
        shapes.voxel_sphere(5.0, (1, 1))
    # what label_curvatures refuses, the voxel shapes refuse alike (before: a bare ValueError from numpy for a string)
    for spacing, message in [
        ("abc", r"`spacing` must be 3 numbers.*got 'abc'"),
        (["1", "1", "1"], r"`spacing` must be 3 numbers"),
        ((True, True, True), r"`spacing` must be 3 numbers"),
        ((1, 0, 1), r"`spacing` must be positive and finite.*\(1.0, 0.0, 1.0\)"),
        ((1, float("nan"), 1), r"`spacing` must be positive and finite"),
    ]:
        with pytest.raises(InvalidOptionError, match=message):
            shapes.voxel_sphere(5.0, spacing)
    with pytest.raises(InvalidOptionError, match=r"`minor_radius` must be below `major_radius`"):
        shapes.voxel_torus(3.0, 4.0)
    with pytest.raises(InvalidOptionError, match=r"`semi_axes` must be 3 positive number"):
        shapes.voxel_ellipsoid((1.0, -1.0, 2.0))


def test_voxel_shapes_refuse_a_huge_grid(skimage):
    with pytest.raises(InvalidOptionError, match=r"the voxel grid would have .* voxels; use a larger `spacing`"):
        shapes.voxel_sphere(100.0, (0.1, 0.1, 0.1))


def test_voxel_shapes_name_the_extra_without_scikit_image(monkeypatch):
    monkeypatch.setitem(sys.modules, "skimage.measure", None)
    monkeypatch.setitem(sys.modules, "skimage", None)
    with pytest.raises(ImportError, match=r"pip install 'meshcurv\[volume\]'"):
        shapes.voxel_sphere(5.0)


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda: shapes.torus(n_major=0), r"`n_major` must be an integer >= 3; got 0"),
        (lambda: shapes.torus(n_minor=2.5), r"`n_minor` must be an integer >= 3; got 2.5"),
        (lambda: shapes.torus(0, 0), r"`major_radius` must be a positive finite number; got 0"),
        (lambda: shapes.uv_sphere(8, 1), r"`n_latitude` must be an integer >= 2; got 1"),
        (lambda: shapes.uv_sphere(0, 4), r"`n_longitude` must be an integer >= 3; got 0"),
        (lambda: shapes.uv_sphere(radius=0), r"`radius` must be a positive finite number; got 0"),
        (lambda: shapes.icosphere(2, radius=-1), r"`radius` must be a positive finite number; got -1"),
        (lambda: shapes.cylinder(n_around=0), r"`n_around` must be an integer >= 3; got 0"),
        (lambda: shapes.cylinder(height=np.inf), r"`height` must be a positive finite number; got inf"),
        (lambda: shapes.saddle(spacing=0), r"`spacing` must be a positive finite number; got 0"),
        (lambda: shapes.saddle(half_width=np.nan), r"`half_width` must be a positive finite number; got nan"),
        (lambda: shapes.saddle(half_width=1.0, spacing=5.0), r"`spacing` must be below 4 times `half_width`"),
        (lambda: shapes.ellipsoid((1.0, 2.0)), r"`semi_axes` must be 3 positive number\(s\); got \(1.0, 2.0\)"),
        (lambda: shapes.random_ellipsoid((1.0, 0.0, 1.0)), r"`semi_axes` must be 3 positive number"),
        (lambda: shapes.random_sphere(100, 0), r"`radius` must be a positive finite number; got 0"),
        # before: a numpy broadcast error, a spindle torus with infinite k_min, a level of True taken as 1
        (lambda: shapes.icosphere(2, center=(1.0, 2.0)), r"`center` must be 3 finite numbers; got \(1.0, 2.0\)"),
        (lambda: shapes.icosphere(2, center="abc"), r"`center` must be 3 finite numbers; got 'abc'"),
        (lambda: shapes.torus(1.0, 2.0), r"`minor_radius` must be below `major_radius` \(a ring torus\)"),
        (lambda: shapes.with_normal_noise(shapes.icosphere(2), True), r"`level` must be a number >= 0"),
        (lambda: shapes.with_normal_noise(shapes.icosphere(2), np.inf), r"`level` must be a number >= 0"),
    ],
)
def test_shape_options_are_checked_not_numpy_errors(make, message):
    # before: ZeroDivisionError, IndexError, numpy broadcast or RuntimeWarning, or a silently inverted sphere
    with pytest.raises(InvalidOptionError, match=message):
        make()


def test_with_normal_noise_takes_numpy_levels_and_refuses_other_meshes():
    mesh = shapes.icosphere(2)
    moved = shapes.with_normal_noise(mesh, np.float32(0.1), seed=3)
    assert moved.vertices.shape == mesh.vertices.shape and (moved.faces == mesh.faces).all()
    # each vertex moved along its exact normal only: the unit sphere's points stay on their rays
    assert np.allclose(np.cross(moved.vertices, mesh.normals), 0.0, atol=1e-12)
    with pytest.raises(InvalidMeshError, match=r"`mesh` must be an AnalyticMesh .*; got tuple"):
        shapes.with_normal_noise((mesh.vertices, mesh.faces), 0.1)


def test_icosphere_center_moves_the_sphere():
    sphere = shapes.icosphere(3, radius=2.0, center=(1.0, -2.0, 3.0))
    assert np.allclose(np.linalg.norm(sphere.vertices - [1.0, -2.0, 3.0], axis=1), 2.0)
