"""The reason of a vertex that a method leaves invalid on a voxel staircase (issue 29): the method's limit, not an
undefined estimate.

``quadric`` at the default radius of a voxel surface drops the fits that the voxels' steps bent (the scatter check
on a staircase and ``quadric._staircase_check``), and ``normal_cycle_ball`` leaves undefined a voxel surface welded
back across cracks (``_ring_noise.welded_grid``). Both said "estimate undefined", the reason of a fit that failed (too
few points, a singular system); the fits there did not fail, they followed the steps. They now carry
``meshcurv.defects.STAIRCASE`` (as ``matgeom`` does on a staircase), and the warning names it.

Oracle: the reasons' own definitions (``meshcurv.defects.INVALID_REASONS``): an invalid vertex with a finite fit that
the check dropped is the staircase's; one whose ball held the other side of the surface keeps "estimate undefined".
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes
from meshcurv.defects import INVALID_REASONS, STAIRCASE, UNDEFINED

from test_double_sided_welds_D24 import _detached


def _curvatures(vertices, faces, method):
    """The result and the call's warnings (joined)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = meshcurv.principal_curvatures(vertices, faces, method=method)
    return result, " ".join(str(warning.message) for warning in caught)


@pytest.mark.parametrize("backend", ["numba", pytest.param("numpy", marks=pytest.mark.slow)])
def test_quadric_on_a_voxel_torus_drops_by_the_staircase(backend):
    """``voxel_torus()`` (a tube of 4 voxels), quadric's default: some 800 of its 2,742 vertices are dropped by the
    staircase's checks (their fits off the exact H by more than half of the largest ``|k|``, before the checks).
    Before: every invalid vertex "estimate undefined"; now those the checks dropped "voxel staircase", the few whose
    ball held the other side of the tube still "estimate undefined", and the warning counts them."""
    pytest.importorskip("skimage")  # (the voxel shapes' marching cubes)
    if backend == "numba":
        pytest.importorskip("numba")
    from meshcurv._backend import use_backend

    torus = shapes.voxel_torus()
    with use_backend(backend):
        result, message = _curvatures(torus.vertices, torus.faces, "quadric")
    reasons = result.invalid_reason
    steps = reasons == STAIRCASE
    assert steps.sum() > 0.1 * reasons.size  # the staircase is the main reason on this thin tube
    assert not result.valid[steps].any()
    assert np.isnan(result.mean[steps]).all()  # dropped: no number is given for them
    assert set(reasons[~result.valid]) <= {STAIRCASE, UNDEFINED}
    assert f"{int(steps.sum())} vertices of this voxel surface are NaN (voxel staircase)" in message
    assert "estimate undefined" not in INVALID_REASONS[STAIRCASE]


def test_quadric_reasons_off_voxels_unchanged():
    """On a clean smooth mesh and on noise at a given radius, no vertex is called a staircase's."""
    sphere = shapes.icosphere(subdivisions=8)
    rng = np.random.default_rng(2)
    normals = sphere.vertices / np.linalg.norm(sphere.vertices, axis=1, keepdims=True)
    edge = float(
        np.mean(np.linalg.norm(sphere.vertices[sphere.faces[:, 0]] - sphere.vertices[sphere.faces[:, 1]], axis=1))
    )
    noisy = sphere.vertices + normals * rng.normal(scale=0.1 * edge, size=(len(normals), 1))
    for vertices, radius in ((sphere.vertices, None), (noisy, 1.5 * edge)):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            result = meshcurv.principal_curvatures(vertices, sphere.faces, method="quadric", radius=radius)
        assert not (result.invalid_reason == STAIRCASE).any()


@pytest.mark.parametrize("backend", ["numba", "numpy"])
def test_normal_cycle_ball_on_a_voxel_sphere_welded_back(backend):
    """fuzz 500/28's form (tests/test_ncb_fine_soups_N25.py): ``voxel_sphere(10)`` wound inward, a fifth of its faces
    detached by 0.039 edges and welded back; off the welds its faces lie on the voxel grid, whose plateaus a ball of
    the default reads flat. The surface is undefined (``_ring_noise.welded_grid``): the vertices free of defects
    that the other checks passed carry "voxel staircase" (before: "estimate undefined"); those of a defect (the cracks'
    rims) or of another check (a ball over a hole, too few edges) keep theirs."""
    pytest.importorskip("skimage")
    if backend == "numba":
        pytest.importorskip("numba")
    from meshcurv._backend import use_backend

    mesh = shapes.voxel_sphere(radius=10.0)
    vertices, faces = _detached(mesh.vertices, mesh.faces[:, [0, 2, 1]], 0.2, 0.039, 0)
    with use_backend(backend):
        result, message = _curvatures(vertices, faces, "normal_cycle_ball")
    assert not result.valid.any()
    steps = result.invalid_reason == STAIRCASE
    # the vertices the other checks passed (a few: the holed balls and the few edges' keep their own reasons)
    assert steps.any()
    assert np.isnan(result.mean[steps]).all()
    assert "vertices of this voxel surface are NaN (voxel staircase): it was welded across cracks" in message
