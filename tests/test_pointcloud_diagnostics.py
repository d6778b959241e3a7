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
        "or more, which turns the normals, or a part thinner than the ball); the default radius is that of a clean "
        "sample"
    ]
    assert np.isnan(radius.cloud_noise_level(points, normals, spacing, centres, usable, facing=np.zeros_like(normals)))


@pytest.mark.parametrize("noise", [0.0, 0.2, 0.5])
def test_where_no_ball_is_refused_the_noise_level_is_the_median_height_of_the_jets(noise):
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
    assert level == np.median(heights)
    # and of the right size: uniform noise of a spacings, a point's median height is a / 2 at most (the jet takes in
    # some of it), a clean sample's a fraction of the fit's own bias
    assert level <= (noise / 2 if noise else 0.01)
    assert level >= noise / 10
