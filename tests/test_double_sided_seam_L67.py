"""A second side stored with vertices of its own, on a mesh whose one side has a seam (issue 29, class 7).

Without a weld (``method='matgeom'``, ``weld=False``) a second side with vertices of its own is found by the
points its vertices share (:func:`meshcurv._prepared._second_side_apart`); each dropped vertex went to the kept
vertex at its point, so a side with coincident vertices of its own (a seam of copies: ogre.obj has 9) was given
up and computed as two surfaces: area twice, H summed to 0, no warning (fuzz_api 730/156, ogre doubled). The
oracles: the one-sided mesh's own result (the same faces and vertices: matGeom's numbers, bit for bit), on both
halves, and its area counted once. A seamed side kept while the second side, on copies, has no seam: a dropped
vertex repeats the corners of two kept copies and the second side was left as given (area twice, G68's strict
xfail); its twin is now the copy most of its faces repeat (``_prepared._twins_by_faces``).
"""

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes

from conftest import chosen_backend
from test_double_sided_unwelded_L64 import _second_side_apart
from test_double_sided_welds_D24 import _seamed


def _computed(vertices, faces, **options):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = meshcurv.principal_curvatures(vertices, faces, **options)
    return result, " ".join(str(w.message) for w in caught)


@pytest.mark.parametrize("backend", ["numba", "numpy"])
@pytest.mark.parametrize("seed", [None, 3])
@pytest.mark.parametrize("options", [{"method": "matgeom"}, {"method": "normal_cycle", "weld": False}], ids=str)
@pytest.mark.parametrize(
    "mesh", [shapes.icosphere(3, radius=2.0), shapes.torus(3.0, 1.0, 32, 16)], ids=lambda mesh: mesh.name
)
def test_a_seamed_side_stored_twice_apart_is_measured_once(mesh, options, seed, backend):
    vertices, faces = _seamed(np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces))
    n, n_faces = vertices.shape[0], faces.shape[0]
    assert np.unique(vertices, axis=0).shape[0] < n  # the seam: coincident vertices of one side
    with chosen_backend(backend):
        one, _ = _computed(vertices, faces, **options)
        both, message = _computed(*_second_side_apart(vertices, faces, seed), **options)
    assert f"dropped {n_faces} faces" in message and "double-sided" in message, message
    assert both.parameters["n_double_sided_faces"] == n_faces
    np.testing.assert_array_equal(both.valid[:n], one.valid)
    np.testing.assert_array_equal(both.valid[n:], one.valid)
    # matGeom's numbers bit for bit (its sums follow the faces given); normal_cycle's sums in the shuffled faces'
    # order: round-off
    tolerance = 0.0 if options["method"] == "matgeom" else 1e-12
    for name in ("k_min", "k_max", "mean", "gaussian"):
        for half in (getattr(both, name)[:n], getattr(both, name)[n:]):
            np.testing.assert_allclose(half, getattr(one, name), rtol=tolerance, atol=tolerance)
    assert both.integral("area") == pytest.approx(one.integral("area"), rel=1e-12)


@pytest.mark.parametrize("backend", ["numba", "numpy"])
@pytest.mark.parametrize(
    "seamed_first",
    [True, False],
)
def test_a_second_side_without_the_seam_is_measured_once(seamed_first, backend):
    # the same surface, one side with a seam of copies, the other side on copies of the vertices without it: the
    # faces and vertices in either order are one mesh (re-indexing), its area that of one side
    mesh = shapes.icosphere(3, radius=2.0)
    plain_vertices, plain_faces = np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces)
    seamed_vertices, seamed_faces = _seamed(plain_vertices, plain_faces)
    sides = [(seamed_vertices, seamed_faces), (plain_vertices, plain_faces[:, ::-1])]
    if not seamed_first:
        sides = [(plain_vertices, plain_faces), (seamed_vertices, seamed_faces[:, ::-1])]
    (first_vertices, first_faces), (second_vertices, second_faces) = sides
    vertices = np.vstack([first_vertices, second_vertices])
    faces = np.vstack([first_faces, second_faces + first_vertices.shape[0]])
    with chosen_backend(backend):
        one, _ = _computed(plain_vertices, plain_faces, method="matgeom")
        both, message = _computed(vertices, faces, method="matgeom")
    assert both.parameters["n_double_sided_faces"] == plain_faces.shape[0], message
    assert both.integral("area") == pytest.approx(one.integral("area"), rel=1e-12)
    # the side kept is the first, measured as given alone (matGeom's numbers bit for bit); each row of the second
    # takes the values of a copy of its point on the first (a seam's copies differ: the one most of its faces repeat)
    with chosen_backend(backend):
        first, _ = _computed(first_vertices, first_faces, method="matgeom")
    n = first_vertices.shape[0]
    np.testing.assert_array_equal(both.mean[:n], first.mean)
    at_point = (second_vertices[:, None, :] == first_vertices[None, :, :]).all(axis=2)
    assert (at_point & (both.mean[n:, None] == first.mean[None, :])).any(axis=1).all()
