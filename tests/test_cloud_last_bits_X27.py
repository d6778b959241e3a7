"""The orientation of a point cloud's estimated normals does not hang on the last bits of a motion (issue 29,
fuzz_api 540/33).

ogre's vertices read as a cloud and shifted by 1024 sizes changed validity at 49 points: three decisions read the
sign of round-off. (1) A flat edge of the orientation graph between normals at right angles passed
``sign(n_i . n_j)`` of a cosine of -0.0 in one pose and -2.4e-16 in the other: a point joined to its part by such
edges alone was turned. (2) The winding numbers' far sum took the sources beyond the tree's distance of the farthest
near point, squared again (a unit in the last place either way of the far sum's own): at about 2% of the queries,
which the pose chose, the farthest near point was counted a second time, weighed by the points per source (winding
numbers 0.15 apart). (3) A neighbour at right angles "faced away" (``n_i . n_j < 0``) by the sign of its round-off.

Oracles: the invariances. A cloud shifted by 1024 sizes is the same cloud (its coordinates rounded to 2^-42 of its
size); normals at right angles whose cosine is +1e-17 or -1e-17 are the same normals.
"""

import numpy as np
import pytest
from scipy.spatial import cKDTree

from meshcurv._backend import use_backend

BACKENDS = ["numpy", "numba"]


def _backend(backend):
    if backend == "numba":
        pytest.importorskip("numba")
    return use_backend(backend)


def sphere(n, rng):
    """``n`` random points on the unit sphere (their outward normals are the points themselves)."""
    unit = rng.normal(size=(n, 3))
    return unit / np.linalg.norm(unit, axis=1, keepdims=True)


@pytest.mark.parametrize("backend", BACKENDS)
def test_winding_numbers_do_not_move_with_a_shift(backend):
    # the winding number of an oriented sphere at its points: 1/2 (the mean of 0 and 1); shifted by 1024 sizes,
    # the same sums to the round-off of the shifted coordinates (about 1e-13 of the spacing), not a term counted twice
    from meshcurv import _pointcloud_normals as normals_module

    points = sphere(3000, np.random.default_rng(3))
    spacing = np.full(points.shape[0], np.sqrt(4.0 * np.pi / points.shape[0]))
    areas = spacing**2
    usable = np.ones(points.shape[0], dtype=bool)
    queries = np.arange(points.shape[0])
    sources = np.arange(0, points.shape[0], 3)  # (a third: each far source stands for three points)
    shifted = points + 1024.0 * 2.0
    with _backend(backend):
        here = normals_module.winding_numbers(points, points, areas, usable, cKDTree(points), queries, sources)
        there = normals_module.winding_numbers(shifted, points, areas, usable, cKDTree(shifted), queries, sources)
    assert np.abs(here - 0.5).max() < 0.1  # (the check reads a closed surface)
    # a farthest near point counted twice adds (3 - 1) of its own terms (about 1e-3 here): 0 of 3000 queries may
    np.testing.assert_allclose(there, here, rtol=0, atol=1e-9)


def _sheet_and_a_point_at_right_angles(tilt):
    """A flat square grid of 15 x 15 points with normals +z, one more point beside its rim (in its plane) whose
    normal lies in the plane, along x, tilted by ``tilt`` towards z (its cosine with the grid's normals)."""
    x, y = (grid.ravel() for grid in np.meshgrid(np.arange(15.0), np.arange(15.0)))
    points = np.column_stack([x, y, np.zeros(x.size)])
    normals = np.tile([0.0, 0.0, 1.0], (x.size, 1))
    points = np.vstack([points, [7.0, -0.9, 0.0]])
    normals = np.vstack([normals, [np.sqrt(1.0 - tilt * tilt), 0.0, tilt]])
    return points, normals


@pytest.mark.parametrize("backend", BACKENDS)
def test_an_edge_at_right_angles_passes_no_sign(backend):
    # the last point's edges to the grid are flat (its offsets to the grid's points lie in both tangent planes)
    # and its normal is at right angles to theirs: a cosine of +1e-17 or -1e-17 (round-off, which a motion
    # chooses) must not decide its side relative to the grid
    from meshcurv._pointcloud_normals import knn, local_spacing, oriented_signs

    sides = []
    for tilt in (1e-17, -1e-17):
        points, normals = _sheet_and_a_point_at_right_angles(tilt)
        tree = cKDTree(points)
        distances, indices = knn(tree, points)
        usable = np.ones(points.shape[0], dtype=bool)
        with _backend(backend):
            signs = oriented_signs(points, normals, indices, usable, local_spacing(distances))[0]
        sides.append(signs[-1] * signs[0])  # the point's sign relative to the grid's
    assert sides[0] == sides[1]


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_neighbour_at_right_angles_faces_away_whatever_its_round_off(backend):
    from meshcurv._pointcloud_normals import facing_away, knn

    found = []
    for tilt in (1e-17, -1e-17):
        points, normals = _sheet_and_a_point_at_right_angles(tilt)
        indices = knn(cKDTree(points), points)[1]
        with _backend(backend):
            found.append(facing_away(normals, indices))
    np.testing.assert_array_equal(found[0], found[1])
    assert found[0][-1]  # (the point itself: every neighbour at right angles)
