"""First use: what `make demo` installs, and the clock of the kernels' first compilation."""

import io
import pathlib
import re
import shutil
import subprocess
import sys
import time
import tomllib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]


def dry_run(target, tmp_path):
    """The commands ``make TARGET`` would run on a fresh clone (``make -n``, the venv in tmp_path)."""
    if shutil.which("make") is None:
        pytest.skip("make is not installed")
    venv = tmp_path / "venv"
    result = subprocess.run(
        ["make", "-n", target, f"VENV={venv}"], cwd=ROOT, capture_output=True, text=True, check=True
    )
    return [line for line in result.stdout.splitlines() if " pip " in line and " install " in line]


def test_make_demo_installs_the_core_and_matplotlib_only_with_pip_progress(tmp_path):
    (install,) = dry_run("demo", tmp_path)
    assert "'.[plot]'" in install and "--quiet" not in install and " -q" not in install
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    assert [dependency.split(">")[0] for dependency in extras["optional-dependencies"]["plot"]] == ["matplotlib"]
    assert {"numba", "click"} <= {dependency.split(">")[0] for dependency in extras["dependencies"]}


def test_make_test_installs_every_part_with_its_own_stamp(tmp_path):
    (install,) = dry_run("test", tmp_path)
    assert "'.[all,batch,test]'" in install and "--quiet" not in install
    makefile = (ROOT / "Makefile").read_text(encoding="utf-8")
    stamps = re.findall(r"^(\$\(\w+\)): pyproject\.toml", makefile, re.M)
    assert stamps == ["$(DEMO_STAMP)", "$(STAMP)"]  # one for each: make demo then make test installs the rest


class _Terminal(io.StringIO):
    def isatty(self):
        return True


class _Event:
    """A stand-in for numba.core.event.Event of kind ``numba:compile`` on one of meshcurv's kernels."""

    def __init__(self, start):
        from meshcurv import smoothing

        function = smoothing.smooth_vertex_field
        self.data = {"dispatcher": type("Dispatcher", (), {"py_func": function})()}
        self.is_start, self.is_end = start, not start


@pytest.fixture
def clock(monkeypatch, caplog):
    """The announcer with a fast clock; the announcement's WARNING goes to caplog."""
    pytest.importorskip("numba")  # what compiles, and the cache the announcement names
    from meshcurv import _backend

    monkeypatch.setattr(_backend, "TICK_SECONDS", 0.02)
    monkeypatch.setattr(_backend, "_clock_wanted", None)
    caplog.set_level("INFO", logger="meshcurv")

    def compile_for(seconds, stream):
        saved, sys.stderr = sys.stderr, stream
        try:
            announcer = _backend._CompileAnnouncer()
            announcer.on_start(_Event(True))
            time.sleep(seconds)
            announcer.on_end(_Event(False))
        finally:
            sys.stderr = saved
        return stream.getvalue(), announcer

    return compile_for


def test_the_compilation_shows_its_elapsed_time_on_a_terminal(clock):
    written, announcer = clock(0.2, _Terminal())
    readings = re.findall(r"\rmeshcurv: compiling the numba kernels \(first use\): (\d+) s\x1b\[K", written)
    assert len(readings) >= 2 and readings == sorted(readings, key=int)
    assert written.endswith("\r\x1b[K")  # cleared: what follows starts on a clean line
    assert announcer.clock is None


def test_no_clock_when_stderr_is_not_a_terminal(clock):
    written, _ = clock(0.15, io.StringIO())
    assert written == ""


def test_the_clock_can_be_asked_for_in_whole_lines(clock):
    from meshcurv import _backend

    _backend.show_compile_time(True)
    try:
        written, _ = clock(0.15, io.StringIO())
    finally:
        _backend.show_compile_time(None)
    lines = written.splitlines(keepends=True)
    assert lines and all(line.startswith("meshcurv: compiling") and line.endswith(" s\n") for line in lines)
    assert "\r" not in written


def test_the_command_lines_progress_option_runs_the_clock_and_leaves_it_as_it_was():
    pytest.importorskip("click")
    from meshcurv import _backend
    from meshcurv.cli._common import Session

    for progress, wanted in ((True, True), (False, False), (None, None)):
        with Session() as session:
            session.progress = progress
            session.update()  # what --progress / --no-progress do
            assert _backend._clock_wanted is wanted
        assert _backend._clock_wanted is None  # the library's rule again: a terminal only
