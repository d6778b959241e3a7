"""Point clouds (files without faces) through `meshcurv compute` and the batch task."""

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


@pytest.mark.parametrize("argv, message", [
    (["-m", "icc"], "method 'icc' needs faces; .* is a point cloud"),
    (["--smoothing-steps", "2"], "--smoothing-steps is for meshes"),
])
@pytest.mark.parametrize("command", ["compute", "plot"])
def test_mesh_options_are_refused_for_a_point_cloud(sphere_points, capsys, argv, message, command):
    code, _, err = run(capsys, command, sphere_points, *argv)
    assert code == 2
    assert re.search(message, err)


def test_plot_draws_a_point_cloud(sphere_points, tmp_path, capsys):
    pytest.importorskip("matplotlib")
    output = tmp_path / "sphere.png"
    code, _, err = run(capsys, "plot", sphere_points, "-o", output, "--field", "mean", "--view", "iso",
                       "--pixels", "600")
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
