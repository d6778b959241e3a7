"""``quadric`` on a voxel soup is the same in any order of the vertices and faces (issue 29; R30, session 64).

A voxel soup's faces have corners of their own, moved by a few hundredths of an edge (the fuzzer's detached faces),
welded back across the cracks. The weld kept each group of crack ends at its first member in the order of the
vertices, so a permutation of the vertices moved the surface measured: ``voxel_sphere(6)`` turned, every face
detached by 0.05 edges, 12 vertices valid in one order only and H 0.19 of the largest ``|k|`` apart; half detached,
27 and 0.19. Each group now stands at a member the order does not choose (``meshcurv.weld``).

Expected values: invariance under re-indexing (vertices and faces permuted: the same valid vertices, the same values
to round-off, the same radius).
"""

import numpy as np
import pytest

from meshcurv import shapes

from test_quadric_soups_V30 import TURN, _quadric, _radius, _rotation, _soup

pytest.importorskip("skimage")


def _permuted(vertices, faces, seed: int):
    """``(vertices, faces, back)``: the vertices and the faces in another order; ``back`` (V,) the row of each
    given vertex in the permuted ones."""
    rng = np.random.default_rng(seed)
    order = rng.permutation(len(vertices))
    back = np.argsort(order)
    return vertices[order], back[faces][rng.permutation(len(faces))], back


@pytest.mark.parametrize(
    ("share", "backend"),
    [
        (1.0, "numba"),
        (0.5, "numba"),
        pytest.param(0.5, "numpy", marks=pytest.mark.slow),
    ],
)
def test_turned_voxel_soup_in_any_order(share, backend):
    """R30's finding 7: the same valid vertices and values with the vertices and faces permuted (the weld's
    crack groups each at a member the order does not choose)."""
    sphere = shapes.voxel_sphere(6.0)
    vertices, faces = _soup(np.asarray(sphere.vertices) @ _rotation(TURN).T, sphere.faces, share, 0.05, 3)
    given = _quadric(vertices, faces, backend)
    moved, moved_faces, back = _permuted(vertices, faces, 11)
    other = _quadric(moved, moved_faces, backend)
    # before: 12 (full) and 27 (half) vertices valid in one order only, H 0.19 / R apart
    np.testing.assert_array_equal(other.valid[back], given.valid)
    assert given.valid.mean() > 0.5
    np.testing.assert_allclose(other.mean[back][given.valid], given.mean[given.valid], rtol=0, atol=1e-9 / 6.0)
    assert _radius(other) == pytest.approx(_radius(given), rel=1e-9)


@pytest.mark.parametrize("shift", [1e5, 2.0**20])
def test_turned_voxel_soup_welded_alike_wherever_it_sits(shift):
    """The crack groups stand at the same members far from the origin (W32): a group's ends equally near their mean
    in exact arithmetic (a pair's; the copies of one corner moved by one gap) were parted by the round-off of the
    coordinates, and 2 to 29 groups of this soup stood at another end 1e5 sizes away (up to 0.06 voxels). Expected:
    translation invariance (the welded vertices moved by the shift, to round-off)."""
    from meshcurv import MeshTopology
    from meshcurv.weld import weld_vertices

    sphere = shapes.voxel_sphere(6.0)
    vertices, faces = _soup(np.asarray(sphere.vertices) @ _rotation(TURN).T, sphere.faces, 0.5, 0.05, 3)
    offset = shift * 12.0 * np.array([0.6, -0.48, 0.64])
    here = weld_vertices(vertices, MeshTopology.from_faces(faces, len(vertices)))
    there = weld_vertices(vertices + offset, MeshTopology.from_faces(faces, len(vertices)))
    assert here.n_cracked > 0
    np.testing.assert_array_equal(there.index, here.index)
    np.testing.assert_allclose(there.vertices - offset, here.vertices, rtol=0, atol=1e-6)
