import numpy as np
import pytest

from meshcurv import shapes
from meshcurv.errors import InvalidMeshError, InvalidOptionError, TriangulationWarning
from meshcurv.topology import MeshTopology, triangulate_faces


def _fan_by_definition(polygons):
    """matGeom's triangulateFaces written out face by face: (f0, f(j-1), f(j)) for j = 2 .. k-1."""
    return [[face[0], face[j - 1], face[j]] for face in polygons for j in range(2, len(face))]


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
    # (1, 2) has faces 0, 3 and 4: non-manifold, which is not "inconsistent" (a two-face property)
    assert top.edge_face_counts[edge[(1, 2)]] == 3 and top.nonmanifold_edges[edge[(1, 2)]]
    assert not top.inconsistent_edges.any()
    assert top.boundary_edges.sum() == top.n_edges - 2
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


def test_vectorised_fan_of_mixed_polygons_matches_the_definition():
    rng = np.random.default_rng(7)
    polygons = [rng.permutation(50)[:k].tolist() for k in rng.integers(3, 9, size=400)]
    triangles = triangulate_faces(polygons)
    assert triangles.dtype == np.int64 and triangles.flags.c_contiguous
    assert triangles.tolist() == _fan_by_definition(polygons)
    # the same faces as arrays, and as one (F, k) array when they have one length
    assert triangulate_faces([np.array(p) for p in polygons]).tolist() == _fan_by_definition(polygons)
    hexagons = rng.integers(0, 50, size=(30, 6))
    assert triangulate_faces(hexagons).tolist() == _fan_by_definition(hexagons.tolist())
    assert triangulate_faces(hexagons.tolist()).tolist() == _fan_by_definition(hexagons.tolist())


def test_triangulate_faces_returns_a_new_array():
    faces = np.array([[0, 1, 2], [2, 1, 3]])
    triangles = triangulate_faces(faces)
    triangles[0, 0] = 7
    assert faces[0, 0] == 0
    top = MeshTopology.from_faces(faces)
    assert triangulate_faces(top).tolist() == faces.tolist() and triangulate_faces(top).flags.writeable


@pytest.mark.parametrize(
    "polygons, message",
    [
        ([[0, 1, 2], [0, 1]], "has a face with fewer than 3 vertices"),
        ([[[0, 1], [2, 3], [4, 5]], [[0, 1], [2, 3], [4, 5], [6, 7]]], "a face holds nested lists"),
        ([[0, 1, 2, 3], [[0, 1], [2, 3], [4, 5]]], "could not be converted to an array"),
        ([[0, 1, 2], 3], "items are not sequences"),
        ([[0, 1, 2], "abc"], "items are not sequences"),
        ([[0, 1, 2], [0, 1, 2.5, 3]], "non-integer values"),
        ([[0, 1, 2], [2**64, 0, 1, 3]], "indices too large for int64"),
        ([[0, 1, 2], [0, 1, "x", 3]], "must hold integer vertex indices"),
        ([[0, 1, 2], [0, -4, 1, 3]], r"negative vertex indices \(smallest -4\)"),
        (np.zeros((0, 3), np.int64), "is empty"),
        (b"012", "got a bytes"),
    ],
)
def test_triangulate_faces_names_what_is_wrong(polygons, message):
    with pytest.raises(InvalidMeshError, match=rf"^`polygons` .*{message}"):
        triangulate_faces(polygons)


@pytest.mark.parametrize("n_vertices", [0, -3, 2.0, True, 2**31], ids=["zero", "negative", "float", "bool", "2**31"])
def test_from_faces_refuses_an_unusable_vertex_count(n_vertices):
    with pytest.raises(InvalidOptionError, match=r"`n_vertices` must be an integer between 1 and 2147483647"):
        MeshTopology.from_faces(np.array([[0, 1, 2]]), n_vertices)


def test_from_faces_checks_the_faces_against_the_vertex_count():
    with pytest.raises(InvalidMeshError, match="vertex index 5 out of range for 4 vertices"):
        MeshTopology.from_faces(np.array([[0, 1, 5]]), 4)
    with pytest.raises(InvalidMeshError, match="look 1-based"):
        MeshTopology.from_faces(np.array([[1, 2, 3]]), 3)


@pytest.mark.slow
def test_from_faces_without_a_count_refuses_a_stray_huge_index():
    far = 2**24  # the floor of inferred counts: one face may reach it, not beyond
    with pytest.raises(
        InvalidMeshError,
        match=rf"reference vertex index {far} but hold only 3 corners: pass "
        r"`n_vertices`",
    ):
        MeshTopology.from_faces(np.array([[0, 1, far]]))
    with pytest.raises(InvalidMeshError, match=r"beyond the largest mesh meshcurv takes \(n_vertices up to"):
        MeshTopology.from_faces(np.array([[0, 1, 2**31]]))
    assert MeshTopology.from_faces(np.array([[0, 1, far - 1]])).n_vertices == far
    assert MeshTopology.from_faces(np.array([[0, 1, far]]), far + 1).n_vertices == far + 1  # when asked for


def test_smoothing_lists_are_the_neighbour_lists_or_empty_without_smoothing():
    top = MeshTopology.from_faces(shapes.icosphere(2).faces)
    indptr, indices = top.smoothing_lists(3)
    assert indptr is top.neighbour_lists[0] and indices is top.neighbour_lists[1]
    empty_indptr, empty_indices = MeshTopology.from_faces(shapes.icosphere(2).faces).smoothing_lists(0)
    np.testing.assert_array_equal(empty_indptr, np.zeros(top.n_vertices + 1))
    assert empty_indices.size == 0 and empty_indptr.dtype == empty_indices.dtype == np.int64


@pytest.mark.parametrize("method", ["normal_cycle", "matgeom"])
def test_the_zero_area_faces_a_kernel_found_are_kept(method, monkeypatch):
    """The kernel's zero-area faces serve the defects (not searched twice): the same as geometry.degenerate_faces."""
    pytest.importorskip("numba")
    from meshcurv import _prepared
    from meshcurv._backend import use_backend
    from meshcurv.estimators import ESTIMATORS
    from meshcurv.estimators._support import Stages
    from meshcurv.geometry import degenerate_faces

    sphere = shapes.icosphere(4)
    n = sphere.vertices.shape[0]
    middle = 0.5 * (sphere.vertices[0] + sphere.vertices[1])  # on edge 0-1: a face of no area, three corners
    vertices = np.vstack([sphere.vertices, middle])
    faces = np.vstack([sphere.faces, [[0, 1, 1], [0, n, 1]]])  # and a repeated corner
    with use_backend("numba"):
        mesh = _prepared.prepare_mesh(vertices, faces, orient="keep", weld=False)
        estimator = ESTIMATORS[method]
        with monkeypatch.context() as patch:
            patch.setattr(_prepared, "degenerate_faces", lambda *args, **kwargs: pytest.fail("searched twice"))
            estimator.function(mesh, smoothing_steps=1, stages=Stages(estimator.stages))
        expected = degenerate_faces(mesh.vertices, mesh.topology)
    np.testing.assert_array_equal(mesh.degenerate, expected)
    assert expected.sum() == 2


def _defective_faces(seed: int) -> np.ndarray:
    """A closed sphere with the defects of the fan walks: two bow-ties (two spheres glued at a vertex, a
    fan split by reversing faces), non-manifold edges, repeated corners, a boundary, a face used twice."""
    rng = np.random.default_rng(seed)
    sphere = shapes.icosphere(3)
    n = sphere.vertices.shape[0]
    faces = sphere.faces.copy()
    second = sphere.faces + n
    second[second == n] = 0  # the second sphere's vertex 0 is the first's: a bow-tie
    flipped = rng.choice(faces.shape[0], 5, replace=False)
    faces[flipped] = faces[flipped][:, ::-1]  # inconsistent edges
    dropped = rng.choice(np.arange(10, faces.shape[0]), 6, replace=False)  # holes: boundaries, half fans
    extra = np.array([[1, 2, 2 * n], [3, 3, 4], [5, 6, 5], faces[20], faces[21][::-1]])  # non-manifold, repeated
    return np.vstack([np.delete(faces, dropped, axis=0), second, extra])


@pytest.mark.parametrize("seed", range(6))
def test_bowtie_vertices_from_the_twin_sides_are_those_of_the_definition(seed):
    """The compiled build's twin sides give the bow-ties of the corner graph (the NumPy definition)."""
    pytest.importorskip("numba")
    from meshcurv._backend import use_backend
    from meshcurv.topology import _bowtie_vertices

    faces = _defective_faces(seed)
    n_vertices = int(faces.max()) + 2  # one unreferenced vertex
    with use_backend("numba"):
        top = MeshTopology.from_faces(faces, n_vertices)
        found = top.bowtie_vertices
    assert top._side_twins is not None
    expected = _bowtie_vertices(top)
    np.testing.assert_array_equal(found, expected)
    assert expected[0] and expected.sum() >= 2
    with use_backend("numpy"):
        assert MeshTopology.from_faces(faces, n_vertices)._side_twins is None


@pytest.mark.parametrize("seed", range(3))
def test_the_builds_corner_counts_give_the_bowties_and_referenced_vertices_of_the_definitions(seed):
    """The compiled build's first pass (corners of faces without a repeated corner, the first side leaving each
    vertex) gives what bowtie_from_twins counts itself, and the referenced vertices of faces.ravel()."""
    pytest.importorskip("numba")
    from meshcurv._backend import use_backend
    from meshcurv._kernels import topology as kernels_topology

    faces = _defective_faces(seed)
    lone = int(faces.max()) + 1
    faces = np.vstack([faces, [[lone, lone, 7]]])  # a vertex only in a face with a repeated corner
    n_vertices = lone + 2  # and one unreferenced vertex
    with use_backend("numba"):
        top = MeshTopology.from_faces(faces, n_vertices)
        referenced, bowties = top.referenced_vertices, top.bowtie_vertices
    assert top._first_sides is not None and top._first_sides[lone] == -2 and top._first_sides[-1] == -1
    np.testing.assert_array_equal(
        bowties, kernels_topology.bowtie_from_twins(top.faces, top._side_twins, top.n_vertices)
    )
    used = np.zeros(n_vertices, dtype=bool)
    used[faces.ravel()] = True
    np.testing.assert_array_equal(referenced, used)
    proper = (faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 2] != faces[:, 0])
    np.testing.assert_array_equal(top._corner_counts, np.bincount(faces[proper].ravel(), minlength=n_vertices))
    np.testing.assert_array_equal(top.degenerate_faces, ~proper)
    with use_backend("numba"):  # no face with a repeated corner: the build's counts say so
        clean = MeshTopology.from_faces(shapes.icosphere(3).faces)
    assert clean._corner_counts is not None and not clean.degenerate_faces.any()
    assert clean.degenerate_faces.shape == (clean.n_faces,)


def test_twin_sides_pair_the_two_sides_of_each_edge_of_two_faces():
    pytest.importorskip("numba")
    from meshcurv._backend import use_backend

    faces = _defective_faces(0)
    with use_backend("numba"):
        top = MeshTopology.from_faces(faces)
    encoded = top._side_twins.astype(np.int64)
    twins = np.where(encoded < -1, -2 - encoded, encoded)  # -2 - t: the two sides run the edge the same way
    side_edge = top.face_edges.ravel()
    paired = np.flatnonzero(twins >= 0)
    np.testing.assert_array_equal(twins[twins[paired]], paired)  # an involution
    np.testing.assert_array_equal(side_edge[twins[paired]], side_edge[paired])  # the same edge
    assert (paired // 3 != twins[paired] // 3).all()  # of another face
    linked = (top.edge_face_counts == 2) & (top.edge_faces[:, 0] != top.edge_faces[:, 1])
    has_edge = side_edge >= 0
    np.testing.assert_array_equal(twins >= 0, has_edge & linked[np.where(has_edge, side_edge, 0)])
    # the same way: the tails of the two sides are the same vertex
    tail = top.faces.ravel()
    same_way = tail[paired] == tail[twins[paired]]
    np.testing.assert_array_equal(encoded[paired] < -1, same_way)
    assert same_way.any() and not same_way.all()
