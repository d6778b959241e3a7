"""``icc`` on a mirror image of a voxel surface (issue 29; fuzz_labels round 26, seed 460 case 30).

The samples, clusters and centres of ``icc``'s dense fits and sums are chosen per cube of a grid
(:func:`meshcurv.jets.mirrored_cubes`). Anchored at the surface's lowest corner, the grid met a mirror image of the
surface elsewhere: on the same mesh and its mirror image a voxel ball got other default radii and curvatures (a ball
of radius 12.5 voxels in fuzz_labels seed 460 case 30: k_min's 5th percentile 0.0386 and 0.0491, 0.080 exact),
so an image flipped along an axis read other statistics. The grid is now laid out from the middle of the
surface's bounding box alike in both directions, and points tied nearest a cube's middle (mirror images of each
other) are all taken. Expected: the values of the mirror image are those of the surface (an invariance), to
round-off.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from meshcurv import principal_curvatures
from meshcurv._backend import use_backend

pytest.importorskip("skimage")

RADIUS = 7.3
SPACING = np.array([1.0, 0.8, 1.3])


def _backend(name: str):
    if name == "numba":
        pytest.importorskip("numba")
    return use_backend(name)


def _ball():
    """A voxel ball's surface (vertices in voxels, outward faces) and the image's extent: its centre off the voxels'."""
    from meshcurv.volume import _surface

    n = int(2 * RADIUS + 5)
    offsets = np.indices((n, n, n)) - np.array([n / 2 - 0.3, n / 2 + 0.15, n / 2 - 0.05])[:, None, None, None]
    mask = (np.einsum("i...,i...->...", offsets, offsets) <= RADIUS**2).astype(np.uint8)
    index, faces, _, _ = _surface(np.pad(mask, 1), np.zeros(3), np.ones(3))
    return index, faces, n


def _curvatures(vertices, faces, backend):
    with _backend(backend), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return principal_curvatures(vertices, faces, orient="consistent")


@pytest.mark.parametrize("backend", ["numpy", "numba"])
@pytest.mark.parametrize("axis", [0, 1, 2])
def test_a_voxel_ball_and_its_mirror_image_read_the_same(axis, backend):
    index, faces, n = _ball()
    mirrored = index.copy()
    mirrored[:, axis] = (n - 1) - mirrored[:, axis]  # (the image flipped: a mirror turns the faces inside out)
    result = _curvatures(index * SPACING, faces, backend)
    image = _curvatures(mirrored * SPACING, np.ascontiguousarray(faces[:, ::-1]), backend)
    assert image.parameters["radius"] == pytest.approx(result.parameters["radius"], rel=1e-12)
    np.testing.assert_array_equal(np.asarray(image.valid), np.asarray(result.valid))
    for field in ("k_min", "k_max"):
        np.testing.assert_allclose(
            np.asarray(getattr(image, field)), np.asarray(getattr(result, field)), rtol=0, atol=1e-9 / RADIUS
        )


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_mirrored_points_get_mirrored_cubes(axis):
    from meshcurv.jets import CUBE_SHIFT, mirrored_cubes

    rng = np.random.default_rng(3)
    points = np.round(rng.uniform(-7, 9, (500, 3)) * 2) / 2  # (a lattice of half units, as a voxel surface's)
    mirrored = points.copy()
    mirrored[:, axis] = 5.0 - mirrored[:, axis]
    for side in (0.5, 1.0, 1.5, 3.0, 1.7):
        cubes, offsets = mirrored_cubes(points, side)
        cubes_m, offsets_m = mirrored_cubes(mirrored, side)
        flipped = cubes.copy()
        flipped[:, axis] = cubes[:, axis].max() - cubes[:, axis]
        np.testing.assert_array_equal(cubes_m, flipped)
        # (the offsets lean towards the points' mean, which the mirror moves with them: the same numbers)
        np.testing.assert_allclose(offsets_m, offsets, atol=1e-12)
        # no point on a boundary, where round-off (a scaled surface) would choose the cube
        middle = 0.5 * (points.min(axis=0) + points.max(axis=0))
        share = np.abs(points - middle) / side + CUBE_SHIFT
        assert np.abs(share - np.round(share)).min() > 1e-3


def test_points_tied_nearest_a_middle_go_to_their_offsets():
    from meshcurv.jets import _nearest_in_cubes

    # offsets from the cubes' middles: a mirror pair (cube 0), one point (cube 1), permuted offsets (cube 2)
    offsets = np.array(
        [[0.0, -1.0, 0.0], [0.0, 1.0, 0.0], [0.0, 2.0, 0.0], [5.0, 0.0, 0.0], [2.0, 1.0, 0.0], [1.0, 2.0, 0]]
    )
    key = np.array([0, 0, 0, 1, 2, 2])
    off_middle = np.einsum("ij,ij->i", offsets, offsets)
    np.testing.assert_array_equal(_nearest_in_cubes(offsets, key, off_middle), [0, 3, 5])
    # (mirrored_cubes' offsets of mirrored points are the same: a point exactly on a mirror plane keeps its choice)
    offsets[:, 0] *= -1
    np.testing.assert_array_equal(_nearest_in_cubes(offsets, key, off_middle), [0, 3, 5])
