"""Which files keep the curvature fields, read back by the readers people use (each skipped when missing).

Every pair of (format, reader) is asserted as it is: the fields it keeps are
compared with the result's, and the loss a reader makes by design (VTK's PLY
reader keeps the normals only, MeshLab one field as its vertex quality) is
asserted too, so that a change of a reader shows here and in
:data:`meshcurv.io.fields.VIEWERS`.
"""

import importlib.util
import json
import subprocess
import sys
import textwrap

import numpy as np

import pytest

import meshcurv
from meshcurv.io import write_curvatures
from meshcurv.io.fields import FIELDS, VIEWERS

SCALARS = ("k_min", "k_max", "mean", "gaussian", "shape_index", "curvedness")
VECTORS = ("dir_min", "dir_max", "normals")

#: Files as written: PLY binary and ASCII, legacy VTK binary and ASCII, VTU, VTP, CSV, NPZ.
WRITTEN = {
    "ply": (".ply", True),
    "ply-ascii": (".ply", False),
    "vtk": (".vtk", True),
    "vtk-ascii": (".vtk", False),
    "vtu": (".vtu", True),
    "vtp": (".vtp", True),
    "csv": (".csv", True),
    "npz": (".npz", True),
}

#: The properties of a PLY file are float32: compared within float32 round-off of the field's scale.
FLOAT32 = 1e-6


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    pytest.importorskip("meshio")  # PLY, VTK and VTU are written through meshio
    mesh = meshcurv.shapes.ellipsoid((3.0, 2.0, 1.0), subdivisions=5)
    result = meshcurv.principal_curvatures(mesh.vertices, mesh.faces)
    assert result.valid.all()
    folder = tmp_path_factory.mktemp("fields")
    paths = {}
    for name, (extension, binary) in WRITTEN.items():
        paths[name] = write_curvatures(
            folder / f"{name}{extension}", mesh.vertices, mesh.faces, result, quality="gaussian", binary=binary
        )
    return mesh, result, paths


def expected(result, name):
    return np.asarray(result.valid, dtype=float) if name == "valid" else np.asarray(getattr(result, name))


def close(values, truth):
    values = np.asarray(values, dtype=float).reshape(truth.shape)
    np.testing.assert_allclose(values, truth, rtol=0, atol=FLOAT32 * np.abs(truth).max() + 1e-300)


def check_all_named(result, data, *, split_vectors, normals_as=None):
    for name in SCALARS + ("valid",):
        close(data[name], expected(result, name))
    close(data["quality"], np.asarray(result.gaussian))
    for name in VECTORS:
        truth = np.asarray(getattr(result, name))
        if name == "normals" and normals_as is not None:
            close(np.column_stack([data[key] for key in normals_as]), truth)
        elif split_vectors:
            close(np.column_stack([data[f"{name}_{axis}"] for axis in "xyz"]), truth)
        else:
            close(data[name], truth)


@pytest.mark.parametrize("name", ["vtp", "vtu", "vtk", "vtk-ascii", "ply", "ply-ascii"])
def test_pyvista(written, name):
    pv = pytest.importorskip("pyvista")
    _, result, paths = written
    read = pv.read(paths[name])
    assert read.n_points == result.n_vertices
    if name.startswith("ply"):  # VTK's PLY reader: x, y, z, normals, colours, texture coordinates only
        assert list(read.point_data) == ["Normals"]
        close(read.point_data["Normals"], np.asarray(result.normals))
        return
    assert set(read.point_data) == set(FIELDS) | {"quality"}
    check_all_named(result, read.point_data, split_vectors=False)


@pytest.mark.parametrize("name", ["ply", "ply-ascii", "vtk", "vtk-ascii", "vtu"])
def test_meshio(written, name):
    meshio = pytest.importorskip("meshio")
    _, result, paths = written
    read = meshio.read(paths[name])
    assert read.points.shape == (result.n_vertices, 3)
    if name.startswith("ply"):  # PLY properties are scalars: vectors split, normals as nx, ny, nz
        check_all_named(result, read.point_data, split_vectors=True, normals_as=("nx", "ny", "nz"))
    else:
        check_all_named(result, read.point_data, split_vectors=False)


def test_meshio_has_no_vtp_reader(written):
    meshio = pytest.importorskip("meshio")
    with pytest.raises(meshio.ReadError):
        meshio.read(written[2]["vtp"])


@pytest.mark.parametrize("name", ["ply", "ply-ascii"])
def test_trimesh_ply_keeps_the_fields_in_its_raw_metadata(written, name):
    trimesh = pytest.importorskip("trimesh")
    mesh, result, paths = written
    read = trimesh.load(paths[name], process=False, force="mesh")
    np.testing.assert_allclose(read.vertices, mesh.vertices, rtol=1e-12)
    assert dict(read.vertex_attributes) == {}  # trimesh puts no PLY property there
    raw = read.metadata["_ply_raw"]["vertex"]["data"]
    data = {key: raw[key] for key in (raw.dtype.names if hasattr(raw, "dtype") else raw)}
    check_all_named(result, data, split_vectors=True, normals_as=("nx", "ny", "nz"))


MESHLAB_SCRIPT = textwrap.dedent("""
    import json, sys
    import pymeshlab
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(sys.argv[1])
    m = ms.current_mesh()
    found = {}
    for name in sys.argv[2:]:
        try:
            found[name] = m.vertex_custom_scalar_attribute_array(name).tolist()
        except pymeshlab.PyMeshLabException:
            pass
    print(json.dumps({"n": m.vertex_number(), "quality": m.vertex_scalar_array().tolist(),
                      "normals": m.vertex_normal_matrix().tolist(), "custom": found}))
""")


@pytest.mark.parametrize("name", ["ply", "ply-ascii"])
def test_meshlab_keeps_the_quality_and_the_normals(written, name):
    """pymeshlab runs in a child process: MeshLab can abort the process on a file it dislikes."""
    pytest.importorskip("pymeshlab")
    _, result, paths = written
    names = [*SCALARS, "valid", "dir_min_x"]
    run = subprocess.run(
        [sys.executable, "-c", MESHLAB_SCRIPT, str(paths[name]), *names], capture_output=True, text=True, timeout=120
    )
    assert run.returncode == 0, run.stderr[-2000:]
    read = json.loads(run.stdout.strip().splitlines()[-1])
    assert read["n"] == result.n_vertices
    close(read["quality"], np.asarray(result.gaussian))  # the field written as quality (--quality)
    normals = np.asarray(read["normals"])
    assert (np.einsum("ij,ij->i", normals, np.asarray(result.normals)) > 1 - 1e-6).all()
    assert read["custom"] == {}  # MeshLab reads no other vertex property of a PLY file


def test_csv_with_pandas(written):
    pd = pytest.importorskip("pandas")
    _, result, paths = written
    table = pd.read_csv(paths["csv"])
    assert len(table) == result.n_vertices
    check_all_named(result, table, split_vectors=True)


def test_npz_with_numpy(written):
    mesh, result, paths = written
    with np.load(paths["npz"]) as archive:
        np.testing.assert_array_equal(archive["vertices"], mesh.vertices)
        for name in SCALARS + VECTORS:
            np.testing.assert_array_equal(archive[name], getattr(result, name))


@pytest.mark.parametrize("name", list(WRITTEN))
def test_meshcurv_reads_its_own_fields_back(written, name):
    from meshcurv.io.fields import read_fields

    mesh, result, paths = written
    fields = read_fields(paths[name])
    assert set(fields) == set(FIELDS) | {"quality"}
    assert fields["valid"].dtype == bool and fields["valid"].all()
    exact = name in ("vtp", "npz", "vtu", "vtk", "vtk-ascii", "csv")  # float64 kept; PLY holds float32
    for key in SCALARS + VECTORS:
        truth = np.asarray(getattr(result, key))
        assert fields[key].shape == truth.shape, key
        if exact:
            np.testing.assert_array_equal(fields[key], truth)
        else:
            close(fields[key], truth)


@pytest.mark.parametrize("binary", [True, False])
def test_read_fields_reads_a_point_cloud_ply(tmp_path, binary):
    # a PLY without faces (what write_point_curvatures writes) has its fields read back by name
    from meshcurv.io import write_point_curvatures
    from meshcurv.io.fields import read_fields

    sphere = meshcurv.shapes.icosphere(subdivisions=3)
    result = meshcurv.principal_curvatures(sphere.vertices, sphere.faces)
    path = write_point_curvatures(tmp_path / "cloud.ply", sphere.vertices, result, binary=binary)
    assert b"element face" not in path.read_bytes()[:2000]
    fields = read_fields(path)
    assert {"k_min", "k_max", "mean", "gaussian", "dir_min", "dir_max", "normals", "valid"} <= set(fields)
    assert fields["dir_max"].shape == (sphere.vertices.shape[0], 3) and fields["valid"].dtype == bool
    for key in ("k_min", "k_max", "dir_max", "normals"):
        close(fields[key], np.asarray(getattr(result, key)))


def test_read_fields_errors(tmp_path):
    from meshcurv.errors import MeshFileError
    from meshcurv.io.fields import read_fields

    with pytest.raises(MeshFileError, match=r"no per-vertex fields in a \.obj; read_fields knows \.ply, \.vtp"):
        read_fields(tmp_path / "mesh.obj")
    with pytest.raises(MeshFileError, match=r"missing\.ply: no such file"):
        read_fields(tmp_path / "missing.ply")
    bad = tmp_path / "bad.csv"
    bad.write_text("vertex,x,y,z,k_min\n0,1,2,3\n")
    with pytest.raises(MeshFileError, match=r"bad\.csv: 4 columns under a header of 5 names"):
        read_fields(bad)
    bad.write_text("vertex,x,y,z,k_min\n0,1,2,3,high\n")
    with pytest.raises(MeshFileError, match=r"bad\.csv: cannot be read as a table of numbers"):
        read_fields(bad)
    truncated = tmp_path / "cut.npz"
    truncated.write_bytes(b"PK\x03\x04 not a whole zip")
    with pytest.raises(MeshFileError, match=r"cut\.npz: cannot be read as NPZ"):
        read_fields(truncated)
    if importlib.util.find_spec("meshio") is not None:
        broken = tmp_path / "broken.vtu"
        broken.write_text("<VTKFile type='UnstructuredGrid'><Unstructured")  # meshio.read would sys.exit
        with pytest.raises(MeshFileError, match=r"broken\.vtu: cannot be read as VTU"):
            read_fields(broken)


def test_every_recommended_extension_is_written_by_meshcurv():
    from meshcurv.io import FORMATS

    for reader, (extensions, keeps) in VIEWERS.items():
        assert keeps and extensions, reader
        for extension in extensions:
            assert FORMATS[extension].fields != "none", (reader, extension)
