"""A point-cloud call checks the caller's arrays once, at the door (issue 33: validate once)."""

import warnings

import pytest

import meshcurv
from meshcurv import shapes

from test_prepared import _validation_entries


@pytest.mark.parametrize("method", ["corrected_measures", "jets"])
@pytest.mark.parametrize("given_normals", [False, True])
def test_a_point_cloud_call_checks_the_points_and_normals_once_at_the_door(method, given_normals):
    # before (6b59a8f): the noise level, the ball budget and the three jet fits of the estimators went through
    # the public radius.cloud_noise_level, neighborhoods.estimate_ball_pairs and jets.fit_jets, which checked
    # the points again (7 entries into _validation a call)
    sphere = shapes.icosphere(3)
    normals = sphere.vertices if given_normals else None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        entries = _validation_entries(
            lambda: meshcurv.point_cloud_curvatures(sphere.vertices, normals=normals, method=method)
        )
    arrays = 2 if given_normals else 1
    assert entries == {
        ("check_choice", "meshcurv.pointcloud"): 1,
        ("as_vertices", "meshcurv.pointcloud"): arrays,
        ("coerced", "as_vertices"): arrays,
    }
