"""meshcurv.batch and ``meshcurv batch``: real Dask clusters on 127.0.0.1, real files, real processes.

The clusters: one ``distributed.LocalCluster`` of two worker processes shared by
the module, a scheduler and a worker started with the ``dask`` command, and the
local cluster that ``meshcurv batch`` starts itself in a subprocess.
Expected values come from the construction of the meshes (vertex and face
counts, triangle areas, boundary edges) and from geometry (sphere, torus).
"""

import io
import json
import os
import pathlib
import signal
import socket
import subprocess
import sys
import time

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes
from meshcurv.errors import InvalidOptionError, MeshFileError, MissingDependencyError

distributed = pytest.importorskip("distributed")
pd = pytest.importorskip("pandas")
pytest.importorskip("pyarrow")
pytest.importorskip("click")
pytest.importorskip("meshio")  # the default result format, PLY

from meshcurv import batch  # noqa: E402
from meshcurv.cli import main  # noqa: E402

LOOPBACK = "127.0.0.1"
MESHCURV = [sys.executable, "-m", "meshcurv"]
DASK = [sys.executable, "-m", "dask"]
RADII = (0.5, 1.0, 2.0, 4.0)


# ---------------------------------------------------------------------------------------------- meshes


def triangle_area(vertices, faces):
    corners = np.asarray(vertices)[np.asarray(faces)]
    return np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1).sum() / 2


def enclosed_volume(vertices, faces):
    """Signed volume of a closed mesh, from its triangles (divergence theorem)."""
    corners = np.asarray(vertices)[np.asarray(faces)]
    return np.einsum("ij,ij->i", corners[:, 0], np.cross(corners[:, 1], corners[:, 2])).sum() / 6


def two_spheres():
    first, second = shapes.icosphere(4, radius=1.0), shapes.icosphere(4, radius=1.0, center=(5, 0, 0))
    vertices = np.concatenate([first.vertices, second.vertices])
    faces = np.concatenate([first.faces, second.faces + len(first.vertices)])
    return vertices, faces


def write_dozen(folder: pathlib.Path) -> dict:
    """Eleven good meshes in six formats and one corrupt file; returns what each good one is, by name."""
    folder.mkdir()
    expected = {}

    def add(name, vertices, faces, **facts):
        meshcurv.write_mesh(folder / name, vertices, faces)
        expected[name] = dict(
            n_vertices=len(vertices),
            n_faces=len(faces),
            area=triangle_area(vertices, faces),
            volume=enclosed_volume(vertices, faces) if facts["n_boundary_loops"] == 0 else None,
            n_invalid=0,
            **facts,
        )  # icc keeps the boundary vertices of the open ones

    for radius, extension in zip(RADII, (".obj", ".off", ".ply", ".npz")):
        sphere = shapes.icosphere(8, radius=radius)
        add(
            f"sphere_{radius:g}{extension}",
            sphere.vertices,
            sphere.faces,
            euler_characteristic=2,
            n_components=1,
            n_boundary_loops=0,
            radius=radius,
        )
    irregular = shapes.random_sphere(500, radius=3.0, seed=1)
    add(
        "random_sphere.vtp",
        irregular.vertices,
        irregular.faces,
        euler_characteristic=2,
        n_components=1,
        n_boundary_loops=0,
    )
    torus = shapes.torus(30, 10, 24, 12)
    add("torus.off", torus.vertices, torus.faces, euler_characteristic=0, n_components=1, n_boundary_loops=0)
    half = shapes.hemisphere(8, radius=2.0)
    add("hemisphere.obj", half.vertices, half.faces, euler_characteristic=1, n_components=1, n_boundary_loops=1)
    tube = shapes.cylinder(1.0, 2.0, 16, 8)
    add("tube.ply", tube.vertices, tube.faces, euler_characteristic=0, n_components=1, n_boundary_loops=2)
    add("two_spheres.obj", *two_spheres(), euler_characteristic=4, n_components=2, n_boundary_loops=0)
    egg = shapes.ellipsoid((3.0, 2.0, 1.0), subdivisions=6)
    add("ellipsoid.obj", egg.vertices, egg.faces, euler_characteristic=2, n_components=1, n_boundary_loops=0)
    saddle = shapes.saddle(1.0, 0.1)
    add("saddle.obj", saddle.vertices, saddle.faces, euler_characteristic=1, n_components=1, n_boundary_loops=1)
    (folder / "corrupt.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1\nf 1 2 3\n")  # a vertex line cut short
    return expected


def write_spheres(folder: pathlib.Path, count: int, subdivisions: int, *, extension=".ply") -> list[pathlib.Path]:
    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    for index in range(count):
        sphere = shapes.icosphere(subdivisions, radius=1.0 + index)
        paths.append(meshcurv.write_mesh(folder / f"sphere_{index:03d}{extension}", sphere.vertices, sphere.faces))
    return paths


def leftovers(out_dir: pathlib.Path) -> list[str]:
    """Hidden files (temporaries) anywhere below ``out_dir``, the record folder itself aside."""
    return sorted(os.fspath(path.relative_to(out_dir)) for path in out_dir.rglob(".*") if path.name != batch.RECORDS)


def assert_complete_npz(path: pathlib.Path, n_vertices: int):
    with np.load(path) as archive:
        assert archive["vertices"].shape == (n_vertices, 3)
        for name in ("k_min", "k_max", "mean", "gaussian", "valid"):
            assert archive[name].shape == (n_vertices,), name


# ---------------------------------------------------------------------------------------------- clusters


@pytest.fixture(scope="module")
def client():
    """The local cluster run() starts (two worker processes on 127.0.0.1), without its dashboard."""
    before = dict(os.environ)
    with batch.local_cluster(workers=2, dashboard=False) as client:
        client.environment_before = before
        yield client
    assert dict(os.environ) == before  # what Dask wrote there to start the workers is put back


@pytest.fixture(scope="module")
def dozen(tmp_path_factory):
    folder = tmp_path_factory.mktemp("dozen") / "meshes"
    return folder, write_dozen(folder)


@pytest.fixture(scope="module")
def first_run(client, dozen, tmp_path_factory):
    folder, expected = dozen
    out_dir = tmp_path_factory.mktemp("first") / "out"
    calls = []
    summary = batch.run([folder], out_dir, client=client, progress=lambda *counts: calls.append(counts))
    written = {suffix: (out_dir / f"summary{suffix}").read_bytes() for suffix in (".parquet", ".csv")}
    return summary, out_dir, calls, written


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind((LOOPBACK, 0))
        return probe.getsockname()[1]


def stop(process: subprocess.Popen) -> None:
    if process.poll() is None:
        process.terminate()
        try:
            process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


@pytest.fixture(scope="module")
def dask_cluster(tmp_path_factory):
    """``dask scheduler`` and ``dask worker`` as separate processes on 127.0.0.1 and free ports; always stopped."""
    logs = tmp_path_factory.mktemp("dask")
    address = f"tcp://{LOOPBACK}:{free_port()}"
    environment = {**os.environ, **batch.WORKER_ENVIRONMENT}
    processes = []
    try:
        with open(logs / "scheduler.log", "w") as log:
            processes.append(
                subprocess.Popen(
                    [
                        *DASK,
                        "scheduler",
                        "--host",
                        LOOPBACK,
                        "--port",
                        address.rsplit(":", 1)[1],
                        "--dashboard-address",
                        f"{LOOPBACK}:{free_port()}",
                    ],
                    stdout=subprocess.DEVNULL,
                    stderr=log,
                    env=environment,
                )
            )
        with open(logs / "worker.log", "w") as log:
            processes.append(
                subprocess.Popen(
                    [
                        *DASK,
                        "worker",
                        address,
                        "--host",
                        LOOPBACK,
                        "--nthreads",
                        "1",
                        "--nworkers",
                        "1",
                        "--no-dashboard",
                    ],
                    stdout=subprocess.DEVNULL,
                    stderr=log,
                    env=environment,
                )
            )
        with distributed.Client(address, timeout=60) as probe:
            probe.wait_for_workers(1, timeout=60)
        yield address
    finally:
        for process in reversed(processes):
            stop(process)


# ---------------------------------------------------------------------------------------------- inputs


def test_expand_inputs_takes_files_folders_and_patterns_sorted_once(tmp_path):
    for name in ("b.obj", "a.ply", "c.OFF", ".hidden.obj", "notes.txt", "sub/d.obj", "sub/deeper/e.vtp", "out/f.obj"):
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text("")
    found = batch.expand_inputs(
        [tmp_path, tmp_path / "b.obj", f"{tmp_path}/**/*.obj", tmp_path / "notes.txt"], exclude=tmp_path / "out"
    )
    relative = [os.fspath(path.relative_to(tmp_path)) for path in found]
    # the folder: its mesh files, not hidden ones nor notes.txt; the pattern crosses folders but not out/;
    # notes.txt named explicitly is kept (its error will be in the summary); b.obj once
    assert relative == ["a.ply", "b.obj", "c.OFF", "notes.txt", "sub/d.obj"]


def test_expand_inputs_refuses_what_names_nothing(tmp_path):
    with pytest.raises(MeshFileError, match="missing.obj: no such file or folder"):
        batch.expand_inputs([tmp_path / "missing.obj"])
    with pytest.raises(MeshFileError, match=r"\*\.ply: the pattern matches no mesh file"):
        batch.expand_inputs([f"{tmp_path}/*.ply"])
    with pytest.raises(MeshFileError, match="no mesh file found in"):
        batch.expand_inputs(tmp_path)


def test_run_refuses_bad_options_before_any_work(tmp_path):
    sphere = shapes.icosphere(2)
    folder = tmp_path / "in"
    folder.mkdir()
    meshcurv.write_mesh(folder / "x.obj", sphere.vertices, sphere.faces)
    out_dir = tmp_path / "out"
    dead = f"tcp://{LOOPBACK}:9"  # nothing listens there: any attempt to connect would fail the test
    with pytest.raises(InvalidOptionError, match="give `client` or `scheduler`, not both"):
        batch.run(folder, out_dir, client=object(), scheduler=dead)
    with pytest.raises(InvalidOptionError, match="`workers` sizes the local cluster"):
        batch.run(folder, out_dir, scheduler=dead, workers=2)
    with pytest.raises(InvalidOptionError, match=r"`workers` must be an integer between 1 and 1024; got 0"):
        batch.run(folder, out_dir, workers=0)
    with pytest.raises(InvalidOptionError, match="unknown method 'gauss'"):
        batch.run(folder, out_dir, scheduler=dead, method="gauss")
    with pytest.raises(InvalidOptionError, match="method 'normal_cycle' does not take the option `radius`"):
        batch.run(folder, out_dir, scheduler=dead, method="normal_cycle", radius=0.1)
    with pytest.raises(InvalidOptionError, match="method 'icc' does not take the option `smoothing_steps`"):
        batch.run(folder, out_dir, scheduler=dead, smoothing_steps=2)
    with pytest.raises(InvalidOptionError, match="`radius` must be a positive finite number"):
        batch.run(folder, out_dir, scheduler=dead, radius=-1.0)
    with pytest.raises(InvalidOptionError, match="unknown orient 'inward'"):
        batch.run(folder, out_dir, scheduler=dead, orient="inward")
    with pytest.raises(InvalidOptionError, match="unknown output_format 'obj'"):
        batch.run(folder, out_dir, scheduler=dead, output_format="obj")
    # were TypeErrors: dask's on connecting, and the first call of `progress` once the cluster ran
    with pytest.raises(InvalidOptionError, match=r"`scheduler` must be an address such as 'tcp://host:8786'; got 8786"):
        batch.run(folder, out_dir, scheduler=8786)
    with pytest.raises(InvalidOptionError, match=r"`progress` must be a function of \(done, total, failed\); got 5"):
        batch.run(folder, out_dir, scheduler=dead, progress=5)
    (tmp_path / "file").write_text("")
    with pytest.raises(MeshFileError, match="file: is a file; the output must be a folder"):
        batch.run(folder, tmp_path / "file", scheduler=dead)
    assert not out_dir.exists()


BAD_OPTIONS = [
    {"method": "gauss"},
    {"method": None},
    {"method": "normal_cycle", "radius": 0.1, "smoothing_steps": -1},  # the option first, then its value
    {"method": "normal_cycle", "smoothing_steps": 10**6},  # above MAX_SMOOTHING_STEPS
    {"method": "matgeom", "smoothing_steps": True},
    {"method": "matgeom", "smoothing_steps": 2.0},
    {"radius": "0.5"},
    {"radius": float("nan")},
    {"radius": 1e-320},  # subnormal
    {"method": "quadric", "radius": "adaptive"},  # icc only
    {"orient": "inward"},
]


@pytest.mark.parametrize("options", BAD_OPTIONS, ids=lambda options: ",".join(f"{k}={v!r}" for k, v in options.items()))
def test_run_refuses_exactly_what_principal_curvatures_refuses(tmp_path, options):
    sphere = shapes.icosphere(2)
    folder = tmp_path / "in"
    folder.mkdir()
    meshcurv.write_mesh(folder / "x.obj", sphere.vertices, sphere.faces)
    with pytest.raises(InvalidOptionError) as call:
        meshcurv.principal_curvatures(sphere.vertices, sphere.faces, **options)
    dead = f"tcp://{LOOPBACK}:9"  # nothing listens there: any attempt to connect would fail the test
    with pytest.raises(InvalidOptionError) as run:
        batch.run(folder, tmp_path / "out", scheduler=dead, **options)
    assert str(run.value) == str(call.value)
    assert not (tmp_path / "out").exists()


def test_run_refuses_inputs_that_would_share_a_result(tmp_path):
    sphere = shapes.icosphere(2)
    folder = tmp_path / "in"
    folder.mkdir()
    for name in ("x.obj", "x.off", "summary.obj"):
        meshcurv.write_mesh(folder / name, sphere.vertices, sphere.faces)
    dead = f"tcp://{LOOPBACK}:9"
    with pytest.raises(InvalidOptionError, match=r"x\.obj and .*x\.off would both be written to .*x\.ply"):
        batch.run(folder, tmp_path / "out", scheduler=dead)
    with pytest.raises(
        InvalidOptionError, match=r"the summary and .*summary\.obj would both be written to .*summary\.csv"
    ):
        batch.run(folder / "summary.obj", tmp_path / "out", scheduler=dead, output_format="csv")


def test_folders_below_a_common_one_are_kept_in_the_output(tmp_path, client):
    sphere = shapes.icosphere(2)
    for name in ("a/x.obj", "b/x.obj"):
        (tmp_path / name).parent.mkdir()
        meshcurv.write_mesh(tmp_path / name, sphere.vertices, sphere.faces)
    summary = batch.run([tmp_path / "a", tmp_path / "b"], tmp_path / "out", client=client, output_format="npz")
    assert summary["output"].tolist() == [os.fspath(tmp_path / "out" / name) for name in ("a/x.npz", "b/x.npz")]
    for name in ("a/x.npz", "b/x.npz"):
        assert_complete_npz(tmp_path / "out" / name, len(sphere.vertices))


def test_missing_dask_names_the_extra(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)  # what `import distributed` meets when it is not installed
    with pytest.raises(MissingDependencyError, match=r"needs distributed: pip install 'meshcurv\[batch\]'"):
        batch.run(tmp_path, tmp_path / "out")


# ---------------------------------------------------------------------------------------------- a local cluster


def test_local_cluster_workers_keep_to_one_thread_and_fast_memory(client):
    names = ("OMP_NUM_THREADS", "NUMBA_NUM_THREADS", "MALLOC_TRIM_THRESHOLD_", "MALLOC_ARENA_MAX")
    found = client.run(lambda: [os.environ.get(name) for name in names])
    assert len(found) == 2
    for values in found.values():
        # one thread each; glibc's trimming as in this process (unset here unless the environment sets it)
        assert values == ["1", "1", client.environment_before.get("MALLOC_TRIM_THRESHOLD_"), "1"]
    assert not any(client.run(lambda: __import__("dask").config.get("distributed.worker.profile.enabled")).values())
    assert [info["nthreads"] for info in client.scheduler_info()["workers"].values()] == [1, 1]
    assert all(address.startswith(f"tcp://{LOOPBACK}:") for address in client.scheduler_info()["workers"])


def test_every_good_mesh_has_its_result_and_row_and_the_corrupt_one_its_error(first_run, dozen):
    summary, out_dir, calls, _ = first_run
    folder, expected = dozen
    assert len(summary) == 12
    rows = summary.set_index(summary["path"].map(lambda path: pathlib.Path(path).name))
    for name in expected:
        assert rows.loc[name, "status"] == "computed", rows.loc[name, "error"]
        assert rows.loc[name, "error"] == ""
        output = out_dir / (pathlib.Path(name).stem + ".ply")
        assert rows.loc[name, "output"] == os.fspath(output)
        vertices, faces = meshcurv.read_mesh(output)
        assert len(vertices) == expected[name]["n_vertices"]
    bad = rows.loc["corrupt.obj"]
    assert bad["status"] == "failed"
    assert bad["error"].startswith("MeshFileError: ") and "corrupt.obj" in bad["error"]
    assert pd.isna(bad["n_vertices"]) and np.isnan(bad["area"]) and bad["output"] == ""
    assert not (out_dir / "corrupt.ply").exists()
    assert leftovers(out_dir) == []
    # progress: once before any mesh, then once per mesh, the last with every mesh and the one failure
    assert calls[0] == (0, 12, 0) and calls[-1] == (12, 12, 1) and len(calls) == 13


def test_rows_follow_the_construction_and_the_geometry(first_run, dozen):
    summary, _, _, _ = first_run
    _, expected = dozen
    rows = summary.set_index(summary["path"].map(lambda path: pathlib.Path(path).name))
    for name, facts in expected.items():
        row = rows.loc[name]
        for key in ("n_vertices", "n_faces", "euler_characteristic", "n_components", "n_boundary_loops", "n_invalid"):
            assert row[key] == facts[key], (name, key)
        assert row["area"] == pytest.approx(facts["area"], rel=1e-9), name  # the sum of the triangle areas
        if facts["volume"] is None:
            assert np.isnan(row["volume"]), name  # a volume for closed meshes only
        else:
            assert row["volume"] == pytest.approx(facts["volume"], rel=1e-9), name
        assert row["seconds"] > 0
        for field in batch.SUMMARY_FIELDS:
            assert row[f"{field}_p5"] <= row[f"{field}_median"] <= row[f"{field}_p95"], (name, field)
            assert row[f"{field}_area_p5"] <= row[f"{field}_area_median"] <= row[f"{field}_area_p95"], (name, field)
        if facts["volume"] is not None:  # closed: Gauss-Bonnet, exact
            chi = facts["euler_characteristic"]
            assert abs(row["total_gaussian"] - 2 * np.pi * chi) < 1e-9 * 4 * np.pi, name
    for radius in RADII:
        row = next(rows.loc[name] for name, facts in expected.items() if facts.get("radius") == radius)
        # an icosphere with 642 vertices: its area and volume are those of the sphere within 1% (0.5% and
        # 1.4% below them, an inscribed polyhedron), its curvatures within 1% (the README's accuracy)
        assert row["area"] == pytest.approx(4 * np.pi * radius**2, rel=0.01)
        assert row["volume"] == pytest.approx(4 / 3 * np.pi * radius**3, rel=0.02)
        for field, exact in (
            ("k_min", 1 / radius),
            ("k_max", 1 / radius),
            ("mean", 1 / radius),
            ("gaussian", 1 / radius**2),
            ("curvedness", 1 / radius),
            ("shape_index", 1.0),
        ):
            assert row[f"{field}_median"] == pytest.approx(exact, rel=0.01), (radius, field)
            assert row[f"{field}_mean"] == pytest.approx(exact, rel=0.01), (radius, field)
            assert row[f"{field}_area_median"] == pytest.approx(exact, rel=0.01), (radius, field)
            assert row[f"{field}_area_mean"] == pytest.approx(exact, rel=0.01), (radius, field)
        # int H dA = 4 pi R and int H^2 dA = 4 pi, within the inscribed polyhedron's 1% (see test_integrals)
        assert row["total_mean"] == pytest.approx(4 * np.pi * radius, rel=0.01)
        assert row["willmore"] == pytest.approx(4 * np.pi, rel=0.01)
    # torus R 30, r 10 of 24 x 12 quads: a 12-gon has sin(30 deg) / (pi / 6) = 95.5% of its circle's area and
    # a 24-gon 98.9%, so the polyhedron's volume is 94% of 2 pi^2 R r^2 and its area 98% of 4 pi^2 R r
    torus = rows.loc["torus.off"]
    assert torus["area"] == pytest.approx(4 * np.pi**2 * 30 * 10, rel=0.03)
    assert torus["volume"] == pytest.approx(2 * np.pi**2 * 30 * 10**2, rel=0.07)


def test_the_summary_files_hold_the_table_ordered_by_path(first_run):
    summary, out_dir, _, written = first_run
    assert summary["path"].tolist() == sorted(summary["path"])
    assert list(summary.columns) == list(batch.COLUMNS)
    from_parquet = pd.read_parquet(io.BytesIO(written[".parquet"]))  # as written by the first run
    pd.testing.assert_frame_equal(from_parquet, summary)
    from_csv = pd.read_csv(io.BytesIO(written[".csv"]))
    assert list(from_csv.columns) == list(batch.COLUMNS)
    assert from_csv["path"].tolist() == summary["path"].tolist()
    for column in ("area", "volume", "mean_median", "n_vertices"):  # every digit, and empty where missing
        np.testing.assert_array_equal(
            from_csv[column].to_numpy(float), summary[column].to_numpy(float, na_value=np.nan)
        )
    assert from_csv["error"].fillna("").tolist() == summary["error"].tolist()


def test_a_second_run_does_no_work(first_run, dozen, client):
    summary, out_dir, _, written = first_run
    folder, expected = dozen
    before = {path: path.stat() for path in out_dir.glob("*.ply")}
    again = batch.run([folder], out_dir, client=client)
    # the corrupt file is tried again (it may have been repaired); the others are not touched
    assert again["status"].tolist() == [
        "failed" if name == "corrupt.obj" else "skipped"
        for name in again["path"].map(lambda path: pathlib.Path(path).name)
    ]
    after = {path: path.stat() for path in out_dir.glob("*.ply")}
    assert {path: (s.st_ino, s.st_mtime_ns) for path, s in after.items()} == {
        path: (s.st_ino, s.st_mtime_ns) for path, s in before.items()
    }
    columns = [column for column in batch.COLUMNS if column != "status"]
    good = again["status"] == "skipped"  # their rows are those recorded then, seconds included
    pd.testing.assert_frame_equal(again.loc[good, columns], summary.loc[good, columns])
    # without the corrupt file there is nothing to do: not even a connection (nothing listens on port 9)
    quiet = batch.run(sorted(folder / name for name in expected), out_dir, scheduler=f"tcp://{LOOPBACK}:9")
    assert (quiet["status"] == "skipped").all() and len(quiet) == 11


def test_a_record_of_an_older_meshcurv_is_computed_again(tmp_path, client):
    paths = write_spheres(tmp_path / "in", 2, 3)
    out_dir = tmp_path / "out"
    batch.run(paths, out_dir, client=client)
    path = out_dir / batch.RECORDS / "sphere_000.ply.json"
    record = json.loads(path.read_text())
    del record["row"]["total_gaussian"]  # as written before the integrals were in the table
    path.write_text(json.dumps(record))
    again = batch.run(paths, out_dir, client=client)
    assert again["status"].tolist() == ["computed", "skipped"]
    assert again["total_gaussian"].to_numpy() == pytest.approx([4 * np.pi] * 2, rel=1e-9)


def test_overwrite_and_results_of_other_options(tmp_path, client):
    paths = write_spheres(tmp_path / "in", 2, 4)
    out_dir = tmp_path / "out"
    batch.run(paths, out_dir, client=client, method="icc")  # the default, spelt out
    first = (out_dir / "sphere_000.ply").stat()
    # the same computation asked without the default: skipped
    assert (batch.run(paths, out_dir, client=client)["status"] == "skipped").all()
    with pytest.raises(
        InvalidOptionError,
        match=r"holds results computed with method='icc', not "
        r"method='icc', radius=0.3; pass overwrite=True",
    ):
        batch.run(paths, out_dir, client=client, radius=0.3)
    redone = batch.run(paths, out_dir, client=client, radius=0.3, overwrite=True)
    assert (redone["status"] == "computed").all()
    assert (out_dir / "sphere_000.ply").stat().st_ino != first.st_ino
    record = json.loads((out_dir / batch.RECORDS / "sphere_000.ply.json").read_text())
    assert record["options"] == {"method": "icc", "radius": 0.3}
    # a file of the same name that no batch wrote is not replaced silently
    small = shapes.icosphere(2)
    meshcurv.write_mesh(tmp_path / "in" / "sphere_002.ply", small.vertices, small.faces)
    meshcurv.write_mesh(out_dir / "sphere_002.ply", small.vertices, small.faces)
    with pytest.raises(MeshFileError, match=r"sphere_002\.ply: exists but was not written by meshcurv batch"):
        batch.run(tmp_path / "in", out_dir, client=client, radius=0.3)


@pytest.mark.slow
def test_a_worker_killed_mid_run_has_its_meshes_run_again(tmp_path, client):
    paths = write_spheres(tmp_path / "in", 10, 24)  # 5762 vertices: long enough to be killed while computing
    out_dir = tmp_path / "out"
    killed = []

    def kill_a_busy_worker(done, total, failed):
        if done >= 1 and not killed:
            busy = [address for address, keys in client.processing().items() if keys]
            pid = client.run(os.getpid, workers=busy[:1])[busy[0]]
            os.kill(pid, signal.SIGKILL)
            killed.append((busy[0], pid))

    summary = batch.run(paths, out_dir, client=client, output_format="npz", progress=kill_a_busy_worker)
    assert killed, "no worker was busy"
    assert (summary["status"] == "computed").all(), summary["error"].tolist()
    for path in paths:
        assert_complete_npz(out_dir / (path.stem + ".npz"), 5762)
    assert leftovers(out_dir) == []
    client.wait_for_workers(2, timeout=60)  # the nanny has started a new worker in its place
    assert killed[0][1] not in client.run(os.getpid).values()


def test_small_meshes_travel_in_chunks_in_path_order(tmp_path, monkeypatch):
    paths = write_spheres(tmp_path / "in", 40, 4)
    jobs = batch._inputs._plan(paths, tmp_path / "out", ".npz")
    chunks = batch._run._chunks(jobs, list(range(40)), workers=2)
    assert [index for chunk in chunks for index in chunk] == list(range(40))
    assert len(chunks) == 2 * batch.CHUNKS_PER_WORKER and {len(chunk) for chunk in chunks} == {2, 3}
    assert batch._run._chunks(jobs, [5, 7, 9], workers=2) == [[5], [7], [9]]  # fewer meshes than tasks
    # the byte budget: two files fit, not three; a file larger than the budget is a task of its own
    size = os.path.getsize(paths[0])
    monkeypatch.setattr(batch._run, "CHUNK_BYTES", 2 * size)
    assert batch._run._chunks(jobs, list(range(5)), workers=0.125) == [[0, 1], [2, 3], [4]]
    monkeypatch.setattr(batch._run, "CHUNK_BYTES", size // 2)
    assert batch._run._chunks(jobs, list(range(3)), workers=0.125) == [[0], [1], [2]]


@pytest.mark.slow
def test_a_task_lost_with_its_workers_is_split_into_single_meshes(tmp_path, caplog):
    """With no retry allowed, killing a worker fails its task at once: its meshes are run again one by one."""
    import dask

    paths = write_spheres(tmp_path / "in", 24, 16)  # 2562 vertices; 2 workers -> tasks of 2 meshes
    out_dir = tmp_path / "out"
    killed = []
    with (
        dask.config.set({"distributed.scheduler.allowed-failures": 0}),
        batch.local_cluster(workers=2, dashboard=False) as client,
    ):

        def kill_a_busy_worker(done, total, failed):
            busy = [address for address, keys in client.processing().items() if keys]
            if done and busy and not killed:
                pid = client.run(os.getpid, workers=busy[:1])[busy[0]]
                os.kill(pid, signal.SIGKILL)
                killed.append(pid)

        with caplog.at_level("INFO", logger="meshcurv.batch"):
            summary = batch.run(paths, out_dir, client=client, output_format="npz", progress=kill_a_busy_worker)
    assert killed, "no worker was busy"
    assert "a task of 2 meshes ended with KilledWorker; running them one by one" in caplog.text
    assert (summary["status"] == "computed").all(), summary["error"].tolist()
    for path in paths:
        assert_complete_npz(out_dir / (path.stem + ".npz"), 2562)
    assert leftovers(out_dir) == []


# ---------------------------------------------------------------------------------------------- the command


@pytest.mark.slow
def test_command_on_a_running_dask_cluster(dask_cluster, dozen, tmp_path):
    folder, expected = dozen
    out_dir = tmp_path / "out"
    done = subprocess.run(
        [
            *MESHCURV,
            "batch",
            os.fspath(folder),
            "-o",
            os.fspath(out_dir),
            "--scheduler",
            dask_cluster,
            "--format",
            "npz",
            "--progress",
            "-v",
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 1, done.stderr
    assert "meshcurv: Dask dashboard: http://127.0.0.1:" in done.stderr
    assert "12/12 meshes, 1 failed" in done.stderr
    assert f"meshcurv: failed: {folder / 'corrupt.obj'}: MeshFileError:" in done.stderr
    assert done.stderr.rstrip().endswith("meshcurv: error: 1 of 12 meshes failed")
    for name, facts in expected.items():
        assert_complete_npz(out_dir / (pathlib.Path(name).stem + ".npz"), facts["n_vertices"])
    assert pd.read_parquet(out_dir / "summary.parquet")["status"].value_counts().to_dict() == {
        "computed": 11,
        "failed": 1,
    }
    assert leftovers(out_dir) == []


@pytest.mark.slow
def test_an_interrupted_command_leaves_no_partial_result_and_resumes(tmp_path, client):
    # 5762 vertices each: about a second of work left when the first result appears
    paths = write_spheres(tmp_path / "in", 80, 24, extension=".obj")
    out_dir = tmp_path / "out"
    process = subprocess.Popen(
        [*MESHCURV, "batch", os.fspath(tmp_path / "in"), "-o", os.fspath(out_dir), "--workers", "2", "--format", "npz"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        # a shell starts background jobs with SIGINT ignored, and children inherit it
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    try:
        deadline = time.monotonic() + 90
        while not list(out_dir.glob("*.npz")) and time.monotonic() < deadline and process.poll() is None:
            time.sleep(0.02)
        process.send_signal(signal.SIGINT)
        _, stderr = process.communicate(timeout=60)
    finally:
        stop(process)
    assert process.returncode == 1 and "meshcurv: aborted" in stderr, stderr
    present = sorted(out_dir.glob("*.npz"))
    assert 0 < len(present) < len(paths)
    for path in present:
        assert_complete_npz(path, 5762)
    assert leftovers(out_dir) == []
    assert not (out_dir / "summary.parquet").exists() and not (out_dir / "summary.csv").exists()
    resumed = batch.run(tmp_path / "in", out_dir, client=client, output_format="npz")
    assert (resumed["status"] == "skipped").sum() == len(present)
    assert (resumed["status"] == "computed").sum() == len(paths) - len(present)
    for path in paths:
        assert_complete_npz(out_dir / (path.stem + ".npz"), 5762)


def test_command_usage_errors(tmp_path, capsys):
    assert main(["batch", f"{tmp_path}/*.obj", "-o", os.fspath(tmp_path / "out")]) == 1
    assert "the pattern matches no mesh file" in capsys.readouterr().err
    assert (
        main(
            [
                "batch",
                os.fspath(tmp_path),
                "-o",
                os.fspath(tmp_path / "out"),
                "--workers",
                "2",
                "--scheduler",
                f"tcp://{LOOPBACK}:9",
            ]
        )
        == 2
    )
    assert "--workers sizes the local cluster" in capsys.readouterr().err
    assert main(["batch", os.fspath(tmp_path), "-o", os.fspath(tmp_path / "out"), "--workers", "0"]) == 2
    assert main(["batch", "-o", os.fspath(tmp_path / "out")]) == 2
