"""Spheres with half of their faces removed or detached are measured outward, whichever way they are wound (issue 29).

With half of the faces gone, every piece of the surface is too open to be turned outward by its own volume
(``orient.FILLED_MARGIN``), and the pieces that touch nothing (detached faces) have no neighbour to follow: before,
they kept the given winding, and a marching-cubes sphere (faces wound inward) was measured inside out, every valid
vertex with the wrong sign. Expected signs are the analytic sphere's: H = +1/r with outward normals.
"""

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes

#: The share of faces removed or detached, and how far each detached face's corners move (mean edge lengths).
SHARE = 0.5
OFFSET = 0.054


def _holey(vertices, faces, *, seed, detach, offset=OFFSET):
    """The mesh with a random half of its faces removed, or detached (each given its own three corners, moved by
    ``offset`` mean edge lengths in random directions)."""
    rng = np.random.default_rng(seed)
    edge = float(np.mean(np.linalg.norm(vertices[faces[:, 0]] - vertices[faces[:, 1]], axis=1)))
    picked = rng.random(len(faces)) < SHARE
    if not detach:
        return vertices, faces[~picked]
    corners = vertices[faces[picked]].reshape(-1, 3)
    direction = rng.normal(size=corners.shape)
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    moved = faces.copy()
    moved[picked] = len(vertices) + np.arange(corners.shape[0]).reshape(-1, 3)
    return np.concatenate([vertices, corners + direction * offset * edge]), moved


def _mean_curvatures(vertices, faces):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the welds, bow-ties and isolated faces are reported: not the point here
        result = meshcurv.principal_curvatures(vertices, faces)
    return ((result.k_min + result.k_max) / 2)[result.valid]


def _sphere(name):
    if name == "icosphere":
        sphere = shapes.icosphere(4)
        return sphere.vertices, sphere.faces, 1.0
    pytest.importorskip("skimage")
    radius = {"voxel_sphere_4": 4.0, "voxel_sphere_8": 8.0}[name]
    sphere = shapes.voxel_sphere(radius=radius)
    return sphere.vertices, sphere.faces, 1.0 / radius


@pytest.mark.parametrize("name", ["voxel_sphere_4", "voxel_sphere_8", "icosphere"])
@pytest.mark.parametrize("reverse", [False, True], ids=["as_made", "reversed"])
@pytest.mark.parametrize("detach", [False, True], ids=["removed", "detached"])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_half_open_sphere_is_measured_outward(name, reverse, detach, seed):
    vertices, faces, exact = _sphere(name)
    if reverse:
        faces = faces[:, [0, 2, 1]]
    mean = _mean_curvatures(*_holey(vertices, faces, seed=seed, detach=detach))
    assert mean.size > 0
    # the sign of every valid vertex is the sphere's; the median within a third of 1/r (a coarse voxel sphere's
    # staircase and the holes' rims spread the values, their signs stay)
    assert np.all(mean > 0)
    assert abs(np.median(mean) - exact) < exact / 3


@pytest.mark.parametrize("reverse", [False, True], ids=["as_made", "reversed"])
def test_hemisphere_keeps_the_given_winding(reverse):
    """A hemisphere encloses nothing: either winding is the user's choice, and the signs follow it."""
    hemisphere = shapes.hemisphere(8)
    faces = hemisphere.faces[:, [0, 2, 1]] if reverse else hemisphere.faces
    mean = _mean_curvatures(hemisphere.vertices, faces)
    sign = -1.0 if reverse else 1.0
    assert np.all(sign * mean > 0)
    assert abs(np.median(mean) - sign * 1.0) < 0.05  # radius 1: |H| = 1


@pytest.mark.parametrize("reverse", [False, True], ids=["as_made", "reversed"])
def test_hemisphere_with_half_of_its_faces_removed_keeps_the_given_winding(reverse):
    hemisphere = shapes.hemisphere(8)
    faces = hemisphere.faces[:, [0, 2, 1]] if reverse else hemisphere.faces
    mean = _mean_curvatures(*_holey(hemisphere.vertices, faces, seed=0, detach=False))
    sign = -1.0 if reverse else 1.0
    assert mean.size > 0
    assert np.median(sign * mean) > 0
