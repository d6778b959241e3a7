"""Mesh objects of trimesh, PyVista, meshio and Open3D passed as they are (duck typing)."""

import types
import warnings

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
    split = pv.PolyData(
        SPHERE.vertices[corners],
        np.c_[np.full(SPHERE.faces.shape[0], 3), np.arange(corners.size).reshape(-1, 3)].ravel(),
    )
    with pytest.warns(meshcurv.MeshQualityWarning, match="welded"):
        r = meshcurv.principal_curvatures(split)
    np.testing.assert_allclose(r.k_max, reference().k_max[corners], rtol=1e-9)  # vertex order differs: round-off


def test_pyvista_triangle_strips_are_their_triangles():
    # `PolyData.strip()` (and VTK files written from it) hold triangle strips and no polygons: the same surface
    pv = pytest.importorskip("pyvista")
    flat = np.c_[np.full(SPHERE.faces.shape[0], 3), SPHERE.faces].ravel()
    stripped = pv.PolyData(SPHERE.vertices, flat).strip()
    assert stripped.n_strips > 0 and np.asarray(stripped.faces).size == 0
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the joins of strips are no faces: no warning about degenerate faces
        result = meshcurv.principal_curvatures(stripped)
    np.testing.assert_allclose(result.k_min, reference().k_min, rtol=1e-9)  # the faces in another order
    np.testing.assert_allclose(result.k_max, reference().k_max, rtol=1e-9)
    # a strip's triangles face its side: every other one wound the other way round, as VTK's
    ours = meshcurv._adapters._strip_triangles(np.array([5, 0, 1, 2, 3, 4]))
    np.testing.assert_array_equal(ours, [[0, 1, 2], [2, 1, 3], [2, 3, 4]])
    # strips beside polygons: both kept
    half = SPHERE.faces.shape[0] // 2
    mixed = pv.PolyData(SPHERE.vertices, np.c_[np.full(half, 3), SPHERE.faces[:half]].ravel())
    mixed.strips = np.c_[np.full(SPHERE.faces.shape[0] - half, 3), SPHERE.faces[half:]].ravel()
    np.testing.assert_allclose(meshcurv.principal_curvatures(mixed).k_max, reference().k_max, rtol=1e-9)


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
    mesh = o3d.geometry.TriangleMesh(
        o3d.utility.Vector3dVector(SPHERE.vertices), o3d.utility.Vector3iVector(SPHERE.faces)
    )
    same(meshcurv.principal_curvatures(mesh))


def polydata():
    pv = pytest.importorskip("pyvista")
    return pv.PolyData(SPHERE.vertices, np.c_[np.full(SPHERE.faces.shape[0], 3), SPHERE.faces].ravel())


def test_pyvista_unstructured_grid_of_triangles():
    same(meshcurv.principal_curvatures(polydata().cast_to_unstructured_grid()))


@pytest.mark.parametrize("suffix", [".vtu", ".vtk"])
def test_our_own_vtu_and_vtk_outputs_read_back_by_pyvista(tmp_path, suffix):
    pv = pytest.importorskip("pyvista")
    pytest.importorskip("meshio")
    path = tmp_path / f"sphere{suffix}"
    meshcurv.io.write_curvatures(path, SPHERE.vertices, SPHERE.faces, reference())
    grid = pv.read(path)
    assert type(grid).__name__ == "UnstructuredGrid"
    same(meshcurv.principal_curvatures(grid))


def test_pyvista_unstructured_grid_of_quads_pixels_triangles_and_lines():
    pv = pytest.importorskip("pyvista")
    torus = shapes.torus(3.0, 1.0, 64, 32)
    quads = np.asarray(torus.quads)
    expected = meshcurv.principal_curvatures(torus.vertices, torus.faces)
    # a pixel's corners run 0, 1, 3, 2; lines and vertices are left out, as a PolyData's are
    cells = {
        pv.CellType.QUAD: quads[:-2],
        pv.CellType.PIXEL: quads[-2:-1, [0, 1, 3, 2]],
        pv.CellType.TRIANGLE: np.array([quads[-1, :3], quads[-1, [0, 2, 3]]]),
        pv.CellType.LINE: quads[:4, :2],
        pv.CellType.VERTEX: quads[:2, :1],
    }
    with pytest.warns(meshcurv.TriangulationWarning):
        result = meshcurv.principal_curvatures(pv.UnstructuredGrid(cells, torus.vertices))
    # the same triangles as the torus's own split of its quads (a, b, c), (a, c, d)
    np.testing.assert_allclose(result.k_max, expected.k_max, rtol=1e-9, atol=1e-12)
    assert np.median(np.abs(result.mean - torus.mean)) < 0.02
    # all quads and a pixel: one (F, 4) array
    grid = pv.UnstructuredGrid(
        {pv.CellType.QUAD: quads[1:], pv.CellType.PIXEL: quads[:1, [0, 1, 3, 2]]}, torus.vertices
    )
    with pytest.warns(meshcurv.TriangulationWarning):
        result = meshcurv.principal_curvatures(grid)
    np.testing.assert_allclose(result.k_max, expected.k_max, rtol=1e-9, atol=1e-12)


def test_pyvista_unstructured_grid_of_volume_cells_is_refused():
    pv = pytest.importorskip("pyvista")
    tetra = pv.UnstructuredGrid(
        {pv.CellType.TETRA: np.array([[0, 1, 2, 3], [1, 2, 3, 4]]), pv.CellType.TRIANGLE: np.array([[0, 1, 2]])},
        np.r_[np.eye(4, 3), [[1, 1, 1]]],
    )
    with pytest.raises(
        InvalidMeshError,
        match=r"the UnstructuredGrid has cells that are not surface polygons "
        r"\(2 tetra\); .*`grid.extract_surface\(\).triangulate\(\)`",
    ):
        meshcurv.principal_curvatures(tetra)
    lines = pv.UnstructuredGrid({pv.CellType.LINE: np.array([[0, 1], [1, 2]])}, np.eye(3))
    with pytest.raises(InvalidMeshError, match=r"the UnstructuredGrid has no surface cells .* it has 2 line"):
        meshcurv.principal_curvatures(lines)
    with warnings.catch_warnings():  # PyVista >= 0.47 warns that the default `algorithm` will change
        warnings.simplefilter("ignore")
        surface = tetra.extract_surface().triangulate()  # what the message suggests works
    with pytest.warns(meshcurv.MeshQualityWarning):  # the two tetrahedra's surface is coarse, not clean
        meshcurv.principal_curvatures(surface, method="normal_cycle")


def test_a_point_object_without_faces_is_sent_to_the_point_cloud_function():
    stand_in = types.SimpleNamespace(points=SPHERE.vertices)
    with pytest.raises(
        InvalidMeshError,
        match="`vertices` is a SimpleNamespace, which has points but no faces; "
        "for a point cloud use meshcurv.point_cloud_curvatures",
    ):
        meshcurv.principal_curvatures(stand_in)


# ------------------------------------------------------------------------------- point clouds in


CLOUD = shapes.icosphere(24, radius=2.0).vertices  # 5762 points on a sphere of radius 2


def cloud_reference():
    return meshcurv.point_cloud_curvatures(CLOUD)


def same_cloud(result):
    expected = cloud_reference()
    np.testing.assert_array_equal(result.k_max, expected.k_max)
    assert np.median(result.mean) == pytest.approx(0.5, rel=2e-2)


def test_point_clouds_from_pyvista_objects():
    pv = pytest.importorskip("pyvista")
    same_cloud(meshcurv.point_cloud_curvatures(pv.PolyData(CLOUD)))
    same_cloud(meshcurv.point_cloud_curvatures(pv.PointSet(CLOUD)))
    same_cloud(meshcurv.point_cloud_curvatures(pv.PolyData(CLOUD).cast_to_unstructured_grid()))


def test_point_clouds_from_trimesh_objects_and_duck_types():
    trimesh = pytest.importorskip("trimesh")
    same_cloud(meshcurv.point_cloud_curvatures(trimesh.PointCloud(CLOUD)))
    sphere = shapes.icosphere(24, radius=2.0)
    same_cloud(meshcurv.point_cloud_curvatures(trimesh.Trimesh(sphere.vertices, sphere.faces, process=False)))
    same_cloud(meshcurv.point_cloud_curvatures(types.SimpleNamespace(points=CLOUD.tolist())))  # open3d, meshio
    same_cloud(meshcurv.point_cloud_curvatures(types.SimpleNamespace(vertices=CLOUD)))


def test_an_unknown_point_object_is_refused_with_a_clear_message():
    with pytest.raises(
        InvalidMeshError,
        match=r"`points` is a dict, not an array of shape \(N, 3\), nor an object "
        r"with a `.points` or `.vertices` array",
    ):
        meshcurv.point_cloud_curvatures({"x": 1})


def test_an_unknown_object_is_refused_with_a_clear_message():
    with pytest.raises(InvalidMeshError, match="`vertices` is a dict, not an array, and not a mesh object"):
        meshcurv.principal_curvatures({"points": 1})


# ------------------------------------------------------------------------------------ results out


SCALARS = ("k_min", "k_max", "mean", "gaussian", "shape_index", "curvedness")


def test_to_pyvista_copies_the_polydata_and_adds_every_field():
    pv = pytest.importorskip("pyvista")
    flat = np.c_[np.full(SPHERE.faces.shape[0], 3), SPHERE.faces].ravel()
    mesh = pv.PolyData(SPHERE.vertices, flat)
    mesh.point_data["label"] = np.arange(mesh.n_points)
    r = meshcurv.principal_curvatures(mesh)
    out = r.to_pyvista(mesh)
    assert out is not mesh and list(mesh.point_data) == ["label"]  # the input is not changed
    assert set(out.point_data) == {"label", *SCALARS, "dir_min", "dir_max", "normals", "valid", "radius"}
    for name in SCALARS:
        np.testing.assert_array_equal(out.point_data[name], getattr(r, name))
    np.testing.assert_array_equal(out.point_data["dir_max"], r.dir_max)
    np.testing.assert_array_equal(out.point_data["valid"], r.valid.astype(np.uint8))
    np.testing.assert_array_equal(out.points, SPHERE.vertices)
    # the mesh the result keeps, and a (vertices, faces) pair, give the same cells
    for other in (r.to_pyvista(), r.to_pyvista((SPHERE.vertices, SPHERE.faces), fields=["mean"])):
        np.testing.assert_array_equal(other.faces, out.faces)
        np.testing.assert_array_equal(other.point_data["mean"], r.mean)


def test_to_pyvista_polygons_and_errors():
    pv = pytest.importorskip("pyvista")
    quads = shapes.torus(n_major=12, n_minor=8)
    quad_faces = np.asarray(quads.quads)
    r = meshcurv.principal_curvatures(quads.vertices, quads.faces)
    out = r.to_pyvista((quads.vertices, quad_faces))
    assert out.n_cells == quad_faces.shape[0] and out.faces[0] == 4
    mixed = [list(face) for face in quad_faces[:-1]] + [list(quad_faces[-1, :3]), list(quad_faces[-1, [0, 2, 3]])]
    assert r.to_pyvista((quads.vertices, mixed)).n_cells == quad_faces.shape[0] + 1
    with pytest.raises(InvalidMeshError, match=r"to_pyvista: the mesh has 3 vertices but the result 96 rows"):
        r.to_pyvista((np.zeros((3, 3)), [[0, 1, 2]]))
    soup = SPHERE.vertices[SPHERE.faces].reshape(-1, 3)
    with pytest.warns(meshcurv.MeshQualityWarning, match="welded"):
        welded = meshcurv.principal_curvatures(soup, np.arange(soup.shape[0]).reshape(-1, 3))
    with pytest.raises(
        InvalidMeshError, match="to_pyvista: pass the mesh the result was computed on; its mesh was welded"
    ):
        welded.to_pyvista()
    assert pv.PolyData  # the module was there: the errors above are meshcurv's


def test_to_trimesh_vertex_attributes():
    trimesh = pytest.importorskip("trimesh")
    mesh = trimesh.Trimesh(SPHERE.vertices, SPHERE.faces, process=False)
    r = meshcurv.principal_curvatures(mesh)
    out = r.to_trimesh(mesh)
    assert out is not mesh and mesh.vertex_attributes == {}
    for name in SCALARS:
        np.testing.assert_array_equal(out.vertex_attributes[name], getattr(r, name))
    assert out.vertex_attributes["normals"].shape == (SPHERE.vertices.shape[0], 3)
    built = r.to_trimesh((SPHERE.vertices, SPHERE.faces), fields=["gaussian"])
    assert list(built.vertex_attributes) == ["gaussian"]
    np.testing.assert_array_equal(built.vertices, SPHERE.vertices)  # process=False: order kept
    np.testing.assert_array_equal(built.faces, SPHERE.faces)


def test_to_dataframe_one_row_per_vertex():
    pd = pytest.importorskip("pandas")
    r = reference()
    frame = r.to_dataframe()
    assert isinstance(frame, pd.DataFrame) and len(frame) == SPHERE.vertices.shape[0]
    assert list(frame.columns) == [
        *SCALARS,
        "dir_min_x",
        "dir_min_y",
        "dir_min_z",
        "dir_max_x",
        "dir_max_y",
        "dir_max_z",
        "normals_x",
        "normals_y",
        "normals_z",
        "valid",
        "radius",
        "vertex_area",
    ]
    assert frame["valid"].dtype == bool
    np.testing.assert_array_equal(frame["normals_y"], r.normals[:, 1])
    corners = SPHERE.vertices[SPHERE.faces]
    area = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1).sum()
    assert frame["vertex_area"].sum() == pytest.approx(area, rel=1e-12)
    assert list(r.to_dataframe(fields=["mean"]).columns) == ["mean"]


@pytest.mark.parametrize(
    "method, module", [("to_pyvista", "pyvista"), ("to_trimesh", "trimesh"), ("to_dataframe", "pandas")]
)
def test_missing_library_names_what_to_install(monkeypatch, method, module):
    import sys

    r = reference()
    monkeypatch.setitem(sys.modules, module, None)  # as if not installed: importing it raises ImportError
    with pytest.raises(meshcurv.errors.MissingDependencyError, match=f"{method} needs {module}: pip install {module}"):
        getattr(r, method)()
