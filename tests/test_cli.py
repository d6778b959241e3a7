"""The ``meshcurv`` command, run in-process through ``main(argv)`` (and once as a real process)."""

import importlib.util
import builtins
import logging
import pathlib
import subprocess
import sys

import numpy as np
import pytest

import meshcurv
from meshcurv.estimators import DEFAULT_METHOD, ESTIMATORS, Estimator

click = pytest.importorskip("click")
from meshcurv.cli import main  # noqa: E402


@pytest.fixture
def torus_file(tmp_path):
    torus = meshcurv.shapes.torus()  # R 30, r 10: k_max = 1/r = 0.1 everywhere
    return meshcurv.write_mesh(tmp_path / "torus.obj", torus.vertices, torus.faces)


@pytest.fixture
def small_torus_file(tmp_path):
    torus = meshcurv.shapes.torus(n_major=24, n_minor=16)
    return meshcurv.write_mesh(tmp_path / "small.obj", torus.vertices, torus.faces)


@pytest.fixture
def saddle_file(tmp_path):
    saddle = meshcurv.shapes.saddle(spacing=0.1)  # open: boundary vertices are invalid, with a warning
    return meshcurv.write_mesh(tmp_path / "saddle.obj", saddle.vertices, saddle.faces)


def run(capsys, *argv):
    code = main([str(arg) for arg in argv])
    out, err = capsys.readouterr()
    return code, out, err


def one_error_line(err):
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


# ---------------------------------------------------------------- methods, info


def test_methods_lists_the_registry_as_it_is_now(capsys, monkeypatch):
    code, out, _ = run(capsys, "methods")
    assert code == 0
    for name, estimator in ESTIMATORS.items():
        assert f"{name} " in out and estimator.summary in out
    # the default method, and it alone, is marked (its line, not the first one nor any line)
    marked = [line.split()[0] for line in out.splitlines() if line.endswith(" (default)")]
    assert marked == [DEFAULT_METHOD], out
    other = next(name for name in ESTIMATORS if name != DEFAULT_METHOD)  # the mark follows the default
    monkeypatch.setattr(meshcurv.cli._app, "_default_method", lambda: other)
    _, out, _ = run(capsys, "methods")
    assert [line.split()[0] for line in out.splitlines() if line.endswith(" (default)")] == [other], out
    extra = Estimator(
        name="made_up",
        function=None,
        options={"radius": None, "width": 2},
        summary="an estimator added later",
        stages=(),
    )
    monkeypatch.setitem(ESTIMATORS, "made_up", extra)
    code, out, _ = run(capsys, "methods")
    assert "made_up" in out and "an estimator added later" in out
    assert "options: --radius (default: from the mesh), --width (default 2)" in out


def test_info_describes_a_torus(capsys, torus_file):
    code, out, err = run(capsys, "info", torus_file)
    assert code == 0 and err == ""
    facts = dict(
        line.split(None, 1)
        if not line.startswith(("boundary", "mean", "euler", "bounding"))
        else (" ".join(line.split()[:2]), " ".join(line.split()[2:]))
        for line in out.splitlines()
    )
    assert facts["vertices"] == "3600" and facts["faces"] == "7200" and facts["genus"] == "1"
    assert facts["boundary loops"] == "0" and facts["euler characteristic"] == "0"
    assert facts["bounding box"].startswith("(-40, -40, -10) to (40, 40, 10)")


def test_info_counts_polygons(capsys, tmp_path):
    torus = meshcurv.shapes.torus(n_major=12, n_minor=8)
    path = meshcurv.write_mesh(tmp_path / "quads.off", torus.vertices, torus.quads)
    code, out, err = run(capsys, "info", path)
    assert code == 0
    assert "polygons               96 (fan-triangulated into 192 triangles)" in out
    assert "fan-triangulated" in err  # the TriangulationWarning, as one line


# ---------------------------------------------------------------- compute


def test_compute_prints_a_summary_table(capsys, torus_file):
    code, out, err = run(capsys, "compute", torus_file)
    assert code == 0 and err == ""
    lines = out.splitlines()
    # the default method, icc, with its default radius: one mean edge length on a clean mesh
    torus = meshcurv.shapes.torus()
    h = meshcurv.geometry.mean_edge_length(torus.vertices, meshcurv.MeshTopology.from_faces(torus.faces).edges)
    assert f"3600 vertices, 7200 faces; method icc (radius={h:.4g}, normal_radius={3 * h:.4g}, " in lines[0]
    assert lines[1].startswith("per vertex")
    assert lines[2].split() == ["field", "min", "p5", "p25", "median", "p75", "p95", "max", "mean"]
    rows = {line.split()[0]: [float(x) for x in line.split()[1:]] for line in lines[3:9]}
    assert list(rows) == ["k_min", "k_max", "mean", "gaussian", "shape_index", "curvedness"]
    assert rows["k_max"][3] == pytest.approx(0.1, rel=0.02)  # median of k_max: 1/r
    # k_min = cos v / (R + r cos v); the vertices are uniform in (u, v), so their mean is
    # (1 - R / sqrt(R^2 - r^2)) / r = -0.00607, while the area-weighted mean is int k_min dA / A = 0
    R, r = 30.0, 10.0
    assert rows["k_min"][7] == pytest.approx((1 - R / np.sqrt(R**2 - r**2)) / r, rel=0.05)
    assert lines[9].startswith("area-weighted")
    assert lines[10].split() == ["field", "p5", "p25", "median", "p75", "p95", "mean"]
    weighted = {line.split()[0]: [float(x) for x in line.split()[1:]] for line in lines[11:17]}
    assert list(weighted) == list(rows)
    assert abs(weighted["k_min"][5]) < 0.01 * abs(rows["k_min"][7])
    assert weighted["k_max"][2] == pytest.approx(0.1, rel=0.02)
    integrals = lines[17]
    area = float(integrals.split("area ")[1].split(",")[0])
    assert area == pytest.approx(4 * np.pi**2 * R * r, rel=0.01)  # inscribed mesh: see test_integrals
    total_gaussian = float(integrals.split("total Gaussian curvature ")[1].split(" ")[0])
    assert abs(total_gaussian) < 1e-9  # chi = 0
    assert "2 pi chi = 0 pi" in integrals
    assert lines[-1] == "invalid vertices (estimate undefined, fields NaN): 0 of 3600"


@pytest.mark.parametrize("extension", [".ply", ".vtp", ".npz"])
def test_compute_writes_the_fields(capsys, torus_file, tmp_path, extension):
    if extension == ".ply":
        pytest.importorskip("meshio")
    output = tmp_path / f"torus{extension}"
    code, _, err = run(
        capsys, "compute", torus_file, "-o", output, "--fields", "k_min,normals", "--quality", "gaussian"
    )
    assert code == 0
    hint = (
        " (ParaView and PyVista read only the normals of a PLY file: write .vtp for them)"
        if extension == ".ply"
        else ""
    )
    assert err.strip() == (f"meshcurv: wrote {output}: 3600 vertices, fields k_min, normals (quality = gaussian){hint}")
    vertices, faces = meshcurv.read_mesh(output)
    expected = meshcurv.principal_curvatures(vertices, faces)
    if extension == ".npz":
        stored = np.load(output)
        np.testing.assert_array_equal(stored["k_min"], expected.k_min)
        np.testing.assert_array_equal(stored["quality"], expected.gaussian)
        assert sorted(stored.files) == ["faces", "k_min", "normals", "quality", "vertices"]
    else:
        assert output.stat().st_size > 0


def test_compute_help_names_the_file_for_each_reader(capsys):
    from meshcurv.io.fields import VIEWERS

    code, out, _ = run(capsys, "compute", "--help")
    assert code == 0
    epilog = " ".join(out.split("Which file for which reader")[1].split())
    for reader, (extensions, keeps) in VIEWERS.items():
        assert f"{reader}: {', '.join(extensions)}" in epilog
        assert " ".join(keeps.split()) in epilog
    code, out, _ = run(capsys, "--help")
    assert "-o out.vtp   per-vertex fields for ParaView and PyVista" in out


def test_compute_method_options(capsys, torus_file, tmp_path):
    code, out, _ = run(capsys, "compute", torus_file, "--method", "matgeom", "--smoothing-steps", "0")
    assert code == 0 and "method matgeom (smoothing_steps=0, " in out
    code, out, _ = run(capsys, "compute", torus_file, "--radius", "3")
    assert code == 0 and "method icc (radius=3, normal_radius=9, " in out
    code, _, err = run(capsys, "compute", torus_file, "--smoothing-steps", "2")
    assert code == 2
    assert "method 'icc' does not take --smoothing-steps (its options: --radius)" in err
    code, _, err = run(capsys, "compute", torus_file, "--method", "normal_cycle", "--radius", "3")
    assert code == 2
    assert "method 'normal_cycle' does not take --radius (its options: --smoothing-steps)" in err
    code, _, err = run(capsys, "compute", torus_file, "--method", "nope")
    assert code == 2 and "'nope' is not one of 'normal_cycle'" in err
    code, _, err = run(capsys, "compute", torus_file, "--method", "normal_cycle", "--smoothing-steps", "-1")
    assert code == 2 and "--smoothing-steps" in err
    code, _, err = run(capsys, "compute", torus_file, "--fields", "k_min,curvature")
    assert code == 2 and "unknown field 'curvature'" in err


def test_compute_refuses_to_overwrite_unless_asked(capsys, torus_file, tmp_path):
    output = tmp_path / "out.vtp"
    output.write_text("keep")
    code, _, err = run(capsys, "compute", torus_file, "-o", output)
    assert code == 1
    assert (
        one_error_line(err) == f"meshcurv: error: {output}: already exists; pass overwrite=True (--overwrite) "
        "to replace it"
    )
    assert output.read_text() == "keep"
    code, _, _ = run(capsys, "compute", torus_file, "-o", output, "--overwrite")
    assert code == 0 and meshcurv.read_mesh(output).vertices.shape == (3600, 3)


def test_compute_refuses_bad_outputs(capsys, torus_file, tmp_path):
    code, _, err = run(capsys, "compute", torus_file, "-o", torus_file, "--overwrite")
    assert code == 1 and "the output would replace the input file" in one_error_line(err)
    code, _, err = run(capsys, "compute", torus_file, "-o", tmp_path / "t.stl")
    assert code == 1 and "STL files cannot hold per-vertex fields" in one_error_line(err)
    code, _, err = run(capsys, "compute", torus_file, "-o", tmp_path / "t.xyz")
    assert code == 1 and "unknown output extension '.xyz'" in one_error_line(err)


def test_unreadable_mesh_is_one_line_and_debug_shows_the_traceback(capsys, tmp_path):
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nf 1 2 3\n")
    code, out, err = run(capsys, "compute", bad)
    assert code == 1 and out == ""
    assert one_error_line(err) == f"meshcurv: error: {bad}: line 3: a face uses vertex 3 but the file has 2 vertices"
    code, _, err = run(capsys, "compute", bad, "--debug")
    assert code == 1 and "Traceback" in err and err.strip().endswith("the file has 2 vertices")
    code, _, err = run(capsys, "info", tmp_path / "missing.ply")
    assert code == 1 and one_error_line(err).endswith("missing.ply: no such file")


def test_library_option_errors_are_usage_errors_and_bugs_are_one_line(capsys, torus_file, monkeypatch):
    def refuses(*args, **kwargs):
        raise meshcurv.InvalidOptionError("`radius` must be a positive finite number; got inf")

    monkeypatch.setattr("meshcurv.cli._common.principal_curvatures", refuses)
    code, _, err = run(capsys, "compute", torus_file)
    assert code == 2 and one_error_line(err) == "meshcurv: error: `radius` must be a positive finite number; got inf"

    def breaks(*args, **kwargs):
        raise RuntimeError("boom")

    monkeypatch.setattr("meshcurv.cli._common.principal_curvatures", breaks)
    code, _, err = run(capsys, "compute", torus_file)
    assert code == 1
    assert one_error_line(err) == "meshcurv: error: unexpected RuntimeError: boom (run with --debug for the traceback)"


def test_usage_errors_exit_2(capsys):
    assert run(capsys, "frobnicate")[0] == 2
    code, out, err = run(capsys)
    assert code == 2 and "Usage: meshcurv" in out + err
    code, out, _ = run(capsys, "--help")
    assert code == 0 and "compute" in out and "methods" in out
    code, out, _ = run(capsys, "--version")
    assert code == 0 and out.startswith(f"meshcurv {meshcurv.__version__} (backend ")
    backend = "numba" if importlib.util.find_spec("numba") else "numpy"
    assert f"backend {backend}, numba " in out


# ---------------------------------------------------------------- messages: warnings, logging, progress


def test_warnings_are_one_line_and_quiet_hides_them(capsys, saddle_file):
    # normal_cycle leaves the rim of an open mesh undefined and says so (icc keeps it, silently)
    code, out, err = run(capsys, "compute", saddle_file, "--method", "normal_cycle")
    assert code == 0 and "invalid vertices" in out
    warning_lines = [line for line in err.splitlines() if line.startswith("meshcurv: warning: ")]
    assert len(warning_lines) == 1 and "boundary" in warning_lines[0]
    code, _, err = run(capsys, "compute", saddle_file, "--method", "normal_cycle", "-q")
    assert code == 0 and err == ""
    code, _, err = run(capsys, "compute", saddle_file)
    assert code == 0 and err == ""


def test_verbose_logs_the_stages_and_the_logger_is_restored(capsys, torus_file):
    logger = logging.getLogger("meshcurv")
    level, handlers = logger.level, list(logger.handlers)
    code, _, err = run(capsys, "-v", "compute", torus_file)
    assert code == 0
    assert f"meshcurv: read {torus_file}: 3600 vertices, 7200 faces" in err
    assert "fit normals (3/6)" in err
    assert logger.level == level and logger.handlers == handlers
    code, _, err = run(capsys, "compute", torus_file, "-vv")
    assert "meshcurv: meshcurv.io: read" in err


def test_progress_only_when_asked_or_on_a_terminal(capsys, torus_file, monkeypatch):
    code, _, err = run(capsys, "compute", torus_file)
    assert err == ""
    code, _, err = run(capsys, "compute", torus_file, "--progress")
    lines = err.splitlines()
    steps = 2 + len(ESTIMATORS[DEFAULT_METHOD].stages)  # read, the method's stages, summary
    assert lines[0] == f"meshcurv: [........................] 1/{steps} read"
    assert lines[-1].endswith(f"{steps}/{steps} summary") and len(lines) == steps
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True, raising=False)
    code, _, err = run(capsys, "compute", torus_file)
    assert "\r\x1b[K[" in err and f"{steps}/{steps} summary" in err and err.endswith("\r\x1b[K")
    code, _, err = run(capsys, "compute", torus_file, "--no-progress")
    assert err == ""


def test_failures_are_listed_ten_at_most_and_the_rest_counted(capsys):
    # batch (meshes) and volume (labels) list their failures through the one helper
    from meshcurv.cli._common import report_failures

    names = [f"label {n}" for n in range(1, 13)]
    report_failures(names, [f"error {n}" for n in range(1, 13)], "the table")
    out, err = capsys.readouterr()
    lines = err.splitlines()
    assert out == "" and len(lines) == 11
    assert lines[0] == "meshcurv: failed: label 1: error 1" and lines[9] == "meshcurv: failed: label 10: error 10"
    assert lines[10] == "meshcurv: ... and 2 more (see the table)"
    report_failures(names[:3], ["a", "b", "c"], "the summary")
    assert capsys.readouterr().err.splitlines() == [
        f"meshcurv: failed: label {n}: {e}" for n, e in zip((1, 2, 3), "abc")
    ]


# ---------------------------------------------------------------- plot, demo


def test_plot_writes_a_png_named_after_the_mesh(capsys, small_torus_file, tmp_path, monkeypatch):
    pytest.importorskip("matplotlib")
    monkeypatch.chdir(tmp_path)
    code, _, err = run(
        capsys, "plot", small_torus_file, "--field", "gaussian", "--directions", "both", "--up", "z", "--pixels", "200"
    )
    assert code == 0 and err.strip() == "meshcurv: wrote small_gaussian.png"
    assert (tmp_path / "small_gaussian.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    code, _, err = run(capsys, "plot", small_torus_file, "--field", "gaussian")
    assert code == 1 and "small_gaussian.png: already exists" in one_error_line(err)
    code, _, _ = run(
        capsys,
        "plot",
        small_torus_file,
        "-o",
        tmp_path / "two.png",
        "--view",
        "iso,top",
        "--view",
        "20,45",
        "--percentiles",
        "5,95",
        "--pixels",
        "120",
    )
    assert code == 0 and (tmp_path / "two.png").exists()


def png_size(path):
    data = pathlib.Path(path).read_bytes()
    return int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")


@pytest.mark.slow  # 6 s: four pictures
def test_plot_size_colour_map_limits_and_up(capsys, small_torus_file, tmp_path):
    pytest.importorskip("matplotlib")
    # --pixels: the width of the PNG, exactly; --dpi: (3.3 n + 1.2) x 4.2 inches for n views
    code, _, err = run(
        capsys, "plot", small_torus_file, "-o", tmp_path / "wide.png", "--view", "iso", "--pixels", "1200", "--up", "z"
    )
    assert code == 0 and png_size(tmp_path / "wide.png")[0] == 1200
    code, _, _ = run(
        capsys,
        "plot",
        small_torus_file,
        "-o",
        tmp_path / "dpi.png",
        "--view",
        "iso,top",
        "--dpi",
        "60",
        "--cmap",
        "cividis",
        "--limits",
        "-0.01,0.02",
    )
    assert code == 0 and png_size(tmp_path / "dpi.png") == (round(7.8 * 60), round(4.2 * 60))
    # the default: 150 dpi; the up axis chosen from the mesh (a torus around z: 0.25 times as tall along z as y)
    code, _, err = run(capsys, "plot", small_torus_file, "-o", tmp_path / "default.png", "--view", "iso")
    assert code == 0 and png_size(tmp_path / "default.png") == (round(4.5 * 150), round(4.2 * 150))
    assert "(up axis y, chosen from the mesh: the mesh is 0.25 times as tall along z as along y" in err


def test_plot_bad_options(capsys, small_torus_file, tmp_path):
    pytest.importorskip("matplotlib")
    for options, message in [
        (["--dpi", "100", "--pixels", "800"], "give --dpi or --pixels, not both"),
        (["--limits", "-1,1", "--percentiles", "5,95"], "give --limits or --percentiles, not both"),
        (["--limits", "1,-1"], "need finite LOW < HIGH"),
        (["--limits", "wide"], "give two numbers as LOW,HIGH"),
        (["--cmap", "no-such-map"], "unknown colour map 'no-such-map'"),
        (["--dpi", "5"], "5 is not in the range 10<=x<=1200"),
        (["--view", "sideways"], "unknown view 'sideways'"),
        (["--percentiles", "98,2"], "need 0 <= LOW < HIGH <= 100"),
        (["--percentiles", "lots"], "give two percentiles as LOW,HIGH"),
        (["-o", tmp_path / "x.jpg"], "the picture is a PNG; got 'x.jpg'"),
        (["--field", "normals"], "'normals' is not one of"),
    ]:
        code, _, err = run(capsys, "plot", small_torus_file, *options)
        assert code == 2 and message in err, (options, err)


def test_plot_an_open_mesh(capsys, saddle_file, tmp_path):
    pytest.importorskip("matplotlib")
    code, _, _ = run(capsys, "plot", saddle_file, "-o", tmp_path / "saddle.png", "--up", "z", "-q", "--pixels", "120")
    assert code == 0 and (tmp_path / "saddle.png").exists()


def test_demo_command(capsys, tmp_path):
    pytest.importorskip("matplotlib")
    output = tmp_path / "demo" / "torus.png"
    code, out, _ = run(capsys, "demo", output)
    assert code == 0 and "3600 vertices" in out and output.exists()
    code, _, err = run(capsys, "demo", output)
    assert code == 1 and "already exists" in one_error_line(err)
    assert run(capsys, "demo", output, "--overwrite")[0] == 0


def test_missing_click_names_the_extra(capsys, monkeypatch):
    real_import = builtins.__import__

    def no_click(name, *args, **kwargs):
        if name == "click" or name.startswith("click."):
            raise ImportError(name, name="click")
        return real_import(name, *args, **kwargs)

    for name in [name for name in sys.modules if name.startswith("meshcurv.cli._")]:
        monkeypatch.delitem(sys.modules, name)
    monkeypatch.delattr(meshcurv.cli, "_app")
    monkeypatch.setattr(builtins, "__import__", no_click)
    code, _, err = run(capsys, "methods")
    assert code == 1 and one_error_line(err) == (
        "meshcurv: error: the command line needs click (a dependency of "
        "meshcurv that cannot be imported): pip install click"
    )


# ---------------------------------------------------------------- real processes


def test_installed_entry_point_runs_as_a_process(torus_file):
    script = pathlib.Path(sys.executable).parent / "meshcurv"
    if not script.exists():
        pytest.skip("meshcurv is not installed as a script in this environment")
    done = subprocess.run([script, "info", torus_file], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0 and "genus                  1" in done.stdout
    done = subprocess.run(
        [script, "compute", torus_file.with_name("none.obj")], capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 1 and done.stderr.strip().endswith("none.obj: no such file")
    done = subprocess.run([sys.executable, "-m", "meshcurv", "--version"], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0 and meshcurv.__version__ in done.stdout


def test_a_command_run_without_the_session_says_how_to_run_it():
    click_testing = pytest.importorskip("click.testing")
    from meshcurv.cli._app import meshcurv as group

    result = click_testing.CliRunner().invoke(group, ["methods"])  # no obj: not through meshcurv.cli.main
    assert isinstance(result.exception, RuntimeError)
    assert "no meshcurv Session in the click context: run the commands through meshcurv.cli.main" in str(
        result.exception
    )


def test_a_quad_mesh_is_triangulated_once_and_said_once(capsys, tmp_path):
    # a cube of six quads: the CLI triangulates it once and hands the topology to the estimate
    corners = [(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]
    quads = [(1, 2, 4, 3), (5, 6, 8, 7), (1, 5, 7, 3), (2, 4, 8, 6), (1, 2, 6, 5), (3, 7, 8, 4)]
    path = tmp_path / "cube.obj"
    path.write_text(
        "".join(f"v {x} {y} {z}\n" for x, y, z in corners) + "".join(f"f {a} {b} {c} {d}\n" for a, b, c, d in quads)
    )
    code, out, err = run(capsys, "compute", path, "-m", "normal_cycle")
    assert code == 0 and "8 vertices, 6 faces" in out
    assert err.count("forces triangulation") == 1, err


def test_info_describes_a_point_cloud(capsys, tmp_path):
    grid = np.stack(np.meshgrid(np.arange(4.0), np.arange(3.0), [0.0, 2.0], indexing="ij"), -1).reshape(-1, 3) * 0.5
    rows = np.vstack([grid, grid[:2], [[np.nan, 0, 0]]])  # 24 grid points spaced 0.5 and 1, 2 copies, 1 NaN
    path = tmp_path / "grid.xyz"
    path.write_text("".join(f"{x} {y} {z}\n" for x, y, z in rows))
    code, out, err = run(capsys, "info", path)
    assert code == 0 and err == ""
    facts = dict(line.split("  ", 1) for line in out.splitlines())
    facts = {key.strip(): value.strip() for key, value in facts.items()}
    assert facts["points"] == "27" and facts["non-finite points"] == "1"
    assert facts["repeated points"].startswith("2 ") and facts["normals"].startswith("none")
    assert facts["bounding box"] == "(0, 0, 0) to (1.5, 1, 1) (size (1.5, 1, 1))"
    assert facts["spacing"].startswith("0.5 ")
