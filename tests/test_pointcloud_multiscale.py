"""meshcurv.multiscale_point_cloud_curvatures: one result per radius, each equal to the single call."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv.errors import InvalidOptionError, MeshQualityWarning

FIELDS = ("k_min", "k_max", "dir_min", "dir_max", "normals", "valid", "invalid_reason")


def sphere_points(n: int, radius: float = 2.0, *, seed: int = 0, copies: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    u = rng.normal(size=(n, 3))
    points = radius * u / np.linalg.norm(u, axis=1, keepdims=True)
    if copies:  # exact duplicates, merged once and copied back
        points = np.concatenate([points, points[:copies]])
    return points


@pytest.mark.parametrize("method", ["corrected_measures", "jets"])
def test_each_radius_equals_the_single_call(method):
    points = sphere_points(3000, copies=50)
    normals = points / np.linalg.norm(points, axis=1, keepdims=True)
    radii = [0.6, 0.3, 0.45]
    for given in (None, -normals):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            results = meshcurv.multiscale_point_cloud_curvatures(points, radii, normals=given, method=method)
            singles = [meshcurv.point_cloud_curvatures(points, normals=given, radius=r, method=method) for r in radii]
        assert len(results) == len(radii)
        for result, single in zip(results, singles):
            for name in FIELDS:
                np.testing.assert_array_equal(getattr(result, name), getattr(single, name), err_msg=name)
            assert dict(result.parameters) == dict(single.parameters)
        # the sphere of radius 2: H = +-1/2 (outward estimated normals, inward given ones)
        sign = 1.0 if given is None else -1.0
        for result in results:
            assert abs(np.median(result.mean[result.valid]) - sign * 0.5) < 0.02


def test_one_warning_naming_the_radius_whose_notes_differ():
    points = sphere_points(2000, copies=20)
    with pytest.warns(MeshQualityWarning) as caught:
        meshcurv.multiscale_point_cloud_curvatures(points, [0.3, 0.01])
    assert len(caught) == 1
    text = str(caught[0].message)
    assert "duplicates" in text and "at radius 0.01" in text


@pytest.mark.parametrize(
    "radii, match",
    [
        ([], "non-empty sequence"),
        (0.5, "non-empty sequence"),
        ("0.5", "non-empty sequence"),
        ([0.5, -1.0], "`radii` must be a positive"),
        ([0.5, np.nan], "`radii` must be a positive"),
        ([0.5, 100.0], "`radii` 100 is larger than the point cloud itself"),
    ],
)
def test_bad_radii(radii, match):
    with pytest.raises(InvalidOptionError, match=match):
        meshcurv.multiscale_point_cloud_curvatures(sphere_points(500), radii)


def test_adaptive_is_for_meshes():
    with pytest.raises(InvalidOptionError, match="'adaptive' is for meshes"):
        meshcurv.point_cloud_curvatures(sphere_points(500), radius="adaptive")
