"""``quadric`` at its default radius on a voxel surface whose faces are all detached (issue 29, fuzz 415/108).

A marching-cubes sphere whose every face has its own corners, moved by 0.03-0.1 edge lengths, is no longer read as
a voxel surface, and the default ball (2.4 voxels) holds some 20 points of its staircase. The steps pull a quadric
over such a ball three times as far as independent noise of their residuals' size would (H off the sphere's by 0.16
for spreads of 0.06), so the scatter check passed them: 1,848 of 11,259 valid vertices off the clean voxel estimate
by more than half its largest ``|k|`` (the fuzzer's tolerance), 3,031 off the sphere's H by more than H. A fit that departs from the one over a ball twice as
wide by more than two spreads while its residuals did not grow as structure's now takes the wider ball's fit.

Expected values: the exact curvature of the sphere of radius 10 (voxels), H = 0.1.
"""

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes

pytest.importorskip("skimage")


def _voxel_soup(gap: float, seed: int):
    """``voxel_sphere(10)`` with every face given its own corners, each moved ``gap`` mean edge lengths in a random
    direction (the fuzzer's detached faces)."""
    mesh = shapes.voxel_sphere(radius=10.0)
    vertices, faces = np.asarray(mesh.vertices, float), np.asarray(mesh.faces)
    edge = float(np.mean(np.linalg.norm(vertices[faces[:, 0]] - vertices[faces[:, 1]], axis=1)))
    corners = vertices[faces].reshape(-1, 3)
    directions = np.random.default_rng(seed).normal(size=corners.shape)
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    return corners + gap * edge * directions, np.arange(len(corners)).reshape(-1, 3)


@pytest.mark.parametrize(("gap", "seed"), [(0.042, 0), (0.1, 3)])
def test_voxel_soup_quadric_mostly_right(gap, seed):
    pytest.importorskip("numba")  # the NumPy backend takes a minute on 11,328 corners
    vertices, faces = _voxel_soup(gap, seed)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the welded cracks' and the noisy balls' warnings: not tested here
        result = meshcurv.principal_curvatures(vertices, faces, method="quadric")
    # off: H away from the sphere's 0.1 by more than 0.1 (negative, or twice the sphere's); before, 24-27% of the
    # valid vertices; the steps whose residuals grow over the wider ball (read as structure) stay: 4.6-5.9%
    off = result.valid & (np.abs(result.mean - 0.1) > 0.1)
    assert off.sum() < 0.1 * result.valid.sum()
    # the share kept: 0.818 after V29; since V30 a soup's fit also agrees with the wider quadric within a fifth of its
    # typical curvature (quadric.SOUP_AGREEMENT: the lies beyond half of the largest |k| on the voxel soups' grid,
    # 7,299 -> 22 of some 200,000 valid vertices, benchmarks/quadric_voxel_soups_V30.py): 0.71 and 0.69 here
    assert result.valid.mean() > 0.65


def test_voxel_soup_quadric_never_lies():
    # xfail until stop 63 (the steps whose residuals grow over the wider ball: 366 valid vertices off by more than
    # 0.1, up to 0.18); since V29 the soup's grid is read, its balls grown to the voxel rule's radius (4.1 voxels for
    # the noise rule's 3.0) and checked as a voxel default's: none (up to 0.071), 81.8% of the vertices valid
    pytest.importorskip("numba")
    vertices, faces = _voxel_soup(0.042, 0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = meshcurv.principal_curvatures(vertices, faces, method="quadric")
    assert not (result.valid & (np.abs(result.mean - 0.1) > 0.1)).any()
