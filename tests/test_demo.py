import builtins

import pytest

import meshcurv.plotting
from meshcurv.errors import MissingDependencyError


def test_demo_writes_a_png_and_summarises_against_the_exact_torus(tmp_path):
    pytest.importorskip("matplotlib")
    from meshcurv.demo import run_demo

    output = tmp_path / "pictures" / "torus.png"
    summary = run_demo(output)
    assert output.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "3600 vertices" in summary and "Gaussian K" in summary
    assert list(tmp_path.joinpath("pictures").iterdir()) == [output]  # no temporary left behind


def test_missing_matplotlib_names_the_extra(monkeypatch):
    real_import = builtins.__import__

    def no_matplotlib(name, *args, **kwargs):
        if name.startswith("matplotlib"):
            raise ImportError(name)
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_matplotlib)
    with pytest.raises(MissingDependencyError, match=r"pip install 'meshcurv\[plot\]'"):
        meshcurv.plotting.plot_field([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], [0, 1, 2])


def test_demo_keeps_an_existing_picture_unless_asked(tmp_path):
    pytest.importorskip("matplotlib")
    from meshcurv.demo import run_demo
    from meshcurv.errors import MeshFileError

    output = tmp_path / "torus.png"
    output.write_bytes(b"mine")
    with pytest.raises(MeshFileError, match=r"torus\.png: already exists"):
        run_demo(output)
    assert output.read_bytes() == b"mine"
    run_demo(output, overwrite=True)
    assert output.read_bytes()[:4] == b"\x89PNG"


def test_python_dash_m_delegates_to_the_command_line(monkeypatch, capsys):
    pytest.importorskip("click")
    import runpy
    import sys

    monkeypatch.setattr(sys, "argv", ["meshcurv", "methods"])
    with pytest.raises(SystemExit) as exit_:
        runpy.run_module("meshcurv", run_name="__main__")
    assert exit_.value.code == 0 and "normal_cycle" in capsys.readouterr().out
