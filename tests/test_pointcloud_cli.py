"""Point clouds (files without faces) through `meshcurv compute` and the batch task."""

import importlib.util
import re

import numpy as np
import pytest

pytest.importorskip("click")

import meshcurv  # noqa: E402
from meshcurv.batch import process_mesh  # noqa: E402
from meshcurv.cli import main  # noqa: E402

RADIUS = 2.0


@pytest.fixture
def sphere_points(tmp_path):
    rng = np.random.default_rng(3)
    points = rng.normal(size=(4000, 3))
    points *= RADIUS / np.linalg.norm(points, axis=1, keepdims=True)
    path = tmp_path / "sphere.xyz"
    np.savetxt(path, points)
    return path


def run(capsys, *argv):
    code = main([str(arg) for arg in argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_compute_summarises_a_point_cloud(sphere_points, capsys):
    code, out, _ = run(capsys, "compute", sphere_points)
    assert code == 0
    assert "4000 points; method corrected_measures" in out
    median_mean = float(next(line for line in out.splitlines() if line.startswith("mean")).split()[4])
    assert median_mean == pytest.approx(1 / RADIUS, rel=0.01)  # a sphere of radius 2: H = 1/2


def test_compute_writes_the_fields_of_a_point_cloud(sphere_points, tmp_path, capsys):
    output = tmp_path / "out.ply"
    code, _, _ = run(capsys, "compute", sphere_points, "-o", output, "-m", "jets")
    assert code == 0
    points, _ = meshcurv.read_points(output)
    np.testing.assert_allclose(points, np.loadtxt(sphere_points), rtol=1e-6)  # float32 in PLY


@pytest.mark.parametrize(
    "argv, message",
    [
        (["-m", "icc"], "method 'icc' needs faces; .* is a point cloud"),
        (["--smoothing-steps", "2"], "--smoothing-steps is for meshes"),
    ],
)
@pytest.mark.parametrize("command", ["compute", "plot"])
def test_mesh_options_are_refused_for_a_point_cloud(sphere_points, capsys, argv, message, command):
    if command == "plot":
        pytest.importorskip("matplotlib")  # without it plot stops first, naming the plot extra
    code, _, err = run(capsys, command, sphere_points, *argv)
    assert code == 2
    assert re.search(message, err)


def test_plot_draws_a_point_cloud(sphere_points, tmp_path, capsys):
    pytest.importorskip("matplotlib")
    output = tmp_path / "sphere.png"
    code, _, err = run(
        capsys, "plot", sphere_points, "-o", output, "--field", "mean", "--view", "iso", "--pixels", "600"
    )
    assert code == 0, err
    from matplotlib.image import imread

    image = imread(output)
    assert image.shape[1] == 600
    # the sphere's disc is drawn in colour (the picture is not blank, white or grey)
    assert (image[..., :3].std(axis=2) > 0.05).mean() > 0.1


def test_a_point_cloud_method_is_refused_for_a_mesh(tmp_path, capsys):
    sphere = meshcurv.shapes.icosphere(4)
    path = meshcurv.write_mesh(tmp_path / "ico.obj", sphere.vertices, sphere.faces)
    code, _, err = run(capsys, "compute", path, "-m", "jets")
    assert code == 2 and "method 'jets' is for point clouds" in err


def test_the_batch_task_computes_a_point_cloud(sphere_points, tmp_path):
    row = process_mesh(sphere_points, tmp_path / "out" / "sphere.ply", tmp_path / "out" / ".rec.json")
    assert row["status"] == "computed", row["error"]
    assert row["method"] == "corrected_measures" and row["n_vertices"] == 4000 and row["n_faces"] == 0
    assert row["mean_median"] == pytest.approx(1 / RADIUS, rel=0.01)


@pytest.mark.parametrize(
    "extension, write",
    [
        (".csv", lambda path, points: np.savetxt(path, points, delimiter=",", header="x,y,z", comments="")),
        (".txt", lambda path, points: np.savetxt(path, points)),
        (
            ".pts",
            lambda path, points: path.write_text(
                f"{len(points)}\n" + "".join(f"{x!r} {y!r} {z!r} 7 200 200 200\n" for x, y, z in points.tolist())
            ),
        ),  # Leica PTS: count, then x y z i r g b
    ],
)
def test_compute_takes_every_point_cloud_text_file(sphere_points, tmp_path, capsys, extension, write):
    """Issue 29, class 9: .csv and .txt clouds exited 1 (read as meshes); .pts files were refused."""
    points = np.loadtxt(sphere_points)
    path = tmp_path / f"sphere{extension}"
    write(path, points)
    code, out, err = run(capsys, "compute", path)
    assert code == 0, err
    assert "4000 points" in out
    median_mean = float(next(line for line in out.splitlines() if line.startswith("mean")).split()[4])
    assert median_mean == pytest.approx(1 / RADIUS, rel=0.01)  # a sphere of radius 2: H = 1/2


def _listed(err: str) -> list[str]:
    return re.findall(r"\.\w+", err.split("written to", 1)[1].split("written to")[0])


def test_an_unknown_output_lists_exactly_the_outputs_compute_writes(sphere_points, tmp_path, capsys):
    """`-o out.xlsx` listed .obj, .stl, .off, which compute then refused; each extension listed must be written."""
    from meshcurv.cli._app import output_extensions

    sphere = meshcurv.shapes.icosphere(2)
    mesh = meshcurv.write_mesh(tmp_path / "ico.obj", sphere.vertices, sphere.faces)
    for source, cloud in ((mesh, False), (sphere_points, True)):
        code, _, err = run(capsys, "compute", source, "-o", tmp_path / "out.xlsx")
        assert code == 1
        kind = "a point cloud's" if cloud else "a mesh's"
        assert re.search(rf"out\.xlsx: unknown output extension '\.xlsx'; {kind} fields are written to \.ply", err)
        listed = _listed(err)
        assert listed == list(output_extensions(cloud=cloud))
        assert ".obj" not in listed and ".stl" not in listed and ".off" not in listed
        for extension in listed:
            if extension in (".las", ".laz"):
                if importlib.util.find_spec("laspy") is None:
                    continue
            meshio_writes = (".vtk", ".vtu") if cloud else (".ply", ".vtk", ".vtu")  # the io extra's formats
            if extension in meshio_writes and importlib.util.find_spec("meshio") is None:
                continue
            output = tmp_path / f"out-{cloud}{extension}"
            code, _, err = run(capsys, "compute", source, "-o", output, "-q")
            assert code == 0 and output.exists(), f"{extension}: {err}"
    code, _, err = run(capsys, "compute", sphere_points, "-o", tmp_path / "out.stl")
    assert code == 1 and "unknown output extension '.stl'; a point cloud's fields are written to .ply" in err
    code, _, err = run(capsys, "compute", mesh, "-o", tmp_path / "out.stl")
    assert code == 1 and "STL files cannot hold per-vertex fields; write a mesh's fields to .ply, .vtk" in err
    code, _, err = run(capsys, "compute", mesh, "-o", tmp_path / "out")
    assert code == 1 and "unknown output extension (none); a mesh's fields are written to" in err
