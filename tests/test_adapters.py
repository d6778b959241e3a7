"""Mesh objects of trimesh, PyVista, meshio and Open3D passed as they are (duck typing)."""

import types

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes
from meshcurv.errors import InvalidMeshError

SPHERE = shapes.icosphere(8, radius=2.0)


def reference():
    return meshcurv.principal_curvatures(SPHERE.vertices, SPHERE.faces)


def same(result):
    expected = reference()
    np.testing.assert_allclose(result.k_min, expected.k_min, rtol=1e-12)
    np.testing.assert_allclose(result.k_max, expected.k_max, rtol=1e-12)
    assert np.median(result.mean) == pytest.approx(0.5, rel=1e-3)


def test_trimesh():
    trimesh = pytest.importorskip("trimesh")
    same(meshcurv.principal_curvatures(trimesh.Trimesh(SPHERE.vertices, SPHERE.faces, process=False)))


def test_pyvista_polydata_and_its_split_corners():
    pv = pytest.importorskip("pyvista")
    flat = np.c_[np.full(SPHERE.faces.shape[0], 3), SPHERE.faces].ravel()
    same(meshcurv.principal_curvatures(pv.PolyData(SPHERE.vertices, flat)))
    # what pyvista.read makes of an OBJ with normals: every corner its own point (welded back, same values)
    corners = SPHERE.faces.ravel()
    split = pv.PolyData(SPHERE.vertices[corners], np.c_[np.full(SPHERE.faces.shape[0], 3),
                                                        np.arange(corners.size).reshape(-1, 3)].ravel())
    with pytest.warns(meshcurv.MeshQualityWarning, match="welded"):
        r = meshcurv.principal_curvatures(split)
    np.testing.assert_allclose(r.k_max, reference().k_max[corners], rtol=1e-9)  # vertex order differs: round-off


def test_meshio_mesh_with_triangles_and_quads():
    meshio = pytest.importorskip("meshio")
    same(meshcurv.principal_curvatures(meshio.Mesh(SPHERE.vertices, [("triangle", SPHERE.faces)])))
    lines = meshio.Mesh(SPHERE.vertices, [("line", SPHERE.faces[:, :2])])
    with pytest.raises(InvalidMeshError, match="the meshio mesh has no surface cells .* it has line"):
        meshcurv.principal_curvatures(lines)


def test_open3d_triangle_mesh():
    # Open3D's TriangleMesh exposes .vertices and .triangles (Vector3dVector/Vector3iVector, array-like)
    stand_in = types.SimpleNamespace(vertices=SPHERE.vertices.tolist(), triangles=SPHERE.faces.tolist())
    same(meshcurv.principal_curvatures(stand_in))
    o3d = pytest.importorskip("open3d")
    mesh = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(SPHERE.vertices),
                                     o3d.utility.Vector3iVector(SPHERE.faces))
    same(meshcurv.principal_curvatures(mesh))


def test_an_unknown_object_is_refused_with_a_clear_message():
    with pytest.raises(InvalidMeshError, match="`vertices` is a dict, not an array, and not a mesh object"):
        meshcurv.principal_curvatures({"points": 1})
