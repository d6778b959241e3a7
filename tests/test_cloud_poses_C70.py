"""Point clouds on a lattice with near copies: the valid points and values do not depend on the pose (issue 29).

``benchmarks/fuzz_api.py --point-clouds --cloud-relations 0.5 --real-meshes 0.5 --radius-forms 0.3
--cloud-shapes 0.3 --seed 771 --replay 19``: a voxel torus read as a cloud, each point in 8 copies a round-off
apart, ``method="jets"``: a rigid motion changed the validity of 25 points (200 rows). Two decisions of the
corrected measures (the jets' reference on a staircase) read the pose:

- a random triangle is dropped when flat (``EDGE_ON``): that compared L1 lengths, which a rotation changes by up
  to 3 times, and the triangles of three points of a voxel line, one of them the centroid of near copies (a sine
  of 1e-9 to a few 1e-9), were kept in one pose and dropped in the other, their mu_1 (0.09) with the sign of
  their near-zero area;
- the points of a ball at one distance are ordered by keys of the offset and the normals, and where those agree
  (a flat facet: every normal the same, opposite points) by their index, which the pose chose (the Morton order).

The oracles are invariances: a rigid motion, a scaling and a re-indexing leave the geometry, so the valid set and
the curvatures (times the scale) must be the same to round-off; the triangles' decisions must be those of the
geometry, which a rotation keeps.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from meshcurv import point_cloud_curvatures, shapes
from meshcurv._backend import use_backend

pytest.importorskip("skimage")

BACKENDS = ["numba", "numpy"]


def _rotation(rng: np.random.Generator) -> np.ndarray:
    """A proper rotation drawn uniformly (QR of a Gaussian matrix)."""
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else q[:, [1, 0, 2]]


def _with_copies(points: np.ndarray, copies: int, jitter: float, seed: int) -> np.ndarray:
    """``copies`` copies of ``points``, each moved by a relative round-off ``jitter`` of the largest coordinate
    (as the fuzz's near copies)."""
    rng = np.random.default_rng(seed)
    scale = np.abs(points).max()
    return np.concatenate([points + rng.normal(size=points.shape) * jitter * scale for _ in range(copies)])


def _curvatures(points, method):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return point_cloud_curvatures(points, method=method)


def _check_same(first, second, factor=1.0):
    np.testing.assert_array_equal(first.valid, second.valid)
    np.testing.assert_array_equal(first.invalid_reason, second.invalid_reason)
    valid = first.valid
    largest = max(np.abs(first.k_min[valid]).max(), np.abs(first.k_max[valid]).max())
    for field in ("k_min", "k_max"):
        a, b = getattr(first, field)[valid], getattr(second, field)[valid] * factor
        # round-off of the pose (a few 1e-14 of the largest |k| on these clouds); 1e-6 as the fuzz's relations
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-6 * largest)


@pytest.mark.slow
@pytest.mark.parametrize("backend", BACKENDS)
def test_voxel_ellipsoid_with_near_copies_under_rigid_motions(backend):
    # a voxel ellipsoid at voxels 0.5 x 0.8 x 1.0, each point in 5 copies 1e-11 of its extent apart, the jets (their
    # reference on a staircase: the measures over the same balls): before, 50 and 75 rows changed validity in two
    # poses of three (NumPy backend)
    if backend == "numba":
        pytest.importorskip("numba")
    surface = shapes.voxel_ellipsoid((10.14, 7.0, 5.53), spacing=(0.5, 0.8, 1.0), seed=959)
    points = _with_copies(np.asarray(surface.vertices, float), 5, 1e-11, seed=1)
    size = float(np.ptp(points))
    rng = np.random.default_rng(70)
    with use_backend(backend):
        first = _curvatures(points, "jets")
        assert first.valid.mean() > 0.25  # (jets on a staircase: 0.31 valid)
        for _ in range(3):
            moved = points @ _rotation(rng).T + rng.uniform(-10.0, 10.0, size=3) * size
            _check_same(first, _curvatures(moved, "jets"))


@pytest.mark.parametrize("backend", BACKENDS)
def test_flat_triangles_are_dropped_in_every_pose(backend):
    # three points of a line, the middle one off it by 1.5e-9 of the edges (a centroid of near copies): the sines
    # of its corners 1.5e-9 to 3e-9, flat within EDGE_ON in no pose (before: L1 lengths, whose ratio a rotation
    # changes by up to 3 times: kept along the axes, dropped in some turned poses); and off it by 2e-10 (sines up
    # to 4e-10: flat in every pose). The sums of a ball of those points turned by any rotation are the sums
    # turned: mu_0, mu_1, mu_2 the same to round-off.
    from meshcurv._pointcloud_estimators import EDGE_ON, _rank_pattern, _triangle_sums

    rng = np.random.default_rng(3)
    for sine in (1.5 * EDGE_ON, 0.2 * EDGE_ON):
        line = np.array([[0.0, 0.0, 0.0], [1.0, sine, 0.0], [2.0, 0.0, 0.0]])
        normals = np.array([[0.3, 0.1, 1.0], [-0.2, 0.0, 1.0], [0.1, -0.3, 1.0]])
        normals /= np.linalg.norm(normals, axis=1, keepdims=True)
        index, counts, pattern = np.array([[0, 1, 2]]), np.array([3]), _rank_pattern(4)
        reference = None
        for turn in [np.eye(3)] + [_rotation(rng) for _ in range(20)]:
            points, turned = line @ turn.T, normals @ turn.T
            if backend == "numba":
                kernels = pytest.importorskip("meshcurv._kernels.pointcloud")
                sums = kernels.ball_triangle_sums(points, turned, index, counts, pattern, EDGE_ON, np.arange(1))[0]
            else:
                sums = _triangle_sums(points, turned, index, counts, pattern)[0]
            if reference is None:
                reference = sums[:3]
                # a flat triangle adds nothing; the other adds its measures (mu_1 of the normals' turning)
                assert (reference[1] == 0.0) == (sine < EDGE_ON)
            np.testing.assert_allclose(sums[:3], reference, rtol=1e-6, atol=1e-12)


def _facet_cloud() -> tuple[np.ndarray, np.ndarray]:
    """A square lattice of step 0.1 on a flat facet beside a curved part (``z = x^2 / 2 + x y / 5`` for ``x > 0``),
    and its exact normals: the balls of the facet's points hold points at one distance whose offsets and normals
    agree (opposite points of the facet), and a curved part that tells them apart. (No ball is symmetric: in a
    ball symmetric about its centre's normal those points are images of each other, and their order, by index,
    is still the pose's.)"""
    x, y = (grid.ravel() for grid in np.meshgrid(np.arange(-12.0, 13.0), np.arange(-12.0, 13.0)))
    x, y = 0.1 * x, 0.1 * y
    curved = x > 0.0
    z = np.where(curved, 0.5 * x * x + 0.2 * x * y, 0.0)
    normals = np.column_stack([-np.where(curved, x + 0.2 * y, 0.0), -np.where(curved, 0.2 * x, 0.0), np.ones(x.size)])
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    return np.column_stack([x, y, z]), normals


@pytest.mark.parametrize("backend", BACKENDS)
def test_measures_beside_a_flat_facet_do_not_depend_on_the_pose(backend):
    # the corrected measures of balls of 0.45 (about 64 points, 4 and 8 at each distance) with the exact normals,
    # turned, moved and re-indexed: the same curvatures to round-off at every point. Before, the points of a
    # facet's ball at one distance were ordered by their index (the Morton order, the pose's in a call): their
    # triangles, and k up to 0.1 of the largest |k| apart.
    from scipy.spatial import cKDTree

    from meshcurv._pointcloud_estimators import corrected_measures

    if backend == "numba":
        pytest.importorskip("numba")
    points, normals = _facet_cloud()
    n = points.shape[0]
    rng = np.random.default_rng(11)

    def measured(turn, perm):
        moved = (points @ turn.T + rng.uniform(-5.0, 5.0, size=3))[perm]
        with use_backend(backend):
            found = corrected_measures(
                cKDTree(moved), moved, (normals @ turn.T)[perm], 0.45, np.arange(n), np.ones(n, dtype=bool), spacing=0.1
            )
        back = np.empty_like(perm)
        back[perm] = np.arange(n)
        return found[0][back], found[1][back]

    k_min, k_max = measured(np.eye(3), np.arange(n))
    measured_points = np.isfinite(k_min)
    assert measured_points.mean() > 0.9
    largest = np.nanmax(np.abs(k_max))  # (1 on the paraboloid's axis)
    for _ in range(4):
        other_min, other_max = measured(_rotation(rng), rng.permutation(n))
        np.testing.assert_array_equal(measured_points, np.isfinite(other_min))
        np.testing.assert_allclose(k_min, other_min, rtol=0, atol=1e-9 * largest)
        np.testing.assert_allclose(k_max, other_max, rtol=0, atol=1e-9 * largest)
