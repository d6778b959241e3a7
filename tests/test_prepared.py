"""The prepared mesh: the caller's arrays checked once, then trusted (issue 33)."""

import importlib.util

import numpy as np
import pytest

import meshcurv
from meshcurv import _prepared, _validation, shapes
from meshcurv._backend import use_backend
from meshcurv.errors import InvalidMeshError
from meshcurv.topology import MeshTopology


def _counted(monkeypatch, module, name: str) -> list:
    calls: list = []
    original = getattr(module, name)

    def spy(*args, **kwargs):
        calls.append(name)
        return original(*args, **kwargs)

    monkeypatch.setattr(module, name, spy)
    return calls


@pytest.mark.parametrize("method", ["normal_cycle", "icc"])
def test_the_vertices_and_faces_are_checked_once_per_call(method, monkeypatch):
    sphere = shapes.icosphere(4)
    vertices = _counted(monkeypatch, _prepared, "as_vertices")
    faces = _counted(monkeypatch, _prepared, "as_faces")
    again = _counted(monkeypatch, _validation, "as_vertices")  # a helper that would check them a second time
    meshcurv.principal_curvatures(sphere.vertices, sphere.faces.tolist(), method=method)
    assert (len(vertices), len(faces), len(again)) == (1, 1, 0)


def test_a_prepared_mesh_holds_the_checked_arrays_and_leaves_the_callers_alone():
    sphere = shapes.icosphere(3)
    given = sphere.vertices.astype(np.float32)
    mesh = _prepared.prepare_mesh(given, sphere.faces.astype(np.int32), orient="keep", weld=False)
    assert mesh.vertices.dtype == np.float64 and mesh.vertices.flags.c_contiguous
    assert mesh.topology.faces.dtype == np.int64
    assert mesh.vertices is not given and given.dtype == np.float32
    np.testing.assert_array_equal(mesh.topology.faces, sphere.faces)


def test_a_given_topology_is_taken_once_its_vertex_count_matches():
    sphere = shapes.icosphere(3)
    topology = MeshTopology.from_faces(sphere.faces, len(sphere.vertices))
    mesh = _prepared.prepare_mesh(sphere.vertices, topology, orient="keep", weld=False)
    assert mesh.topology is topology
    n = len(sphere.vertices)
    with pytest.raises(InvalidMeshError, match=f"is a MeshTopology of {n} vertices but `vertices` has {n - 1} rows"):
        _prepared.prepare_mesh(sphere.vertices[:-1], topology, orient="keep", weld=False)


def test_a_welded_vertex_stands_on_the_first_of_its_rows():
    # a triangle soup of an octahedron: every vertex given 4 times, welded into 6
    octahedron = np.array([[1.0, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]])
    faces = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
    soup = octahedron[faces.ravel()]
    with pytest.warns(meshcurv.MeshQualityWarning, match="welded 18 coincident vertices"):
        result = meshcurv.principal_curvatures(soup, np.arange(24).reshape(8, 3), method="normal_cycle")
    surface = result._surface
    rows = np.asarray(surface.rows)
    np.testing.assert_array_equal(surface.vertices, soup[rows])  # each welded vertex is its first row's
    np.testing.assert_array_equal(surface.index[rows], np.arange(6))  # row rows[w] stands for vertex w ...
    assert all(rows[w] == np.flatnonzero(surface.index == w).min() for w in range(6))  # ... and is its first
    area = result.vertex_integrals("area")
    # the octahedron's area, 8 equilateral triangles of side sqrt(2), once: on the first rows, 0 on copies
    assert area.sum() == pytest.approx(8 * np.sqrt(3) / 4 * 2)
    assert (area[np.setdiff1d(np.arange(24), rows)] == 0).all() and (area[rows] > 0).all()


def test_the_vertex_areas_share_out_the_area_of_the_faces_that_weigh():
    # each face gives a third of its area to each corner: the vertex areas add up to the area of the faces
    # kept (an identity), a zero-area face gives nothing, and they come from the pass of the vertex normals
    sphere = shapes.icosphere(6)
    vertices = sphere.vertices.copy()
    faces = np.asarray(sphere.faces)
    vertices[faces[0, 1]] = vertices[faces[0, 0]]  # face 0 (and its neighbour across that side) of zero area
    mesh = _prepared.prepare_mesh(vertices, faces, orient="keep", weld=False)
    areas = np.linalg.norm(mesh.cross, axis=1) / 2
    assert mesh.dropped.sum() == 2 and not mesh.vertex_areas.flags.writeable
    np.testing.assert_allclose(mesh.vertex_areas.sum(), areas[~mesh.dropped].sum(), rtol=1e-12)
    np.testing.assert_allclose(mesh.vertex_areas.sum(), 4 * np.pi, rtol=0.05)  # inscribed in the unit sphere
    backends = ("numpy", "numba") if importlib.util.find_spec("numba") else ("numpy",)
    for backend in backends:
        with use_backend(backend):
            again = _prepared.prepare_mesh(vertices, faces, orient="keep", weld=False)
            np.testing.assert_allclose(again.vertex_areas, mesh.vertex_areas, rtol=1e-14)
            np.testing.assert_allclose(again.vertex_normals, mesh.vertex_normals, rtol=1e-14, equal_nan=True)


@pytest.mark.parametrize("method", ["icc", "normal_cycle", "matgeom"])
def test_the_length_scales_and_needle_vertices_are_found_once_per_call(method, monkeypatch):
    # the orientation, the defects, the radius rules and the diagnosis all read them (10 and 7 passes before)
    sphere = shapes.icosphere(6)
    vertices = sphere.vertices.copy()
    vertices[5] *= 10.0  # a needle: the scale rules leave it out, the defects mark it
    from meshcurv import _geometry, defects

    needles = _counted(monkeypatch, defects, "_needle_vertices")
    scales = _counted(monkeypatch, _geometry, "_vertex_length_scales")
    with pytest.warns(meshcurv.MeshQualityWarning, match="1 needle vertices"):
        result = meshcurv.principal_curvatures(vertices, sphere.faces, method=method)
    assert (len(needles), len(scales)) == (1, 1)
    assert result.invalid_reason[5] == defects.NEEDLE


def test_a_derived_array_is_shared_only_for_the_adopted_vertices_topology_and_inputs():
    from meshcurv import _once
    from meshcurv._geometry import vertex_length_scales
    from meshcurv.defects import needle_vertices

    sphere = shapes.icosphere(4)
    vertices = sphere.vertices.copy()
    vertices[3] *= 10.0
    topology = MeshTopology.from_faces(sphere.faces, len(vertices))
    scales = vertex_length_scales(vertices, topology)
    alone = needle_vertices(vertices, topology, scales)
    assert np.flatnonzero(alone).tolist() == [3]
    assert needle_vertices(vertices, topology, scales) is not alone  # no scope: computed each time
    with _once.computed_once():
        _once.adopt(vertices)
        shared = vertex_length_scales(vertices, topology)
        assert vertex_length_scales(vertices, topology) is shared and shared.flags.writeable  # kernels take it
        first = needle_vertices(vertices, topology, shared)
        assert needle_vertices(vertices, topology, shared) is first and not first.flags.writeable
        np.testing.assert_array_equal(first, alone)
        # other scales, another topology of the same faces, other vertices: not the remembered array
        assert needle_vertices(vertices, topology, 1e3 * shared) is not first
        assert not needle_vertices(vertices, topology, 1e3 * shared).any()  # every edge within reach
        other = MeshTopology.from_faces(sphere.faces, len(vertices))
        assert needle_vertices(vertices, other, vertex_length_scales(vertices, other)) is not first
        moved = sphere.vertices.copy()
        assert not needle_vertices(moved, topology, vertex_length_scales(moved, topology)).any()
    assert needle_vertices(vertices, topology, shared) is not first  # the scope closed


def test_a_call_inside_another_keeps_the_outer_calls_derived_arrays():
    from meshcurv import _once
    from meshcurv._geometry import vertex_length_scales

    sphere = shapes.icosphere(4)
    topology = MeshTopology.from_faces(sphere.faces, len(sphere.vertices))
    outer = sphere.vertices.copy()
    with _once.computed_once():
        _once.adopt(outer)
        shared = vertex_length_scales(outer, topology)
        inner = 2.0 * sphere.vertices
        with _once.computed_once():
            _once.adopt(inner)
            doubled = vertex_length_scales(inner, topology)
            assert vertex_length_scales(inner, topology) is doubled
            np.testing.assert_allclose(doubled, 2.0 * shared, rtol=1e-15)  # lengths scale with the vertices
        assert vertex_length_scales(outer, topology) is shared
