"""The interpolation of :func:`meshcurv.jets.sampled_jet_normals` (``jets.interpolated_normals``) and its compiled
twin (``meshcurv._kernels.pilot.interpolated_normals``, issue 30): exact on a sphere, the same on both backends."""

from __future__ import annotations

import numpy as np
import pytest

from meshcurv import jets, shapes
from meshcurv._tensors import tangent_basis

pytest.importorskip("skimage")  # (the marching-cubes sphere: shapes.voxel_sphere)


def _sphere_case(reach):
    """A marching-cubes sphere's vertices with the sphere's exact normals, samples one per cube of 0.8."""
    mesh = shapes.voxel_sphere(6.0, (0.5, 0.2, 0.2), seed=0)
    points = np.asarray(mesh.vertices, dtype=np.float64)
    centre = points.mean(axis=0)
    normals = (points - centre) / np.linalg.norm(points - centre, axis=1, keepdims=True)
    sampled = jets._cube_samples(points, 0.8)
    t1, t2 = tangent_basis(normals)
    return points, sampled, normals, t1, t2


def _kernel():
    pytest.importorskip("numba")
    from meshcurv._kernels import pilot

    return pilot.interpolated_normals


def test_the_interpolation_of_a_sphere_s_normals_is_exact():
    # the tangential components of a sphere's normal (x - c) / R are linear in the tangent-plane coordinates,
    # and its normal component is 1 at the centre: the linear least-squares fit returns x / R at each centre
    # up to the curvature of the samples' heights (second order in reach / R), normalised
    points, sampled, normals, t1, t2 = _sphere_case(1.2)
    out, reached = jets.interpolated_normals(points, points[sampled], normals[sampled], t1, t2, 1.2, 1e-4)
    assert reached.all()
    out /= np.linalg.norm(out, axis=1, keepdims=True)
    # the normal component of the samples' normals, 1 - d^2 / (2 R^2), is quadratic: within (reach / R)^2 / 2
    # of the exact normal, 0.02 rad (measured: 1.7e-3)
    angle = np.arccos(np.clip(np.einsum("ij,ij->i", out, normals), -1, 1))
    assert np.max(angle) < 0.5 * (1.2 / 6.0) ** 2


@pytest.mark.parametrize("reach", [1.2, 0.3])
def test_the_compiled_interpolation_is_the_numpy_one(reach):
    # reach 0.3: some centres have no sample in reach (NaN, not reached), others one or two (the mean)
    points, sampled, normals, t1, t2 = _sphere_case(reach)
    expected, expected_reached = jets.interpolated_normals(
        points, points[sampled], normals[sampled], t1, t2, reach, 1e-4
    )
    got, got_reached = _kernel()(points, points[sampled], normals[sampled], t1, t2, reach, 1e-4)
    np.testing.assert_array_equal(got_reached, expected_reached)
    assert (reach == 1.2) == bool(expected_reached.all())
    # sums of about 20 terms of order 1 in another order, a 3 x 3 solve by Cramer's rule against LAPACK's
    np.testing.assert_allclose(got[got_reached], expected[expected_reached], rtol=0, atol=1e-12)
    assert np.isnan(got[~got_reached]).all()


def test_collinear_samples_take_their_weighted_mean_on_both_backends():
    # samples on a line do not span the tangent plane: the weighted mean of their normals
    samples = np.column_stack([np.linspace(-1, 1, 9), np.zeros(9), np.zeros(9)])
    fitted = np.tile([0.0, 0.0, 1.0], (9, 1))
    fitted[:, 0] = np.linspace(-0.1, 0.1, 9)
    centres = np.array([[0.05, 0.0, 0.0], [0.3, 0.0, 0.0]])
    t1, t2 = np.tile([1.0, 0.0, 0.0], (2, 1)), np.tile([0.0, 1.0, 0.0], (2, 1))
    expected, reached = jets.interpolated_normals(centres, samples, fitted, t1, t2, 0.6, 1e-4)
    assert reached.all()
    offsets = (samples[None, :, 0] - centres[:, None, 0]) / 0.6
    weights = np.maximum(1 - offsets**2, 0) ** 2
    np.testing.assert_allclose(expected, weights @ fitted / weights.sum(axis=1, keepdims=True), rtol=1e-14)
    got, got_reached = _kernel()(centres, samples, fitted, t1, t2, 0.6, 1e-4)
    assert got_reached.all()
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-14)
