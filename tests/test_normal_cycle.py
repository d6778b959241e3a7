"""method="normal_cycle": analytic surfaces first, then invariances."""

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes
from meshcurv.errors import MeshQualityWarning

from conftest import random_rotation, relative_error


def curvatures(mesh_or_vertices, faces=None, **options):
    if faces is None:
        mesh_or_vertices, faces = mesh_or_vertices.vertices, mesh_or_vertices.faces
    return meshcurv.principal_curvatures(mesh_or_vertices, faces, method="normal_cycle", **options)


@pytest.mark.parametrize("radius", [1.0, 1000.0])
def test_sphere_curvature_is_one_over_radius(radius):
    # 2562-vertex icosphere, default smoothing: median within 1%, worst within 3%
    sphere = shapes.icosphere(16, radius=radius)
    r = curvatures(sphere)
    assert r.valid.all()
    for values in (r.k_min, r.k_max, r.mean):
        error = relative_error(values, 1 / radius)
        assert np.median(error) < 0.01
        assert error.max() < 0.03
    assert np.median(relative_error(r.gaussian, 1 / radius**2)) < 0.02


def test_normals_are_outward_on_an_outward_wound_sphere():
    sphere = shapes.icosphere(8)
    r = curvatures(sphere)
    assert np.sum(r.normals * sphere.normals, axis=1).min() > 0.9999


def test_directions_are_unit_and_orthogonal_to_each_other_and_the_normal():
    torus = shapes.torus()
    r = curvatures(torus)
    for d in (r.dir_min, r.dir_max, r.normals):
        np.testing.assert_allclose(np.linalg.norm(d, axis=1), 1, atol=1e-12)
    for a, b in ((r.dir_min, r.dir_max), (r.dir_min, r.normals), (r.dir_max, r.normals)):
        np.testing.assert_allclose(np.sum(a * b, axis=1), 0, atol=1e-12)


def test_torus_curvatures_and_directions():
    torus = shapes.torus()
    r = curvatures(torus)
    assert (r.k_max >= r.k_min).all()
    assert np.median(relative_error(r.k_max, torus.k_max)) < 0.03
    # k_min crosses zero on the top and bottom circles: compare to the tube's scale
    assert np.abs(r.k_min - torus.k_min).max() < 0.03 * torus.k_max.max()
    assert np.median(relative_error(r.mean, torus.mean)) < 0.01
    angle = np.degrees(np.arccos(np.abs(np.sum(r.dir_max * torus.dir_max, axis=1)).clip(0, 1)))
    assert angle.max() < 1.0


def test_cylinder_fixes_the_conventions():
    # open tube of radius 2, faces wound outward: k_max = 1/2 around, k_min = 0 along the axis
    tube = shapes.cylinder(radius=2.0, height=8.0, n_around=48, n_along=40)
    with pytest.warns(MeshQualityWarning, match="boundary edges"):
        r = curvatures(tube)
    inner = r.valid
    assert inner.sum() == tube.vertices.shape[0] - 2 * 48  # the two boundary rings are invalid
    np.testing.assert_allclose(r.k_max[inner], 0.5, rtol=0.02)
    np.testing.assert_allclose(r.k_min[inner], 0.0, atol=0.01)
    assert np.abs(np.sum(r.dir_max[inner] * tube.dir_max[inner], axis=1)).min() > 0.999
    assert np.abs(r.dir_min[inner, 2]).min() > 0.999  # along the axis
    np.testing.assert_allclose(r.mean[inner], 0.25, rtol=0.02)
    np.testing.assert_allclose(r.gaussian[inner], 0.0, atol=0.005)


def test_saddle_centre_and_boundary():
    saddle = shapes.saddle(half_width=1.0, spacing=0.025)
    with pytest.warns(MeshQualityWarning, match="320 boundary edges") as record:
        r = curvatures(saddle)
    assert len(record) == 1
    centre = np.argmin(np.linalg.norm(saddle.vertices[:, :2], axis=1))
    assert abs(r.k_min[centre] + 2) < 0.06 and abs(r.k_max[centre] - 2) < 0.06
    np.testing.assert_allclose(r.normals[centre], [0, 0, 1], atol=1e-12)
    assert abs(r.dir_min[centre, 0]) > 0.9999  # bends towards the normal along x
    assert abs(r.dir_max[centre, 1]) > 0.9999
    # boundary vertices: undefined (their cells miss the bending across the boundary)
    boundary = np.abs(saddle.vertices[:, :2]).max(axis=1) > 1 - 1e-9
    assert not r.valid[boundary].any() and r.valid[~boundary].all()
    assert np.isnan(r.k_min[boundary]).all() and np.isnan(r.mean[boundary]).all()
    assert np.isfinite(r.normals).all()


def test_scaling_divides_curvature_by_the_factor():
    torus = shapes.torus(n_major=30, n_minor=20)
    base = curvatures(torus)
    for s in (1e-3, 7.5, 1e4):
        scaled = curvatures(torus.vertices * s, torus.faces)
        np.testing.assert_allclose(scaled.k_min * s, base.k_min, rtol=1e-12, atol=1e-12 * base.k_max.max())
        np.testing.assert_allclose(scaled.k_max * s, base.k_max, rtol=1e-12)
        np.testing.assert_allclose(scaled.gaussian * s * s, base.gaussian, rtol=1e-10, atol=1e-14)


def test_rigid_motion_rotates_directions_only():
    torus = shapes.torus(n_major=30, n_minor=20)
    base = curvatures(torus)
    rotation = random_rotation(1)
    moved = curvatures(torus.vertices @ rotation.T + [3.0, -40.0, 12.5], torus.faces)
    np.testing.assert_allclose(moved.k_min, base.k_min, atol=1e-11)
    np.testing.assert_allclose(moved.k_max, base.k_max, atol=1e-11)
    np.testing.assert_allclose(moved.normals, base.normals @ rotation.T, atol=1e-10)
    for name in ("dir_min", "dir_max"):
        dots = np.sum(getattr(moved, name) * (getattr(base, name) @ rotation.T), axis=1)
        np.testing.assert_allclose(np.abs(dots), 1, atol=1e-8)


def test_reindexing_vertices_permutes_the_result():
    torus = shapes.torus(n_major=30, n_minor=20)
    base = curvatures(torus)
    perm = np.random.default_rng(2).permutation(torus.vertices.shape[0])
    inverse = np.argsort(perm)
    shuffled = curvatures(torus.vertices[perm], inverse[torus.faces])
    np.testing.assert_allclose(shuffled.k_min, base.k_min[perm], atol=1e-12)
    np.testing.assert_allclose(shuffled.k_max, base.k_max[perm], atol=1e-12)
    np.testing.assert_allclose(shuffled.normals, base.normals[perm], atol=1e-12)


def test_reversing_every_face_flips_signs_and_keeps_gaussian():
    torus = shapes.torus(n_major=30, n_minor=20)
    base = curvatures(torus)
    flipped = curvatures(torus.vertices, torus.faces[:, ::-1], orient="keep")
    np.testing.assert_allclose(flipped.k_min, -base.k_max, atol=1e-12)
    np.testing.assert_allclose(flipped.k_max, -base.k_min, atol=1e-12)
    np.testing.assert_allclose(flipped.mean, -base.mean, atol=1e-12)
    np.testing.assert_allclose(flipped.gaussian, base.gaussian, atol=1e-12)
    np.testing.assert_allclose(flipped.normals, -base.normals, atol=1e-12)


@pytest.mark.parametrize("steps", [0, 1, 3])
def test_smoothing_steps_are_accepted_and_zero_means_none(steps):
    sphere = shapes.icosphere(12)
    r = curvatures(sphere, smoothing_steps=steps)
    assert r.parameters["smoothing_steps"] == steps
    # without smoothing the 12 valence-5 vertices stand out; smoothing spreads them
    spread = np.ptp(r.mean)
    if steps == 0:
        assert spread > 0.05
    else:
        assert spread < 0.05


def test_defects_give_defined_results_and_one_aggregated_warning():
    sphere = shapes.icosphere(6)
    v, f = sphere.vertices.copy(), sphere.faces
    a, b, c = f[0]
    v[c] = v[a]  # faces on edge (a, c) lose their area
    tip = v.shape[0]
    v = np.vstack([v, [[3.0, 3.0, 3.0]]])
    p, q = f[100, :2]
    faces = np.vstack([f, [p, q, tip]])  # a fin: edge (p, q) gets a third face
    with pytest.warns(MeshQualityWarning) as record:
        r = curvatures(v, faces)
    assert len(record) == 1
    message = str(record[0].message)
    assert "1 non-manifold edges" in message
    assert "2 boundary edges" in message
    assert "2 zero-area faces" in message
    assert not r.valid[[a, c, p, q, tip]].any()
    assert np.isnan(r.k_min[~r.valid]).all() and np.isfinite(r.k_min[r.valid]).all()
    assert r.valid.sum() >= sphere.vertices.shape[0] - 10
    # far from the defects the estimate is the clean sphere's
    clean = curvatures(sphere)
    far = np.linalg.norm(sphere.vertices - sphere.vertices[a], axis=1) > 1.0
    far &= np.linalg.norm(sphere.vertices - sphere.vertices[p], axis=1) > 1.0
    np.testing.assert_allclose(r.k_min[:tip][far], clean.k_min[far], rtol=1e-12)
