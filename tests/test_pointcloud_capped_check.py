"""The check of point-cloud estimates over balls cut to their nearest points (issue 29).

``corrected_measures`` draws its triangles from at most ``MAX_BALL_POINTS`` nearest points of a ball; its check
compares each estimate with the same measures over a ball sqrt(2) larger. Where both balls were cut to the same
nearest points (a radius above about 4.9 spacings: a given radius, or the default on noisy clouds), the check
compared an estimate with itself and passed every estimate: on a wave whose curvature changes within the ball,
valid points off the exact mean curvature by more than half of it.
"""

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv.errors import MeshQualityWarning


def _wave_cloud(seed: int, wavelength: float, n: int = 20_000):
    """Points of ``z = a cos(2 pi x / wavelength)`` (spacings), exact outward (up) normals, exact H, largest |k|."""
    rng = np.random.default_rng(seed)
    xy = rng.uniform(-1.0, 1.0, size=(n, 2))
    spacing = np.sqrt(4.0 / n)
    w = 2 * np.pi / (wavelength * spacing)
    amplitude = 0.05 * wavelength * spacing
    slope = -amplitude * w * np.sin(w * xy[:, 0])
    bend = -amplitude * w * w * np.cos(w * xy[:, 0])
    stretch = (1 + slope**2) ** 1.5
    normals = np.column_stack([-slope, np.zeros(n), np.ones(n)]) / np.sqrt(1 + slope**2)[:, None]
    # a crest (bend < 0) bulges towards the normal: positive H, as a sphere with outward normals
    return (
        np.column_stack([xy, amplitude * np.cos(w * xy[:, 0])]),
        normals,
        -0.5 * bend / stretch,
        np.abs(bend) / stretch,
        spacing,
    )


@pytest.mark.parametrize(("seed", "wavelength"), [(0, 20.0), (1, 16.0), (2, 16.0), (2, 20.0)])
def test_no_valid_point_off_the_wave(seed, wavelength):
    points, normals, mean, largest, spacing = _wave_cloud(seed, wavelength)
    radius = 6.0 * spacing  # balls of about 113 points, cut to the nearest 96
    with pytest.warns(MeshQualityWarning, match="changed by more than"):
        result = meshcurv.point_cloud_curvatures(points, normals=normals, radius=radius)
    inner = (np.abs(points[:, :2]) < 1.0 - 2 * radius).all(axis=1)  # balls whole
    valid = result.valid & inner
    error = np.abs(result.mean - mean) / np.maximum(largest, 0.2 * largest.max())
    assert not (error[valid] > 0.5).any(), f"{int((error[valid] > 0.5).sum())} of {int(valid.sum())} valid points off"
    assert (result.invalid_reason[inner & ~result.valid] > 0).all()


def test_the_check_still_passes_a_steady_estimate():
    """A radius within the wave's resolution: most points valid and right."""
    points, normals, mean, largest, spacing = _wave_cloud(0, 60.0)
    radius = 6.0 * spacing
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshQualityWarning)  # (the open sheet's rim)
        result = meshcurv.point_cloud_curvatures(points, normals=normals, radius=radius)
    inner = (np.abs(points[:, :2]) < 1.0 - 2 * radius).all(axis=1)
    valid = result.valid & inner
    assert valid.sum() > 0.9 * inner.sum()
    error = np.abs(result.mean - mean) / np.maximum(largest, 0.2 * largest.max())
    assert np.median(error[valid]) < 0.05
