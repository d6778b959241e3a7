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
