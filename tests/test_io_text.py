"""Issue 29, class 5: text rows of the wrong length are named by their line, never re-cut into shifted points.

Each file below is a valid file with one row changed so that the total number of values still
divides evenly (the case the readers re-cut silently before): the reader must refuse it with a
MeshFileError naming the file and the line, or read exactly the points written.
"""

import numpy as np
import pytest

import meshcurv
from meshcurv.errors import MeshFileError
from meshcurv.io._text import not_a_number

_PLY_CLOUD = (
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n"
)
_PLY_MESH = (
    "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 2\nproperty list uchar int vertex_indices\nend_header\n"
)
_FOUR = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
_PCD = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 3\nHEIGHT 1\nPOINTS 3\nDATA ascii\n"


def _write(tmp_path, name, text):
    path = tmp_path / name
    path.write_bytes(text.encode())
    return path


@pytest.mark.parametrize(
    "name, text, message",
    [
        # 2 + 4 values: the total (9) is still 3 points of 3; read before as shifted points
        ("cloud.csv", "x,y,z\n1,2,3\n4,5\n6,7,8,9\n", r"line 3: 2 values, expected 3 \(x, y, z\)"),
        ("cloud.xyz", "1 2 3\n4 5\n6 7 8 9\n", r"line 2: 2 values, expected 3 \(as most rows: x, y, z\)"),
        ("cloud.txt", "1 2 3\n4 5 6 7\n8 9\n", r"line 2: 4 values, expected 3"),
        ("cloud.xyz", "1 2\n3 4 5\n6 7 8 9\n", r"line 1: 2 values, expected 3"),  # a tie: rows of 3 or more win
        ("cloud.csv", "x,y,z\n1,,3\n4,5,6\n", r"line 2: an empty value in '1,,3'"),
        ("cloud.csv", "1,2,3,\n4,5,6,\n", r"line 1: an empty value in '1,2,3,'"),  # was a StopIteration
        ("cloud.csv", "1;2;3\n;4;5\n", r"line 2: an empty value in ';4;5'"),
        ("cloud.txt", "# scan\n\n1 2 3\n4 five 6\n", r"line 4: 'five' is not a number"),
        ("cloud.csv", "1 2 x\n4 5 6\n", r"line 1: 'x' is not a number"),  # a word among numbers: not a header
        ("cloud.ply", _PLY_CLOUD + "0 0 0\n1 0\n0 1 0 5\n", r"line 9: 2 values, expected 3 \(vertex: x, y, z\)"),
        ("cloud.ply", _PLY_CLOUD + "0 0 0\n1 0 0 0 1 0\n", r"line 9: 6 values, expected 3"),  # two rows as one
        ("cloud.pcd", _PCD + "0 0 0\n1 0\n0 1 0 5\n", r"line 11: 2 values, expected 3 \(x, y, z\)"),
        ("cloud.pcd", _PCD + "0 0 0\n1 0 0\n0 1 0\n1 1 1\n", r"line 13: a row after the 3 points the header declares"),
    ],
)
def test_a_cloud_row_of_the_wrong_length_is_named(tmp_path, name, text, message):
    path = _write(tmp_path, name, text)
    with pytest.raises(MeshFileError, match=rf"{name}: {message}"):
        meshcurv.read_points(path)


@pytest.mark.parametrize(
    "name, text, message",
    [
        (
            "mesh.ply",
            _PLY_MESH + "0 0 0\n1 0\n0 0 1 0\n0 0 1\n3 0 1 2\n3 0 2 3\n",
            r"line 11: 2 values, expected 3 \(vertex: x, y, z\)",
        ),
        (
            "mesh.ply",
            _PLY_MESH + _FOUR + "3 0 1\n4 0 2 3 1\n",
            r"line 14: 3 values, expected 4 \(face: vertex_indices: a count of 3 and 3 values\)",
        ),
        ("mesh.ply", _PLY_MESH + _FOUR + "3 0 1 2 0\n3 0 2 3\n", r"line 14: 5 values, expected 4"),
        (
            "mesh.ply",
            _PLY_MESH + _FOUR + "3 0 1 2\n3 0 2 3\n3 0 1 3\n",
            r"line 16: a row after the last element \(the header declares 4 vertices, 2 faces\)",
        ),
        (
            "mesh.ply",
            _PLY_MESH + _FOUR + "3 0 1 2\n3 0 2.5 3\n",
            r"line 15: a PLY face index is not an integer \(2.5\)",
        ),
        (
            "mesh.ply",
            _PLY_MESH + _FOUR + "3 0 1 2\n2.5 0 2 3\n",
            r"line 15: the face list count of vertex_indices is not",
        ),
        (
            "mesh.ply",
            _PLY_MESH + _FOUR + "3 0 1 2\n3 0 2 7\n",
            r"line 15: a face uses vertex 7; the file has 4 vertices",
        ),
        (
            "mesh.ply",
            _PLY_MESH + _FOUR + "3 0 1 2 3 0 2 3\n",  # two faces on one line: the row is named
            r"line 14: 8 values, expected 4 .*and the file ends before the 2 faces",
        ),
        (
            "mesh.ply",
            _PLY_MESH + _FOUR + "3 0 1 2\n",
            r"the PLY header declares 2 faces but the file ends after line 14, 1 rows later",
        ),
        (
            "mesh.off",
            "OFF\n4 2 0\n0 0 0\n1 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 2 3\n",
            r"line 4: 2 values, expected 3 or more \(x, y, z, then maybe a colour\)",
        ),
        (
            "mesh.off",
            "OFF\n4 2 0\n0 0 0\n1 0 0 7\n0 1 0\n0 0 1\n3 0 1 2\n3 0 2 3\n",
            r"line 4: 4 values, expected 3 \(as most vertex rows: x, y, z\)",
        ),
        ("mesh.off", "OFF\n4 2 0\n" + _FOUR + "3 0 1\n3 0 2 3\n", r"line 7: 3 values, expected 4 or more"),
        ("mesh.off", "OFF\n4 2 0\n" + _FOUR + "2 0 1\n3 0 2 3\n", r"line 7: a face of 2 corners"),
        ("mesh.off", "OFF\n4 2 0\n" + _FOUR + "3 0 1 2\n3 0 x 3\n", r"line 8: 'x' is not a number \(a face\)"),
        (
            "mesh.off",
            "OFF\n4 2 0\n0 0 0\n1 0 0,\n0 1 0\n0 0 1\n3 0 1 2\n3 0 2 3\n",
            r"line 4: '0,' is not a number \(a vertex coordinate\)",
        ),
        (
            "mesh.off",
            "OFF\n4 2 0\n" + _FOUR + "3 0 1 2\n3 0 2.5 3\n",
            r"line 8: a face index is not an integer \(2.5\)",
        ),
        ("mesh.off", "OFF\n4 2 0\n" + _FOUR + "3 0 1 2\n3 0 2 9\n", r"line 8: a face uses vertex 9; the file has 4"),
        (
            "mesh.off",
            "OFF\n4 2 0\n" + _FOUR + "3 0 1 2\n3 0 2 3\n3 0 1 3\n",
            r"line 9: a row after the 4 vertices and 2 faces the header declares",
        ),
        (
            "mesh.off",
            "OFF\n4 2 0\n" + _FOUR + "3 0 1 2\n",
            r"the header declares 4 vertices and 2 faces but the file holds only 5 lines for them, up to line 7",
        ),
        ("mesh.ply", _PLY_MESH + _FOUR + "3 0 1 2\n2 0 2\n", r"line 15: a face of 2 corners; a face needs 3 or more"),
        ("mesh.obj", "v 0 0 0\nv 1 0 0,\nv 0 1 0\nf 1 2 3\n", r"line 2: a vertex coordinate is not a number \('0,'\)"),
        ("mesh.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 3\n", r"line 5: a face has fewer than 3 corners"),
        ("mesh.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3,\n", r"line 4: a face index is not an integer"),
        ("mesh.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 4 5\nf 1 2 x\n", r"line 5: a face index is not an integer"),
        ("mesh.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 0 2 3\n", r"line 5: a face uses vertex index 0"),
    ],
)
def test_a_mesh_row_of_the_wrong_length_is_named(tmp_path, name, text, message):
    path = _write(tmp_path, name, text)
    with pytest.raises(MeshFileError, match=rf"{name}: {message}"):
        meshcurv.read_mesh(path)


_STL = (
    "solid t\nfacet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 0 1 0\n endloop\n"
    "endfacet\nendsolid t\n"
)


@pytest.mark.parametrize(
    "text, message",
    [
        (_STL.replace("vertex 1 0 0", "vertex 1 0 0 5"), r"line 5: 4 values, expected 3 \(vertex x y z\)"),
        (_STL.replace("vertex 1 0 0", "vertex 1 0"), r"line 5: 2 values, expected 3 \(vertex x y z\)"),
        (_STL.replace("normal 0 0 1", "normal 0 1"), r"line 2: 2 values, expected 3 \(facet normal nx ny nz\)"),
        (_STL.replace("vertex 1 0 0", "vertex 1,0,0"), r"line 5: '1,0,0' is not a number \(vertex x y z\)"),
        # a loop of 4 vertices beside one of 2: meshio cut the rows by fours into shifted triangles
        (
            _STL.replace("  vertex 0 1 0\n", "  vertex 0 1 0\n  vertex 1 1 0\n") + _STL.replace("  vertex 0 1 0\n", ""),
            r"line 2: a facet of 4 vertices; an STL facet is a triangle of 3",
        ),
        ("solid t\n  vertex 0 0 0\n" + _STL[8:], r"line 2: a vertex before any facet"),
        ("solid t\nendsolid t\n", r"no facets"),
    ],
)
def test_an_ascii_stl_row_of_the_wrong_length_is_named(tmp_path, text, message):
    path = _write(tmp_path, "mesh.stl", text)
    with pytest.raises(MeshFileError, match=rf"mesh\.stl: {message}"):  # meshio took the last 3 numbers
        meshcurv.read_mesh(path)


@pytest.mark.parametrize(
    "name, text",
    [
        ("cloud.csv", "# exported\nX, Y, Z\n1.5, 2, 3\n\n4, 5, 6\n"),  # comma and blank, a blank line
        ("cloud.csv", "x;y;z\n1,5;2;3\n4;5;6\n"),  # semicolons with decimal commas
        ("cloud.xyz", "1.5\t2\t3 \r\n4  5\t6\r\n"),  # tabs, doubled blanks, CRLF, trailing blanks
        ("cloud.pts", "2\n1.5 2 3 7 200 200 200\n4 5 6 7 200 200 200\n"),  # Leica PTS: a count, then x y z i r g b
        ("cloud.pts", "1\n1.5 2 3\n1\n4 5 6\n"),  # two scans, each with its count
        ("cloud.ply", _PLY_CLOUD.replace("3\n", "2\n", 1) + "1.5 2 3\n\n4 5 6\n"),  # a blank line
    ],
)
def test_valid_text_rows_are_read_exactly(tmp_path, name, text):
    points, _ = meshcurv.read_points(_write(tmp_path, name, text))
    np.testing.assert_array_equal(points, [[1.5, 2, 3], [4, 5, 6]])


@pytest.mark.parametrize(
    "text, message",
    [
        ("3\n1 2 3\n4 5 6\n", r"line 1: a count of 3 points, but 2 rows follow it"),
        ("2.5\n1 2 3\n4 5 6\n", r"line 1: 1 value \(2.5\), expected a count of points or x, y, z"),
        ("0\n", r"no points in the file \(only counts of points\)"),
        ("1 2\n3 4\n", r"rows of 2 numbers; a point needs x, y and z"),
        ("1 2\n3\n4 5\n", r"rows of 2 numbers \(most rows\); a point needs x, y and z"),
        ("# only a comment\n", "no points in the file"),
        ("x y z\n\n", "a header line and no points"),
    ],
)
def test_counts_and_sizes_of_pts_files(tmp_path, text, message):
    with pytest.raises(MeshFileError, match=rf"cloud\.pts: {message}"):
        meshcurv.read_points(_write(tmp_path, "cloud.pts", text))


def test_a_nul_byte_is_named_and_the_fallback_message(tmp_path, monkeypatch):
    error = not_a_number(tmp_path / "cloud.xyz", b"1 2 3\n4 5\x006\n", 1)
    assert str(error).endswith("cloud.xyz: line 2: '5\\x006' is not a number")
    # no word found on its own (none known; kept so that the error never lacks a message)
    monkeypatch.setattr("meshcurv.io._text.first_bad_line", lambda text: (-1, b""))
    error = not_a_number(tmp_path / "cloud.xyz", b"1 2 3\n", 1, "the rows")
    with pytest.raises(MeshFileError, match=r"cloud\.xyz: something is not a number \(the rows\)$"):
        raise error


def test_an_ascii_stl_is_read_as_meshio_did_and_with_blank_lines(tmp_path):
    two = _STL.replace("endsolid t\n", "") + _STL[8:].replace("vertex 0 0 0", "vertex 1 1 0")
    vertices, faces = meshcurv.read_mesh(_write(tmp_path, "mesh.stl", two.replace("endloop", "\n\nendloop")))
    np.testing.assert_array_equal(vertices, [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])  # first seen first
    np.testing.assert_array_equal(faces, [[0, 1, 2], [3, 1, 2]])
    meshio = pytest.importorskip("meshio")
    with np.errstate(over="ignore"):  # meshio multiplies a uint32 count taken from the text's bytes
        mesh = meshio.stl.read(str(_write(tmp_path, "plain.stl", two)))
    np.testing.assert_array_equal(vertices, mesh.points)
    np.testing.assert_array_equal(faces, mesh.cells[0].data)


def test_valid_meshes_with_blank_lines_and_polygons_are_read_exactly(tmp_path):
    expected = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]
    vertices, faces = meshcurv.read_mesh(_write(tmp_path, "mesh.ply", _PLY_MESH + _FOUR + "\n4 0 1 2 3\n3 0 2 3\n\n"))
    np.testing.assert_array_equal(vertices, expected)
    assert [list(face) for face in faces] == [[0, 1, 2, 3], [0, 2, 3]]
    vertices, faces = meshcurv.read_mesh(
        _write(tmp_path, "mesh.off", "OFF\n4 2 0\n" + _FOUR + "3 0 1 2 255 0 0\n3 0 2 3\n")
    )
    np.testing.assert_array_equal(vertices, expected)
    np.testing.assert_array_equal(faces, [[0, 1, 2], [0, 2, 3]])


def test_reading_stays_vectorised(tmp_path):
    """A row check must not make reading a loop over rows: the Python calls of a read do not grow with its rows."""
    import sys

    def python_calls(n_rows: int) -> int:
        points = np.random.default_rng(0).normal(size=(n_rows, 3))
        path = tmp_path / f"rows_{n_rows}.csv"
        np.savetxt(path, points, delimiter=",", header="x,y,z", comments="")
        calls = 0

        def profile(frame, event, arg):
            nonlocal calls
            calls += event in ("call", "c_call")  # Python functions and builtins (a per-row split, float)

        sys.setprofile(profile)
        try:
            read, _ = meshcurv.read_points(path)
        finally:
            sys.setprofile(None)
        np.testing.assert_array_equal(read, points)
        return calls

    # (a wall-clock limit here failed at 17.8 s under a load of 12 for 0.5 s of CPU: counted, not timed)
    assert python_calls(200_000) <= python_calls(1_000) + 10


_BOM = "\ufeff"  # what Excel ("CSV UTF-8") and Notepad write first: b"\xef\xbb\xbf" in UTF-8


@pytest.mark.parametrize(
    "name, text",
    [
        ("cloud.csv", "x,y,z\n1.5,2,3\n4,5,6\n"),
        ("cloud.csv", "x;y;z\n1,5;2;3\n4;5;6\n"),
        ("cloud.csv", "1.5,2,3\n4,5,6\n"),
        ("cloud.xyz", "1.5 2 3\n4 5 6\n"),
        ("cloud.txt", "x\ty\tz\n1.5\t2\t3\n4\t5\t6\n"),
        ("cloud.pts", "2\n1.5 2 3\n4 5 6\n"),
        ("cloud.ply", _PLY_CLOUD.replace("3\n", "2\n", 1) + "1.5 2 3\n4 5 6\n"),
        ("cloud.pcd", _PCD.replace("3\n", "2\n").replace("POINTS 3", "POINTS 2") + "1.5 2 3\n4 5 6\n"),
    ],
)
def test_a_byte_order_mark_is_not_part_of_the_first_row(tmp_path, name, text):
    points, _ = meshcurv.read_points(_write(tmp_path, name, _BOM + text))
    np.testing.assert_array_equal(points, [[1.5, 2, 3], [4, 5, 6]])


_FIVE = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]]


@pytest.mark.parametrize(
    "name, text",
    [
        # the BOM made the first `v` line unreadable: vertex 1 was dropped and faces 1-4 took vertices 2-5
        ("mesh.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 1 1\nf 1 2 3\nf 1 3 4\n"),
        ("mesh.off", "OFF\n5 2 0\n" + _FOUR + "1 1 1\n3 0 1 2\n3 0 2 3\n"),
        (
            "mesh.ply",
            _PLY_MESH.replace("vertex 4", "vertex 5") + _FOUR + "1 1 1\n3 0 1 2\n3 0 2 3\n",
        ),
    ],
)
def test_a_byte_order_mark_before_a_mesh_is_skipped(tmp_path, name, text):
    vertices, faces = meshcurv.read_mesh(_write(tmp_path, name, _BOM + text))
    np.testing.assert_array_equal(vertices, _FIVE)
    np.testing.assert_array_equal(faces, [[0, 1, 2], [0, 2, 3]])


def test_a_byte_order_mark_before_an_ascii_stl_is_skipped(tmp_path):
    vertices, faces = meshcurv.read_mesh(_write(tmp_path, "mesh.stl", _BOM + _STL))
    expected, expected_faces = meshcurv.read_mesh(_write(tmp_path, "plain.stl", _STL))
    np.testing.assert_array_equal(vertices, expected)
    np.testing.assert_array_equal(faces, expected_faces)
