"""meshcurv.read_mesh / write_mesh: round trips, third-party readers, and every error path."""

import base64
import dataclasses
import builtins
import logging
import pathlib

import numpy as np
import pytest

import meshcurv
from meshcurv.errors import InvalidMeshError, InvalidOptionError, MeshFileError, MissingDependencyError
from meshcurv.io import FORMATS, Mesh, write_curvatures
from meshcurv.io.fields import curvature_fields

MESHES = (
    pathlib.Path(__file__).resolve().parents[1].parent / "shared" / "meshes"
)  # ../shared beside the repository; tests skip when absent
MESH_FORMATS = [".obj", ".ply", ".stl", ".off", ".vtk", ".vtu", ".vtp", ".npz"]
FIELD_FORMATS = [".ply", ".vtk", ".vtu", ".vtp", ".npz"]
MESHIO_FORMATS = {".ply", ".stl", ".vtk", ".vtu"}


def needs(extension):
    if extension in MESHIO_FORMATS:
        pytest.importorskip("meshio")


@pytest.fixture
def torus():
    return meshcurv.shapes.torus(n_major=12, n_minor=8)


def triangle_set(vertices, faces):
    """The triangles as sorted tuples of corner coordinates: equal for any vertex numbering."""
    corners = np.round(vertices[np.asarray(faces)], 12)
    return sorted(map(tuple, np.sort(corners.reshape(len(faces), 3, 3).tolist(), axis=1).reshape(len(faces), 9)))


# ---------------------------------------------------------------- round trips


@pytest.mark.parametrize("binary", [True, False])
@pytest.mark.parametrize("extension", MESH_FORMATS)
def test_round_trip_keeps_the_mesh_and_leaves_the_input_unchanged(tmp_path, torus, extension, binary):
    needs(extension)
    vertices, faces = torus.vertices.copy(), torus.faces.copy()
    path = meshcurv.write_mesh(tmp_path / f"torus{extension}", vertices, faces, binary=binary)
    np.testing.assert_array_equal(vertices, torus.vertices)
    np.testing.assert_array_equal(faces, torus.faces)
    mesh = meshcurv.read_mesh(path)
    assert isinstance(mesh, Mesh)
    read_vertices, read_faces = mesh
    assert read_vertices.dtype == np.float64 and read_faces.dtype == np.int64
    if extension == ".stl":  # STL stores every facet's corners: meshio merges them again
        assert read_vertices.shape == vertices.shape
        tolerance = 1e-6 * np.abs(vertices).max()  # STL coordinates are float32
        assert triangle_set(np.round(read_vertices / tolerance), read_faces) == triangle_set(
            np.round(vertices / tolerance), faces
        )
    else:
        np.testing.assert_array_equal(read_vertices, vertices)
        np.testing.assert_array_equal(read_faces, faces)
    assert [p.name for p in tmp_path.iterdir()] == [path.name]  # no temporary left behind


@pytest.mark.parametrize("extension", [".obj", ".ply", ".off", ".vtu", ".vtp", ".npz"])
def test_quads_and_mixed_polygons_round_trip(tmp_path, torus, extension):
    needs(extension)
    quads = torus.quads
    meshcurv.write_mesh(tmp_path / f"quads{extension}", torus.vertices, quads)
    np.testing.assert_array_equal(meshcurv.read_mesh(tmp_path / f"quads{extension}").faces, quads)
    mixed = [quads[0], quads[1, :3], np.array([2, 3, 11, 10, 1])]
    meshcurv.write_mesh(tmp_path / f"mixed{extension}", torus.vertices, mixed)
    read = meshcurv.read_mesh(tmp_path / f"mixed{extension}").faces
    assert sorted(map(tuple, read)) == sorted(map(tuple, mixed))


@pytest.mark.parametrize("extension", FIELD_FORMATS)
def test_point_data_round_trips(tmp_path, torus, extension):
    needs(extension)
    result = meshcurv.principal_curvatures(torus.vertices, torus.faces)
    fields = curvature_fields(result)
    write_curvatures(tmp_path / f"k{extension}", torus.vertices, torus.faces, result)
    stored = _read_point_data(tmp_path / f"k{extension}")
    if extension == ".ply":  # float properties: float32, vectors split into components
        np.testing.assert_allclose(stored["k_min"], result.k_min, rtol=1e-6)
        np.testing.assert_allclose(stored["quality"], result.mean, rtol=1e-6)
        np.testing.assert_allclose(
            np.column_stack([stored["nx"], stored["ny"], stored["nz"]]), result.normals, rtol=1e-6, atol=1e-7
        )
        np.testing.assert_allclose(stored["dir_max_z"], result.dir_max[:, 2], rtol=1e-6, atol=1e-7)
        assert stored["k_max"].dtype == np.float32
    else:
        for name, value in fields.items():
            np.testing.assert_array_equal(stored[name], value, err_msg=name)


def _read_point_data(path):
    if path.suffix == ".npz":
        return dict(np.load(path))
    if path.suffix == ".vtp":
        return _read_vtp_point_data(path)
    import meshio

    return meshio.read(path).point_data


def _read_vtp_point_data(path):
    import xml.etree.ElementTree as ElementTree

    out = {}
    for element in ElementTree.parse(path).getroot().iter("DataArray"):
        if element.get("Name") and element.get("Name") not in ("connectivity", "offsets"):
            text = element.text.strip()
            data = base64.b64decode(text[12:])  # after the base64 UInt64 byte count
            dtype = {"Float64": "<f8", "UInt8": "u1"}[element.get("type")]
            values = np.frombuffer(data, dtype)
            components = int(element.get("NumberOfComponents", 1))
            out[element.get("Name")] = values.reshape(-1, components) if components > 1 else values
    return out


def test_csv_has_one_row_per_vertex_with_named_columns(tmp_path, torus):
    result = meshcurv.principal_curvatures(torus.vertices, torus.faces)
    write_curvatures(tmp_path / "k.csv", torus.vertices, torus.faces, result, fields=["k_min", "normals", "valid"])
    table = np.genfromtxt(tmp_path / "k.csv", delimiter=",", names=True)
    assert table.dtype.names == (
        "vertex",
        "x",
        "y",
        "z",
        "k_min",
        "normals_x",
        "normals_y",
        "normals_z",
        "valid",
        "quality",
    )
    np.testing.assert_array_equal(table["vertex"], np.arange(96))
    np.testing.assert_array_equal(table["z"], torus.vertices[:, 2])
    np.testing.assert_array_equal(table["k_min"], result.k_min)
    np.testing.assert_array_equal(table["quality"], result.mean)
    with pytest.raises(MeshFileError, match=r"k\.csv: CSV table files hold per-vertex values, not a mesh"):
        meshcurv.read_mesh(tmp_path / "k.csv")


# ---------------------------------------------------------------- third-party readers


def test_ply_fields_read_by_trimesh(tmp_path, torus):
    trimesh = pytest.importorskip("trimesh")
    pytest.importorskip("meshio")
    result = meshcurv.principal_curvatures(torus.vertices, torus.faces)
    write_curvatures(tmp_path / "k.ply", torus.vertices, torus.faces, result)
    loaded = trimesh.load(tmp_path / "k.ply", process=False)
    np.testing.assert_allclose(loaded.vertices, torus.vertices, rtol=1e-12)
    np.testing.assert_array_equal(loaded.faces, torus.faces)
    properties = loaded.metadata["_ply_raw"]["vertex"]["data"]
    for name in (
        "k_min",
        "k_max",
        "mean",
        "gaussian",
        "shape_index",
        "curvedness",
        "quality",
        "nx",
        "dir_min_x",
        "dir_max_z",
        "valid",
    ):
        assert name in properties.dtype.names, name
    np.testing.assert_allclose(properties["k_max"], result.k_max, rtol=1e-6)
    np.testing.assert_allclose(properties["quality"], result.mean, rtol=1e-6)


@pytest.mark.parametrize("extension", [".obj", ".stl", ".off"])
def test_plain_meshes_read_by_trimesh(tmp_path, torus, extension):
    trimesh = pytest.importorskip("trimesh")
    needs(extension)
    meshcurv.write_mesh(tmp_path / f"t{extension}", torus.vertices, torus.faces)
    loaded = trimesh.load(tmp_path / f"t{extension}", process=extension == ".stl", force="mesh")
    assert loaded.vertices.shape == torus.vertices.shape and loaded.faces.shape == torus.faces.shape
    assert loaded.is_watertight and loaded.euler_number == 0  # a torus: closed, genus 1


@pytest.mark.parametrize("extension", [".vtk", ".vtu"])
def test_vtk_vectors_read_by_meshio(tmp_path, torus, extension):
    meshio = pytest.importorskip("meshio")
    result = meshcurv.principal_curvatures(torus.vertices, torus.faces)
    write_curvatures(tmp_path / f"k{extension}", torus.vertices, torus.faces, result)
    loaded = meshio.read(tmp_path / f"k{extension}")
    np.testing.assert_array_equal(loaded.cells_dict["triangle"], torus.faces)
    assert loaded.point_data["normals"].shape == (96, 3)
    np.testing.assert_array_equal(loaded.point_data["dir_max"], result.dir_max)
    np.testing.assert_array_equal(loaded.point_data["gaussian"], result.gaussian)


def test_vtp_read_by_vtk(tmp_path, torus):
    vtk = pytest.importorskip("vtk")
    from vtk.util.numpy_support import vtk_to_numpy

    result = meshcurv.principal_curvatures(torus.vertices, torus.faces)
    write_curvatures(tmp_path / "k.vtp", torus.vertices, torus.faces, result)
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(str(tmp_path / "k.vtp"))
    reader.Update()
    polydata = reader.GetOutput()
    assert polydata.GetNumberOfPoints() == 96 and polydata.GetNumberOfPolys() == 192
    np.testing.assert_array_equal(vtk_to_numpy(polydata.GetPointData().GetArray("k_min")), result.k_min)
    np.testing.assert_array_equal(vtk_to_numpy(polydata.GetPointData().GetArray("dir_min")), result.dir_min)


# ---------------------------------------------------------------- reading real and hand-written files


def test_spot_with_vertex_texture_corners_reads_as_one_closed_surface():
    if not (MESHES / "spot.obj").exists():
        pytest.skip("shared meshes not available")
    vertices, faces = meshcurv.read_mesh(MESHES / "spot.obj")
    assert vertices.shape == (2930, 3) and faces.shape == (5856, 3)
    topology = meshcurv.MeshTopology.from_faces(faces, vertices.shape[0])
    assert not topology.boundary_edges.any()


def write_text(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_obj_comments_normals_texture_polygons_and_relative_indices(tmp_path):
    path = write_text(
        tmp_path,
        "square.obj",
        """# a comment
# another
o square
v 0 0 0 1.0
v 1 0 0 0.5 0.5 0.5
  v 1 1 0
v 0 1 0
vt 0 0
vn 0 0 1
f 1/1/1 2/1/1 3/1/1 # inline comment
f -4 -2 -1
""",
    )
    vertices, faces = meshcurv.read_mesh(path)
    np.testing.assert_array_equal(vertices, [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    np.testing.assert_array_equal(faces, [[0, 1, 2], [0, 2, 3]])
    path = write_text(tmp_path, "mixed.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nf 1 2 3 4\nf 2  5 3\n")
    assert [f.tolist() for f in meshcurv.read_mesh(path).faces] == [[0, 1, 2, 3], [1, 4, 2]]


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n", "line 2: a `v` line has fewer than 3 coordinates"),
        ("v 0 0 0\nv 1 x 0\nv 0 1 0\nf 1 2 3\n", "a vertex coordinate is not a number"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\n", r"no faces \(`f` lines\) found"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3.5\n", "a face index is not an integer"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\nf 1 2 3 1\n", "a face has fewer than 3 corners"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "a face uses vertex index 0; OBJ indices start at 1"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", "a face uses vertex 4 but the file has 3 vertices"),
        ("v 0 0 0\nv 1 0 nan\nv 0 1 0\nf 1 2 3\n", "NaN or infinite coordinates"),
        ("solid x\nfacet normal 0 0 1\nendsolid x\n", r"no vertices \(`v` lines\) found; is it an OBJ file\?"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf\t1 2 3\nf 2\n", "a face has fewer than 3 corners"),
    ],
)
def test_bad_obj_files_name_the_file_and_the_problem(tmp_path, text, message):
    path = write_text(tmp_path, "bad.obj", text)
    with pytest.raises(MeshFileError, match=rf"bad\.obj: .*{message}"):
        meshcurv.read_mesh(path)


def test_missing_directory_empty_and_unknown_files(tmp_path):
    with pytest.raises(MeshFileError, match=r"nothere\.obj: no such file"):
        meshcurv.read_mesh(tmp_path / "nothere.obj")
    (tmp_path / "folder.obj").mkdir()
    with pytest.raises(MeshFileError, match=r"folder\.obj: is a directory, not a mesh file"):
        meshcurv.read_mesh(tmp_path / "folder.obj")
    with pytest.raises(MeshFileError, match=r"empty\.ply: the file is empty"):
        meshcurv.read_mesh(write_text(tmp_path, "empty.ply", ""))
    with pytest.raises(
        MeshFileError,
        match=r"x\.dxf: unknown mesh file extension '\.dxf'; known formats: \.obj, "
        r"\.ply, \.stl, \.off, \.vtk, \.vtu, \.vtp, \.csv, \.npz",
    ):
        meshcurv.read_mesh(write_text(tmp_path, "x.dxf", "0\nSECTION\n"))
    with pytest.raises(MeshFileError, match="unknown mesh file format 'dxf'"):
        meshcurv.read_mesh(tmp_path / "x.obj", file_format="dxf")
    with pytest.raises(MeshFileError, match="unknown mesh file no extension"):
        meshcurv.write_mesh(tmp_path / "noext", [[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])


def test_unreadable_file_is_a_mesh_file_error(tmp_path, monkeypatch):
    path = write_text(tmp_path, "locked.obj", "v 0 0 0\n")
    monkeypatch.setattr("os.access", lambda *args: False)
    with pytest.raises(MeshFileError, match=r"locked\.obj: permission denied"):
        meshcurv.read_mesh(path)


def test_os_errors_while_reading_and_writing_become_mesh_file_errors(tmp_path, monkeypatch, torus):
    path = meshcurv.write_mesh(tmp_path / "t.obj", torus.vertices, torus.faces)

    def fails(*args, **kwargs):
        raise IsADirectoryError(21, "Is a directory")

    monkeypatch.setitem(FORMATS, ".obj", dataclasses.replace(FORMATS[".obj"], read=fails, write=fails))
    with pytest.raises(MeshFileError, match=r"t\.obj: Is a directory"):
        meshcurv.read_mesh(path)
    with pytest.raises(MeshFileError, match=r"u\.obj: cannot be written \(Is a directory\)"):
        meshcurv.write_mesh(tmp_path / "u.obj", torus.vertices, torus.faces)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.obj"]  # the temporary was removed


@pytest.mark.parametrize("extension", [".ply", ".stl", ".vtk", ".vtu", ".off"])
def test_truncated_and_mislabelled_files_are_mesh_file_errors(tmp_path, torus, extension):
    needs(extension)
    path = meshcurv.write_mesh(tmp_path / f"t{extension}", torus.vertices, torus.faces)
    data = path.read_bytes()
    truncated = tmp_path / f"truncated{extension}"
    truncated.write_bytes(data[: len(data) // 2])
    with pytest.raises(MeshFileError, match=rf"truncated\{extension}: "):
        meshcurv.read_mesh(truncated)
    mislabelled = tmp_path / f"mislabelled{extension}"
    mislabelled.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")  # an OBJ under another name
    with pytest.raises(MeshFileError, match=rf"mislabelled\{extension}: "):
        meshcurv.read_mesh(mislabelled)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n", "the header announces 4 vertices; the file has 3"),
        ("OFF\n3 x 0\n", "the OFF counts, vertices or faces cannot be read"),
        (
            "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n3 0 1\n",
            r"line 8: 3 values, expected 4 or more \(a count of 3",
        ),
        ("COFF\n3 1 0\n", "not an OFF file \\(it should start with 'OFF'; starts with 'COFF'\\)"),
    ],
)
def test_bad_off_files(tmp_path, text, message):
    with pytest.raises(MeshFileError, match=rf"bad\.off: {message}"):
        meshcurv.read_mesh(write_text(tmp_path, "bad.off", text))


def test_binary_ply_under_an_obj_name(tmp_path, torus):
    pytest.importorskip("meshio")
    path = meshcurv.write_mesh(tmp_path / "t.ply", torus.vertices, torus.faces)
    (tmp_path / "t.obj").write_bytes(path.read_bytes())
    with pytest.raises(MeshFileError, match=r"t\.obj: no vertices"):
        meshcurv.read_mesh(tmp_path / "t.obj")


def without_meshio(monkeypatch):
    """Make ``import meshio`` fail for the rest of the test."""
    real_import = builtins.__import__

    def no_meshio(name, *args, **kwargs):
        if name == "meshio":
            raise ImportError(name)
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_meshio)


def _ply_bytes(order, vertex_fields, vertex_rows, face_fields, face_rows, *, extra=""):
    """A binary PLY built by hand: header lines and numpy records of the given fields."""
    vertex_type = np.dtype([(name, order + kind) for name, kind, _ in vertex_fields])
    face_type = np.dtype(
        [(name, order + kind, shape) if shape else (name, order + kind) for name, kind, shape in face_fields]
    )
    names = {"f8": "double", "f4": "float", "u1": "uchar", "i4": "int", "u4": "uint", "i2": "short"}
    header = [
        "ply",
        f"format binary_{'little' if order == '<' else 'big'}_endian 1.0",
        "comment by hand",
        f"element vertex {len(vertex_rows)}",
    ]
    header += [f"property {names[kind]} {name}" for name, kind, _ in vertex_fields]
    header += [f"element face {len(face_rows)}"]
    for name, kind, _shape in face_fields:
        if name == "count":
            continue
        if name == "corners":
            header.append(f"property list uchar {names[kind]} vertex_indices")
        else:
            header.append(f"property {names[kind]} {name}")
    header += [line for line in extra.splitlines() if line] + ["end_header", ""]
    return (
        "\n".join(header).encode()
        + np.array(vertex_rows, vertex_type).tobytes()
        + np.array(face_rows, face_type).tobytes()
    )


def test_binary_ply_fast_path_reads_other_tools_layouts(tmp_path):
    """Big-endian, float32 coordinates among colour properties, face properties around uint corners."""
    from meshcurv.io import _ply

    quad = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.5], [1.0, 1.0, 0.25], [0.0, 1.0, 0.125]])
    vertex_fields = [("red", "u1", None), ("x", "f4", None), ("y", "f4", None), ("z", "f4", None), ("nx", "f4", None)]
    vertex_rows = [(200, *point, 1.0) for point in quad]
    face_fields = [("flags", "i2", None), ("count", "u1", None), ("corners", "u4", (3,)), ("quality", "f4", None)]
    triangles = [[0, 1, 2], [0, 2, 3]]
    for order in "<>":
        path = tmp_path / f"hand{order == '>'}.ply"
        path.write_bytes(
            _ply_bytes(
                order,
                vertex_fields,
                vertex_rows,
                face_fields,
                [(7, 3, corners, 0.5) for corners in triangles],
                extra="element edge 0\nproperty int vertex1",
            )
        )
        vertices, faces = _ply.read_ply(path)
        np.testing.assert_array_equal(vertices, quad)  # these coordinates are exact in float32
        assert faces.dtype == np.int64 and faces.tolist() == triangles
        mesh = meshcurv.read_mesh(path)
        np.testing.assert_array_equal(mesh.vertices, quad)
        assert mesh.faces.tolist() == triangles
    # quads stay quads, as meshio gives them
    path = tmp_path / "quad.ply"
    path.write_bytes(
        _ply_bytes(
            "<", vertex_fields, vertex_rows, [("count", "u1", None), ("corners", "i4", (4,))], [(4, [0, 1, 2, 3])]
        )
    )
    assert _ply.read_ply(path)[1].tolist() == [[0, 1, 2, 3]]


def test_binary_ply_fast_path_agrees_with_meshio_and_steps_aside_for_the_rest(tmp_path, torus):
    meshio = pytest.importorskip("meshio")
    from meshcurv.io import _ply

    path = meshcurv.write_mesh(
        tmp_path / "t.ply", torus.vertices, torus.faces, point_data={"k": np.arange(len(torus.vertices), dtype=float)}
    )
    vertices, faces = _ply.read_ply(path)
    reference = meshio.ply.read(str(path))
    np.testing.assert_array_equal(vertices, reference.points)
    np.testing.assert_array_equal(faces, reference.cells_dict["triangle"])
    np.testing.assert_array_equal(faces, torus.faces)
    # ASCII and faces of mixed sizes are read too, in file order; a truncated file is an error
    ascii_path = meshcurv.write_mesh(tmp_path / "a.ply", torus.vertices, torus.faces, binary=False)
    vertices, faces = _ply.read_ply(ascii_path)
    np.testing.assert_array_equal(faces, torus.faces)
    np.testing.assert_allclose(vertices, torus.vertices, rtol=1e-6)  # meshio writes ASCII floats short
    polygons = [[0, 1, 2, 3], *torus.faces[2:].tolist()]
    mixed = meshcurv.write_mesh(tmp_path / "m.ply", torus.vertices, polygons)
    read = meshcurv.read_mesh(mixed).faces  # meshio writes the triangles first, then the quad
    assert sorted(map(tuple, (face.tolist() for face in read))) == sorted(map(tuple, polygons))
    truncated = tmp_path / "cut.ply"
    truncated.write_bytes(path.read_bytes()[:-100])
    with pytest.raises(MeshFileError, match=r"cut\.ply: the PLY file ends inside its faces"):
        meshcurv.read_mesh(truncated)


def test_binary_ply_needs_no_meshio(tmp_path, monkeypatch, torus):
    pytest.importorskip("meshio")
    path = meshcurv.write_mesh(tmp_path / "t.ply", torus.vertices, torus.faces)
    without_meshio(monkeypatch)
    vertices, faces = meshcurv.read_mesh(path)
    np.testing.assert_array_equal(faces, torus.faces)


def test_volume_cells_only_is_an_error(tmp_path):
    meshio = pytest.importorskip("meshio")
    points = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
    meshio.write(tmp_path / "tet.vtu", meshio.Mesh(points, [("tetra", np.array([[0, 1, 2, 3]]))]))
    with pytest.raises(MeshFileError, match=r"tet\.vtu: the file has no surface faces .*cells found: tetra"):
        meshcurv.read_mesh(tmp_path / "tet.vtu")


def test_two_dimensional_points_get_z_zero(tmp_path):
    meshio = pytest.importorskip("meshio")
    points = np.array([[0, 0], [1, 0], [0, 1.0]])
    meshio.write(tmp_path / "flat.vtu", meshio.Mesh(points, [("triangle", np.array([[0, 1, 2]]))]))
    vertices, _ = meshcurv.read_mesh(tmp_path / "flat.vtu")
    np.testing.assert_array_equal(vertices[:, 2], 0)


def test_meshio_messages_go_to_the_log_not_the_terminal(tmp_path, torus, caplog, capfd):
    pytest.importorskip("meshio")
    from meshcurv.io import _meshio

    with caplog.at_level(logging.INFO, logger="meshcurv.io._meshio"):
        _meshio.write_with_meshio(
            tmp_path / "t.ply", torus.vertices, torus.faces, {"normals": torus.normals}, file_format="ply", binary=True
        )
    assert "meshio: Warning: PLY writer doesn't support multidimensional point data" in caplog.text
    assert capfd.readouterr().err == ""


def test_missing_meshio_names_the_extra(tmp_path, monkeypatch, torus):
    without_meshio(monkeypatch)
    with pytest.raises(MissingDependencyError, match=r"pip install 'meshcurv\[io\]'"):
        meshcurv.write_mesh(tmp_path / "t.ply", torus.vertices, torus.faces)


# ---------------------------------------------------------------- VTP and NPZ errors


def test_bad_vtp_files(tmp_path, torus):
    with pytest.raises(MeshFileError, match=r"a\.vtp: not a VTK XML file"):
        meshcurv.read_mesh(write_text(tmp_path, "a.vtp", "v 0 0 0\n"))
    with pytest.raises(MeshFileError, match=r"b\.vtp: not a VTK PolyData file \(root <VTKFile type='Unstr"):
        meshcurv.read_mesh(write_text(tmp_path, "b.vtp", '<VTKFile type="UnstructuredGrid"/>'))
    with pytest.raises(MeshFileError, match=r"c\.vtp: the PolyData has no points or no polygons"):
        meshcurv.read_mesh(write_text(tmp_path, "c.vtp", '<VTKFile type="PolyData"><PolyData/></VTKFile>'))
    good = meshcurv.write_mesh(tmp_path / "good.vtp", torus.vertices, torus.faces).read_text()
    cases = {
        "d": (good.replace('Name="offsets"', 'Name="sizes"'), "the polygons lack a connectivity or an offsets"),
        "e": (good.replace('format="binary"', 'format="appended"'), "DataArray format 'appended' is not supported"),
        "f": (
            good.replace(
                'type="Int64" format="binary" Name="connectivity"', 'type="Int128" format="binary" Name="connectivity"'
            ),
            "unsupported DataArray type 'Int128'",
        ),
        "g": (
            good.replace(
                'format="binary" Name="offsets">',
                'format="ascii" Name="offsets">x</DataArray><DataArray type="Int64" format="binary" Name="old">',
            ),
            "a data array cannot be decoded",
        ),
        "h": (
            good.replace(
                'format="binary" Name="offsets">',
                'format="ascii" Name="offsets">2 5 </DataArray><DataArray type="Int64" format="binary" Name="old">',
            ),
            "the polygon offsets do not match the connectivity",
        ),
        "i": (
            '<VTKFile type="PolyData"><PolyData><Piece><Points><DataArray type="Float64" format="ascii"/>'
            '</Points><Polys><DataArray type="Int64" Name="connectivity" format="ascii"/><DataArray '
            'type="Int64" Name="offsets" format="ascii"/></Polys></Piece></PolyData></VTKFile>',
            "the PolyData has no points or no polygons",
        ),
    }
    for name, (text, message) in cases.items():
        with pytest.raises(MeshFileError, match=rf"{name}\.vtp: {message}"):
            meshcurv.read_mesh(write_text(tmp_path, f"{name}.vtp", text))


def test_vtp_ascii_compressed_and_mixed_polygons_are_read(tmp_path):
    import zlib

    points = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0]], dtype="<f4")
    block = zlib.compress(points.tobytes())
    header = np.array([1, points.nbytes, points.nbytes, len(block)], dtype="<u4").tobytes()
    encoded = (base64.b64encode(header) + base64.b64encode(block)).decode()
    text = f"""<VTKFile type="PolyData" byte_order="LittleEndian" compressor="vtkZLibDataCompressor">
<PolyData><Piece NumberOfPoints="5" NumberOfPolys="2">
<Points><DataArray type="Float32" NumberOfComponents="3" format="binary">{encoded}</DataArray></Points>
<Polys><DataArray type="Int32" Name="connectivity" format="ascii">0 1 2 3 1 4 2</DataArray>
<DataArray type="Int32" Name="offsets" format="ascii">4 7</DataArray></Polys>
</Piece></PolyData></VTKFile>"""
    vertices, faces = meshcurv.read_mesh(write_text(tmp_path, "z.vtp", text))
    np.testing.assert_array_equal(vertices, points)
    assert [f.tolist() for f in faces] == [[0, 1, 2, 3], [1, 4, 2]]


def test_bad_npz_files(tmp_path, torus):
    with pytest.raises(MeshFileError, match=r"a\.npz: cannot be read as NPZ"):
        meshcurv.read_mesh(write_text(tmp_path, "a.npz", "not a zip"))
    np.savez(tmp_path / "b.npz", points=torus.vertices)
    with pytest.raises(
        MeshFileError,
        match=r"b\.npz: an NPZ mesh needs arrays named 'vertices' and 'faces'; "
        r"found \['points'\]",
    ):
        meshcurv.read_mesh(tmp_path / "b.npz")
    with pytest.raises(MeshFileError, match=r"c\.npz: a field may not be called 'faces' in an NPZ file"):
        meshcurv.write_mesh(tmp_path / "c.npz", torus.vertices, torus.faces, point_data={"faces": torus.k_min})


# ---------------------------------------------------------------- writing rules


def test_existing_files_are_kept_unless_overwrite(tmp_path, torus):
    path = write_text(tmp_path, "t.obj", "keep me")
    with pytest.raises(MeshFileError, match=r"t\.obj: already exists; pass overwrite=True \(--overwrite\)"):
        meshcurv.write_mesh(path, torus.vertices, torus.faces)
    assert path.read_text() == "keep me"
    meshcurv.write_mesh(path, torus.vertices, torus.faces, overwrite=True)
    np.testing.assert_array_equal(meshcurv.read_mesh(path).vertices, torus.vertices)


def test_output_equal_to_input_is_refused_even_with_overwrite(tmp_path, torus):
    path = meshcurv.write_mesh(tmp_path / "t.obj", torus.vertices, torus.faces)
    vertices, faces = meshcurv.read_mesh(path)
    alias = tmp_path / "sub" / ".." / "t.obj"
    (tmp_path / "sub").mkdir()
    with pytest.raises(MeshFileError, match="the output would replace the input file"):
        meshcurv.write_mesh(alias, vertices, faces, source=path, overwrite=True)


def test_bad_output_paths(tmp_path, torus):
    (tmp_path / "d.obj").mkdir()
    with pytest.raises(MeshFileError, match=r"d\.obj: is a directory; give a file name"):
        meshcurv.write_mesh(tmp_path / "d.obj", torus.vertices, torus.faces)
    with pytest.raises(MeshFileError, match=r"the folder .*nowhere does not exist"):
        meshcurv.write_mesh(tmp_path / "nowhere" / "t.obj", torus.vertices, torus.faces)


@pytest.mark.parametrize("extension", [".obj", ".stl", ".off"])
def test_formats_without_fields_refuse_point_data(tmp_path, torus, extension):
    with pytest.raises(MeshFileError, match=r"files cannot hold per-vertex fields; write \.ply, \.vtk"):
        meshcurv.write_mesh(tmp_path / f"t{extension}", torus.vertices, torus.faces, point_data={"k": torus.k_min})
    from meshcurv.io import _obj

    with pytest.raises(MeshFileError, match="OBJ files cannot hold per-vertex fields"):
        _obj.write_obj(tmp_path / "direct.obj", torus.vertices, torus.faces, {"k": torus.k_min})


def test_bad_point_data_and_meshes_are_refused(tmp_path, torus):
    with pytest.raises(InvalidOptionError, match=r"`point_data\['k'\]` must be a numeric array of shape \(96,\)"):
        meshcurv.write_mesh(tmp_path / "t.vtp", torus.vertices, torus.faces, point_data={"k": np.zeros(5)})
    with pytest.raises(InvalidOptionError, match="`point_data` names must be identifiers"):
        meshcurv.write_mesh(tmp_path / "t.vtp", torus.vertices, torus.faces, point_data={"k min": torus.k_min})
    with pytest.raises(InvalidMeshError, match="`faces` has vertex index 97 out of range"):
        meshcurv.write_mesh(tmp_path / "t.vtp", torus.vertices, torus.faces + 2)
    assert list(tmp_path.iterdir()) == []


def test_failed_backend_write_is_a_mesh_file_error(tmp_path, torus, monkeypatch):
    meshio = pytest.importorskip("meshio")

    def broken(*args, **kwargs):
        raise meshio.WriteError("cannot do that")

    monkeypatch.setattr(meshio.vtu, "write", broken)
    with pytest.raises(MeshFileError, match=r"t\.vtu: cannot be written as VTU \(cannot do that\)"):
        meshcurv.write_mesh(tmp_path / "t.vtu", torus.vertices, torus.faces)
    assert list(tmp_path.iterdir()) == []


# ---------------------------------------------------------------- fields


def test_curvature_fields_errors(torus):
    result = meshcurv.principal_curvatures(torus.vertices, torus.faces)
    with pytest.raises(InvalidOptionError, match="unknown field 'curvature'; choose from k_min, k_max"):
        curvature_fields(result, fields=["curvature"])
    with pytest.raises(InvalidOptionError, match=r"`quality` must be a scalar field \(k_min, .*\); got 'normals'"):
        curvature_fields(result, quality="normals")
    assert list(curvature_fields(result, fields=["k_min"], quality=None)) == ["k_min"]
