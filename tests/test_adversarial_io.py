"""Corrupt, truncated and lying mesh files, and racing writers: errors, never hangs or blow-ups.

Every read that could hang (a reader looping at the end of the file) or
allocate for a count the file only declares runs in a child process with a
timeout and an address-space limit (``RLIMIT_AS``), so that a regression is a
test failure, not a stuck run or an exhausted machine.
"""

import base64
import json
import os
import subprocess
import sys
import zipfile

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes
from meshcurv.errors import MeshFileError
from meshcurv.io import FORMATS, _files

TIMEOUT = 20  # seconds for a child that reads a few small files; a hang fails the test

_CHILD = r"""
import json, resource, sys
paths, memory = json.loads(sys.argv[1])
from meshcurv import read_mesh
from meshcurv.errors import MeshFileError
if memory:
    with open("/proc/self/status") as status:
        size = next(int(line.split()[1]) * 1024 for line in status if line.startswith("VmSize:"))
    limit = size + memory * 2 ** 20
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
out = []
for path in paths:
    try:
        mesh = read_mesh(path)
        out.append(["ok", f"{len(mesh.vertices)} vertices, {len(mesh.faces)} faces"])
    except MeshFileError as exc:
        out.append(["MeshFileError", str(exc)])
    except BaseException as exc:
        out.append([type(exc).__name__, str(exc)[:300]])
print(json.dumps(out))
"""


def read_in_child(paths, *, memory_mib=None):
    """``[(kind, message)]`` of ``read_mesh`` on each path, in a child with a timeout (and a memory limit)."""
    if memory_mib is not None and not os.path.exists("/proc/self/status"):
        pytest.skip("the memory limit needs /proc (Linux)")
    try:
        done = subprocess.run(
            [sys.executable, "-c", _CHILD, json.dumps([[str(p) for p in paths], memory_mib])],
            capture_output=True,
            text=True,
            timeout=TIMEOUT,
        )
    except subprocess.TimeoutExpired:
        pytest.fail(f"reading {[p.name for p in paths]} did not finish within {TIMEOUT} s (a reader hangs)")
    assert done.returncode == 0, done.stderr[-2000:]
    return [tuple(row) for row in json.loads(done.stdout)]


@pytest.fixture
def torus():
    return shapes.torus(n_major=8, n_minor=6)


def ply_header(n_vertices, n_faces, *, fmt="binary_little_endian", index="int"):
    return (
        f"ply\nformat {fmt} 1.0\ncomment adversarial\nelement vertex {n_vertices}\nproperty float x\n"
        f"property float y\nproperty float z\nelement face {n_faces}\n"
        f"property list uchar {index} vertex_indices\nend_header\n"
    ).encode()


# ---------------------------------------------------------------- 1. PLY header cut short: an error, not a hang


def test_ply_cut_anywhere_in_its_header_is_an_error_not_a_hang(tmp_path, torus):
    """meshio's header loop never ends at the end of the file; our header parser is bounded."""
    pytest.importorskip("meshio")
    good = meshcurv.write_mesh(tmp_path / "good.ply", torus.vertices, torus.faces).read_bytes()
    header_end = good.index(b"end_header")
    cuts = sorted(
        {3, 4, *[i + 1 for i, byte in enumerate(good[:header_end]) if byte == ord("\n")], header_end, header_end + 5}
    )
    paths = []
    for cut in cuts:
        paths.append(tmp_path / f"cut{cut}.ply")
        paths[-1].write_bytes(good[:cut])
    paths.append(tmp_path / "garbage_header.ply")
    paths[-1].write_bytes(b"ply\n" + b"comment " + b"x" * 3000 + b"\n")  # a header that never ends
    for (kind, message), path in zip(read_in_child(paths), paths):
        assert kind == "MeshFileError", (path.name, kind, message)
        assert path.name in message and "end_header" in message, message


def test_ply_header_without_end_header_within_the_limit_is_refused(tmp_path):
    from meshcurv.io import _ply

    path = tmp_path / "long.ply"
    path.write_bytes(b"ply\nformat ascii 1.0\n" + b"comment padding\n" * (_ply.HEADER_LIMIT // 16 + 10))
    with pytest.raises(MeshFileError, match=rf"long\.ply: no 'end_header' line in the first {_ply.HEADER_LIMIT} bytes"):
        meshcurv.read_mesh(path)


# ---------------------------------------------------------------- 2. declared counts checked against the file size


def test_huge_declared_counts_are_refused_before_allocating(tmp_path):
    """300 million faces declared over 4 would allocate gigabytes; the child has 300 MiB to spare."""
    square = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype="<f4")
    face_records = np.array(
        [(3, [0, 1, 2]), (3, [0, 2, 3]), (3, [0, 1, 3]), (3, [1, 2, 3])], dtype=[("n", "u1"), ("i", "<i4", (3,))]
    )
    files = {}
    files["faces.ply"] = ply_header(4, 300_000_000) + square.tobytes() + face_records.tobytes()
    files["vertices.ply"] = ply_header(300_000_000, 4) + square.tobytes() + face_records.tobytes()
    files["ascii.ply"] = ply_header(4, 300_000_000, fmt="ascii") + b"0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n"
    files["mixed.ply"] = ply_header(4, 300_000_000) + square.tobytes() + b"\x04" + b"\0" * 16
    files["count.off"] = b"OFF\n4 300000000 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n"
    files["points.vtk"] = (
        b"# vtk DataFile Version 4.2\nx\nBINARY\nDATASET POLYDATA\nPOINTS 300000000 double\n"
        + b"\0" * 96
        + b"\nPOLYGONS 1 4\n"
        + np.array([3, 0, 1, 2], ">i4").tobytes()
    )
    header = np.array([2_400_000_000], "<u8").tobytes()
    files["size.vtp"] = (
        f'<VTKFile type="PolyData" header_type="UInt64"><PolyData><Piece><Points>'
        f'<DataArray type="Float64" NumberOfComponents="3" format="binary">'
        f'{base64.b64encode(header).decode()}AAAA</DataArray></Points><Polys><DataArray type="Int64" '
        f'Name="connectivity" format="ascii">0 1 2</DataArray><DataArray type="Int64" '
        f'Name="offsets" format="ascii">3</DataArray></Polys></Piece></PolyData>'
        f"</VTKFile>"
    ).encode()
    # an NPZ whose .npy header claims 10**11 vertices over 96 bytes of data
    npy = bytearray()
    npy += b"\x93NUMPY\x01\x00"
    text = "{'descr': '<f8', 'fortran_order': False, 'shape': (100000000000, 3), }"
    text += " " * (117 - len(text)) + "\n"
    npy += len(text).to_bytes(2, "little") + text.encode() + b"\0" * 96
    with zipfile.ZipFile(tmp_path / "shape.npz", "w") as archive:
        archive.writestr("vertices.npy", bytes(npy))
        archive.writestr("faces.npy", bytes(npy))
    paths = [tmp_path / "shape.npz"]
    for name, data in files.items():
        paths.append(tmp_path / name)
        paths[-1].write_bytes(data)
    results = read_in_child(paths, memory_mib=300)
    for (kind, message), path in zip(results, paths):
        assert kind == "MeshFileError", (path.name, kind, message)
        assert path.name in message and ("declares" in message or "announces" in message), message
    assert "declares 300000000 faces but the file holds only" in results[1][1]
    assert "declares 300000000 vertices but the file holds only" in results[2][1]


@pytest.mark.parametrize("extension", [".ply", ".off", ".vtp", ".npz", ".obj"])
def test_a_file_cut_anywhere_is_never_a_silently_shorter_mesh(tmp_path, torus, extension):
    """Binary counts are checked exactly; a cut is an error (or, in text, at most the last number changes)."""
    if extension == ".ply":
        pytest.importorskip("meshio")  # PLY is written through meshio
    good = meshcurv.write_mesh(tmp_path / f"good{extension}", torus.vertices, torus.faces).read_bytes()
    cuts = np.linspace(0, len(good) - 1, 40).astype(int)
    paths = []
    for cut in cuts:
        paths.append(tmp_path / f"cut{cut}{extension}")
        paths[-1].write_bytes(good[:cut])
    for cut, path, (kind, message) in zip(cuts, paths, read_in_child(paths)):
        if kind == "MeshFileError":
            assert path.name in message
        elif extension == ".obj":  # OBJ has no counts: a prefix is a smaller mesh
            assert kind == "ok", (cut, kind, message)
        else:  # only a cut of the final line end leaves the whole mesh
            assert kind == "ok" and good[cut:].strip() == b"", (cut, len(good), kind, message)
            assert message == f"{len(torus.vertices)} vertices, {len(torus.faces)} faces"


# ---------------------------------------------------------------- 3. OBJ vertex lines of 2 and 4 numbers


def test_obj_vertex_lines_of_other_lengths_do_not_shift_the_next_ones(tmp_path):
    path = tmp_path / "w.obj"
    path.write_text("v 0 0 0 1\nv 1 0 0 0.9 0.1 0.2\nv 1 1 0\nv 0 1 0 0.5\nf 1 2 3\nf 1 3 4\n")
    vertices, faces = meshcurv.read_mesh(path)
    np.testing.assert_array_equal(vertices, [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    path.write_text("v 0 0 0\nv 1 0\nv 1 1 0 7\nv 0 1 0\nf 1 2 3\n")  # 2 + 4 numbers: the total is still 12
    with pytest.raises(MeshFileError, match=r"w\.obj: line 2: a `v` line has fewer than 3 coordinates \(2\)"):
        meshcurv.read_mesh(path)


# ---------------------------------------------------------------- 4. float indices refused, not truncated


def test_float_indices_are_refused(tmp_path):
    cases = {
        "a.ply": ply_header(3, 1, fmt="ascii") + b"0 0 0\n1 0 0\n0 1 0\n3 0.5 1 2\n",
        "b.ply": ply_header(4, 2, fmt="ascii") + b"0 0 0\n1 0 0\n0 1 0\n1 1 0\n4 0 1 3 2\n3 0 1 2.5\n",
        "c.vtp": b'<VTKFile type="PolyData"><PolyData><Piece><Points><DataArray type="Float64" '
        b'NumberOfComponents="3" format="ascii">0 0 0 1 0 0 0 1 0</DataArray></Points><Polys>'
        b'<DataArray type="Int64" Name="connectivity" format="ascii">0 1.5 2</DataArray>'
        b'<DataArray type="Int64" Name="offsets" format="ascii">3</DataArray></Polys></Piece>'
        b"</PolyData></VTKFile>",
        "d.off": b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1.5 2\n",
        "e.vtk": b"# vtk DataFile Version 4.2\nx\nASCII\nDATASET POLYDATA\nPOINTS 3 float\n0 0 0 1 0 0 0 1 0\n"
        b"POLYGONS 1 4\n3 0 1.5 2\n",
    }
    for name, data in cases.items():
        (tmp_path / name).write_bytes(data)
        with pytest.raises(MeshFileError, match=rf"{name.replace('.', '[.]')}: .*not an integer"):
            meshcurv.read_mesh(tmp_path / name)


# ---------------------------------------------------------------- 5. every reader failure is a MeshFileError


def test_vtp_empty_binary_array_and_npz_corruption_are_mesh_file_errors(tmp_path, torus):
    good = meshcurv.write_mesh(tmp_path / "good.vtp", torus.vertices, torus.faces).read_text()
    start = good.index('Name="offsets">') + len('Name="offsets">')
    (tmp_path / "empty.vtp").write_text(good[:start] + good[good.index("</DataArray>", start) :])
    with pytest.raises(MeshFileError, match=r"empty\.vtp: a binary DataArray is empty or cut short"):
        meshcurv.read_mesh(tmp_path / "empty.vtp")

    npz = meshcurv.write_mesh(tmp_path / "good.npz", torus.vertices, torus.faces).read_bytes()
    cases = {
        "cut.npz": npz[: len(npz) // 2],
        "flipped.npz": npz[:60] + bytes(b ^ 0xFF for b in npz[60:200]) + npz[200:],
    }
    stored = bytearray()
    with zipfile.ZipFile(tmp_path / "stored.npz", "w") as archive:  # a .npy header that is not a dict
        archive.writestr(
            "vertices.npy", b"\x93NUMPY\x01\x00" + (118).to_bytes(2, "little") + b"{'descr': (" + b" " * 106 + b"\n"
        )
        archive.writestr("faces.npy", b"")
    stored += (tmp_path / "stored.npz").read_bytes()
    cases["header.npz"] = bytes(stored)
    for name, data in cases.items():
        (tmp_path / name).write_bytes(data)
        with pytest.raises(MeshFileError, match=rf"{name.replace('.', '[.]')}: "):
            meshcurv.read_mesh(tmp_path / name)


def test_unexpected_reader_exceptions_become_mesh_file_errors_but_memory_errors_do_not(tmp_path, torus, monkeypatch):
    import dataclasses

    path = meshcurv.write_mesh(tmp_path / "t.obj", torus.vertices, torus.faces)

    def raises(error):
        def read(path):
            raise error

        return read

    monkeypatch.setitem(FORMATS, ".obj", dataclasses.replace(FORMATS[".obj"], read=raises(IndexError("index 0"))))
    with pytest.raises(MeshFileError, match=r"t\.obj: cannot be read as Wavefront OBJ \(IndexError: index 0\)"):
        meshcurv.read_mesh(path)
    monkeypatch.setitem(FORMATS, ".obj", dataclasses.replace(FORMATS[".obj"], read=raises(MemoryError())))
    with pytest.raises(MemoryError):
        meshcurv.read_mesh(path)


# ---------------------------------------------------------------- 6. OFF face colours


def test_off_faces_with_colours_are_read(tmp_path):
    path = tmp_path / "colour.off"
    path.write_text("OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2 255 0 0\n3 0 2 3 0.1 0.2 0.3 1.0\n")
    vertices, faces = meshcurv.read_mesh(path)
    assert faces.tolist() == [[0, 1, 2], [0, 2, 3]]
    path.write_text("OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3 9 9 9\n3 0 2\n")
    with pytest.raises(MeshFileError, match=r"colour\.off: line 8: 3 values, expected 4 or more"):
        meshcurv.read_mesh(path)


# ---------------------------------------------------------------- 7. legacy VTK POLYDATA


def legacy_polydata(vertices, faces, *, binary, version):
    """A legacy .vtk POLYDATA as vtkPolyDataWriter writes it (4.2: count-prefixed cells; 5.1: offsets)."""

    def array(values, code):
        if binary:
            return np.asarray(values).astype(">" + code).tobytes() + b"\n"
        return (" ".join(map(str, np.asarray(values).ravel().tolist())) + "\n").encode()

    parts = [
        f"# vtk DataFile Version {version}\nvtk output\n{'BINARY' if binary else 'ASCII'}\n"
        "DATASET POLYDATA\nFIELD FieldData 1\nTimeValue 1 1 double\n".encode()
        + array([0.5], "f8"),
        f"POINTS {len(vertices)} double\n".encode() + array(vertices, "f8"),
    ]
    if version == "5.1":
        offsets = np.arange(len(faces) + 1) * faces.shape[1]
        parts.append(b"METADATA\nINFORMATION 0\n\n")
        parts.append(
            f"POLYGONS {len(offsets)} {faces.size}\nOFFSETS vtktypeint64\n".encode()
            + array(offsets, "i8")
            + b"CONNECTIVITY vtktypeint64\n"
            + array(faces, "i8")
        )
    else:
        cells = np.column_stack([np.full(len(faces), faces.shape[1]), faces])
        parts.append(f"POLYGONS {len(faces)} {cells.size}\n".encode() + array(cells, "i4"))
    parts.append(
        f"POINT_DATA {len(vertices)}\nSCALARS k float 1\nLOOKUP_TABLE default\n".encode()
        + array(np.arange(len(vertices)), "f4")
    )
    return b"".join(parts)


@pytest.mark.parametrize("version", ["4.2", "5.1"])
@pytest.mark.parametrize("binary", [False, True])
def test_legacy_vtk_polydata_is_read(tmp_path, torus, version, binary):
    path = tmp_path / "surface.vtk"
    path.write_bytes(legacy_polydata(torus.vertices, torus.faces, binary=binary, version=version))
    vertices, faces = meshcurv.read_mesh(path)
    np.testing.assert_array_equal(vertices, torus.vertices)  # repr of a float64 and big-endian f8 are exact
    np.testing.assert_array_equal(faces, torus.faces)
    path.write_bytes(path.read_bytes()[: path.read_bytes().index(b"POLYGONS") + 30])
    with pytest.raises(MeshFileError, match=r"surface\.vtk: "):
        meshcurv.read_mesh(path)


def test_legacy_vtk_mixed_polygons_and_triangle_strips(tmp_path):
    path = tmp_path / "strips.vtk"
    path.write_text(
        "# vtk DataFile Version 3.0\nx\nASCII\nDATASET POLYDATA\nPOINTS 5 float\n"
        "0 0 0 1 0 0 1 1 0 0 1 0 2 0 0\nPOLYGONS 2 9\n4 0 1 2 3\n3 1 4 2\n"
        "TRIANGLE_STRIPS 1 5\n4 0 1 3 2\n"
    )
    vertices, faces = meshcurv.read_mesh(path)
    assert [face.tolist() for face in faces] == [[0, 1, 2, 3], [1, 4, 2], [0, 1, 3], [3, 1, 2]]


# ---------------------------------------------------------------- 8. a folder that cannot take the temporary


def test_write_into_a_folder_that_refuses_the_temporary_names_the_output(tmp_path, torus, monkeypatch):
    def refuse(*args, **kwargs):
        raise PermissionError(13, "Permission denied", str(tmp_path / ".t.obj.abc123.obj"))

    monkeypatch.setattr(_files.os, "open", refuse)
    with pytest.raises(MeshFileError, match=r"t\.obj: cannot be written \(Permission denied\)") as caught:
        meshcurv.write_mesh(tmp_path / "t.obj", torus.vertices, torus.faces)
    assert ".t.obj." not in str(caught.value)
    monkeypatch.undo()
    with pytest.raises(MeshFileError, match=r"gone[/\\]t\.obj: cannot be written"):
        with _files.atomic_output(tmp_path / "gone" / "t.obj"):
            pass


def test_an_output_takes_the_umask_and_the_umask_is_never_changed(tmp_path, torus, monkeypatch):
    """Outputs get 0o666 less the umask, as open() gives; the process-wide umask is not touched meanwhile.

    Setting the umask, even for a moment, would change the mode of the files that other threads
    create in that moment (world-writable files under a umask of 0).
    """
    previous = os.umask(0o027)
    try:

        def changed(*args):
            raise AssertionError("the process umask was changed during a write")

        monkeypatch.setattr(_files.os, "umask", changed)
        meshcurv.write_mesh(tmp_path / "t.obj", torus.vertices, torus.faces)
        monkeypatch.undo()
    finally:
        os.umask(previous)
    assert (tmp_path / "t.obj").stat().st_mode & 0o777 == 0o640
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.obj"]


# ---------------------------------------------------------------- 9. exclusive creation, real file identity


@pytest.mark.parametrize("hard_links", [True, False])
def test_a_file_created_meanwhile_is_not_replaced_without_overwrite(tmp_path, torus, monkeypatch, hard_links):
    """Two writers of one output: the one that finishes second gets an error, the first one's file stays."""
    import dataclasses

    target = tmp_path / "t.obj"
    real_write = FORMATS[".obj"].write

    def write_while_another_finishes(path, *args):
        real_write(path, *args)
        target.write_text("the other writer's mesh")

    if not hard_links:

        def no_link(*args):
            raise OSError(1, "Operation not permitted")

        monkeypatch.setattr(_files.os, "link", no_link)
    monkeypatch.setitem(FORMATS, ".obj", dataclasses.replace(FORMATS[".obj"], write=write_while_another_finishes))
    with pytest.raises(MeshFileError, match=r"t\.obj: already exists \(another writer created it meanwhile\)"):
        meshcurv.write_mesh(target, torus.vertices, torus.faces)
    assert target.read_text() == "the other writer's mesh"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.obj"]  # no temporary left behind
    target.unlink()
    monkeypatch.setitem(FORMATS, ".obj", dataclasses.replace(FORMATS[".obj"], write=real_write))
    meshcurv.write_mesh(target, torus.vertices, torus.faces)  # without a race: written
    np.testing.assert_array_equal(meshcurv.read_mesh(target).faces, torus.faces)
    meshcurv.write_mesh(target, torus.vertices[::-1].copy(), torus.faces, overwrite=True)  # replaced when asked
    np.testing.assert_array_equal(meshcurv.read_mesh(target).vertices, torus.vertices[::-1])


@pytest.mark.slow
def test_writers_started_together_do_not_both_succeed(tmp_path):
    pytest.importorskip("meshio")  # PLY is written through meshio
    script = (
        "import sys, time, meshcurv\nfrom meshcurv import shapes\n"
        "s = shapes.icosphere(subdivisions=60)\nstart = float(sys.argv[2])\n"
        "time.sleep(max(0.0, start - time.time()))\n"
        "try:\n    meshcurv.write_mesh(sys.argv[1], s.vertices, s.faces)\n    print('written')\n"
        "except meshcurv.errors.MeshFileError as exc:\n    print('refused', exc)\n"
    )
    import time

    start = str(time.time() + 3)
    target = str(tmp_path / "same.ply")
    children = [
        subprocess.Popen([sys.executable, "-c", script, target, start], stdout=subprocess.PIPE, text=True)
        for _ in range(2)
    ]
    outputs = [child.communicate(timeout=TIMEOUT)[0] for child in children]
    assert sorted(out.split()[0] for out in outputs) == ["refused", "written"], outputs
    assert "already exists" in next(out for out in outputs if out.startswith("refused"))


def test_the_input_is_never_the_output_through_any_alias(tmp_path, torus):
    source = meshcurv.write_mesh(tmp_path / "in.obj", torus.vertices, torus.faces)
    (tmp_path / "link.obj").symlink_to(source)
    os.link(source, tmp_path / "hard.obj")
    (tmp_path / "folder_link").symlink_to(tmp_path, target_is_directory=True)
    for alias in (
        tmp_path / "link.obj",
        tmp_path / "hard.obj",
        tmp_path / "folder_link" / "in.obj",
        tmp_path / "folder_link" / ".." / tmp_path.name / "in.obj",
    ):
        with pytest.raises(MeshFileError, match="the output would replace the input file"):
            _files.check_output(alias, overwrite=True, source=source)
        with pytest.raises(MeshFileError, match="the output would replace the input file"):
            _files.check_output(source, overwrite=True, source=alias)
    assert _files.check_output(tmp_path / "out.obj", overwrite=True, source=source) == tmp_path / "out.obj"
