"""Every registered method on the analytic surfaces, and its options.

Tolerances are set from the estimators' known bias: a ball of radius ``r``
(default 2.5 mean edge lengths) averages the curvature over a region whose
size relative to the radius of curvature sets the error; 1-ring methods are
exact to second order on regular meshes.
"""

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes
from meshcurv.errors import InvalidOptionError, MeshQualityWarning
from meshcurv.estimators import ESTIMATORS, icc
from meshcurv import radius as radius_rules
from meshcurv.neighborhoods import face_in_ball_ratios, segment_in_ball_lengths
from meshcurv.radius import DEFAULT_RADIUS_FACTOR

from conftest import relative_error

#: the methods in true units (matGeom's mode is dimensionless: tested in test_matgeom_parity)
METHODS = [name for name in ESTIMATORS if name != "matgeom"]
WITH_DIRECTIONS = [m for m in METHODS if m != "meyer"]
WITH_RADIUS = [m for m in METHODS if "radius" in ESTIMATORS[m].options]
#: methods that keep boundary vertices (the others mark them invalid)
KEEP_BOUNDARY = ["icc", "quadric", "rusinkiewicz", "normal_cycle_ball"]


def curvatures(mesh, method, **options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshQualityWarning)
        return meshcurv.principal_curvatures(mesh.vertices, mesh.faces, method=method, **options)


@pytest.fixture(scope="module")
def sphere():
    return shapes.icosphere(12, radius=2.0)


@pytest.fixture(scope="module")
def torus():
    return shapes.torus(3.0, 1.0, 96, 48)


@pytest.mark.parametrize("method", METHODS)
def test_sphere_is_one_over_radius(method, sphere):
    # 1442 vertices, r = 2: every method within 4% (median) of 1/2
    r = curvatures(sphere, method)
    assert r.valid.all()
    for values in (r.k_min, r.k_max, r.mean):
        assert np.median(relative_error(values, 0.5)) < 0.04
    assert np.median(relative_error(r.gaussian, 0.25)) < 0.08
    assert np.sum(r.normals * sphere.normals, axis=1).min() > 0.99


@pytest.mark.parametrize("method", METHODS)
def test_irregular_sphere(method):
    # random Delaunay sphere, 2000 points: the ball methods stay within 5% (median);
    # the 1-ring ones are known not to converge pointwise there (15%)
    sphere = shapes.random_sphere(2000, seed=3)
    r = curvatures(sphere, method)
    bound = 0.05 if method in WITH_RADIUS or method == "normal_cycle" else 0.2
    assert np.median(relative_error(r.mean[r.valid], 1.0)) < bound


@pytest.mark.parametrize("method", METHODS)
def test_torus_curvatures_and_directions(method, torus):
    r = curvatures(torus, method)
    assert r.valid.all()
    # k_min crosses zero: errors relative to the tube curvature 1
    assert np.median(np.abs(r.k_max - torus.k_max)) < 0.05
    assert np.median(np.abs(r.k_min - torus.k_min)) < 0.05
    assert np.median(np.abs(r.mean - torus.mean)) < 0.03
    if method in WITH_DIRECTIONS:
        cos = np.abs(np.sum(r.dir_max * torus.dir_max, axis=1))
        assert np.mean(cos > np.cos(np.radians(8))) > 0.99
    else:
        assert np.isnan(r.dir_min).all() and np.isnan(r.dir_max).all()


@pytest.mark.parametrize("method", METHODS)
def test_cylinder_signs_and_directions(method):
    tube = shapes.cylinder(radius=2.0, height=8.0, n_around=48, n_along=40)
    r = curvatures(tube, method)
    inner = np.abs(tube.vertices[:, 2]) < 4 - 1e-9
    if method in KEEP_BOUNDARY:
        assert r.valid.all()
    else:
        assert r.valid.sum() == inner.sum()
    away = np.abs(tube.vertices[:, 2]) < 2  # a ball radius away from the rims
    np.testing.assert_allclose(r.k_max[away], 0.5, rtol=0.05)
    np.testing.assert_allclose(r.k_min[away], 0.0, atol=0.025)
    np.testing.assert_allclose(r.gaussian[away], 0.0, atol=0.0125)
    if method in WITH_DIRECTIONS:
        assert np.abs(r.dir_min[away, 2]).min() > 0.99  # along the axis


@pytest.mark.parametrize("method", METHODS)
def test_saddle_centre(method):
    saddle = shapes.saddle(half_width=1.0, spacing=0.025)
    r = curvatures(saddle, method)
    centre = np.argmin(np.linalg.norm(saddle.vertices[:, :2], axis=1))
    assert abs(r.k_min[centre] + 2) < 0.1 and abs(r.k_max[centre] - 2) < 0.1
    assert abs(r.gaussian[centre] + 4) < 0.4
    assert r.normals[centre, 2] > 0.999
    if method in WITH_DIRECTIONS:
        assert abs(r.dir_min[centre, 0]) > 0.99 and abs(r.dir_max[centre, 1]) > 0.99


@pytest.mark.parametrize("method", KEEP_BOUNDARY)
def test_hemisphere_boundary_is_kept_and_close(method):
    # open hemisphere: boundary vertices are valid and within 10% at the 95th percentile
    half = shapes.hemisphere(12)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = meshcurv.principal_curvatures(half.vertices, half.faces, method=method)
    boundary = meshcurv.MeshTopology.from_faces(half.faces).boundary_vertices
    assert r.valid.all()
    # measured (icosphere(12) half): icc 0.1%, quadric 1.5%, the others up to 30%;
    # the 10% target for icc is pinned below
    assert np.percentile(relative_error(r.mean[boundary], 1.0), 95) < (0.1 if method in ("icc", "quadric") else 0.35)


@pytest.mark.parametrize("irregular", [False, True])
def test_icc_hemisphere_boundary_p95_below_ten_percent(irregular):
    # issue 3 target: with normals from jets fitted over the (one-sided) ball, icc's boundary
    # vertices are as good as the interior: measured p95 0.1% (regular), 0.2% (irregular)
    half = shapes.hemisphere(12, irregular=irregular, seed=12)
    r = curvatures(half, "icc")
    boundary = meshcurv.MeshTopology.from_faces(half.faces).boundary_vertices
    assert r.valid[boundary].all()
    assert np.percentile(relative_error(r.mean[boundary], 1.0), 95) < 0.1


@pytest.mark.parametrize("method", ["meyer", "normal_cycle"])
def test_one_ring_methods_mark_the_boundary_invalid(method):
    half = shapes.hemisphere(6)
    with pytest.warns(MeshQualityWarning, match="boundary edges"):
        r = meshcurv.principal_curvatures(half.vertices, half.faces, method=method)
    boundary = meshcurv.MeshTopology.from_faces(half.faces).boundary_vertices
    assert not r.valid[boundary].any() and np.isnan(r.mean[boundary]).all()


def test_icc_converges_on_an_irregular_sphere():
    # error falls as the random sphere is refined (radius a fixed multiple of h)
    errors = []
    for n in (500, 2000, 8000):
        r = curvatures(shapes.random_sphere(n, seed=1), "icc")
        errors.append(np.median(relative_error(r.mean, 1.0)))
    assert errors[0] > errors[1] > errors[2]


def test_icc_is_accurate_under_noise():
    # 0.1 x mean edge length of normal noise on a 2562-vertex sphere: below 5% median error of H
    noisy = shapes.with_normal_noise(shapes.icosphere(16), 0.1, seed=0)
    r = curvatures(noisy, "icc")
    assert np.median(relative_error(r.mean, 1.0)) < 0.05


@pytest.mark.parametrize("method", WITH_RADIUS)
def test_radius_is_recorded_and_has_a_mesh_default(method, sphere):
    r = curvatures(sphere, method)
    h = meshcurv.geometry.mean_edge_length(sphere.vertices, meshcurv.MeshTopology.from_faces(sphere.faces).edges)
    # icc: one edge length on a clean mesh (its default follows the noise, tested below)
    assert r.parameters["radius"] == pytest.approx((1.0 if method == "icc" else DEFAULT_RADIUS_FACTOR) * h)
    wider = curvatures(sphere, method, radius=0.8)
    assert wider.parameters["radius"] == 0.8
    assert np.median(relative_error(wider.mean, 0.5)) < 0.05


@pytest.mark.parametrize("amplitude", [0.1, 0.3])
def test_icc_noise_level_follows_the_noise(amplitude):
    # uniform normal noise of amplitude a x h: the distance to the fitted jets is about 0.23 a
    # (the fit absorbs part of it); a clean mesh stays below the floor
    sphere = shapes.icosphere(16)
    noisy = shapes.with_normal_noise(sphere, amplitude, seed=3)
    clean, rough = curvatures(sphere, "icc"), curvatures(noisy, "icc")
    assert clean.parameters["noise"] < radius_rules.NOISE_FLOOR
    assert 0.15 * amplitude < rough.parameters["noise"] < 0.35 * amplitude
    h = meshcurv.geometry.mean_edge_length(noisy.vertices, meshcurv.MeshTopology.from_faces(noisy.faces).edges)
    expected = h * (1 + radius_rules.NOISE_GAIN * np.sqrt(rough.parameters["noise"] - radius_rules.NOISE_FLOOR))
    assert rough.parameters["radius"] == pytest.approx(expected)
    assert rough.parameters["normal_radius"] == pytest.approx(icc.NORMAL_RADIUS_RATIO * expected)


def test_icc_noise_level_is_scale_free():
    # measured in edge lengths: scaling the mesh changes neither the level nor the radius in edge lengths
    noisy = shapes.with_normal_noise(shapes.icosphere(12), 0.1, seed=4)
    small = meshcurv.principal_curvatures(noisy.vertices, noisy.faces, method="icc")
    large = meshcurv.principal_curvatures(noisy.vertices * 1000.0, noisy.faces, method="icc")
    assert large.parameters["noise"] == pytest.approx(small.parameters["noise"], rel=1e-9)
    assert large.parameters["radius"] == pytest.approx(1000.0 * small.parameters["radius"], rel=1e-9)
    np.testing.assert_allclose(large.mean * 1000.0, small.mean, rtol=1e-8, atol=1e-10)


def test_icc_noise_level_is_measured_at_the_local_resolution():
    # a fine sphere (radius 0.05, h 0.0037) beside a coarse one (radius 10, h 5): at the mean edge
    # length (0.18) a jet cannot follow the small sphere, which would read as noise 0.26 and a radius
    # of 5.5 h; measured in each vertex's own edge length, the clean mesh stays below the floor
    small = shapes.icosphere(16, radius=0.05)
    big = shapes.icosphere(4, radius=10.0, center=(30, 0, 0))
    vertices = np.vstack([small.vertices, big.vertices])
    faces = np.vstack([small.faces, big.faces + small.vertices.shape[0]])
    r = meshcurv.principal_curvatures(vertices, faces, method="icc")
    # two components of scales 1000x apart: each is measured and summed at its own edge length
    edge_lengths = [
        meshcurv.geometry.mean_edge_length(mesh.vertices, meshcurv.MeshTopology.from_faces(mesh.faces).edges)
        for mesh in (small, big)
    ]
    assert max(r.parameters["noise"]) < radius_rules.NOISE_FLOOR
    np.testing.assert_allclose(r.parameters["radius"], edge_lengths, rtol=1e-12)
    n = small.vertices.shape[0]
    # result.radius: the radius of each vertex's own ball
    np.testing.assert_allclose(r.radius[:n], edge_lengths[0], rtol=1e-12)
    np.testing.assert_allclose(r.radius[n:], edge_lengths[1], rtol=1e-12)
    assert np.median(relative_error(r.mean[:n], 20.0)) < 0.01
    assert np.median(relative_error(r.mean[n:], 0.1)) < 0.05


def test_icc_noise_level_on_a_sample(monkeypatch):
    # above NOISE_SAMPLE valid vertices the median is taken over evenly spaced vertices:
    # the level stays close to that of all vertices, and a run gives the same level again
    noisy = shapes.with_normal_noise(shapes.icosphere(16), 0.1, seed=6)
    full = curvatures(noisy, "icc").parameters["noise"]
    monkeypatch.setattr(radius_rules, "NOISE_SAMPLE", 500)
    sampled = curvatures(noisy, "icc").parameters["noise"]
    assert sampled != full
    assert sampled == pytest.approx(full, rel=0.1)
    assert curvatures(noisy, "icc").parameters["noise"] == sampled


@pytest.mark.parametrize("method", WITH_RADIUS)
def test_same_radius_same_answer_across_resolutions(method):
    # radius in length units: two resolutions of one sphere agree (to the discretization error)
    coarse = curvatures(shapes.icosphere(10), method, radius=0.5)
    fine = curvatures(shapes.icosphere(20), method, radius=0.5)
    assert abs(np.median(coarse.mean) - np.median(fine.mean)) < 0.02


@pytest.mark.parametrize("bad", [0, -1.0, np.nan, np.inf, "big", True])
def test_bad_radius_is_refused(bad, sphere):
    with pytest.raises(InvalidOptionError, match="`radius` must be a positive"):
        meshcurv.principal_curvatures(sphere.vertices, sphere.faces, method="icc", radius=bad)


@pytest.mark.parametrize("method", ["normal_cycle", "matgeom", "rusinkiewicz", "meyer"])
def test_radius_is_refused_by_methods_without_one(method, sphere):
    with pytest.raises(InvalidOptionError, match=f"method '{method}' does not take the option `radius`"):
        meshcurv.principal_curvatures(sphere.vertices, sphere.faces, method=method, radius=1.0)


@pytest.mark.parametrize("method", WITH_RADIUS + ["rusinkiewicz", "meyer"])
def test_smoothing_steps_is_refused_by_the_new_methods(method, sphere):
    with pytest.raises(InvalidOptionError, match="does not take the option `smoothing_steps`"):
        meshcurv.principal_curvatures(sphere.vertices, sphere.faces, method=method, smoothing_steps=1)


def test_quadric_with_too_few_points_is_nan_with_one_warning(sphere):
    with pytest.warns(MeshQualityWarning, match="fewer than 6 vertices") as record:
        r = meshcurv.principal_curvatures(sphere.vertices, sphere.faces, method="quadric", radius=1e-3)
    assert len(record) == 1
    assert not r.valid.any() and np.isnan(r.k_min).all()


@pytest.mark.parametrize("method", METHODS)
def test_defects_give_nan_and_one_warning(method):
    sphere = shapes.icosphere(6)
    v = np.vstack([sphere.vertices, [[5.0, 5.0, 5.0]]])  # one unreferenced vertex
    with pytest.warns(MeshQualityWarning, match="1 unreferenced vertices") as record:
        r = meshcurv.principal_curvatures(v, sphere.faces, method=method)
    assert len(record) == 1
    assert not r.valid[-1] and np.isnan(r.k_min[-1]) and r.valid[:-1].all()


def test_face_in_ball_ratios_limits():
    tri = np.array([[[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]])
    centre = np.zeros((1, 3))
    assert face_in_ball_ratios(tri, centre, 2.0)[0] == 1.0
    assert face_in_ball_ratios(tri + 5, centre, 1.0)[0] == 0.0
    assert 0 < face_in_ball_ratios(tri, centre, 0.5)[0] < 1


def test_segment_in_ball_lengths_are_exact():
    starts = np.array([[-2.0, 0, 0], [-2.0, 0.6, 0], [0.0, 0, 0], [3.0, 0, 0]])
    ends = np.array([[2.0, 0, 0], [2.0, 0.6, 0], [0.5, 0, 0], [4.0, 0, 0]])
    lengths = segment_in_ball_lengths(starts, ends, np.zeros((4, 3)), 1.0)
    np.testing.assert_allclose(lengths, [2.0, 1.6, 0.5, 0.0], atol=1e-12)  # chord 2 sqrt(1 - 0.36)


def exact_result(mesh):
    return meshcurv.CurvatureResult(
        k_min=mesh.k_min,
        k_max=mesh.k_max,
        dir_min=mesh.dir_min,
        dir_max=mesh.dir_max,
        normals=mesh.normals,
        valid=np.ones(mesh.k_min.shape, bool),
        method="exact",
    )


def test_shape_index_sign_convention_on_exact_curvatures():
    # meshcurv's signs (convex outward = positive): sphere +1 (cap), cylinder +1/2 (ridge),
    # symmetric saddle 0; seen from the other side (every sign flipped): -1 (cup), -1/2 (rut)
    sphere, tube, saddle = shapes.icosphere(2, radius=2.0), shapes.cylinder(radius=2.0), shapes.saddle(spacing=0.5)
    np.testing.assert_allclose(exact_result(sphere).shape_index, 1.0)
    np.testing.assert_allclose(exact_result(sphere).curvedness, 0.5)
    np.testing.assert_allclose(exact_result(tube).shape_index, 0.5)
    np.testing.assert_allclose(exact_result(tube).curvedness, 0.5 / np.sqrt(2))
    centre = np.argmin(np.linalg.norm(saddle.vertices[:, :2], axis=1))
    assert abs(exact_result(saddle).shape_index[centre]) < 1e-12
    inside_out = meshcurv.CurvatureResult(
        k_min=-tube.k_max,
        k_max=-tube.k_min,
        dir_min=tube.dir_max,
        dir_max=tube.dir_min,
        normals=-tube.normals,
        valid=np.ones(tube.k_min.shape, bool),
        method="exact",
    )
    np.testing.assert_allclose(inside_out.shape_index, -0.5)


@pytest.mark.parametrize("method", METHODS)
def test_estimated_shape_index_follows_the_faces(method):
    sphere = shapes.icosphere(8)
    r = curvatures(sphere, method)
    flipped = meshcurv.principal_curvatures(sphere.vertices, sphere.faces[:, ::-1], method=method, orient="keep")
    np.testing.assert_allclose(r.shape_index, 1.0, atol=0.05)
    np.testing.assert_allclose(flipped.shape_index, -r.shape_index, atol=1e-9)


def test_shape_index_is_nan_where_flat():
    flat = meshcurv.CurvatureResult(
        k_min=[0.0, -1.0],
        k_max=[0.0, 1.0],
        dir_min=np.zeros((2, 3)),
        dir_max=np.zeros((2, 3)),
        normals=np.zeros((2, 3)),
        valid=[True, True],
        method="test",
    )
    assert np.isnan(flat.shape_index[0]) and flat.shape_index[1] == 0.0
    with pytest.raises(ValueError, match="read-only"):
        flat.shape_index[0] = 1.0


def test_quadric_jet_on_an_irregular_ellipsoid():
    # random Delaunay ellipsoid (3, 2, 1), 2562 points: the degree-4 jet with its
    # re-estimated normal is within 1% (median) of the exact H and K, measured 0.17% / 0.13%;
    # errors relative to the largest |k| at the vertex (K: its square)
    ellipsoid = shapes.random_ellipsoid((3.0, 2.0, 1.0), 2562, seed=4)
    r = curvatures(ellipsoid, "quadric")
    scale = np.maximum(np.abs(ellipsoid.k_min), np.abs(ellipsoid.k_max))
    assert r.valid.all()
    assert np.median(np.abs(r.mean - ellipsoid.mean) / scale) < 0.01
    assert np.median(np.abs(r.gaussian - ellipsoid.gaussian) / scale**2) < 0.01
    # the reported normal is the fitted one: within 1 degree of the exact normal everywhere
    assert np.sum(r.normals * ellipsoid.normals, axis=1).min() > np.cos(np.radians(1))


def test_icc_converges_on_an_irregular_torus_at_second_order():
    # jittered torus, resolution doubled twice (radius a fixed multiple of h): the median
    # error of H falls about fourfold each time (measured 2.3%, 0.58%, 0.15%: order 2)
    errors = []
    for level, (n_major, n_minor) in enumerate([(48, 16), (96, 32)]):
        torus = shapes.torus(3.0, 1.0, n_major, n_minor, jitter=0.35, seed=level)
        r = curvatures(torus, "icc")
        errors.append(np.median(np.abs(r.mean - torus.mean)))
    assert errors[1] < errors[0] / 3


@pytest.mark.parametrize("method", METHODS)
def test_result_radius_is_the_ball_of_each_vertex(method):
    # one radius on a mesh of one scale, given or default; None for the methods without a ball;
    # one row per input vertex through welding (a soup: every face its own corners)
    torus = shapes.torus()
    soup = torus.vertices[torus.faces].reshape(-1, 3)
    faces = np.arange(soup.shape[0]).reshape(-1, 3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshQualityWarning)
        r = meshcurv.principal_curvatures(soup, faces, method=method)
    if "radius" not in ESTIMATORS[method].options:
        assert r.radius is None
        return
    assert r.radius.shape == (soup.shape[0],) and not r.radius.flags.writeable
    np.testing.assert_array_equal(r.radius, r.parameters["radius"])
    twice = 2.0 * float(r.parameters["radius"])
    given = meshcurv.principal_curvatures(torus.vertices, torus.faces, method=method, radius=twice)
    np.testing.assert_array_equal(given.radius, twice)
