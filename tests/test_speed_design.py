"""The compiled ball searches that walk the mesh (issue 15) against the Euclidean balls.

icc's normal fits and ball sums search each ball breadth-first over the mesh
from its centre (``adjacency=`` of ``fit_jets``, ``connected=`` of
``ball_face_sums``) instead of on a grid over all the points. Where the
surface inside a ball is connected this is the same ball, so the results must
be those of the Euclidean search (NumPy path: k-d tree pairs) up to the order
of the sums; where the ball also holds another sheet of the surface, that
sheet is left out. Skipped without numba.
"""

import numpy as np
import pytest

from meshcurv import shapes
from meshcurv._backend import use_backend
from meshcurv.jets import fit_jet_normals, fit_jets, jet_normals
from meshcurv.geometry import robust_mean_edge_length
from meshcurv.neighborhoods import ball_face_sums
from meshcurv.topology import MeshTopology

pytest.importorskip("numba")


def _irregular_sphere():
    mesh = shapes.with_normal_noise(shapes.icosphere(12), 0.2, seed=3)
    topology = MeshTopology.from_faces(mesh.faces, n_vertices=mesh.vertices.shape[0])
    return mesh.vertices, mesh.faces, topology, robust_mean_edge_length(mesh.vertices, topology.edges)


def _two_sheets(gap):
    """Two parallel square grids ``gap`` apart (edge 0.1): each ball of radius > gap reaches the other sheet."""
    saddle = shapes.saddle(half_width=0.5, spacing=0.1)
    flat = saddle.vertices * [1.0, 1.0, 0.0]
    n = flat.shape[0]
    vertices = np.vstack([flat, flat + [0.0, 0.0, gap]])
    faces = np.vstack([saddle.faces, saddle.faces + n])
    return vertices, faces, MeshTopology.from_faces(faces, n_vertices=2 * n), n


@pytest.mark.parametrize("factor", [1.0, 2.5])
def test_connected_face_sums_are_the_euclidean_sums_on_a_connected_surface(factor):
    vertices, faces, _, h = _irregular_sphere()
    rng = np.random.default_rng(0)
    values = rng.normal(size=(faces.shape[0], 3))
    usable = rng.random(faces.shape[0]) > 0.1
    with use_backend("numpy"):
        euclidean = ball_face_sums(vertices, faces, factor * h, values, usable=usable)
    with use_backend("numba"):
        connected = ball_face_sums(vertices, faces, factor * h, values, usable=usable, connected=True)
    # the same terms summed in another order: rounding only (|terms| <= 1, about 20 to 100 of them)
    np.testing.assert_allclose(connected, euclidean, rtol=0, atol=1e-12)
    assert np.abs(euclidean).max() > 1  # the sums are not all zero


def test_connected_face_sums_leave_out_the_other_sheet():
    vertices, faces, _, n = _two_sheets(0.15)
    values = np.ones((faces.shape[0], 1))
    with use_backend("numba"):
        one_sheet, _, _, _ = _two_sheets(5.0)  # the same sheets with the other one far away
        alone = ball_face_sums(one_sheet, faces, 0.25, values, connected=True)
        connected = ball_face_sums(vertices, faces, 0.25, values, connected=True)
        euclidean = ball_face_sums(vertices, faces, 0.25, values)
    np.testing.assert_allclose(connected, alone, rtol=0, atol=1e-12)
    assert (euclidean[:n] > connected[:n] + 0.5).all()  # the grid search reaches the other sheet


def test_connected_jets_are_the_euclidean_jets_on_a_connected_surface():
    vertices, _, topology, h = _irregular_sphere()
    normals = vertices / np.linalg.norm(vertices, axis=1, keepdims=True)
    with use_backend("numpy"):
        euclidean, frame, counts = fit_jets(vertices, normals, 3 * h, degree=3)
    with use_backend("numba"):
        connected, frame_c, counts_c = fit_jets(vertices, normals, 3 * h, degree=3, adjacency=topology.neighbour_lists)
        normals_c = fit_jet_normals(vertices, normals, 3 * h, degree=3, adjacency=topology.neighbour_lists)
    np.testing.assert_array_equal(counts_c, counts)
    assert counts.min() >= 10  # every ball holds a degree-3 fit
    np.testing.assert_allclose(connected, euclidean, rtol=0, atol=1e-9)
    np.testing.assert_allclose(frame_c[2], frame[2], rtol=0, atol=1e-12)
    # the one-pass normals are those of the coefficients and frames
    np.testing.assert_allclose(normals_c, jet_normals(connected, frame_c), rtol=0, atol=1e-15)


def test_connected_jets_leave_out_the_other_sheet_and_unlisted_vertices():
    vertices, _, topology, n = _two_sheets(0.13)  # no distance within 0.01 of the radius 0.27
    normals = np.tile([0.0, 0.0, 1.0], (vertices.shape[0], 1))
    neighbours = np.ones(vertices.shape[0], dtype=bool)
    neighbours[::5] = False
    with use_backend("numba"):
        _, _, both = fit_jets(vertices, normals, 0.27, degree=2, neighbours=neighbours)
        _, _, counts = fit_jets(
            vertices, normals, 0.27, degree=2, neighbours=neighbours, adjacency=topology.neighbour_lists
        )
    # brute force: the points of the centre's own sheet within the radius, listed in `neighbours`
    distances = np.linalg.norm(vertices[:, None, :] - vertices[None, :, :], axis=2)
    sheet = np.arange(vertices.shape[0]) >= n
    same = sheet[:, None] == sheet[None, :]
    inside = distances < 0.27
    np.testing.assert_array_equal(counts, (inside & same & neighbours[None, :]).sum(axis=1))
    np.testing.assert_array_equal(both, (inside & neighbours[None, :]).sum(axis=1))


@pytest.mark.parametrize("function", [fit_jet_normals, fit_jets])
def test_adjacency_of_another_mesh_is_refused(function):
    vertices, _, topology, h = _irregular_sphere()
    indptr, indices = topology.neighbour_lists
    with use_backend("numba"), pytest.raises(ValueError, match="`adjacency` must be CSR lists of"):
        function(vertices, vertices, 3 * h, adjacency=(indptr[:-1], indices))


@pytest.mark.parametrize(
    ("option", "match"), [("normals", "`normals` must have shape"), ("neighbours", "`neighbours` must have shape")]
)
def test_fit_jet_normals_refuses_arrays_of_another_size(option, match):
    vertices, _, topology, h = _irregular_sphere()
    arguments = {"normals": vertices, "neighbours": np.ones(vertices.shape[0], dtype=bool)}
    arguments[option] = arguments[option][:-1]
    with use_backend("numba"), pytest.raises(ValueError, match=match):
        fit_jet_normals(
            vertices,
            arguments["normals"],
            3 * h,
            neighbours=arguments["neighbours"],
            adjacency=topology.neighbour_lists,
        )
