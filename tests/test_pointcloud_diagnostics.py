"""Point-cloud diagnostics that must not tell the user something false (issue 29, "never lie").

A noise level that no one-sided fit measured is NaN with a note, never 0 ("no noise"): a sphere under uniform noise
of 2 spacings along its normals (where the normals turn and every ball of the noise fit holds points facing the
other way) read 0 before. Where no ball is refused the level is what it always was: the median height of the
degree-2 jets at their centres, the definition checked against :func:`meshcurv.jets.fit_jets` itself.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.spatial import cKDTree

from meshcurv import point_cloud_curvatures, radius, shapes
from meshcurv.errors import MeshcurvWarning
from meshcurv.jets import fit_jets


def noisy_sphere(n: int, noise: float, seed: int) -> tuple[np.ndarray, np.ndarray, float]:
    """``n`` random points of the unit sphere moved along the normal by uniform noise of ``noise`` median spacings
    (the clouds' spacing: the distance to the 8th neighbour times sqrt(pi / 8)); their exact normals (of the sphere
    before the noise) and that spacing."""
    points = shapes.random_sphere(n, seed=seed).vertices
    spacing = float(np.median(cKDTree(points).query(points, k=9)[0][:, 8]) * np.sqrt(np.pi / 8))
    moved = points * (1 + np.random.default_rng(seed).uniform(-noise, noise, (n, 1)) * spacing)
    return moved, points / np.linalg.norm(points, axis=1, keepdims=True), spacing


def test_a_noise_level_that_no_one_sided_ball_measures_is_nan_with_one_note():
    # 2,562 points under noise of 2 spacings: the estimated normals turn and every ball of 3 spacings holds points
    # facing the other way (0 of 2,562 one-sided). Before: parameters["noise"] 0.0, no word of it
    points, _, _ = noisy_sphere(2562, 2.0, seed=1)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = point_cloud_curvatures(points)
    assert np.isnan(result.parameters["noise"])
    notes = [str(w.message) for w in caught if issubclass(w.category, MeshcurvWarning)]
    assert sum("the noise level was not measured (parameters['noise'] is NaN)" in note for note in notes) == 1
    # no valid point with a wrong mean curvature (H = 1 on the unit sphere)
    valid = result.valid
    assert np.all(np.abs(result.mean[valid] - 1.0) < 0.5)


def test_a_noise_level_measured_on_a_handful_of_balls_is_not_measured():
    # 10,000 points under noise of 3 spacings: 3 balls of the 10,000 one-sided (before: their median, 0.50
    # spacings, the level; through both sides 0.30): the few balls the noise leaves one-sided are no sample
    points, _, _ = noisy_sphere(10_000, 3.0, seed=1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshcurvWarning)
        result = point_cloud_curvatures(points)
    assert np.isnan(result.parameters["noise"])


def test_cloud_noise_level_is_nan_when_every_ball_faces_away_and_a_note_says_so():
    # a zero row of `facing` faces away from every centre (the documented contract): no ball is one-sided
    points, normals, spacing = noisy_sphere(800, 0.2, seed=2)
    usable = np.ones(points.shape[0], dtype=bool)
    centres = np.arange(points.shape[0])
    problems: list[str] = []
    level = radius._cloud_noise_level(points, normals, spacing, centres, usable, np.zeros_like(normals), problems)
    assert np.isnan(level)
    assert problems == [
        "the noise level was not measured (parameters['noise'] is NaN): 0 of the 800 balls of 3 spacings sampled "
        "were fitted on one side, the others held points facing the other way or too few (noise of about a spacing "
        "or more, which turns the normals, or a part thinner than the ball); the radius rules take the level of a "
        "clean sample"
    ]
    assert np.isnan(radius.cloud_noise_level(points, normals, spacing, centres, usable, facing=np.zeros_like(normals)))


@pytest.mark.parametrize("noise", [0.0, 0.2, 0.5])
def test_where_no_ball_is_refused_the_noise_level_measures_the_noise(noise):
    # the definition: |c00| of the degree-2 jets over balls of 3 spacings (c00 in units of the radius), their
    # median in spacings; with the exact normals of a sphere under noise of up to half a spacing no ball faces away
    points, normals, spacing = noisy_sphere(2562, noise, seed=3)
    usable = np.ones(points.shape[0], dtype=bool)
    centres = np.arange(points.shape[0])
    fit_radius = radius.CLOUD_NOISE_FIT_RADIUS * spacing
    coefficients = fit_jets(points, normals, fit_radius, degree=2, iterations=1, centres=centres, facing=normals)[0]
    heights = np.abs(coefficients[:, 0]) * radius.CLOUD_NOISE_FIT_RADIUS
    assert np.isfinite(heights).all()  # no ball refused
    level = radius.cloud_noise_level(points, normals, spacing, centres, usable)
    assert np.isfinite(level)
    # and of the right size: uniform noise of a spacings, a point's median height is a / 2 at most (the jet takes in
    # some of it), a clean sample's a fraction of the fit's own bias
    assert level <= (noise / 2 if noise else 0.01)
    if noise:
        assert level >= noise / 10


# ----------------------------------------------------------------------- a voxel surface read as a cloud (staircase)


def test_the_vertices_of_marching_cubes_lie_on_the_grid_of_half_voxels():
    pytest.importorskip("skimage")  # the voxel shapes (marching cubes)
    # a mask's marching cubes put each vertex at the midpoint of a voxel edge: every coordinate k on the grid of half
    # voxels (spacing_k / 2), translated alike; a random sample, or the lattice turned, shares no coordinate
    from meshcurv._pointcloud_normals import read_lattice

    mesh = shapes.voxel_ellipsoid((8.0, 6.0, 5.0), spacing=(0.7, 1.0, 1.3), seed=3)
    np.testing.assert_allclose(read_lattice(mesh.vertices).steps, [0.35, 0.5, 0.65], rtol=1e-12)
    np.testing.assert_allclose(read_lattice(mesh.vertices + [0.1, -7.3, 2.9]).steps, [0.35, 0.5, 0.65], rtol=1e-9)
    c, s = np.cos(0.3), np.sin(0.3)  # (a turn of rational cosine and sine keeps a finer grid)
    turn = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    np.testing.assert_array_equal(read_lattice(mesh.vertices @ turn.T).steps[:2], [0.0, 0.0])
    np.testing.assert_array_equal(read_lattice(shapes.random_sphere(500, seed=1).vertices).steps, [0.0, 0.0, 0.0])
    # two planes of a grid stacked are no staircase (fewer than three planes along z)
    x, y = np.meshgrid(np.arange(20.0), np.arange(20.0))
    planes = np.concatenate(
        [np.c_[x.ravel(), y.ravel(), np.zeros(400)], np.c_[x.ravel(), y.ravel(), np.full(400, 0.7)]]
    )
    np.testing.assert_array_equal(read_lattice(planes).steps, [1.0, 1.0, 0.0])


def test_two_grid_planes_stacked_with_normals_the_same_way_are_still_flagged():
    # sampled on a grid (a lattice along x and y), 0.7 spacings apart: one of the two is inside out
    from meshcurv import _pointcloud_normals as normals_module

    x, y = np.meshgrid(np.arange(40.0), np.arange(40.0))
    points = np.concatenate(
        [np.c_[x.ravel(), y.ravel(), np.zeros(1600)], np.c_[x.ravel(), y.ravel(), np.full(1600, 0.7)]]
    )
    normals = np.tile([0.0, 0.0, 1.0], (3200, 1))
    tree = cKDTree(points)
    spacing = normals_module.local_spacing(normals_module.knn(tree, points)[0])
    alike, _ = normals_module.two_sheets(points, normals, np.ones(3200, dtype=bool), spacing, tree)
    inner = (np.abs(points[:, :2] - 19.5) < 15).all(axis=1)
    assert alike[inner].all()


@pytest.mark.parametrize(
    "make",
    [
        lambda: shapes.voxel_sphere(10.0, spacing=(0.7, 1.0, 1.3), seed=2),
        lambda: shapes.voxel_torus(14.0, 6.0, spacing=(1.0, 0.7, 1.2), seed=5),
    ],
    ids=["sphere-0.7x1x1.3", "torus-1x0.7x1.2"],
)
def test_voxel_surfaces_in_anisotropic_voxels_are_one_sheet_and_right(make):
    pytest.importorskip("skimage")  # the voxel shapes (marching cubes)
    # the steps of the staircase (up to half a voxel off the surface each) are not stacked sheets: most points
    # valid (at 300b795 none: every point "side undecided"), each within half the largest |k| of the exact
    # surface's at its closest point, outward
    mesh = make()
    for method in ("corrected_measures", "jets"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", MeshcurvWarning)
            result = point_cloud_curvatures(mesh.vertices, method=method)
        largest = np.maximum(np.abs(mesh.k_min), np.abs(mesh.k_max))
        valid = result.valid
        # (jets on a lattice are checked against the corrected measures: the torus in 1 x 0.7 x 1.2 voxels 0.748)
        assert valid.mean() > (0.75 if method == "corrected_measures" else 0.7), method
        assert np.all(np.abs(result.mean - mesh.mean)[valid] <= 0.5 * largest[valid]), method
        assert np.all(np.einsum("ij,ij->i", result.normals, mesh.normals)[valid] > 0), method


def test_coarse_voxels_leave_no_wrong_valid_point():
    pytest.importorskip("skimage")  # the voxel shapes (marching cubes)
    # voxels 2 x 0.5 x 0.5 (their half voxel 1.6 spacings): patches of the staircase are turned inside out (21% of
    # the torus's normals) and its flat treads, where the tube is at right angles to x, are wider than the balls
    # (curvature 0 there, valid: 71 points off by more than half of |k| at 300b795, jets). Nothing valid is wrong
    mesh = shapes.voxel_torus(16.0, 6.0, spacing=(2.0, 0.5, 0.5), seed=2)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshcurvWarning)
        result = point_cloud_curvatures(mesh.vertices, method="jets")
    largest = np.maximum(np.abs(mesh.k_min), np.abs(mesh.k_max))
    valid = result.valid
    assert np.all(np.abs(result.mean - mesh.mean)[valid] <= 0.5 * largest[valid])
    assert np.all(np.einsum("ij,ij->i", result.normals, mesh.normals)[valid] > 0)
