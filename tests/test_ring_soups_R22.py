"""The ring methods on a voxel surface whose faces were detached and welded back across the cracks (issue 29).

A voxel sphere with half of its faces given corners of their own, each moved a few hundredths of an edge: the
weld joins the cracks, the vertices kept in place stay on the grid, the rest leave it by the cracks' width, and
the staircase is still there. The ring methods refuse the intact voxel sphere (its staircase reads as
curvature); on the welded soup they must not give valid numbers off the sphere's H = 1 / radius either.
"""

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes

RADIUS = 10.0


def half_detached(vertices, faces, gap, seed):
    """Half of the faces (at random) with corners of their own, each moved ``gap`` mean edges in a random direction."""
    rng = np.random.default_rng(seed)
    edge = np.linalg.norm(vertices[faces[:, 0]] - vertices[faces[:, 1]], axis=1).mean()
    chosen = rng.random(faces.shape[0]) < 0.5
    copies = vertices[faces[chosen].ravel()]
    offsets = rng.normal(size=copies.shape)
    offsets *= gap * edge / np.linalg.norm(offsets, axis=1, keepdims=True)
    detached = faces.copy()
    detached[chosen] = vertices.shape[0] + np.arange(copies.shape[0]).reshape(-1, 3)
    return np.concatenate([vertices, copies + offsets]), detached


@pytest.mark.parametrize("method", ["rusinkiewicz", "meyer", "normal_cycle"])
@pytest.mark.parametrize(("winding", "gap"), [("inward", 0.03), ("outward", 0.06)])
def test_no_valid_vertex_off_the_sphere(method, winding, gap):
    pytest.importorskip("skimage")
    sphere = shapes.voxel_sphere(radius=RADIUS)
    faces = np.asarray(sphere.faces)
    if winding == "inward":
        faces = faces[:, ::-1]
    vertices, faces = half_detached(np.asarray(sphere.vertices, float), faces, gap, seed=0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = meshcurv.principal_curvatures(vertices, faces, method=method)
    # the fuzzer's bound: a valid H within half of the largest |k| (1 / RADIUS) of the truth
    error = np.abs(result.mean[result.valid] - 1.0 / RADIUS) * RADIUS
    assert (error <= 0.5).all(), f"{int((error > 0.5).sum())} of {int(result.valid.sum())} valid vertices off"
