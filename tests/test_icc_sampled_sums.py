"""The voxel pilot's sampled ball sums (``icc._sampled_face_sums``, issue 30) and the interpolation of
fields that they share with the sampled normal fits (``jets.interpolated_normals`` and its compiled twin)."""

from __future__ import annotations

import numpy as np
import pytest

from meshcurv import jets, shapes
from meshcurv._tensors import tangent_basis
from meshcurv.estimators import icc


def _kernel():
    pytest.importorskip("numba")
    from meshcurv._kernels import pilot

    return pilot.interpolated_normals


def _slab(seed=0):
    """Two parallel sheets 0.2 apart (a part thinner than the reach), normals facing away from each other; a
    field linear in x and y on the lower sheet, another on the upper."""
    rng = np.random.default_rng(seed)
    lower = np.column_stack([rng.uniform(-1, 1, (400, 2)), np.zeros(400)])
    upper = np.column_stack([rng.uniform(-1, 1, (400, 2)), np.full(400, 0.2)])
    points = np.concatenate([lower, upper])
    normals = np.concatenate([np.tile([0.0, 0.0, -1.0], (400, 1)), np.tile([0.0, 0.0, 1.0], (400, 1))])
    fields = np.column_stack(
        [
            np.where(points[:, 2] > 0.1, 5.0 + points[:, 0], 1.0 + 2.0 * points[:, 0] - points[:, 1]),
            np.where(points[:, 2] > 0.1, -3.0, 0.5 * points[:, 1]),
        ]
    )
    return points, normals, fields


@pytest.mark.parametrize("backend", ["numpy", "compiled"])
def test_fields_linear_over_the_tangent_plane_are_interpolated_exactly_on_their_own_sheet(backend):
    # the linear least-squares fit reproduces a linear field; the samples of the other sheet (0.2 away, within the
    # reach of 0.5) face the other way and are left out: without that, each sheet's values would mix
    points, normals, fields = _slab()
    sampled = np.arange(0, 800, 3)
    at = np.delete(np.arange(800), sampled)
    t1, t2 = tangent_basis(normals[at])
    interpolate = jets.interpolated_normals if backend == "numpy" else _kernel()
    got, reached = interpolate(
        points[at], points[sampled], fields[sampled], t1, t2, 0.5, 1e-4, normals[at], normals[sampled], 0.5
    )
    assert reached.all()
    np.testing.assert_allclose(got, fields[at], rtol=0, atol=1e-12)
    mixed, _ = interpolate(points[at], points[sampled], fields[sampled], t1, t2, 0.5, 1e-4)
    assert np.abs(mixed - fields[at]).max() > 1.0  # the filter is what keeps the sheets apart


def test_the_compiled_interpolation_of_fields_is_the_numpy_one():
    # reach 0.08: some centres have no sample of their sheet in reach (NaN, not reached), others one or two
    points, normals, fields = _slab(seed=1)
    rng = np.random.default_rng(2)
    values = np.column_stack([fields, rng.normal(size=(800, 3))])
    sampled = np.arange(0, 800, 4)
    t1, t2 = tangent_basis(normals)
    for reach in (0.5, 0.08):
        arguments = (points, points[sampled], values[sampled], t1, t2, reach, 1e-4, normals, normals[sampled], 0.5)
        expected, expected_reached = jets.interpolated_normals(*arguments)
        got, got_reached = _kernel()(*arguments)
        np.testing.assert_array_equal(got_reached, expected_reached)
        assert (reach == 0.5) == bool(expected_reached.all())
        np.testing.assert_allclose(got[got_reached], expected[expected_reached], rtol=0, atol=1e-12)
        assert np.isnan(got[~got_reached]).all()


@pytest.mark.parametrize("seed", [0, 1])
def test_the_sampled_sums_of_a_dense_voxel_sphere_give_its_curvature(seed):
    # a marching-cubes sphere of radius 6 at 0.5 x 0.2 x 0.2 with the sphere's normals, balls of 2.7 (about 10
    # median edges): the sums at one vertex per cube of 1.35, interpolated elsewhere, against H = 1 / 6 and
    # K = 1 / 36. The sums over each vertex's own ball are within 0.05% (median) and 0.5% (95th percentile) of
    # them here; the sampled ones may not exceed 0.2% and 1% (K: 0.4%)
    pytest.importorskip("skimage")
    from meshcurv._measures import face_measures, principal_from_measures

    mesh = shapes.voxel_sphere(6.0, (0.5, 0.2, 0.2), seed=seed)
    vertices = np.asarray(mesh.vertices, dtype=np.float64)
    faces = np.ascontiguousarray(mesh.faces[:, ::-1])  # outward, as the sphere's normals
    measures = face_measures(vertices, faces, mesh.normals)
    radii = np.full(vertices.shape[0], 2.7)
    summed = icc._sampled_face_sums(
        vertices, faces, radii, measures, None, mesh.normals, np.arange(vertices.shape[0]), 1.35
    )
    k_min, k_max = principal_from_measures(summed)
    assert np.isfinite(k_min).all()
    error = np.abs(0.5 * (k_min + k_max) * 6.0 - 1.0)
    assert np.median(error) < 0.002
    assert np.percentile(error, 95) < 0.01
    assert np.median(np.abs(k_min * k_max * 36.0 - 1.0)) < 0.004
