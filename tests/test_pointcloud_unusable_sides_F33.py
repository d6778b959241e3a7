"""A point that is not usable (an outlier, a point on a line) has no side: its neighbours' checks do not read it
(issue 29; fuzz_api 721/2).

The orientation makes each unusable point a part of its own with no weight, so its normal keeps the sign the
eigensolver gave its PCA normal, which a rigid motion changes. ``_pointcloud_normals.facing_away`` (the points whose
neighbours face away, whose failed normal fits are then taken as two-sided) read those signs: on ogre's cloud turned
by 721/2's motion nine outliers were turned over, and 8 points beside them had other reasons in the two poses
(11 <-> 9; the valid sets equal). Unusable neighbours no longer count.

Oracles: the invariance under the sign of a normal that has no side (both backends), the contract's value (a flat
sheet faces nowhere away), the invariance under a rigid motion (the same reasons in both poses; with 660/28's
motion too, whose test this one took over from ``test_pointcloud_settled_sides_F31.py``).
"""

from __future__ import annotations

import os
import pathlib
import warnings

import numpy as np
import pytest
from conftest import chosen_backend

SHARED = pathlib.Path(
    os.environ.get("MESHCURV_SHARED_MESHES", pathlib.Path(__file__).resolve().parents[2] / "shared" / "meshes")
)
OGRE = SHARED / "ogre.obj"


def _sheet_with_an_outlier(sign: float):
    """A 5 x 5 grid on z = 0 with normals +z, and an outlier 1.2 spacings above its centre with normal ``sign`` z:
    every point's 8 nearest neighbours (the outlier among the centre's). Returns ``(normals, indices, usable)``."""
    from scipy.spatial import cKDTree

    x, y = np.meshgrid(np.arange(5.0), np.arange(5.0))
    points = np.concatenate([np.stack([x.ravel(), y.ravel(), np.zeros(25)], axis=1), [[2.0, 2.0, 1.2]]])
    normals = np.tile([0.0, 0.0, 1.0], (26, 1))
    normals[25, 2] = sign
    indices = cKDTree(points).query(points, k=9)[1][:, 1:]
    usable = np.ones(26, dtype=bool)
    usable[25] = False
    return normals, indices, usable


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_an_unusable_neighbours_sign_does_not_decide(backend):
    from meshcurv._pointcloud_normals import facing_away

    up = _sheet_with_an_outlier(1.0)
    down = _sheet_with_an_outlier(-1.0)
    assert (up[1][:25] == 25).any()  # (the outlier is a neighbour of the sheet's points)
    with chosen_backend(backend):
        here, there = facing_away(*up), facing_away(*down)
    np.testing.assert_array_equal(here[:25], there[:25])
    assert not here[:25].any()  # one flat sheet, its normals one way: nothing faces away


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_a_usable_neighbour_facing_away_still_counts(backend):
    from meshcurv._pointcloud_normals import facing_away

    normals, indices, usable = _sheet_with_an_outlier(-1.0)
    usable[25] = True  # (the same neighbour, usable: it faces away from the sheet's points near it)
    with chosen_backend(backend):
        away = facing_away(normals, indices, usable)
    assert np.array_equal(away[:25], (indices[:25] == 25).any(axis=1))


@pytest.mark.slow
@pytest.mark.skipif(not OGRE.exists(), reason="../shared/meshes/ogre.obj is not here")
@pytest.mark.parametrize("seed", [380720820, 1077282963])  # (fuzz_api 721/2's and 660/28's rotation and shift)
def test_turned_ogre_keeps_its_reasons(seed):
    pytest.importorskip("numba")  # (the fuzzer's backend for both)
    import meshcurv
    from meshcurv.pointcloud import point_cloud_curvatures

    points = np.asarray(meshcurv.read_mesh(str(OGRE)).vertices, float)
    q, r = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    turn = q if np.linalg.det(q) > 0 else q[:, [1, 0, 2]]
    moved = points @ turn.T + np.random.default_rng(seed).uniform(-10.0, 10.0, size=3) * float(np.ptp(points))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        here, there = point_cloud_curvatures(points), point_cloud_curvatures(moved)
    assert here.valid.sum() > 2000
    np.testing.assert_array_equal(here.valid, there.valid)
    np.testing.assert_array_equal(here.invalid_reason, there.invalid_reason)
    largest = np.abs(here.k_max[here.valid]).max()
    assert np.abs(here.k_max[here.valid] - there.k_max[there.valid]).max() <= 1e-6 * largest
