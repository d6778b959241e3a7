"""icc's default on a voxel surface under a rigid motion (issue 29).

The voxel default lays cube grids over the vertices: the pilot's centres (``icc._pilot_centres``), the samples of
its fits and sums, the coarse level of the wide normal fits and the clusters of the coarse sums
(:func:`meshcurv.jets.turned_cubes`). Laid along x, y and z, a turned voxel surface got other cubes, hence other
centres and another default radius: ``voxel_torus(10, 4)``'s k moved by up to 7.7% of its largest ``|k|`` between
two poses (median 0.25%), its normals by 5 degrees, and at a given radius of 6 (normal fits on the coarse level) by
up to 17% of it, normals by up to 88 degrees. They are now laid along the axes of the voxel grid the call reads
(its ``frame``, for a turned grid), so a rigid motion keeps every cube with the vertices it holds.

Oracle: the invariance itself. A rigid motion keeps every distance, area and angle; with the same cubes, the same
centres, balls, clusters and samples, hence the same numbers up to round-off: sums of hundreds of terms of about
``1e-16`` relative error each, the grid's axes read to about ``1e-15`` (the turned vertices are the given ones
moved, to that), amplified by the conditioning of the fits (about ``1e6`` for a cubic over a wide ball). Measured:
at most ``2e-13`` of the largest ``|k|``. The bound, ``1e-8`` of the largest ``|k|`` and ``1e-8`` for the
normals' components, is a hundred thousand times below the spread of the cubes along x, y and z (``1e-3`` to
``1e-1``, every case here) and far above the round-off.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from conftest import chosen_backend, random_rotation
from meshcurv import principal_curvatures, shapes

pytest.importorskip("skimage")

BOUND = 1e-8


def _moved(vertices: np.ndarray, seed: int) -> tuple[np.ndarray, np.ndarray]:
    turn = random_rotation(seed)
    shift = np.random.default_rng(seed).uniform(-50.0, 50.0, 3)
    return vertices @ turn.T + shift, turn


def _assert_turns_with_the_mesh(mesh, backend: str, **options) -> None:
    vertices = np.asarray(mesh.vertices, dtype=np.float64)
    faces = np.asarray(mesh.faces)
    with chosen_backend(backend), warnings.catch_warnings():
        warnings.simplefilter("ignore")  # (marching cubes winds its faces inward: reversed, and said so)
        base = principal_curvatures(vertices, faces, method="icc", **options)
        assert base.valid.mean() > 0.95
        scale = float(np.max(np.abs(np.r_[base.k_min[base.valid], base.k_max[base.valid]])))
        for seed in (3, 4):
            moved, turn = _moved(vertices, seed)
            result = principal_curvatures(moved, faces, method="icc", **options)
            np.testing.assert_array_equal(result.valid, base.valid)
            np.testing.assert_allclose(
                np.median(result.radius), np.median(base.radius), rtol=BOUND, err_msg="the default radius moved"
            )
            for field in ("k_min", "k_max"):
                np.testing.assert_allclose(
                    getattr(result, field)[base.valid], getattr(base, field)[base.valid], rtol=0, atol=BOUND * scale
                )
            np.testing.assert_allclose(
                result.normals[base.valid], base.normals[base.valid] @ turn.T, rtol=0, atol=BOUND
            )


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_anisotropic_voxel_ellipsoid_default_turns_with_the_mesh(backend):
    # main: k apart by up to 2.0% of the largest |k|, the default radius by 2.0%
    _assert_turns_with_the_mesh(shapes.voxel_ellipsoid((9.0, 6.0, 4.0), spacing=(1.0, 0.8, 0.6)), backend)


@pytest.mark.parametrize("backend", [pytest.param("numpy", marks=pytest.mark.slow), "numba"])
def test_voxel_torus_default_turns_with_the_mesh(backend):
    # main: k apart by up to 7.7% of the largest |k| (median 0.25%), the default radius by 0.3%
    _assert_turns_with_the_mesh(shapes.voxel_torus(10.0, 4.0), backend)


@pytest.mark.parametrize("backend", [pytest.param("numpy", marks=pytest.mark.slow), "numba"])
def test_voxel_torus_at_a_given_radius_turns_with_the_mesh(backend):
    # normal fits over 18 voxels, on the coarse level (icc._coarse_fits); main: k apart by up to 17%, normals 88 deg
    _assert_turns_with_the_mesh(shapes.voxel_torus(10.0, 4.0), backend, radius=6.0)
