"""Each vertex of a voxel surface at its own scale (issue 30): icc's default on marching-cubes meshes.

Oracles: the exact curvatures of voxelised analytic solids (at each vertex's
closest point, :mod:`meshcurv.shapes`); the closed form of the rule on given
normals and curvatures (:func:`meshcurv.radius.voxel_vertex_radii`); and
invariances of the radii: a translation and a rotation that maps the voxel grid
onto itself (a cyclic permutation of the axes, with the spacing permuted) leave
them unchanged, a scaling of the mesh scales them.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes
from meshcurv.errors import MeshQualityWarning
from meshcurv.radius import voxel_vertex_radii
from meshcurv.topology import MeshTopology


def quiet(vertices, faces, **options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshQualityWarning)
        return meshcurv.principal_curvatures(vertices, faces, **options)


def _lists(n):
    """Edge lists of ``n`` vertices without edges (each vertex its own ring)."""
    return np.zeros(n + 1, dtype=np.int64), np.zeros(0, dtype=np.int64)


def test_the_rule_in_closed_form():
    # isolated vertices (each its own ring) in 2 x 0.5 x 0.5 voxels, surface curvature radius R = 32:
    # r_v = max(2.02, min(2 sqrt(h_v R), 1 / c_v, 0.5 / sqrt(K_v), sqrt(area / (18 pi)), R / 2 + t_v (1 / c_v - R / 2)))
    spacing = np.array([2.0, 0.5, 0.5])
    x, y = [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]
    normals = np.array([x, y, x, y, x])
    k_min = np.array([1 / 20, 1 / 20, 0.0, 0.0, 1 / 4])
    k_max = np.array([1 / 20, 1 / 20, 1 / 24, 1 / 24, 1 / 4])
    radii, normal_radii = voxel_vertex_radii(spacing, normals, k_min, k_max, np.ones(5, bool), 32.0, _lists(5), 3.0)
    # sphere-like at R_v 20: 0.5 / sqrt(K) = 10 below 2 sqrt(2 * 32) = 16 (h_v 2 along x); 2 sqrt(0.5 * 32) = 8
    # (h_v 0.5 along y); a tube of radius 24 (t_v = 1): the cap R / 2 = 16 rises to 24, above 16 and 8;
    # a small sphere (R_v 4): 0.5 / sqrt(K) = 2, the largest voxel size, raised to the floor 1.01 h_max = 2.02
    np.testing.assert_allclose(radii, [10.0, 8.0, 16.0, 8.0, 2.02], rtol=1e-12)
    # min(3 r_v, max(1.5 / c_v, 4 h_max)): the tube's 48 capped at 1.5 / c_v = 36; elsewhere 3 r_v
    np.testing.assert_allclose(normal_radii, [30.0, 24.0, 36.0, 24.0, 6.06], rtol=1e-12)
    capped, _ = voxel_vertex_radii(
        spacing, normals, k_min, k_max, np.ones(5, bool), 32.0, _lists(5), 3.0, area=18 * np.pi * 25.0
    )
    np.testing.assert_allclose(capped, [5.0, 5.0, 5.0, 5.0, 2.02], rtol=1e-12)  # sqrt(area / (18 pi)) = 5


def test_vertices_without_pilot_values_take_the_fallback():
    normals = np.array([[0, 0, 1.0], [0, 0, 1.0]])
    radii, normal_radii = voxel_vertex_radii(
        (1.0, 1.0, 1.0),
        normals,
        np.array([np.nan, 0.1]),
        np.array([np.nan, 0.1]),
        np.array([True, False]),
        10.0,
        _lists(2),
        4.5,
    )
    np.testing.assert_array_equal(radii, [4.5, 4.5])
    np.testing.assert_array_equal(normal_radii, [13.5, 13.5])


@pytest.fixture(scope="module")
def torus_2x():
    pytest.importorskip("skimage")
    return shapes.voxel_torus(12.0, 4.0, (2.0, 0.5, 0.5), seed=12)


def _relative_h_error(mesh, result):
    return float(np.median(np.abs(result.mean - mesh.mean) / np.abs(mesh.mean)))


@pytest.mark.slow
def test_a_thin_torus_in_elongated_voxels_is_within_the_anisotropic_target():
    # R 20, r 2 under voxels of 0.5 x 0.25 x 0.25 (2:1; 26,262 vertices): the torus H = (1/r + cos(phi) /
    # (R + r cos(phi))) / 2 at each vertex's closest point; target 6% (issue 14). One radius for the surface gave
    # 10% (benchmarks/scale_default.md, 5.2% of max|k|)
    pytest.importorskip("skimage")
    mesh = shapes.voxel_torus(20.0, 2.0, (0.5, 0.25, 0.25), seed=207)
    r = quiet(mesh.vertices, mesh.faces)
    assert r.parameters["scale"] == "voxel"
    assert _relative_h_error(mesh, r) <= 0.06


def test_the_torus_under_4_to_1_voxels_is_no_longer_a_quarter_off(torus_2x):
    # R 12, r 4 under voxels of 2 x 0.5 x 0.5 (4 voxels across the tube along the torus axis): one radius for
    # the surface gave a median H error of 25% of |H| (benchmarks/accuracy_voxel.md); each vertex at its own
    # scale 14% (still above the 6% target: the pilot at two voxels, 4 units, barely resolves the tube)
    mesh = torus_2x
    r = quiet(mesh.vertices, mesh.faces)
    assert r.parameters["scale"] == "voxel" and r.parameters["scale_rule"].startswith("voxel:")
    assert r.radius.shape == (mesh.vertices.shape[0],) and np.ptp(r.radius) > 0
    assert r.valid.all()
    assert _relative_h_error(mesh, r) <= 0.16


def _sphere_and_thin_torus():
    """Marching cubes of one mask: a ball of radius 10 at the origin and, beside it, a torus R 6, r 1.5 (voxel 0.5)."""
    measure = pytest.importorskip("skimage.measure")
    spacing = 0.5
    x0, y0, z0 = -12.87, -12.93, -12.89  # origins off the grid's symmetry
    ax, ay, az = (np.arange(n) * spacing + o for n, o in ((88, x0), (52, y0), (52, z0)))
    x, y, z = np.meshgrid(ax, ay, az, indexing="ij", sparse=True)
    ball = x**2 + y**2 + z**2 <= 10.0**2
    tube = (np.sqrt((x - 22.0) ** 2 + y**2) - 6.0) ** 2 + z**2 <= 1.5**2
    vertices, faces, _, _ = measure.marching_cubes((ball | tube).astype(float), 0.5, spacing=(spacing,) * 3)
    vertices = vertices + np.array([x0, y0, z0])  # the ball's centre at the origin
    on_ball = np.linalg.norm(vertices, axis=1) < 10.0 + 2 * spacing
    return vertices.astype(float), np.ascontiguousarray(faces[:, ::-1]), on_ball


def test_radii_are_smaller_on_a_thin_tube_than_on_a_big_sphere_of_the_same_mesh():
    vertices, faces, on_ball = _sphere_and_thin_torus()
    r = quiet(vertices, faces)
    assert r.parameters["scale"] == "voxel"
    tube, ball = np.median(r.radius[~on_ball]), np.median(r.radius[on_ball])
    assert tube < 0.6 * ball and tube <= 2 * 1.5  # about its radius of curvature, 1.5 (1 / c_v)
    exact = 1.0 / np.linalg.norm(vertices[on_ball], axis=1)  # the closest sphere point's curvature
    assert float(np.median(np.abs(r.mean[on_ball] - exact) / exact)) < 0.03  # isotropic target


def test_radii_follow_rigid_motions_of_the_grid_and_scale_with_the_mesh():
    pytest.importorskip("skimage")
    mesh = shapes.voxel_ellipsoid((6.0, 4.0, 3.0), (1.0, 0.5, 0.5), seed=4)
    vertices, faces = np.asarray(mesh.vertices, float), mesh.faces
    reference = quiet(vertices, faces).radius
    moved = quiet(vertices + np.array([7.25, -3.5, 1.75]), faces).radius  # a translation by a grid step's multiple
    np.testing.assert_allclose(moved, reference, rtol=1e-6)
    turned = quiet(np.ascontiguousarray(vertices[:, [1, 2, 0]]), faces).radius  # x->z, y->x, z->y: a rotation
    np.testing.assert_allclose(turned, reference, rtol=1e-6)
    scaled = quiet(3.0 * vertices, faces).radius
    np.testing.assert_allclose(scaled, 3.0 * reference, rtol=1e-6)


def test_other_ball_methods_keep_one_radius_on_a_voxel_surface(torus_2x):
    mesh = torus_2x
    topology = MeshTopology.from_faces(mesh.faces, mesh.vertices.shape[0])
    assert topology.n_faces
    r = quiet(mesh.vertices, mesh.faces, method="quadric")
    assert r.parameters["surface"] == "voxel" and "scale" not in r.parameters
    # one default radius; a vertex whose fit departs from a ball twice as wide's takes a grown ball (issue 29)
    assert np.ndim(r.parameters["radius"]) == 0
    assert np.min(r.radius[np.isfinite(r.radius)]) == pytest.approx(r.parameters["radius"], rel=1e-12)


def _smoothed_sphere(radius, sigma):
    """Marching cubes at 0.5 of a ball's mask (voxel 1) blurred by a Gaussian of ``sigma`` voxels, centred at 0."""
    measure = pytest.importorskip("skimage.measure")
    from scipy.ndimage import gaussian_filter

    n = int(2 * radius + 16)
    centre = np.array([0.5 * (n - 1) + 0.31, 0.5 * (n - 1) - 0.27, 0.5 * (n - 1) + 0.13])  # off the grid's symmetry
    x, y, z = np.meshgrid(*(np.arange(n) - c for c in centre), indexing="ij", sparse=True)
    mask = (x**2 + y**2 + z**2 <= radius**2).astype(float)
    vertices, faces, _, _ = measure.marching_cubes(gaussian_filter(mask, sigma), 0.5)
    return vertices - centre, np.ascontiguousarray(faces[:, ::-1])


def test_a_smoothed_isosurface_sphere_is_within_half_a_percent_of_the_blurred_sphere():
    # the isosurface of a blurred mask (the biology pipeline; a held-out family of benchmarks/scale_families.py):
    # the 0.5 level set of a ball of radius R blurred by a Gaussian of sigma is, to first order, the sphere of
    # radius R - sigma^2 / R (heat flow for a time sigma^2 / 2 moves it at k_1 + k_2 = 2 / R); H = 1 / (R - sigma^2
    # / R). Issue 30's target is a median H error of 0.5% of max|k| on spheres of radius >= 10 voxels; at R 20,
    # sigma 1 the default gives 0.33% (benchmarks/smoothed_isosurfaces.md). The shift is the input's geometry: the
    # analytic 1 / R is 0.25% away from the blurred sphere's H here, 1% at sigma 2
    radius, sigma = 20.0, 1.0
    vertices, faces = _smoothed_sphere(radius, sigma)
    r = quiet(vertices, faces)
    assert r.parameters["scale"] == "voxel" and r.valid.all()
    blurred = 1.0 / (radius - sigma**2 / radius)
    assert float(np.median(np.abs(r.mean - blurred))) / blurred <= 0.005
    # the measured mean distance to the centre confirms the shift within a hundredth of a voxel
    assert abs(float(np.mean(np.linalg.norm(vertices, axis=1))) - (radius - sigma**2 / radius)) < 0.01


def test_the_pilot_runs_at_about_half_of_the_vertices_and_spreads_its_normals():
    # the pilot fits and sums at one vertex per cube of 1.25 median edges (issue 30: a dense voxel sphere's
    # pilot cost 0.36 s of its 1.06); the others get NaN curvatures and the normals of their neighbours
    pytest.importorskip("skimage")
    from meshcurv._prepared import prepare_mesh
    from meshcurv.estimators import icc

    mesh = shapes.voxel_sphere(2.0, (0.25, 0.1, 0.1), seed=2)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshQualityWarning)
        prepared = prepare_mesh(mesh.vertices, mesh.faces[:, ::-1], orient="outward", weld=False)
    k_min, k_max, valid, normals = icc.voxel_pilot(prepared)(0.5)
    measured = np.isfinite(k_min) & np.isfinite(k_max)
    assert 0.3 < measured.mean() < 0.6
    np.testing.assert_allclose(np.linalg.norm(normals, axis=1), 1.0, rtol=1e-12)
    # the normals within 10 degrees of the sphere's (outward), fitted or spread, but for the odd vertex whose
    # fit turns more than 60 degrees from its mean of face normals and keeps the latter (one vertex here,
    # 64 degrees off; the pilot at every vertex keeps it too)
    assert np.mean(np.einsum("ij,ij->i", normals, mesh.normals) > np.cos(np.radians(10))) > 0.999
    # the pilot's curvatures where it ran: the sphere's 1 / R within 10% (a ball of 2 voxels)
    assert np.median(np.abs(k_max[measured] - 0.5)) < 0.05


def test_the_pilot_at_a_subset_keeps_the_radii_of_the_pilot_at_every_vertex(monkeypatch):
    # against the pilot at every vertex (cubes of 0.01 edges): the radii move by a few percent and the
    # median H error by about a tenth of itself (benchmarks/accuracy_voxel.md: within 6% on 19 meshes)
    pytest.importorskip("skimage")
    from meshcurv.estimators import icc

    mesh = shapes.voxel_ellipsoid((5.0, 8.0, 12.0), (1.2, 0.4, 0.4), seed=16)
    subset = quiet(mesh.vertices, mesh.faces)
    monkeypatch.setattr(icc, "PILOT_CELL_EDGES", 0.01)
    every = quiet(mesh.vertices, mesh.faces)
    assert np.median(np.abs(subset.radius / every.radius - 1.0)) < 0.05
    error = [np.median(np.abs(r.mean - mesh.mean) / np.abs(mesh.mean)) for r in (subset, every)]
    # (1.1 until the cube grids turned with the mesh, issue 29, L25: both errors fell, 0.0785 -> 0.0778 and
    # 0.0722 -> 0.0705, their ratio rose 1.086 -> 1.104: where the cubes fall is a lottery of a few percent)
    assert error[0] < 1.12 * error[1]


def test_the_default_radius_of_a_small_voxel_object_is_never_refused():
    # the label fuzzer (seed 73, case 39): a row of 4 voxels in anisotropic voxels read a curvature radius of about
    # 10 voxels, and its default radius, 4.66, was refused as larger than the object (diagonal 4.09): the whole
    # table of 27 labels was lost. The default is at most half the diagonal; the surface is closed, of genus 0
    pytest.importorskip("skimage")
    pytest.importorskip("pandas")
    image = np.zeros((3, 6, 3), np.uint8)
    image[1, 1:5, 1] = 1
    spacing = (0.5758719089057498, 1.0, 0.650750358252876)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshQualityWarning)
        row = meshcurv.label_curvatures(image, spacing=spacing).iloc[0]
    assert row["status"] == "ok"
    diagonal = np.linalg.norm([0.5758719089057498, 4.0, 0.650750358252876])
    assert row["radius"] <= 0.5 * diagonal
    assert row["total_gaussian"] == pytest.approx(4 * np.pi)


@pytest.mark.parametrize("method", ["icc", "quadric", "normal_cycle_ball"])
def test_the_voxel_default_does_not_depend_on_the_order_of_the_vertices(method):
    # the API fuzzer (seed 91, cases 14214, 19363, 31657): the pilot took the first vertex of each cube, by
    # index, so re-indexed vertices got other pilot centres, another radius, and k up to 82% apart (quadric)
    pytest.importorskip("skimage")
    mesh = shapes.voxel_sphere(5.0, (1.0, 1.0, 1.0))
    vertices, faces = np.asarray(mesh.vertices), np.asarray(mesh.faces)
    order = np.random.default_rng(3).permutation(vertices.shape[0])
    inverse = np.argsort(order)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshQualityWarning)
        plain = meshcurv.principal_curvatures(vertices, faces, method=method)
        permuted = meshcurv.principal_curvatures(vertices[order], inverse[faces], method=method)
    assert plain.parameters["radius"] == pytest.approx(permuted.parameters["radius"], rel=1e-12)
    np.testing.assert_array_equal(plain.valid, permuted.valid[inverse])
    np.testing.assert_allclose(plain.k_max, permuted.k_max[inverse], rtol=1e-9, atol=1e-12)
