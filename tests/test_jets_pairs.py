"""``jets.fit_jets(larger=)``: the fits over two radii at the same centres, in one walk (issue 31).

The point clouds' jets check each estimate against the same fit over balls sqrt(2) times larger; both are
fitted in one walk of the larger ball. The oracle is the call of :func:`meshcurv.jets.fit_jets` at each radius
alone: the smaller balls' fits must be those to the bit (the same points summed in the same order), the larger
balls' within rounding (the same points in another order), on both backends.
"""

import importlib.util

import numpy as np
import pytest

from meshcurv import jets
from meshcurv._backend import use_backend
from meshcurv.errors import InvalidOptionError

BACKENDS = [
    "numpy",
    pytest.param(
        "numba", marks=pytest.mark.skipif(importlib.util.find_spec("numba") is None, reason="numba is not installed")
    ),
]


def _sphere_cloud(n=3000, seed=3):
    """Random points of the unit sphere, their outward normals, and a few flipped (balls refused by ``facing``)."""
    rng = np.random.default_rng(seed)
    points = rng.normal(size=(n, 3))
    points /= np.linalg.norm(points, axis=1, keepdims=True)
    facing = points.copy()
    facing[rng.random(n) < 0.03] *= -1
    return points, points.copy(), facing


@pytest.mark.parametrize("backend", BACKENDS)
def test_both_radii_are_the_fits_of_each_radius_alone(backend):
    points, normals, facing = _sphere_cloud()
    rng = np.random.default_rng(4)
    centres = np.flatnonzero(rng.random(points.shape[0]) > 0.3)
    usable = rng.random(points.shape[0]) > 0.05
    radius, larger = 0.12, 0.12 * 2.0**0.5
    options = {"degree": 3, "centres": centres, "neighbours": usable, "facing": facing}
    with use_backend(backend):
        details = {}
        small = jets.fit_jets(points, normals, radius, details=details, larger=larger, **options)
        alone_small = jets.fit_jets(points, normals, radius, **options)
        alone_large = jets.fit_jets(points, normals, larger, **options)
    large = details["larger"]
    for got, expected in ((small, alone_small), (large, alone_large)):
        np.testing.assert_array_equal(got[2], expected[2])  # the counts: the same balls
        np.testing.assert_array_equal(np.isnan(got[0]), np.isnan(expected[0]))
    np.testing.assert_array_equal(small[0], alone_small[0])  # the same sums in the same order
    for got_part, expected_part in zip(small[1], alone_small[1]):
        np.testing.assert_array_equal(got_part, expected_part)
    # the larger balls' sums in another order: a well-conditioned fit (about 60 points on a sphere) moves by a
    # few hundred eps of its coefficients (in units of the radius, of order 1)
    np.testing.assert_allclose(large[0], alone_large[0], rtol=0, atol=1e-11)
    for got_part, expected_part in zip(large[1], alone_large[1]):
        np.testing.assert_allclose(got_part, expected_part, rtol=0, atol=1e-11)
    # and the sphere's curvature from the fits (k = 1 on the unit sphere, up to the jets' bias, r^2 of k)
    fitted = np.isfinite(small[0][:, 3])  # (a ball holding a flipped normal is refused: a third of them)
    assert fitted[centres].mean() > 0.5
    k = jets.jet_curvatures(small[0], small[1], np.full(points.shape[0], radius), normals)[:2]
    assert np.nanmedian(np.abs(np.concatenate(k) - 1.0)) < 0.05


@pytest.mark.parametrize("backend", BACKENDS)
def test_larger_with_a_radius_per_centre_is_a_second_call(backend):
    points, normals, _ = _sphere_cloud(1500)
    radii = np.linspace(0.15, 0.2, points.shape[0])
    with use_backend(backend):
        details = {}
        jets.fit_jets(points, normals, radii, degree=3, details=details, larger=0.3)
        expected = jets.fit_jets(points, normals, 0.3, degree=3)
    for got_part, expected_part in zip(details["larger"][0:1] + details["larger"][2:], expected[0:1] + expected[2:]):
        np.testing.assert_array_equal(got_part, expected_part)


def test_larger_needs_details():
    points, normals, _ = _sphere_cloud(200)
    with pytest.raises(InvalidOptionError, match="`larger` needs `details`"):
        jets.fit_jets(points, normals, 0.2, larger=0.3)


@pytest.mark.parametrize("larger", [0.2, 0.1, np.nan, np.inf, "0.3"])
def test_larger_must_exceed_the_radius(larger):
    points, normals, _ = _sphere_cloud(200)
    with pytest.raises(InvalidOptionError, match="`larger` must be a finite number larger than `radius` 0.2"):
        jets.fit_jets(points, normals, 0.2, details={}, larger=larger)


def _whole_cube_members(pool_points, grid, centre, cutoff):
    """The ranks within ``cutoff`` of ``centre`` among those of the cube of ``2 ceil(cutoff / cell) + 1`` cells a
    side around the centre's cell, in rank order (NumPy): the walk of every cell of the cube, the oracle of the
    walk that skips the cells the ball does not reach."""
    _, starts, levels, lo, cell, nx, ny = grid
    span = int(np.ceil(cutoff / cell))
    base = np.floor((np.asarray(centre) - lo) / cell)
    column = np.searchsorted(starts, np.arange(pool_points.shape[0]), side="right") - 1
    cells = np.stack([column // ny, column % ny, levels], axis=1)
    in_cube = np.all(np.abs(cells - base) <= span, axis=1)
    dx, dy, dz = (pool_points - np.asarray(centre)).T
    return np.flatnonzero(in_cube & (dx * dx + dy * dy + dz * dz <= cutoff * cutoff))


@pytest.mark.skipif(importlib.util.find_spec("numba") is None, reason="numba is not installed")
@pytest.mark.parametrize("cloud", ["gaussian", "lattice", "far and small", "flat"])
def test_the_walk_over_the_cells_a_ball_reaches_finds_what_the_whole_cube_finds(cloud):
    """``_ball_members`` (the balls of the grid: the jets' pairs, the point clouds, the cell sums) skips the cells
    beyond the ball: the same members in the same order as a walk of the whole cube of cells around the centre's
    cell, at every ratio of radius to cell, centres on the points, off them and outside the grid, on a lattice
    (points on the cells' bounds) and far from the origin (rounding of the bounds)."""
    from meshcurv._kernels.neighborhoods import _ball_members, pool_grid

    rng = np.random.default_rng(7)
    if cloud == "gaussian":
        points = rng.normal(size=(3000, 3))
    elif cloud == "lattice":
        points = np.stack(np.meshgrid(*[np.arange(14.0)] * 3), axis=-1).reshape(-1, 3)
    elif cloud == "far and small":
        points = 1e6 + 1e-3 * rng.random((3000, 3))
    else:
        points = rng.random((3000, 3)) * [1.0, 1.0, 1e-3]
    extent = float(np.ptp(points, axis=0).max())
    walked = 0
    for reach in (0.05 * extent, 0.2 * extent, 1.0 / 7.0 * 14.0 if cloud == "lattice" else 0.1 * extent):
        pool_points, _, grid = pool_grid(points, np.arange(points.shape[0]), reach)
        for ratio in (1.0, 2.0**0.5, 2.0, 2.7, 3.0):
            cutoff = reach * ratio
            centres = np.concatenate(
                [points[rng.integers(0, points.shape[0], 60)], points[:20] + rng.normal(size=(20, 3)) * cutoff]
            )
            for centre in centres:
                expected = _whole_cube_members(pool_points, grid, centre, cutoff)
                got, got_count = _ball_members(pool_points, grid, *centre, cutoff, np.empty(8, np.int64))
                np.testing.assert_array_equal(got[:got_count], expected)
                walked += got_count
    assert walked > 0
