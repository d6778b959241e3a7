"""meshcurv.io._points: point-cloud files written and read back, and every malformed file refused by name."""

import numpy as np
import pytest

from meshcurv.errors import (
    InvalidMeshError,
    InvalidOptionError,
    MeshFileError,
    MeshQualityWarning,
    MissingDependencyError,
)
from meshcurv.io._points import POINT_EXTENSIONS, read_points, write_points


@pytest.fixture
def cloud():
    rng = np.random.default_rng(0)
    points = rng.normal(size=(50, 3)) * [1.0, 2.0, 1e3]
    normals = rng.normal(size=(50, 3))
    return points, normals / np.linalg.norm(normals, axis=1, keepdims=True)


@pytest.mark.parametrize("extension", POINT_EXTENSIONS)
@pytest.mark.parametrize("binary", [True, False])
@pytest.mark.parametrize("with_normals", [True, False])
def test_write_then_read_round_trip(tmp_path, cloud, extension, binary, with_normals):
    if extension in (".las", ".laz"):
        pytest.importorskip("laspy")
    points, normals = cloud
    before = points.copy(), normals.copy()
    path = tmp_path / f"cloud{extension}"
    write_points(
        path,
        points,
        normals if with_normals else None,
        binary=binary,
        point_data={"k_max": points[:, 0], "dir_max": normals},
    )
    read, read_normals = read_points(path)
    # LAS stores integers: scale = extent / 2^30
    tolerance = np.ptp(points, axis=0) / 2.0**30 if extension in (".las", ".laz") else 0.0
    assert np.all(np.abs(read - points) <= tolerance)
    if with_normals:
        np.testing.assert_array_equal(read_normals, normals)
    elif extension in (".las", ".laz", ".ply", ".pcd") or extension == ".csv":
        assert read_normals is None
    np.testing.assert_array_equal(points, before[0])  # the input is not changed
    np.testing.assert_array_equal(normals, before[1])


def test_ply_with_faces_and_other_names(tmp_path):
    path = tmp_path / "mesh.ply"
    path.write_bytes(
        b"ply\nformat ascii 1.0\ncomment made by hand\nelement vertex 3\nproperty float x\n"
        b"property float y\nproperty float z\nproperty float normal_x\nproperty float normal_y\n"
        b"property float normal_z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
        b"0 0 0 0 0 1\r\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n"
    )
    points, normals = read_points(path)
    np.testing.assert_array_equal(points, [[0, 0, 0], [1, 0, 0], [0, 1, 0]])
    np.testing.assert_array_equal(normals, [[0, 0, 1]] * 3)


@pytest.mark.parametrize(
    "body, match",
    [
        (
            b"ply\nformat binary_little_endian 1.0\nelement vertex 1000000000\nproperty double x\nproperty double y\n"
            b"property double z\nend_header\n" + b"\0" * 48,
            "declares 1000000000 vertices but the file holds only 48 bytes",
        ),
        (
            b"ply\nformat ascii 1.0\nelement vertex 1000000000\nproperty float x\nproperty float y\nproperty float z\n"
            b"end_header\n0 0 0\n",
            "declares 1000000000 vertices",
        ),
        (
            b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
            b"end_header\n0 0 0\n1 1 1\n" + b"2 2 2 2 2 2 2 2 2 2 2 2 2 2 2 2 2 2",
            r"line 10: 18 values, expected 3 \(vertex: x, y, z\)",
        ),
        (
            b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
            b"end_header\n0 0 0\n1 one 1\n",
            "line 9: 'one' is not a number",
        ),
        (
            b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nend_header\n0 0\n1 1\n",
            "has no x, y and z",
        ),
        (
            b"ply\nformat ascii 1.0\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n",
            "no 'vertex' element",
        ),
        (b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n", "cut short"),
        (b"solid cube\n", "not a PLY file"),
    ],
)
def test_malformed_ply_is_refused_by_name(tmp_path, body, match):
    path = tmp_path / "bad.ply"
    path.write_bytes(body)
    with pytest.raises(MeshFileError, match=f"bad.ply: .*{match}"):
        read_points(path)


def test_text_with_header_colours_comments_and_separators(tmp_path):
    path = tmp_path / "scan.csv"
    path.write_text('# exported\n"X";"Y";"Z";"Intensity"\n1;2;3;7\n4;5;6;8\n\n7;8;9;9\n')
    points, normals = read_points(path)
    np.testing.assert_array_equal(points, [[1, 2, 3], [4, 5, 6], [7, 8, 9]])
    assert normals is None
    path = tmp_path / "scan.xyz"
    path.write_text("0 0 0 255 128 0\n1 0 0 255 128 0\n")  # colours, not unit vectors: no normals
    assert read_points(path)[1] is None
    path.write_text("0 0 0 0 0 1\n1 0 0 0 1 0\n")  # unit vectors: normals
    np.testing.assert_array_equal(read_points(path)[1], [[0, 0, 1], [0, 1, 0]])


@pytest.mark.parametrize(
    "text, match",
    [
        ("1 2 3\n4 5 6\n7 8\n", r"line 3: 2 values, expected 3 \(as most rows: x, y, z\)"),
        ("1 2\n3 4\n", "rows of 2 numbers"),
        ("1 2 3\n4 five 6\n", "line 2: 'five' is not a number"),
        ("# nothing\n\n", "no points"),
        ("x,y,z\n", "a header line and no points"),
        ("a,b,c\n1,2,3\n", "has no x, y and z"),
    ],
)
def test_malformed_text_is_refused_by_name(tmp_path, text, match):
    path = tmp_path / "bad.txt"
    path.write_text(text)
    with pytest.raises(MeshFileError, match=f"bad.txt: .*{match}"):
        read_points(path)


_PCD = (
    "VERSION 0.7\nFIELDS x y z normal_x normal_y normal_z\nSIZE 4 4 4 4 4 4\nTYPE F F F F F F\n"
    "COUNT 1 1 1 1 1 1\nWIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA {kind}\n"
)


def test_pcd_binary_float32_and_ascii_with_missing_points(tmp_path):
    values = np.array([[0, 0, 0, 0, 0, 1], [1, 0, 0, 0, 0, 1], [2, 0, 0, 0, 1, 0]], dtype="<f4")
    path = tmp_path / "a.pcd"
    path.write_bytes(_PCD.format(n=3, kind="binary").encode() + values.tobytes())
    points, normals = read_points(path)
    np.testing.assert_array_equal(points, values[:, :3])
    np.testing.assert_array_equal(normals, values[:, 3:])
    path.write_text(_PCD.format(n=3, kind="ascii") + "0 0 0 0 0 1\nnan nan nan nan nan nan\n2 0 0 0 1 0\n")
    with pytest.warns(MeshQualityWarning, match="1 of 3 points have NaN coordinates"):
        points, normals = read_points(path)
    np.testing.assert_array_equal(points, [[0, 0, 0], [2, 0, 0]])


@pytest.mark.parametrize(
    "body, match",
    [
        (_PCD.format(n=10**9, kind="binary").encode() + b"\0" * 24, "declares 1000000000 points"),
        (_PCD.format(n=2, kind="binary_compressed").encode(), "binary_compressed"),
        (_PCD.format(n=2, kind="ascii").encode() + b"0 0 0 0 0 1\n", "declares 2 points"),
        (
            _PCD.format(n=2, kind="ascii").encode() + b"0 0 0 0 0 1\n1 1 1 1 1 1 1 1 1 1 1 1\n",
            r"line 12: 12 values, expected 6 \(x, y, z, normal_x",
        ),
        (
            b"VERSION 0.7\nFIELDS x y z\nSIZE 4 4\nTYPE F F F\nCOUNT 1 1 1\nPOINTS 1\nDATA ascii\n0 0 0\n",
            "do not match",
        ),
        (b"VERSION 0.7\nFIELDS x y z\nPOINTS many\nDATA ascii\n", "malformed PCD header"),
        (b"VERSION 0.7\nFIELDS x y z\n", "cut short"),
        (
            b"VERSION 0.7\nFIELDS x y z\nSIZE 3 3 3\nTYPE F F F\nCOUNT 1 1 1\nPOINTS 1\nDATA binary\n" + b"\0" * 9,
            "unknown TYPE/SIZE",
        ),
    ],
)
def test_malformed_pcd_is_refused_by_name(tmp_path, body, match):
    path = tmp_path / "bad.pcd"
    path.write_bytes(body)
    with pytest.raises(MeshFileError, match=f"bad.pcd: .*{match}"):
        read_points(path)


def test_las_cut_short_or_garbage_is_refused(tmp_path, cloud):
    pytest.importorskip("laspy")
    path = tmp_path / "cloud.las"
    write_points(path, cloud[0])
    data = path.read_bytes()
    short = tmp_path / "short.las"
    short.write_bytes(data[:-100])
    with pytest.raises(MeshFileError, match="short.las: .*declares 50 points"):
        read_points(short)
    garbage = tmp_path / "garbage.laz"
    garbage.write_bytes(b"not a las file at all" * 10)
    with pytest.raises(MeshFileError, match="garbage.laz: not a readable LAS / LAZ file"):
        read_points(garbage)


def test_las_without_laspy_names_the_extra(tmp_path, monkeypatch, cloud):
    path = tmp_path / "cloud.las"
    path.write_bytes(b"LASF" + b"\0" * 400)
    monkeypatch.setitem(__import__("sys").modules, "laspy", None)
    with pytest.raises(MissingDependencyError, match=r"cloud.las: .*pip install 'meshcurv\[points\]'"):
        read_points(path)


def test_paths_are_checked(tmp_path, cloud):
    with pytest.raises(MeshFileError, match="no such file"):
        read_points(tmp_path / "missing.xyz")
    unknown = tmp_path / "cloud.e57"
    unknown.write_text("1 2 3\n")
    with pytest.raises(
        MeshFileError, match=r"cloud.e57: unknown point-cloud file extension '.e57'; known formats: .ply"
    ):
        read_points(unknown)
    path = tmp_path / "cloud.ply"
    write_points(path, cloud[0])
    with pytest.raises(MeshFileError, match="already exists"):
        write_points(path, cloud[0])
    with pytest.raises(MeshFileError, match=r"field 'k' must have shape \(50,\) or \(50, 3\)"):
        write_points(tmp_path / "other.ply", cloud[0], point_data={"k": np.zeros(3)})
    # point_data as write_mesh takes it: a name with a space wrote a PLY header no reader reads, a key 5 was
    # written as "5", words were numpy's ValueError and a list an AttributeError
    for point_data, message in [
        ({"k max": np.zeros(50)}, r"`point_data` names must be identifiers \(letters, digits, _\); got 'k max'"),
        ({5: np.zeros(50)}, "`point_data` names must be identifiers"),
        ({"k": np.array(["x"] * 50)}, r"`point_data\['k'\]` must be a numeric array; got dtype <U1"),
        ([np.zeros(50)], "`point_data` must be a dict of name -> array; got list"),
    ]:
        with pytest.raises(InvalidOptionError, match=message):
            write_points(tmp_path / "other.ply", cloud[0], point_data=point_data)
    # normals were reshaped: (3, 3) was numpy's ValueError, (25, 6) passed as (50, 3)
    for normals in (cloud[1][:3], cloud[1].reshape(25, 6)):
        with pytest.raises(InvalidMeshError, match=r"`normals` must have shape \(50, 3\), one per point; got"):
            write_points(tmp_path / "other.ply", cloud[0], normals)
    assert not (tmp_path / "other.ply").exists()


def test_is_point_cloud_and_curvature_fields(tmp_path, cloud):
    from meshcurv.io._points import is_point_cloud, write_point_curvatures
    from meshcurv.pointcloud import point_cloud_curvatures

    points = np.random.default_rng(1).normal(size=(300, 3))
    points /= np.linalg.norm(points, axis=1, keepdims=True)
    write_points(tmp_path / "cloud.ply", points)
    mesh = tmp_path / "mesh.ply"
    mesh.write_bytes(
        b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        b"property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
        b"0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"
    )
    assert is_point_cloud(tmp_path / "cloud.ply") and not is_point_cloud(mesh)
    assert is_point_cloud(tmp_path / "scan.laz") and not is_point_cloud(tmp_path / "m.obj")
    result = point_cloud_curvatures(points)
    write_point_curvatures(tmp_path / "out.csv", points, result, fields=["k_max", "normals"])
    header = (tmp_path / "out.csv").read_text().splitlines()[0].split(",")
    assert header == ["x", "y", "z", "k_max", "normals_x", "normals_y", "normals_z", "quality"]
    table = np.loadtxt(tmp_path / "out.csv", delimiter=",", skiprows=1)
    np.testing.assert_array_equal(table[:, 3], result.k_max)
