import numpy as np
import pytest

from meshcurv import _geometry, geometry, shapes
from meshcurv.errors import InvalidMeshError
from meshcurv.geometry import face_normals
from meshcurv.topology import MeshTopology


def test_sphere_area_and_volume_approach_the_exact_ones():
    sphere = shapes.icosphere(32, radius=2.0)
    area = geometry.face_areas(sphere.vertices, sphere.faces).sum()
    volume = geometry.signed_volume(sphere.vertices, sphere.faces)
    assert abs(area / (16 * np.pi) - 1) < 2e-3
    assert abs(volume / (32 * np.pi / 3) - 1) < 3e-3
    np.testing.assert_allclose(geometry.signed_volume(sphere.vertices, sphere.faces[:, ::-1]), -volume, rtol=1e-14)


def test_vertex_areas_sum_to_the_total_area():
    torus = shapes.torus()
    areas = geometry.face_areas(torus.vertices, torus.faces)
    np.testing.assert_allclose(geometry.vertex_areas(torus.vertices, torus.faces).sum(), areas.sum())
    # exact area of a torus: 4 pi^2 R r
    assert abs(areas.sum() / (4 * np.pi**2 * 300) - 1) < 5e-3


def test_face_normals_are_unit_outward_and_nan_without_area():
    sphere = shapes.icosphere(4)
    normals = geometry.face_normals(sphere.vertices, sphere.faces)
    centres = sphere.vertices[sphere.faces].mean(axis=1)
    np.testing.assert_allclose(np.linalg.norm(normals, axis=1), 1)
    assert (np.sum(normals * centres, axis=1) > 0).all()
    flat = geometry.face_normals(np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0.0]]), np.array([[0, 1, 2]]))
    assert np.isnan(flat).all()


def test_vertex_normals_match_the_exact_ones():
    torus = shapes.torus()
    normals = geometry.vertex_normals(torus.vertices, torus.faces)
    assert np.sum(normals * torus.normals, axis=1).min() > 0.999


def test_mean_edge_length_of_a_unit_grid():
    saddle = shapes.saddle(half_width=1.0, spacing=0.5)
    top = MeshTopology.from_faces(saddle.faces)
    flat = saddle.vertices * [1, 1, 0]
    # 5 x 5 points: 20 + 20 axis-aligned edges of 0.5, 16 diagonals of 0.5 sqrt(2)
    expected = (40 * 0.5 + 16 * 0.5 * np.sqrt(2)) / 56
    assert abs(geometry.mean_edge_length(flat, top.edges) - expected) < 1e-12


@pytest.mark.parametrize("fold", [0.0, 0.3, np.pi / 2, 2.0])
def test_edge_dihedral_angles_of_a_folded_pair(fold):
    # two triangles on the edge (0, 1) along x, the second turned by `fold` about it: their normals differ by it
    vertices = np.array([[0.0, 0, 0], [1, 0, 0], [0.5, 1, 0], [0.5, -np.cos(fold), np.sin(fold)]])
    faces = np.array([[0, 1, 2], [1, 0, 3]])
    top = MeshTopology.from_faces(faces, 4)
    normals = face_normals(vertices, faces)
    usable = top.interior_edges.copy()
    beta, lengths, unit = geometry.edge_dihedral_angles(vertices, top, normals, usable)
    shared = np.flatnonzero(usable)
    assert shared.size == 1 and np.allclose(abs(beta[shared]), fold) and (beta[~usable] == 0).all()
    np.testing.assert_allclose(lengths[shared], 1.0)
    np.testing.assert_allclose(np.abs(unit[shared]), [[1.0, 0, 0]])
    mirrored = vertices * [1, 1, -1]  # the fold the other way: the opposite sign
    other, _, _ = geometry.edge_dihedral_angles(mirrored, top, face_normals(mirrored, faces), usable)
    np.testing.assert_allclose(other[shared], -beta[shared], atol=1e-15)


def test_edge_dihedral_angles_refuse_mismatched_arrays():
    vertices = np.array([[0.0, 0, 0], [1, 0, 0], [0.5, 1, 0], [0.5, -1, 0]])
    faces = np.array([[0, 1, 2], [1, 0, 3]])
    top = MeshTopology.from_faces(faces, 4)
    normals = face_normals(vertices, faces)
    with pytest.raises(InvalidMeshError, match=r"`unit_normals` must be a real array of shape \(2, 3\)"):
        geometry.edge_dihedral_angles(vertices, top, normals[:1], top.interior_edges)
    with pytest.raises(InvalidMeshError, match=r"`unit_normals` must be a real array of shape \(2, 3\)"):
        geometry.edge_dihedral_angles(vertices, top, None, top.interior_edges)
    with pytest.raises(InvalidMeshError, match=r"`usable_edges` must be a bool array of shape \(5,\)"):
        geometry.edge_dihedral_angles(vertices, top, normals, np.ones(5))
    with pytest.raises(InvalidMeshError, match=r"`topology` must be a MeshTopology; got ndarray"):
        geometry.edge_dihedral_angles(vertices, faces, normals, top.interior_edges)


def _arguments(name: str, mesh, topology: MeshTopology) -> tuple:
    """The arguments of ``geometry.<name>`` on one mesh (vertices first)."""
    vertices, faces = mesh.vertices, mesh.faces
    if name.endswith(("edge_length", "edge_lengths")):
        return vertices, topology.edges
    if name in ("vertex_length_scales", "degenerate_faces"):
        return vertices, topology
    if name == "degenerate_face_mask":
        return geometry.face_areas(vertices, faces), 0.5
    if name == "edge_dihedral_angles":
        return vertices, topology, geometry.face_normals(vertices, faces), topology.interior_edges
    return vertices, faces


#: The public functions of meshcurv.geometry over a core of the same name in meshcurv._geometry.
SHELLS = [name for name in geometry.__all__ if hasattr(_geometry, name)]


@pytest.mark.parametrize("name", SHELLS)
def test_a_public_function_is_its_core_on_checked_arrays(name):
    mesh = shapes.with_normal_noise(shapes.torus(), 0.1)  # an irregular mesh: no tie hides a difference
    topology = MeshTopology.from_faces(mesh.faces, len(mesh.vertices))
    arguments = _arguments(name, mesh, topology)
    public = getattr(geometry, name)(*arguments)
    # the core of vertex_edge_lengths takes the vertex count too, as its kernel does
    core = getattr(_geometry, name)(*arguments, *([len(mesh.vertices)] if name == "vertex_edge_lengths" else []))
    for a, b in zip(public if isinstance(public, tuple) else (public,), core if isinstance(core, tuple) else (core,)):
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("name", SHELLS)
def test_a_public_function_checks_its_vertices(name):
    mesh = shapes.icosphere(2)
    topology = MeshTopology.from_faces(mesh.faces, len(mesh.vertices))
    arguments = _arguments(name, mesh, topology)
    if name == "degenerate_face_mask":  # areas and a scale, no vertices
        with pytest.raises(InvalidMeshError, match="`areas` must hold real numbers"):
            geometry.degenerate_face_mask(["a"], 0.5)
        return
    vertices = mesh.vertices.copy()
    vertices[3, 1] = np.nan
    with pytest.raises(InvalidMeshError, match="`vertices` has NaN or infinite coordinates at 1 vertices"):
        getattr(geometry, name)(vertices, *arguments[1:])
