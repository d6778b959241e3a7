"""The smallest enclosing ball and the extent that no rigid motion changes (issue 29, fuzz_api 512/16).

Oracles: closed-form balls (points on a sphere whose centre lies inside their hull: the sphere itself; a segment:
half its length; a cube's lattice: half the cube's diagonal), a brute-force search over every ball through 1 to 4
of a few points, and the invariances (rotation, translation, a power-of-two scale, the density of the sampling).
"""

import itertools

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from meshcurv.radius import ENCLOSING_TOLERANCE, EXTENT_FACTOR, enclosing_ball, rigid_extent


def on_sphere(n, rng, radius=1.0, centre=(0.0, 0.0, 0.0)):
    unit = rng.normal(size=(n, 3))
    return radius * unit / np.linalg.norm(unit, axis=1, keepdims=True) + np.asarray(centre)


def holds(points, centre, radius):
    return bool((np.linalg.norm(points - centre, axis=1) <= radius * (1.0 + 4 * ENCLOSING_TOLERANCE)).all())


def brute_force_radius(points):
    """The smallest radius of the balls through 1 to 4 of ``points`` that hold them all."""
    best = np.inf
    for m in (1, 2, 3, 4):
        for chosen in itertools.combinations(range(points.shape[0]), m):
            boundary = points[list(chosen)]
            spans = boundary[1:] - boundary[0]
            gram = spans @ spans.T
            if m > 1 and np.linalg.matrix_rank(gram, tol=1e-10 * np.abs(gram).max()) < m - 1:
                continue
            centre = boundary[0] + (np.linalg.solve(gram, 0.5 * np.diag(gram)) @ spans if m > 1 else 0.0)
            radius = float(np.linalg.norm(boundary - centre, axis=1).max())
            if radius < best and (np.linalg.norm(points - centre, axis=1) <= radius * (1 + 1e-13)).all():
                best = radius
    return best


@pytest.mark.parametrize("kind", ["normal", "lattice", "plane", "sphere", "repeated"])
def test_the_ball_is_the_smallest_of_a_brute_force_search(kind):
    rng = np.random.default_rng(["normal", "lattice", "plane", "sphere", "repeated"].index(kind))
    for _ in range(20):
        n = int(rng.integers(1, 9))
        if kind == "normal":
            points = rng.normal(size=(n, 3))
        elif kind == "lattice":  # cospherical and coplanar points: the degenerate sets of voxel clouds
            points = rng.integers(0, 3, size=(n, 3)).astype(float)
        elif kind == "plane":
            points = np.column_stack([rng.normal(size=(n, 2)), np.zeros(n)])
        elif kind == "sphere":
            points = on_sphere(n, rng)
        else:
            points = np.repeat(rng.normal(size=(2, 3)), n, axis=0)
        centre, radius = enclosing_ball(points)
        assert holds(points, centre, radius)
        np.testing.assert_allclose(radius, brute_force_radius(points), rtol=1e-12, atol=0)


def test_closed_form_balls():
    rng = np.random.default_rng(1)
    # points on a sphere all around its centre: the sphere itself
    centre, radius = enclosing_ball(on_sphere(5000, rng, radius=2.5, centre=(1.0, -4.0, 7.0)))
    np.testing.assert_allclose(radius, 2.5, rtol=1e-12)
    np.testing.assert_allclose(centre, [1.0, -4.0, 7.0], rtol=0, atol=1e-9)
    # a segment: half its length, at its middle
    segment = np.outer(np.linspace(0.0, 1.0, 1001), [3.0, 4.0, 12.0])
    centre, radius = enclosing_ball(segment)
    np.testing.assert_allclose(radius, 6.5, rtol=1e-12)
    np.testing.assert_allclose(centre, [1.5, 2.0, 6.0], rtol=1e-12)
    # a cube's lattice (every point on a sphere of 8 corners and more): half the cube's diagonal
    lattice = np.stack(np.meshgrid(*[np.arange(11.0)] * 3), axis=-1).reshape(-1, 3)
    np.testing.assert_allclose(enclosing_ball(lattice)[1], 5.0 * np.sqrt(3.0), rtol=1e-12)
    # one point, and one point repeated
    np.testing.assert_array_equal(enclosing_ball([[1.0, 2.0, 3.0]])[0], [1.0, 2.0, 3.0])
    assert enclosing_ball(np.ones((7, 3)))[1] == 0.0
    assert rigid_extent(np.zeros((0, 3))) == 0.0


def test_the_extent_is_the_box_diagonal_of_a_sphere_and_at_least_that_of_any_cloud():
    rng = np.random.default_rng(2)
    sphere = on_sphere(20000, rng)
    # the cube around the unit ball: its diagonal 2 sqrt(3), the bounding box's of a dense sphere in any pose
    np.testing.assert_allclose(rigid_extent(sphere), 2.0 * np.sqrt(3.0), rtol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(np.ptp(sphere, axis=0)), 2.0 * np.sqrt(3.0), rtol=1e-3)
    # each side of a box is at most the ball's diameter: the diagonal is at most sqrt(3) diameters
    slab = rng.normal(size=(3000, 3)) * [5.0, 1.0, 0.1]
    size = rigid_extent(slab)
    for seed in range(20):
        turned = slab @ Rotation.random(random_state=seed).as_matrix().T
        assert np.linalg.norm(np.ptp(turned, axis=0)) <= size


def test_the_ball_moves_with_the_points_and_ignores_the_density():
    rng = np.random.default_rng(3)
    # three sparse unit spheres in a row (fuzz_api 512/16's form) and a dense tiny cluster inside the middle one
    parts = [on_sphere(60, rng, centre=(x, 0.0, 0.0)) for x in (0.0, 2.3, 4.6)]
    points = np.vstack(parts)
    centre, radius = enclosing_ball(points)
    assert radius <= 3.3  # inside the ball of the three whole spheres
    np.testing.assert_allclose(radius, np.linalg.norm(points - centre, axis=1).max(), rtol=1e-12)
    dense = np.vstack([points, rng.normal(size=(100000, 3)) * 0.01 + [2.3, 0.5, 0.0]])
    np.testing.assert_allclose(enclosing_ball(dense)[1], radius, rtol=ENCLOSING_TOLERANCE)
    for seed in range(10):
        turn = Rotation.random(random_state=seed).as_matrix()
        shift = rng.uniform(-100.0, 100.0, size=3)
        moved_centre, moved_radius = enclosing_ball(points @ turn.T + shift)
        # (the coordinates' own round-off, 1e-16 of 100, is 1e-14 of the radius)
        np.testing.assert_allclose(moved_radius, radius, rtol=1e-12)
        np.testing.assert_allclose(moved_centre, centre @ turn.T + shift, rtol=0, atol=1e-10)


@pytest.mark.parametrize("scale", [2.0**-1040, 2.0**-600, 1.0, 2.0**600, 2.0**1000])
def test_far_scales_neither_overflow_nor_underflow(scale):
    rng = np.random.default_rng(4)
    points = on_sphere(500, rng) + [0.5, 0.0, 0.0]
    radius = enclosing_ball(points)[1]
    points_scaled = points * scale
    with np.errstate(over="raise", invalid="raise", divide="raise"):
        scaled = enclosing_ball(points_scaled)[1]
    # a power of two scales every coordinate exactly (but subnormal ones, which keep fewer bits)
    np.testing.assert_allclose(scaled / scale, radius, rtol=1e-12 if scale > 2.0**-1000 else 1e-6)
    assert EXTENT_FACTOR == pytest.approx(2.0 * np.sqrt(3.0), rel=1e-15)
