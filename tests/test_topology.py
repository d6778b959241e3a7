import numpy as np
import pytest

from meshcurv import shapes
from meshcurv.errors import TriangulationWarning
from meshcurv.topology import MeshTopology, triangulate_faces


def test_fan_triangulation_follows_matgeom():
    assert triangulate_faces(np.array([[0, 1, 2, 3]])).tolist() == [[0, 1, 2], [0, 2, 3]]
    assert triangulate_faces(np.array([[0, 1, 2, 3, 4]])).tolist() == [[0, 1, 2], [0, 2, 3], [0, 3, 4]]
    mixed = triangulate_faces([[0, 1, 2], [3, 4, 5, 6]])
    assert mixed.tolist() == [[0, 1, 2], [3, 4, 5], [3, 5, 6]]


def test_closed_sphere_edges_faces_and_euler_characteristic():
    sphere = shapes.icosphere(4)
    top = MeshTopology.from_faces(sphere.faces, sphere.vertices.shape[0])
    assert top.n_edges == 3 * top.n_faces // 2
    assert (top.edge_face_counts == 2).all() and top.interior_edges.all()
    assert top.euler_characteristic == 2 and top.n_components == 1 and top.n_boundary_loops == 0
    # column 0 runs p -> q, column 1 runs q -> p
    for e in (0, 17, top.n_edges - 1):
        p, q = top.edges[e]
        f0, f1 = top.faces[top.edge_faces[e]]
        k0 = list(f0).index(p)
        assert f0[(k0 + 1) % 3] == q
        k1 = list(f1).index(q)
        assert f1[(k1 + 1) % 3] == p


def test_face_edges_point_to_the_sides():
    torus = shapes.torus(n_major=8, n_minor=6)
    top = MeshTopology.from_faces(torus.faces)
    sides = np.stack([torus.faces, np.roll(torus.faces, -1, axis=1)], axis=-1)
    np.testing.assert_array_equal(top.edges[top.face_edges], np.sort(sides, axis=-1))
    assert top.euler_characteristic == 0


def test_open_grid_has_one_boundary_loop():
    saddle = shapes.saddle(spacing=0.25)  # 9 x 9 grid
    top = MeshTopology.from_faces(saddle.faces)
    assert top.boundary_edges.sum() == 4 * 8
    assert top.n_boundary_loops == 1
    assert top.boundary_vertices.sum() == 4 * 8
    assert (top.edge_faces[top.boundary_edges] == -1).any(axis=1).all()


def test_nonmanifold_inconsistent_and_unreferenced_are_found():
    faces = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4], [2, 1, 5], [2, 1, 6]])
    top = MeshTopology.from_faces(faces, n_vertices=8)
    edge = {tuple(e): i for i, e in enumerate(top.edges.tolist())}
    assert top.edge_face_counts[edge[(0, 1)]] == 3 and top.nonmanifold_edges[edge[(0, 1)]]
    assert top.inconsistent_edges[edge[(1, 2)]] is np.True_ or top.edge_face_counts[edge[(1, 2)]] == 3
    assert not top.referenced_vertices[7]
    assert top.n_components == 1


def test_inconsistent_orientation_between_two_faces():
    faces = np.array([[0, 1, 2], [0, 1, 3]])  # both run 0 -> 1
    top = MeshTopology.from_faces(faces)
    e = top.edges.tolist().index([0, 1])
    assert top.inconsistent_edges[e] and not top.interior_edges[e]


def test_repeated_corner_face_is_degenerate_and_adds_no_self_edge():
    top = MeshTopology.from_faces(np.array([[0, 1, 2], [2, 2, 3]]))
    assert top.degenerate_faces.tolist() == [False, True]
    assert (top.edges[:, 0] < top.edges[:, 1]).all()
    assert top.face_edges[1, 0] == -1


def test_from_faces_triangulates_quads_with_a_warning():
    with pytest.warns(TriangulationWarning):
        top = MeshTopology.from_faces(np.array([[0, 1, 2, 3]]))
    assert top.n_faces == 2 and top.n_edges == 5


def test_topology_is_read_only():
    top = MeshTopology.from_faces(shapes.icosphere(2).faces)
    with pytest.raises(ValueError):
        top.edges[0, 0] = 5
    with pytest.raises(AttributeError):
        top.n_vertices = 3
