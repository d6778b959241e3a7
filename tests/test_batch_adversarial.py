"""Adversarial cases of ``meshcurv batch``, the other commands that write, and the pictures (issue 20).

One class per section: outputs that alias inputs, meshes that never end,
workers that keep dying, inputs changed after their results, damaged records,
output folders that cannot be written, option values beyond any sensible
bound, pictures too large for memory, two commands writing the same file.
Every case that could hang runs in a child process with a timeout (so a
regression is a failure, not a stuck run); Dask clusters start only in child
processes and only in the tests marked slow.
"""

import json
import os
import pathlib
import re
import shutil
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes
from meshcurv.errors import InvalidOptionError, MeshcurvWarning, MeshFileError

pytest.importorskip("distributed")
pytest.importorskip("pandas")
pytest.importorskip("pyarrow")
pytest.importorskip("click")

from meshcurv import batch  # noqa: E402
from meshcurv.cli import main  # noqa: E402

DEAD = "tcp://127.0.0.1:9"  # nothing listens there: a test that connects fails
MESHCURV = [sys.executable, "-m", "meshcurv"]


def write_meshes(folder: pathlib.Path, names, subdivisions: int = 2) -> list[pathlib.Path]:
    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    for index, name in enumerate(names):
        sphere = shapes.icosphere(subdivisions, radius=1.0 + index)
        paths.append(meshcurv.write_mesh(folder / name, sphere.vertices, sphere.faces))
    return paths


def contents(paths) -> dict:
    return {os.fspath(path): pathlib.Path(path).read_bytes() for path in paths}


def one_line(text: str) -> str:
    lines = [line for line in text.splitlines() if line.strip()]
    assert len(lines) == 1, text
    return lines[0]


def run_bounded(argv, *, timeout: float = 60, memory: int = 8 * 2**30) -> subprocess.CompletedProcess:
    """Run ``argv`` in its own session with at most ``memory`` bytes of address space; a hang fails the test."""
    import resource

    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (memory, memory))

    process = subprocess.Popen(
        [os.fspath(arg) for arg in argv],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=limit,
        start_new_session=True,
    )
    try:
        out, err = process.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, 9)  # the command and whatever it started
        process.communicate()
        pytest.fail(f"{argv} did not end within {timeout} s")
    return subprocess.CompletedProcess(argv, process.returncode, out, err)


def run_child(code: str, *, timeout: float, cwd=None) -> dict:
    """Run ``code`` in a new Python; it prints one JSON line last, returned. A hang fails the test."""
    try:
        done = subprocess.run(
            [sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, timeout=timeout, cwd=cwd
        )
    except subprocess.TimeoutExpired as exc:
        pytest.fail(f"the child did not end within {timeout} s (a hang): {exc.stderr!r}")
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


# ------------------------------------------------------------------------- 1. outputs that are inputs


@pytest.mark.parametrize("alias", ["symlink", "dot", "dotdot"])
def test_an_output_folder_that_is_the_input_folder_by_another_name_is_refused(tmp_path, alias):
    paths = write_meshes(tmp_path / "in", ["a.ply", "b.ply"])
    before = contents(paths)
    if alias == "symlink":
        out_dir = tmp_path / "link"
        out_dir.symlink_to(tmp_path / "in", target_is_directory=True)
    else:
        out_dir = tmp_path / "in" / "." if alias == "dot" else tmp_path / "in" / ".." / "in"
    # the old code compared absolute paths: a symbolic link was another folder, and --overwrite
    # replaced the inputs (here it would have tried to connect to the dead scheduler)
    with pytest.raises(MeshFileError, match=r"in: is in the output folder .*choose an output folder apart"):
        batch.run(tmp_path / "in", out_dir, scheduler=DEAD, overwrite=True, output_format="ply")
    with pytest.raises(MeshFileError, match=r"a\.ply: is in the output folder"):
        batch.run(paths[0], out_dir, scheduler=DEAD, overwrite=True)
    # a pattern's matches in the output folder are left out (results are never inputs), and said so
    with pytest.raises(MeshFileError, match=r"no mesh file found in .* but in the output folder .*\(2 files"):
        batch.run(os.fspath(tmp_path / "in" / "*.ply"), out_dir, scheduler=DEAD, overwrite=True)
    assert contents(paths) == before


def test_a_result_that_would_be_an_input_file_is_refused_before_any_work(tmp_path):
    paths = write_meshes(tmp_path / "in", ["a.npz", "b.npz"])
    before = contents(paths)
    out_dir = tmp_path / "out"
    out_dir.mkdir()
    os.link(paths[0], out_dir / "a.npz")  # a hard link: the same file in the output folder
    with pytest.raises(MeshFileError, match=r"out/a\.npz: is the input file .*in/a\.npz under another name"):
        batch.run(tmp_path / "in", out_dir, scheduler=DEAD, overwrite=True, output_format="npz")
    assert contents(paths) == before


def test_a_worker_never_writes_a_result_over_its_input(tmp_path):
    """The last check, in the task, just before the rename: an alias made after the plan."""
    (source,) = write_meshes(tmp_path / "in", ["a.npz"])
    before = contents([source])
    link = tmp_path / "link"
    link.symlink_to(tmp_path / "in", target_is_directory=True)
    row = batch.process_mesh(source, link / "a.npz", tmp_path / "records" / "a.npz.json")
    assert row["status"] == "failed"
    assert re.search(r"MeshFileError: .*link/a\.npz: is the input file .*under another name", row["error"])
    assert contents([source]) == before


def test_compute_refuses_an_output_that_is_its_input_by_another_name(tmp_path, capsys):
    (source,) = write_meshes(tmp_path / "in", ["a.ply"])
    before = contents([source])
    link = tmp_path / "link"
    link.symlink_to(tmp_path / "in", target_is_directory=True)
    os.link(source, tmp_path / "hard.ply")
    for output in (link / "a.ply", tmp_path / "in" / "." / "a.ply", tmp_path / "hard.ply"):
        assert main(["compute", source, "-o", output, "--overwrite"]) == 1
        assert "the output would replace the input file" in one_line(capsys.readouterr().err)
    assert contents([source]) == before


# ------------------------------------------------------------------------- 2, 3. hangs and dying workers

FAULTS = """
import importlib, json, os, pathlib, signal, sys, time
import distributed
import meshcurv, meshcurv.io, meshcurv.batch._process
from meshcurv import batch, shapes


class Faults(distributed.WorkerPlugin):
    '''On every worker, also those started after a death: files named hang* never end, crash* kill
    their worker (as the out-of-memory killer does), fatal* kill the worker and its nanny.'''

    def setup(self, worker):
        original = meshcurv.io.read_mesh

        def read_mesh(path, *args, **kwargs):
            name = os.path.basename(os.fspath(path))
            if name.startswith("hang"):
                time.sleep(3600)
            if name.startswith("fatal"):
                os.kill(os.getppid(), signal.SIGKILL)
            if name.startswith(("crash", "fatal")):
                os.kill(os.getpid(), signal.SIGKILL)
            return original(path, *args, **kwargs)

        meshcurv.io.read_mesh = read_mesh
        # the task's own name for it (imported at module level there)
        importlib.import_module("meshcurv.batch._process").read_mesh = read_mesh


def write(folder, names):
    folder.mkdir(parents=True, exist_ok=True)
    for index, name in enumerate(names):
        sphere = shapes.icosphere(2, radius=1.0 + index)
        meshcurv.write_mesh(folder / name, sphere.vertices, sphere.faces)


def rows(summary):
    return {pathlib.Path(path).name: [status, error] for path, status, error in
            zip(summary["path"], summary["status"], summary["error"])}
"""


def run_twice(tmp_path, names, options: str) -> dict:
    """A batch of ``names`` on a local cluster of one worker with the faults, then its resume (a child process)."""
    return run_child(
        FAULTS
        + f"""
folder, out_dir = pathlib.Path({os.fspath(tmp_path)!r}) / "in", pathlib.Path({os.fspath(tmp_path)!r}) / "out"
write(folder, {names!r})
# the compiled kernels on disk before the worker starts (a fresh clone compiles them here, once), so
# that the time limits below measure the batch, not the first compilation
meshcurv.principal_curvatures(shapes.icosphere(subdivisions=2).vertices, shapes.icosphere(subdivisions=2).faces)
with batch.local_cluster(workers=1, dashboard=False) as client:
    client.register_plugin(Faults())
    start = time.monotonic()
    first = batch.run(folder, out_dir, client=client, output_format="npz", {options})
    first_seconds = time.monotonic() - start
    start = time.monotonic()
    again = batch.run(folder, out_dir, client=client, output_format="npz", {options})
    again_seconds = time.monotonic() - start
print(json.dumps({{"first": rows(first), "again": rows(again), "first_seconds": first_seconds,
                  "again_seconds": again_seconds}}))
""",
        timeout=300,
    )


@pytest.mark.slow
def test_a_mesh_that_never_ends_times_out_and_a_resume_does_not_wait_for_it_again(tmp_path):
    result = run_twice(tmp_path, ["a.obj", "hang.obj", "z.obj"], "timeout=10")  # room for a loaded machine
    first, again = result["first"], result["again"]
    assert first["a.obj"] == ["computed", ""] and first["z.obj"] == ["computed", ""]
    assert first["hang.obj"][0] == "failed"
    assert first["hang.obj"][1].startswith("TimeoutError: timed out after 10 s")
    assert result["first_seconds"] < 60
    # the resume reports the recorded failure without computing it (nor waiting 10 s for it)
    assert again["hang.obj"] == first["hang.obj"]
    assert again["a.obj"][0] == again["z.obj"][0] == "skipped"
    assert result["again_seconds"] < 2


@pytest.mark.slow
def test_a_mesh_that_keeps_killing_its_workers_fails_alone_and_is_not_retried(tmp_path):
    result = run_twice(tmp_path, ["a.obj", "crash.obj", "z.obj"], "retry_failed=False")
    first, again = result["first"], result["again"]
    assert first["a.obj"] == ["computed", ""] and first["z.obj"] == ["computed", ""]
    assert first["crash.obj"][0] == "failed"
    assert first["crash.obj"][1].startswith(
        f"WorkerDied: the worker computing this mesh died {batch.MAX_WORKER_DEATHS} times (killed by the system"
    )
    assert again["crash.obj"] == first["crash.obj"] and result["again_seconds"] < 2


@pytest.mark.slow
def test_a_cluster_left_without_workers_ends_the_run_with_a_message(tmp_path):
    """``dask scheduler`` and one ``dask worker`` (its nanny in its own process): the mesh kills both."""
    result = run_child(
        FAULTS
        + f"""
import socket, subprocess

def free_port():
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]

folder, out_dir = pathlib.Path({os.fspath(tmp_path)!r}) / "in", pathlib.Path({os.fspath(tmp_path)!r}) / "out"
write(folder, ["fatal.obj"])
port = free_port()
dask = [sys.executable, "-m", "dask"]
processes = [subprocess.Popen([*dask, "scheduler", "--host", "127.0.0.1", "--port", str(port),
                               "--dashboard-address", f"127.0.0.1:{{free_port()}}"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
address = f"tcp://127.0.0.1:{{port}}"
try:
    processes.append(subprocess.Popen([*dask, "worker", address, "--host", "127.0.0.1", "--nthreads", "1",
                                       "--nworkers", "1", "--no-dashboard"],
                                      stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
    with distributed.Client(address, timeout=60) as client:
        client.wait_for_workers(1, timeout=60)
        client.register_plugin(Faults())
    batch._driver.NO_WORKER_SECONDS = {{"local": 3.0, "remote": 3.0}}
    start = time.monotonic()
    try:
        batch.run(folder, out_dir, scheduler=address, output_format="npz")
        message = None
    except batch.NoWorkerError as exc:
        message = str(exc)
    seconds = time.monotonic() - start
finally:
    for process in processes:
        process.kill()
        process.wait()
print(json.dumps({{"message": message, "seconds": seconds}}))
""",
        timeout=120,
    )
    assert result["message"] is not None, "the run ended without NoWorkerError"
    assert result["message"].startswith("the cluster has had no worker for 3 s: the workers died and none could")
    assert result["seconds"] < 30


# ------------------------------------------------------------------------- 4, 5. fingerprints, damaged records


def computed_batch(tmp_path, names):
    """Meshes processed as a batch's tasks do (no cluster): their jobs, with results and records."""
    paths = write_meshes(tmp_path / "in", names)
    jobs = batch._inputs._plan(paths, tmp_path / "out", ".npz")
    options = batch._inputs._options("icc", None, None, None)
    for job in jobs:
        row = batch.process_mesh(job.source, job.output, job.record)
        assert row["status"] == "computed", row["error"]
    return paths, jobs, options


def completed(jobs, options, **given):
    damaged = []
    settings = {"overwrite": False, "retry_failed": False, "timeout": batch.DEFAULT_TIMEOUT, **given}
    return [batch._run._completed(job, options, damaged=damaged, **settings) for job in jobs], damaged


def test_an_input_changed_after_its_result_is_computed_again(tmp_path):
    paths, jobs, options = computed_batch(tmp_path, ["a.obj", "b.obj", "c.obj"])
    rows, _ = completed(jobs, options)
    assert [row["status"] for row in rows] == ["skipped"] * 3
    # a: one coordinate changed, same size, mtime put back (cp -p, rsync -t): only the hash tells
    stat = paths[0].stat()
    text = paths[0].read_text()
    changed = text.replace("v 0", "v 1", 1)
    assert changed != text and len(changed) == len(text)
    paths[0].write_text(changed)
    os.utime(paths[0], ns=(stat.st_atime_ns, stat.st_mtime_ns))
    assert (paths[0].stat().st_size, paths[0].stat().st_mtime_ns) == (stat.st_size, stat.st_mtime_ns)
    # b: a newer file (another mesh)
    time.sleep(0.01)
    sphere = shapes.icosphere(1)
    meshcurv.write_mesh(paths[1], sphere.vertices, sphere.faces, overwrite=True)
    rows, _ = completed(jobs, options)
    assert rows[0] is None and rows[1] is None and rows[2]["status"] == "skipped"
    record = json.loads(pathlib.Path(jobs[2].record).read_text())
    assert record["input"] == batch.fingerprint(paths[2])
    assert record["input"]["size"] == paths[2].stat().st_size


def test_a_large_file_is_fingerprinted_by_its_ends(tmp_path, monkeypatch):
    monkeypatch.setattr(batch._records, "HASH_WHOLE_BYTES", 1000)
    monkeypatch.setattr(batch._records, "HASH_PART_BYTES", 100)
    path = tmp_path / "big.bin"
    path.write_bytes(bytes(range(256)) * 10)
    first = batch.fingerprint(path)
    with open(path, "r+b") as stream:  # the last byte: seen
        stream.seek(-1, os.SEEK_END)
        stream.write(b"\x00")
    assert batch.fingerprint(path)["blake2b"] != first["blake2b"]


def test_a_damaged_record_is_ignored_with_one_warning_not_a_refusal(tmp_path, monkeypatch):
    paths, jobs, options = computed_batch(tmp_path, ["a.obj", "b.obj", "c.obj", "d.obj"])
    cut = pathlib.Path(jobs[0].record)
    cut.write_text(cut.read_text()[:20])  # a run cut short while writing
    pathlib.Path(jobs[1].record).write_bytes(b"\xff\xfe garbage")
    pathlib.Path(jobs[2].record).write_text("[1, 2]")  # valid JSON, not a record
    rows, damaged = completed(jobs, options)
    assert rows[:3] == [None, None, None] and rows[3]["status"] == "skipped"
    assert [record.name for record, _ in damaged] == ["a.npz.json", "b.npz.json", "c.npz.json"]
    # through run: one warning, then the three meshes go to a cluster (stopped there: none in this test)
    asked = []

    def no_cluster(**given):
        asked.append(given)
        raise ConnectionError("no cluster in this test")

    monkeypatch.setattr(batch._run, "cluster", no_cluster)
    with pytest.warns(
        MeshcurvWarning,
        match=r"3 records in .* cannot be read \(cut short or corrupt: "
        r"a\.npz\.json: JSONDecodeError",
    ):
        with pytest.raises(ConnectionError, match="no cluster in this test"):
            batch.run(tmp_path / "in", tmp_path / "out", scheduler=DEAD, output_format="npz")
    assert len(asked) == 1


# ------------------------------------------------------------------------- 6. output folders that cannot be written


def test_an_output_folder_that_cannot_be_written_fails_before_any_work(tmp_path):
    (tmp_path / "in").mkdir()
    write_meshes(tmp_path / "in", ["a.obj"])
    out_dir = tmp_path / "out"
    out_dir.mkdir()
    (out_dir / batch.RECORDS).write_text("")  # a file where the records folder goes
    start = time.monotonic()
    with pytest.raises(
        MeshFileError,
        match=r"\.meshcurv-batch: cannot write the results there .*nothing was "
        r"computed",
    ):
        batch.run(tmp_path / "in", out_dir, scheduler=DEAD)  # no connection tried
    assert time.monotonic() - start < 2


@pytest.mark.skipif(
    not hasattr(os, "geteuid") or (os.geteuid() == 0 and not shutil.which("setpriv")),
    reason="needs a user for whom permissions hold (not root) or setpriv",
)
def test_a_read_only_output_folder_is_one_line_and_exit_1_before_a_cluster(tmp_path):
    import tempfile

    base = pathlib.Path(tempfile.mkdtemp(prefix="meshcurv-ro-"))  # /tmp: open to another user
    try:
        base.chmod(0o755)
        write_meshes(base / "in", ["a.obj"])
        (base / "out").mkdir(mode=0o555)
        (base / "out").chmod(0o555)
        prefix = ["setpriv", "--reuid=65534", "--regid=65534", "--clear-groups"] if os.geteuid() == 0 else []
        done = subprocess.run(
            [*prefix, *MESHCURV, "batch", base / "in", "-o", base / "out"],
            capture_output=True,
            text=True,
            timeout=60,
            cwd=base,
        )
        assert done.returncode == 1, done.stderr
        assert re.fullmatch(
            r"meshcurv: error: .*out: cannot write the results there \(Permission denied\); "
            r"nothing was computed",
            one_line(done.stderr),
        )
    finally:
        (base / "out").chmod(0o755)
        shutil.rmtree(base)


def test_a_summary_that_cannot_be_written_keeps_the_failure_rows(tmp_path, monkeypatch):
    paths, jobs, _ = computed_batch(tmp_path, ["a.obj", "b.obj"])
    (tmp_path / "in" / "bad.obj").write_text("v 0 0 0\nf 1 2 3\n")
    bad = batch._inputs._plan([tmp_path / "in" / "bad.obj"], tmp_path / "out", ".npz")[0]
    assert batch.process_mesh(bad.source, bad.output, bad.record)["status"] == "failed"

    def full_disk(summary, out_dir):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(batch._run, "_write_summary", full_disk)
    with pytest.warns(MeshcurvWarning, match="the summary could not be written"):
        summary = batch.run(tmp_path / "in", tmp_path / "out", scheduler=DEAD, output_format="npz")
    assert summary["status"].tolist() == ["skipped", "skipped", "failed"]
    assert summary["error"].iloc[2].startswith("MeshFileError: ")
    assert "No space left on device" in summary.attrs["not_written"]


# ------------------------------------------------------------------------- 7. command-line errors


@pytest.mark.parametrize("command", ["compute", "info", "plot"])
def test_an_unusable_input_is_exit_1_and_one_line(tmp_path, capsys, command):
    (tmp_path / "folder.ply").mkdir()
    for mesh, message in [(tmp_path / "folder.ply", "is a directory"), (tmp_path / "none.ply", "no such file")]:
        assert main([command, mesh]) == 1
        line = one_line(capsys.readouterr().err)
        assert line.startswith("meshcurv: error: ") and message in line


@pytest.mark.skipif(
    not hasattr(os, "geteuid") or (os.geteuid() == 0 and not shutil.which("setpriv")),
    reason="needs a user for whom permissions hold (not root) or setpriv",
)
def test_an_input_without_read_permission_is_exit_1_and_one_line(tmp_path):
    import tempfile

    base = pathlib.Path(tempfile.mkdtemp(prefix="meshcurv-perm-"))
    try:
        base.chmod(0o755)
        (mesh,) = write_meshes(base, ["secret.obj"])
        mesh.chmod(0o600)
        prefix = ["setpriv", "--reuid=65534", "--regid=65534", "--clear-groups"] if os.geteuid() == 0 else []
        if not prefix:
            mesh.chmod(0o000)
        # the old command let click check the path: exit 2 and its usage text
        done = subprocess.run([*prefix, *MESHCURV, "info", mesh], capture_output=True, text=True, timeout=60)
        assert done.returncode == 1, done.stderr
        assert "secret.obj" in one_line(done.stderr) and "ermission" in done.stderr
    finally:
        shutil.rmtree(base)


@pytest.mark.parametrize(
    "arguments, option",
    [
        (["compute", "{mesh}", "-m", "matgeom", "--smoothing-steps", "99999999999999999999"], "--smoothing-steps"),
        (["compute", "{mesh}", "-m", "matgeom", "--smoothing-steps", str(2**63)], "--smoothing-steps"),
        (["compute", "{mesh}", "--radius", "1e400"], "--radius"),
        (["compute", "{mesh}", "--radius", "inf"], "--radius"),
        (["batch", "{mesh}", "-o", "{out}", "--timeout", "1e400"], "--timeout"),
    ],
)
def test_option_values_beyond_any_bound_are_one_usage_line(tmp_path, capsys, arguments, option):
    (mesh,) = write_meshes(tmp_path, ["m.obj"])
    argv = [item.format(mesh=mesh, out=tmp_path / "out") for item in arguments]
    assert main(argv) == 2
    line = one_line(capsys.readouterr().err)
    assert line.startswith(f"meshcurv: error: Invalid value for '{option}'") and "--help" in line
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    "arguments, option",
    [
        (["plot", "{mesh}", "--pixels", "100000"], "--pixels"),  # was a 75 GiB z-buffer
        (
            ["batch", "{mesh}", "-o", "{out}", "--workers", "99999999999999999999"],
            "--workers",
        ),  # was that many processes
    ],
)
def test_option_values_that_would_take_the_machine_are_refused_first(tmp_path, arguments, option):
    """In a process of its own with 8 GiB of address space and a timeout: a regression fails, it does not kill."""
    (mesh,) = write_meshes(tmp_path, ["m.obj"])
    done = run_bounded([*MESHCURV, *(item.format(mesh=mesh, out=tmp_path / "out") for item in arguments)])
    assert done.returncode == 2, done.stderr[-2000:]
    line = one_line(done.stderr)
    assert line.startswith(f"meshcurv: error: Invalid value for '{option}'") and "--help" in line
    assert not (tmp_path / "out").exists() and not list(tmp_path.glob("*.png"))


# ------------------------------------------------------------------------- 8. pictures too large


def test_pixels_beyond_the_bound_or_the_memory_are_refused_before_allocating(tmp_path):
    """In a child with 8 GiB of address space: the old code's 75 GiB z-buffer is a failure, not the OOM killer."""
    pytest.importorskip("matplotlib")
    code = f"""
import json, os
from meshcurv import plotting, shapes
from meshcurv.errors import InvalidOptionError

torus = shapes.torus(12, 4, 8, 4)
values = torus.vertices[:, 0]
messages = []

def refused(call):
    try:
        call()
    except (InvalidOptionError, MemoryError) as exc:
        messages.append(f"{{type(exc).__name__}}: {{exc}}")
    else:
        messages.append(None)

refused(lambda: plotting.plot_field(torus.vertices, torus.faces, values, pixels=100_000))
refused(lambda: plotting.plot_field(torus.vertices, torus.faces, values, pixels=2**64))
plotting._available_memory = lambda: 2 * 2**30
refused(lambda: plotting.plot_field(torus.vertices, torus.faces, values, pixels=8192))
figure = plotting.plot_field(torus.vertices, torus.faces, values, pixels=64)
refused(lambda: plotting.save_figure(figure, {os.fspath(tmp_path / "never.png")!r}, dpi=100_000))
print(json.dumps(messages))
"""
    done = run_bounded([sys.executable, "-c", code])
    assert done.returncode == 0, done.stderr[-2000:]
    messages = json.loads(done.stdout.splitlines()[-1])
    assert re.fullmatch(
        r"InvalidOptionError: `pixels` must be an integer between 16 and 8192.*; got 100000", messages[0]
    )
    assert re.fullmatch(r"InvalidOptionError: `pixels` must be an integer between 16 and 8192.*; got \d+", messages[1])
    assert messages[2] == (
        "InvalidOptionError: `pixels`=8192 needs about 6.0 GiB for each view; 2.0 GiB of memory "
        "is available: give fewer pixels"
    )
    assert re.fullmatch(r"InvalidOptionError: `dpi` must be an integer between 10 and 1200.*; got 100000", messages[3])
    assert not (tmp_path / "never.png").exists()


# ------------------------------------------------------------------------- 9. two commands, one output


@pytest.mark.slow
def test_two_commands_writing_the_same_file_do_not_both_succeed(tmp_path):
    sphere = shapes.icosphere(5)
    mesh = meshcurv.write_mesh(tmp_path / "sphere.obj", sphere.vertices, sphere.faces)
    output = tmp_path / "same.ply"
    processes = [
        subprocess.Popen(
            [*MESHCURV, "compute", mesh, "-o", output], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
        )
        for _ in range(2)
    ]
    try:
        outcomes = [(process.returncode, process.communicate(timeout=120)[1]) for process in processes]
        outcomes = [(process.returncode, err) for process, (_, err) in zip(processes, outcomes)]
    finally:
        for process in processes:
            if process.poll() is None:
                process.kill()
                process.communicate()
    codes = sorted(code for code, _ in outcomes)
    assert codes == [0, 1], outcomes
    refused = next(err for code, err in outcomes if code == 1)
    assert "same.ply: already exists" in refused
    assert meshcurv.read_mesh(output).vertices.shape == (len(sphere.vertices), 3)


def test_a_picture_written_meanwhile_by_another_process_is_not_replaced(tmp_path):
    pytest.importorskip("matplotlib")
    from meshcurv import plotting

    torus = shapes.torus(12, 4, 8, 4)
    figure = plotting.plot_field(torus.vertices, torus.faces, torus.vertices[:, 0], pixels=32)
    path = tmp_path / "t.png"
    savefig = figure.savefig

    def racing(*args, **kwargs):  # another `meshcurv plot -o t.png` publishes first
        path.write_bytes(b"the other one")
        return savefig(*args, **kwargs)

    figure.savefig = racing
    with pytest.raises(MeshFileError, match=r"t\.png: already exists"):
        plotting.save_figure(figure, path)
    assert path.read_bytes() == b"the other one"


def test_adaptive_radius_is_taken_as_principal_curvatures_takes_it(tmp_path):
    # the CLI's --radius offers 'adaptive' (icc): the batch options take it too, and the task computes what
    # principal_curvatures(radius="adaptive") computes; other methods refuse it with the usual message
    assert batch._inputs._options("icc", None, "adaptive", None) == {"method": "icc", "radius": "adaptive"}
    with pytest.raises(InvalidOptionError, match="`radius` must be a positive"):
        batch._inputs._options("quadric", None, "adaptive", None)
    torus = meshcurv.shapes.torus()
    source = tmp_path / "torus.ply"
    meshcurv.write_mesh(source, torus.vertices, torus.faces)
    row = batch.process_mesh(source, tmp_path / "torus.npz", tmp_path / "torus.json", radius="adaptive")
    assert row["status"] == "computed", row["error"]
    stored = np.load(tmp_path / "torus.npz")
    expected = meshcurv.principal_curvatures(*meshcurv.read_mesh(source), radius="adaptive")
    np.testing.assert_array_equal(stored["k_max"], expected.k_max)
