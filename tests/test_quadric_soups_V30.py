"""``quadric`` at its default radius on voxel soups in any pose (issue 29; R29's F6, F4, F5).

A marching-cubes surface whose faces have corners of their own, moved by a few hundredths of an edge (the fuzzer's
detached faces), is measured at the voxel rule's radius and checked as a voxel surface's where its grid is read
(tests/test_quadric_voxel_soups_V29.py). That grid was read along the coordinate axes only: turned by a rotation,
``voxel_sphere(6)`` with every face detached read no grid (the proposal of the grid's axes groups the faces' sides
within 0.05 rad, which the detached faces' offsets scatter by about 0.07) and got the smooth noise rule's radius, 2.90
voxels against 3.41 unturned, with 433 valid vertices off its H by more than half of it against 76; half detached, the
turned vertices that kept their place were rounded apart (one plane's coordinates split by the rounding), so no grid
either. Now the soup's frame is read from its faces' sides (refitted to round-off) and the same grid is read in every
pose.

Expected values: the exact curvature of the sphere of radius ``R`` voxels (``H = 1 / R``) and invariance under a
rotation (the default radius read in two poses). The bar of a lie is the fuzzer's (``benchmarks/fuzz_api.py``,
``detached_check``): H off the clean surface's estimate in the same pose (at the nearest vertex) by more than half of
that estimate's largest ``|k|`` (1.47 / R on ``voxel_sphere(6)``); and none off the exact H by more than 0.6 / R (the
soups' tail reaches 0.54 / R: 3-8 vertices beyond 0.5 / R of about 3,000; benchmarks/quadric_voxel_soups_V30.py).
"""

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes

from conftest import chosen_backend

pytest.importorskip("skimage")

#: The fuzzer's bar (``DETACHED_TOLERANCE``), in units of the clean estimate's largest |k|.
BAR = 0.5
#: The least error in units of the exact 1 / R that is a lie whatever the bar's reference.
EXACT_BAR = 0.6


def _beyond_bars(result, vertices, clean, clean_vertices, radius: float) -> tuple[int, int]:
    """``(fuzzer, exact)``: the valid vertices beyond the fuzzer's bar (against the ``clean`` estimate at the nearest
    of ``clean_vertices``, valid in both) and beyond :data:`EXACT_BAR` of the exact H."""
    from scipy.spatial import cKDTree

    nearest = cKDTree(clean_vertices).query(vertices)[1]
    both = result.valid & clean.valid[nearest]
    size = max(np.abs(clean.k_min[clean.valid]).max(), np.abs(clean.k_max[clean.valid]).max())
    fuzzer = np.abs(result.mean - clean.mean[nearest])[both] > BAR * size
    exact = np.abs(result.mean[result.valid] * radius - 1.0) > EXACT_BAR
    return int(fuzzer.sum()), int(exact.sum())


def _rotation(angles) -> np.ndarray:
    a, b, c = angles
    rx = np.array([[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]])
    ry = np.array([[np.cos(b), 0, np.sin(b)], [0, 1, 0], [-np.sin(b), 0, np.cos(b)]])
    rz = np.array([[np.cos(c), -np.sin(c), 0], [np.sin(c), np.cos(c), 0], [0, 0, 1]])
    return rz @ ry @ rx


def _soup(vertices, faces, share: float, gap: float, seed: int):
    """A ``share`` of the ``faces`` given corners of their own (after the vertices), each moved ``gap`` mean edge
    lengths in a random direction (the fuzzer's detached faces)."""
    vertices, faces = np.asarray(vertices, float), np.asarray(faces)
    sides = vertices[faces[:, 1]] - vertices[faces[:, 0]]
    rng = np.random.default_rng(seed)
    moved = np.flatnonzero(rng.random(len(faces)) < share)
    offsets = rng.normal(size=(3 * moved.size, 3))
    offsets *= gap * float(np.mean(np.linalg.norm(sides, axis=1))) / np.linalg.norm(offsets, axis=1, keepdims=True)
    copies = vertices[faces[moved].ravel()] + offsets
    faces = faces.copy()
    faces[moved] = (len(vertices) + np.arange(copies.shape[0])).reshape(-1, 3)
    return np.concatenate([vertices, copies]), faces


def _quadric(vertices, faces, backend: str = "numba"):
    with chosen_backend(backend), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return meshcurv.principal_curvatures(vertices, faces, method="quadric")


def _radius(result) -> float:
    return float(np.median(np.atleast_1d(result.parameters["radius"])))


TURN = (0.3, 0.5, 0.7)


@pytest.mark.parametrize(
    ("share", "turned_first"),
    [
        (1.0, False),
        pytest.param(1.0, True, marks=pytest.mark.slow),
        (0.5, True),
        pytest.param(0.5, False, marks=pytest.mark.slow),
    ],
)
def test_turned_voxel_soup_reads_its_grid(share, turned_first):
    """R29's F6: the soup turned (before or after its faces are detached) gets the default radius of the soup in
    the grid's axes, and no valid vertex off the sphere's H by more than the fuzzer's bar."""
    sphere = shapes.voxel_sphere(6.0)
    rotation = _rotation(TURN)
    if turned_first:
        vertices, faces = _soup(np.asarray(sphere.vertices) @ rotation.T, sphere.faces, share, 0.05, 3)
        unturned = _soup(sphere.vertices, sphere.faces, share, 0.05, 3)
    else:
        unturned = _soup(sphere.vertices, sphere.faces, share, 0.05, 3)
        vertices, faces = unturned[0] @ rotation.T, unturned[1]
    turned, straight = _quadric(vertices, faces), _quadric(*unturned)
    assert _radius(turned) == pytest.approx(_radius(straight), rel=0.02)  # (before: 2.90 against 3.41)
    clean_vertices = np.asarray(sphere.vertices) @ rotation.T
    clean = _quadric(clean_vertices, sphere.faces)
    # before: 433 of 3,951 valid off the exact H by more than 0.5 / R (full, turned after), 125 of 2,162 (half)
    assert _beyond_bars(turned, vertices, clean, clean_vertices, 6.0) == (0, 0)
    assert turned.valid.mean() > 0.5


def test_soup_grid_in_any_pose():
    """The grid read on a turned soup is the voxel grid: unit voxels, its axes the image's turned."""
    sphere = shapes.voxel_sphere(6.0)
    rotation = _rotation(TURN)
    for share, seed in ((1.0, 3), (0.5, 3), (0.5, 5)):
        vertices, faces = _soup(np.asarray(sphere.vertices) @ rotation.T, sphere.faces, share, 0.05, seed)
        _assert_turned_unit_grid(vertices, faces, rotation)


def _assert_turned_unit_grid(vertices, faces, rotation) -> None:
    """The grid quadric reads on the soup: unit voxels, each axis along one of the image's axes ``rotation`` turned
    (to the detached faces' scatter)."""
    from meshcurv._prepared import prepare_mesh
    from meshcurv.estimators._support import Stages
    from meshcurv.estimators.quadric import STAGES, _soup_grid

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        prepared = prepare_mesh(vertices, faces, orient="outward", weld=True)
    defects, valid = prepared.start(boundary=True, fragments=True)
    grid = _soup_grid(prepared, defects, valid, Stages(STAGES))
    assert grid is not None and grid.frame is not None
    np.testing.assert_allclose(grid.spacing, 1.0, rtol=1e-3)
    np.testing.assert_allclose(np.sort(np.abs(grid.frame @ rotation), axis=1)[:, -1], 1.0, atol=1e-4)


@pytest.mark.parametrize("shift", [1e4, 1e5, 2.0**20])
def test_soup_grid_wherever_the_soup_sits(shift):
    """The same grid far from the origin (R30, session 64): the coordinates of a plane, turned into the grid's axes,
    were made one within a tolerance that grew with their distance from the origin, not with the mesh: at 1e5 sizes
    no grid was read (the default radius 3.27 for 3.86 at the origin, H off by 0.76 / R), at 2**20 (the fuzzer's
    translation) a grid of spacing (0, 0, 0.5). Expected: translation invariance (the grid read at the origin)."""
    sphere = shapes.voxel_sphere(6.0)
    rotation = _rotation(TURN)
    vertices, faces = _soup(np.asarray(sphere.vertices) @ rotation.T, sphere.faces, 0.5, 0.05, 3)
    _assert_turned_unit_grid(vertices + shift * 12.0 * np.array([0.6, -0.48, 0.64]), faces, rotation)


@pytest.mark.parametrize("backend", ["numba", pytest.param("numpy", marks=pytest.mark.slow)])
def test_turned_half_soup_both_backends(backend):
    sphere = shapes.voxel_sphere(6.0)
    vertices, faces = _soup(np.asarray(sphere.vertices) @ _rotation(TURN).T, sphere.faces, 0.5, 0.05, 3)
    result = _quadric(vertices, faces, backend)
    clean_vertices = np.asarray(sphere.vertices) @ _rotation(TURN).T
    clean = _quadric(clean_vertices, sphere.faces)
    # before: 125 of 2,162 valid off the exact H by more than 0.5 / R (the noise rule's balls, 3.27 voxels)
    assert _beyond_bars(result, vertices, clean, clean_vertices, 6.0) == (0, 0)
    assert np.median(np.abs(result.mean[result.valid] * 6.0 - 1.0)) < 0.15
