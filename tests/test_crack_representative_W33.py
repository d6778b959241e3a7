"""A group of crack ends welded back stands at the corner its faces left in place (issue 29; W33, session 67).

Half of a mesh's faces given corners of their own, each moved a few hundredths of an edge (the fuzzer's detached
faces): the weld joins each corner left in place with the copies of it across the cracks (``meshcurv.weld``). The
group stands at a member the order of the vertices does not choose, first the one in the most faces; where the
corner left in place is in one face, as each copy is, a pair ties exactly on its mean and the faces' area chose a
moved copy: 63-91 of about 1,900 such groups of the uv sphere below (W32's rule), the surface measured moved off
the sphere there and ``normal_cycle_ball`` kept 4-6% fewer vertices valid (tests/test_ncb_cracks_N21.py). Now the
member whose faces' corners are in the most faces: a corner left in place shares its faces' corners with their
neighbours, a detached face's copies are in that face alone.

Expected values: the construction (the corners left in place are the analytic sphere's points, at radius 1; a
copy is ``gap`` edges off them in a random direction) and invariance under re-indexing.
"""

import numpy as np
import pytest

from meshcurv import MeshTopology, shapes
from meshcurv.weld import weld_vertices

from test_ncb_cracks_N21 import half_detached


def _off_the_clean_corner(mesh, seed: int, gap: float, reverse: bool = False):
    """``(groups, off)``: the crack groups holding a corner left in place, and how many stand elsewhere."""
    vertices, faces, _ = half_detached(mesh, seed, gap, reverse=reverse)
    n_given = len(mesh.vertices)
    welding = weld_vertices(vertices, MeshTopology.from_faces(faces, len(vertices)))
    used = np.zeros(len(vertices), dtype=bool)
    used[faces.ravel()] = True
    sizes = np.bincount(welding.index[used], minlength=welding.vertices.shape[0])
    clean = np.flatnonzero(used[:n_given])
    clean = clean[sizes[welding.index[clean]] > 1]
    off = ~np.all(welding.vertices[welding.index[clean]] == vertices[clean], axis=1)
    return clean.size, int(off.sum())


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_uv_sphere_half_detached_welded_at_the_corners_left(seed):
    """N21's uv sphere (64 x 32, wound inward, half detached by 0.044 edges): of about 1,900 groups with a corner
    left in place, at most 1 in 200 stand elsewhere (0-2 now: the corner left in one face whose neighbours are too;
    63-91 with the area deciding the ties)."""
    groups, off = _off_the_clean_corner(shapes.uv_sphere(n_longitude=64, n_latitude=32), seed, 0.044, reverse=True)
    assert groups > 1500
    assert off <= groups // 200, f"{off} of {groups} groups welded off the corner left in place"


@pytest.mark.parametrize("seed", [0, 1])
def test_icosphere_half_detached_welded_at_the_corners_left(seed):
    """Not the family the rule was read on: icosphere(24) (valence 5-6), half detached by 0.03 edges: 0 of about
    5,580 groups off the corner left in place (146 and 122 with the area deciding the ties)."""
    groups, off = _off_the_clean_corner(shapes.icosphere(24), seed, 0.03)
    assert groups > 5000
    assert off <= groups // 200, f"{off} of {groups} groups welded off the corner left in place"


def test_the_corner_left_in_place_whatever_the_order():
    """The choice is the same with the vertices and faces permuted (an integer count, no order)."""
    sphere = shapes.uv_sphere(n_longitude=64, n_latitude=32)
    vertices, faces, _ = half_detached(sphere, 0, 0.044, reverse=True)
    rng = np.random.default_rng(5)
    order = rng.permutation(len(vertices))
    back = np.argsort(order)
    given = weld_vertices(vertices, MeshTopology.from_faces(faces, len(vertices)))
    moved = weld_vertices(vertices[order], MeshTopology.from_faces(back[faces][rng.permutation(len(faces))]))
    assert given.n_cracked > 0
    np.testing.assert_array_equal(moved.vertices[moved.index[back]], given.vertices[given.index])
