"""``icc``'s cube grids under a scaling, a mirror and a perturbation of a voxel surface (issue 29; fuzz_labels round
26, seed 460 cases 313 and 30).

The samples, clusters and centres of ``icc``'s dense fits and sums are chosen per cube of a grid, and the coarse
level's clusters also by the side of their vertex normals:

- the side: at a voxel surface's edges and corners two components of a vertex normal are equal
  (``(-3, 3, 1) / sqrt(19)`` at a corner of a slab one voxel thick), and ``argmax`` took the one round-off made
  larger: a label of 10 voxels in one slice (case 313) had an area of 18.5976 voxels^2 at unit spacing and 18.5892
  at 0.7. The tied components are now one side of their own (``icc.AXIS_TIE``).
- the grid: anchored at the surface's lowest corner, it met a mirror image of the surface elsewhere (case 30: a
  ball of 12.5 voxels and its mirror image, k_min's 5th percentile 0.0386 and 0.0491). The grid now starts at the
  lowest corner of the points turned along the axes where their third moment is negative, shifted by a
  share of a side of its own per axis, given in the order of the points' spreads
  (:func:`meshcurv.jets.turned_cubes`). A grid from the middle of the bounding box (tried first) put the middle of
  its central cubes on the lattice, where vertices tie and a perturbation of 1e-9 of the size chose: the voxel
  ellipsoid of ``tests/test_lattice_perturbed.py`` read its default radius 2.7% apart.

Expected values come from invariances: the unit spacing's values scaled (areas by ``s^2``, curvatures by
``1 / s``), the surface's values on its mirror image, the clean surface's centres on the perturbed one.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from meshcurv import principal_curvatures, shapes
from conftest import assert_label_row_scaled, chosen_backend, label_row

pytest.importorskip("skimage")

RADIUS = 7.3
SPACING = np.array([1.0, 0.8, 1.3])


@pytest.mark.slow
@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_a_radius_of_whole_voxels_puts_no_cube_boundary_on_the_lattice(backend):
    # a voxel ball of radius 8.3 voxels at a given radius of 10 voxels: coarse cubes of 3 voxels, whose boundaries
    # ran through 378 of its vertices when the coarse level's grid started at the lowest vertex
    offsets = np.indices((21, 21, 21)) - 10.2
    ball = (np.einsum("i...,i...->...", offsets, offsets) <= 8.3**2).astype(np.uint8)
    assert_label_row_scaled(label_row(ball, 1.0, backend, radius=10.0), label_row(ball, 0.7, backend, radius=10.0), 0.7)


def _ball():
    """A voxel ball's surface (vertices in voxels, outward faces) and the image's extent: its centre off the voxels'."""
    from meshcurv.volume import _surface

    n = int(2 * RADIUS + 5)
    offsets = np.indices((n, n, n)) - np.array([n / 2 - 0.3, n / 2 + 0.15, n / 2 - 0.05])[:, None, None, None]
    mask = (np.einsum("i...,i...->...", offsets, offsets) <= RADIUS**2).astype(np.uint8)
    index, faces, _, _ = _surface(np.pad(mask, 1), np.zeros(3), np.ones(3))
    return index, faces, n


@pytest.mark.parametrize("backend", ["numpy", "numba"])
@pytest.mark.parametrize("axis", [0, 1, 2])
def test_a_voxel_ball_and_its_mirror_image_read_the_same(axis, backend):
    index, faces, n = _ball()
    mirrored = index.copy()
    mirrored[:, axis] = (n - 1) - mirrored[:, axis]  # (the image flipped: a mirror turns the faces inside out)
    with chosen_backend(backend), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = principal_curvatures(index * SPACING, faces, orient="consistent")
        image = principal_curvatures(mirrored * SPACING, np.ascontiguousarray(faces[:, ::-1]), orient="consistent")
    assert image.parameters["radius"] == pytest.approx(result.parameters["radius"], rel=1e-12)
    np.testing.assert_array_equal(np.asarray(image.valid), np.asarray(result.valid))
    for field in ("k_min", "k_max"):
        np.testing.assert_allclose(
            np.asarray(getattr(image, field)), np.asarray(getattr(result, field)), rtol=0, atol=1e-9 / RADIUS
        )


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_mirrored_points_get_the_same_cubes(axis):
    from meshcurv.jets import turned_cubes

    rng = np.random.default_rng(3)
    points = np.round(rng.exponential(3.0, (500, 3)) * 2) / 2  # (a lattice of half units, skewed on every axis)
    mirrored = points.copy()
    mirrored[:, axis] = 5.0 - mirrored[:, axis]
    for side in (0.5, 1.0, 1.5, 3.0, 1.7):
        cubes, offsets, _ = turned_cubes(points, side)
        cubes_m, offsets_m, _ = turned_cubes(mirrored, side)
        np.testing.assert_array_equal(cubes_m, cubes)
        np.testing.assert_allclose(offsets_m, offsets, atol=1e-12)
        # no point on a boundary, where round-off (a scaled surface) would choose the cube
        assert np.abs(np.abs(offsets) - 0.5).min() > 1e-3
        # a permutation of the axes (a transposed image) permutes the cubes
        np.testing.assert_array_equal(turned_cubes(points[:, [1, 2, 0]], side)[0], cubes[:, [1, 2, 0]])


def test_symmetric_points_keep_their_axes():
    from meshcurv.jets import axis_turns

    # a box of half units, symmetric along every axis: its third moments are round-off, whose sign a scaling chose
    grid = np.stack(np.meshgrid(*[np.arange(7) * 0.5 + 0.1] * 3, indexing="ij"), axis=-1).reshape(-1, 3)
    for scale in (1.0, 0.7, 1e-3, 3.0):
        np.testing.assert_array_equal(axis_turns(grid * scale + 0.3), [1.0, 1.0, 1.0])
        np.testing.assert_array_equal(axis_turns(-grid * scale), [1.0, 1.0, 1.0])
    skewed = grid[grid.sum(axis=1) < 3.0]  # (a corner of it: skewed towards the low ends)
    np.testing.assert_array_equal(axis_turns(skewed), [1.0, 1.0, 1.0])
    np.testing.assert_array_equal(axis_turns(-skewed), [-1.0, -1.0, -1.0])


def test_a_perturbation_of_a_voxel_surface_keeps_its_pilot_centres():
    from meshcurv.estimators import icc
    from meshcurv.topology import MeshTopology

    # the voxel ellipsoid of tests/test_lattice_perturbed.py: with one shift of the grid on every axis, 19 of its
    # 699 centres went elsewhere when its vertices moved by 1e-9 of their size (lattice points whose offsets from a
    # cube's middle are permuted tie there); with 1e-4 of an edge, 17
    mesh = shapes.voxel_ellipsoid((12.0, 9.0, 6.0), seed=1)
    vertices = np.asarray(mesh.vertices, dtype=np.float64)
    topology = MeshTopology.from_faces(np.asarray(mesh.faces), n_vertices=vertices.shape[0])
    valid = np.ones(vertices.shape[0], dtype=bool)
    clean = icc._pilot_centres(vertices, topology, valid)
    rng = np.random.default_rng(3)
    for size in (1e-9 * np.abs(vertices).max(), 1e-4 * 0.7):
        moved = vertices + rng.normal(size=vertices.shape) * size
        np.testing.assert_array_equal(icc._pilot_centres(moved, topology, valid), clean)
