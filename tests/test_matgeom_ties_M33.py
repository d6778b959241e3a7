"""matgeom's round-off tie decision is the same in every pose (issue 29, fuzz_api 551/171).

matGeom's dihedral angles ``arccos(n1 . n2)`` carry up to 1e-7 of round-off that follows the pose of the mesh,
so the magnitudes of the tensor's two smallest eigenvalues (the normal's and the smaller curvature's) are known to
within a floor only. Whether they may swap (the vertex then ``valid=False``) was decided on the round-off tensor's
own gap: at a vertex whose gap sits at the floor, the pose decided. The decision is now taken on the tensor of the
exact angles.

The oracle is an invariance: a tube of radius 1 bent along an arc of radius ``bend`` (a torus patch) has principal
curvatures 1 and ``cos v / (bend + cos v)``; around the tube the smaller one sweeps through 0, so the gap between the
two smallest eigenvalues takes every value from 0 to some floors, and rows of vertices sit at the bound. A rigid
motion and a scaling leave matGeom's dimensionless numbers, so its valid mask and, where valid, its directions.
"""

import importlib.util
import warnings
from pathlib import Path

import numpy as np
import pytest

import meshcurv
from meshcurv.estimators.matgeom import ANGLE_NOISE
from conftest import chosen_backend

DATA = Path(__file__).parent / "data" / "matgeom"
BACKENDS = ["numpy"] + (["numba"] if importlib.util.find_spec("numba") else [])


def rotation(seed):
    """A random proper rotation (QR of a Gaussian matrix)."""
    q, r = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else q[:, [1, 0, 2]]


def bent_tube(bend, n_around=200, n_along=40, length=0.6):
    """A unit tube bent along an arc of radius ``bend`` (an open torus patch), ``(vertices, faces)``."""
    v = np.linspace(0.0, 2.0 * np.pi, n_around, endpoint=False) + 0.0123  # no row exactly on top
    u = np.linspace(-length / 2, length / 2, n_along) / bend
    along, around = np.meshgrid(u, v, indexing="ij")
    ring = bend + np.cos(around)
    vertices = np.stack([ring * np.cos(along) - bend, ring * np.sin(along), np.sin(around)], axis=-1).reshape(-1, 3)
    ids = np.arange(n_along * n_around).reshape(n_along, n_around)
    a, b = ids[:-1], np.roll(ids[:-1], -1, axis=1)
    c, d = ids[1:], np.roll(ids[1:], -1, axis=1)
    faces = np.concatenate([np.stack([a, b, d], -1).reshape(-1, 3), np.stack([a, d, c], -1).reshape(-1, 3)])
    return vertices, faces


def matgeom(vertices, faces, backend, steps):
    with chosen_backend(backend), warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the open patch's warning
        return meshcurv.principal_curvatures(vertices, faces, method="matgeom", smoothing_steps=steps, orient="keep")


def poses(vertices, n):
    """``n`` rigid motions (shifted by up to 10 sizes) and scalings (1e-2 to 1e2) of ``vertices``."""
    size = float(np.ptp(vertices))
    for seed in range(n):
        shift = np.random.default_rng(seed).uniform(-10.0, 10.0, size=3) * size
        yield seed, (vertices @ rotation(seed).T + shift) * 10.0 ** (seed % 5 - 2), rotation(seed)


def assert_same_decisions(result, moved, turn, label):
    assert np.array_equal(moved.valid, result.valid), (
        f"{label}: the valid mask differs at {int((moved.valid != result.valid).sum())} vertices"
    )
    both = result.valid
    scale = max(np.abs(result.k_max[both]).max(), np.abs(result.k_min[both]).max())
    # matGeom's numbers are dimensionless: where valid, the same to the round-off of its angles (ANGLE_NOISE x
    # the edges' lengths over their mean, below 2 on these meshes, per eigenvalue), the directions turned with the mesh
    atol = 1e-6 * scale + 2 * ANGLE_NOISE
    np.testing.assert_allclose(moved.k_min[both], result.k_min[both], rtol=0, atol=atol)
    np.testing.assert_allclose(moved.k_max[both], result.k_max[both], rtol=0, atol=atol)
    for name in ("dir_min", "dir_max", "normals"):
        cosines = np.abs(np.sum(getattr(moved, name)[both] * (getattr(result, name)[both] @ turn.T), axis=1))
        assert cosines.min() > 1 - 1e-6, f"{label}: {name} turned by {np.degrees(np.arccos(cosines.min())):.3g} deg"


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("steps", [0, 2])
@pytest.mark.parametrize("bend", [5e3, 2e4])
def test_bent_tube_ties_are_the_same_in_every_pose(bend, steps, backend):
    vertices, faces = bent_tube(bend)
    result = matgeom(vertices, faces, backend, steps)
    assert 0.3 * len(vertices) < result.valid.sum() < len(vertices)  # the bound is exercised: some tied, most not
    for seed, moved_vertices, turn in poses(vertices, 5):
        assert_same_decisions(result, matgeom(moved_vertices, faces, backend, steps), turn, f"pose {seed}")


@pytest.mark.parametrize("backend", BACKENDS)
def test_straight_tube_and_flat_rows_are_tied_in_every_pose(backend):
    # bend -> infinity: a cylinder, its smaller curvature exactly 0 (the axis), at every vertex away from the ends
    vertices, faces = bent_tube(1e12)
    result = matgeom(vertices, faces, backend, 2)
    assert not result.valid.any()
    for seed, moved_vertices, _ in poses(vertices, 3):
        assert not matgeom(moved_vertices, faces, backend, 2).valid.any(), f"pose {seed}"


@pytest.mark.parametrize("backend", BACKENDS)
def test_fandisk_far_motion_of_fuzz_551_171(backend):
    # fandisk's vertex 1306 (a cylindrical face, k_min -1.9e-7, its gap at the floor) was tied in the file's pose
    # and valid after this motion (fuzz_api's rigid relation 170833528: turned and shifted by up to 10 sizes)
    with np.load(DATA / "fandisk.npz") as case:
        vertices, faces = np.asarray(case["vertices"], float), case["faces"]
    value = 170833528
    shift = np.random.default_rng(value).uniform(-10.0, 10.0, size=3) * float(np.ptp(vertices))
    turn = rotation(value)
    result = matgeom(vertices, faces, backend, 2)
    assert_same_decisions(result, matgeom(vertices @ turn.T + shift, faces, backend, 2), turn, "551/171")
