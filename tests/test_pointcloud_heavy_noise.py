"""Point clouds under noise of half a spacing or more (open, issue 30's local noise and issue 29's checks).

Dense scans often carry noise of the order of their spacing. A unit sphere sampled at 5,000 random points and
moved along its normal by uniform noise of +-0.5 spacings (1.2% of its radius) is a surface anyone can measure
at a radius of a few noise widths; today every point is NaN: the checks that tell two sheets apart (stacked
sheets facing the same way at 0.45 spacings, heights in two groups, edges steeper than ``SHEET_SLOPE`` left
out of the orientation) were set under noise of at most 0.2 spacings, read one noisy sheet as two, and the
whole part is "side undecided". The truth: H = 1 at every point.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from meshcurv.pointcloud import POINT_CLOUD_METHODS, point_cloud_curvatures


def _noisy_sphere(n: int = 5000, level: float = 0.5, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    unit = rng.normal(size=(n, 3))
    unit /= np.linalg.norm(unit, axis=1, keepdims=True)
    spacing = np.sqrt(4 * np.pi / n)
    return unit * (1 + level * spacing * rng.uniform(-1, 1, size=(n, 1)))


@pytest.mark.parametrize(
    ("level", "least_valid"),
    [
        (0.25, 0.9),  # the level the checks were set for (and a little above): most points valid, H right
        pytest.param(
            0.5,
            0.5,
            marks=pytest.mark.xfail(
                strict=True, raises=AssertionError, reason="open: noise of 0.5 spacings reads as two sheets"
            ),
        ),
    ],
)
@pytest.mark.parametrize("method", POINT_CLOUD_METHODS)
def test_a_noisy_sphere_is_measured(method, level, least_valid):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = point_cloud_curvatures(_noisy_sphere(level=level), method=method)
    error = np.abs(result.mean[result.valid] - 1.0)
    assert result.valid.mean() > least_valid, f"{result.valid.mean():.1%} of the points valid"
    assert np.median(error) < 0.1 and (error <= 0.5).all()
