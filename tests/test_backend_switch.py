"""The backend switch (issue 18): decided once per process, overridable, announced once.

numba is hidden the way a base install lacks it: a finder at the head of
``sys.meta_path`` refuses ``import numba`` (and counts the attempts), and the
modules that import it are taken out of ``sys.modules`` for the test.
"""

from __future__ import annotations

import importlib.abc
import logging
import pathlib
import sys
import tomllib
import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import _backend, shapes
from meshcurv._backend import backend_name, numba_kernels, use_backend
from meshcurv.errors import InvalidOptionError, MeshQualityWarning, MissingDependencyError

PYPROJECT = pathlib.Path(__file__).resolve().parents[1] / "pyproject.toml"
#: The package whose modules import numba when imported themselves.
COMPILED = "meshcurv._kernels"


class _NoNumba(importlib.abc.MetaPathFinder):
    """Refuses ``numba`` as an absent package would, counting the attempts."""

    def __init__(self):
        self.attempts = 0

    def find_spec(self, name, path=None, target=None):
        if name == "numba" or name.startswith("numba."):
            self.attempts += 1
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)
        return None


@pytest.fixture
def no_numba(monkeypatch):
    """numba cannot be imported for the duration of the test; the backend decides afresh before and after."""
    finder = _NoNumba()
    monkeypatch.setattr(sys, "meta_path", [finder, *sys.meta_path])
    for name in [
        name for name in sys.modules if name in ("numba", COMPILED) or name.startswith(("numba.", COMPILED + "."))
    ]:
        monkeypatch.delitem(sys.modules, name, raising=False)
    monkeypatch.delattr(meshcurv, "_kernels", raising=False)
    monkeypatch.delenv("MESHCURV_BACKEND", raising=False)
    _backend._forget()
    yield finder
    _backend._forget()


@pytest.fixture
def fresh_backend(monkeypatch):
    monkeypatch.delenv("MESHCURV_BACKEND", raising=False)
    _backend._forget()
    yield
    _backend._forget()


def _normal_cycle(mesh):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshQualityWarning)
        return meshcurv.principal_curvatures(mesh.vertices, mesh.faces, method="normal_cycle")


def test_without_numba_the_numpy_path_runs_and_the_import_is_tried_once(no_numba, caplog):
    torus = shapes.torus(n_major=48, n_minor=24)  # R 30, r 10
    with caplog.at_level(logging.INFO, logger="meshcurv"):
        results = [_normal_cycle(torus) for _ in range(3)]
    assert no_numba.attempts == 1  # one failed import per process, not one per kernel lookup
    assert backend_name() == "numpy"
    with use_backend("numpy"):
        reference = _normal_cycle(torus)
    for result in results:  # the same code path as the NumPy backend asked for by name
        np.testing.assert_array_equal(result.k_min, reference.k_min)
        np.testing.assert_array_equal(result.k_max, reference.k_max)
    # the exact curvatures within 15% of the tube's 1/r (a coarse torus: 4.5% for k_max, 8.9% for k_min)
    assert result.valid.all()
    assert np.abs(result.k_max - torus.k_max).max() < 0.15 / 10.0
    assert np.abs(result.k_min - torus.k_min).max() < 0.15 / 10.0


def test_without_numba_one_info_line_names_the_extra(no_numba, caplog):
    sphere = shapes.icosphere(4)
    with caplog.at_level(logging.INFO, logger="meshcurv"):
        _normal_cycle(sphere)
        _normal_cycle(sphere)
    lines = [r.getMessage() for r in caplog.records if r.name.startswith("meshcurv") and "backend" in r.getMessage()]
    assert len(lines) == 1, lines
    assert all(r.levelno == logging.INFO for r in caplog.records if "backend" in r.getMessage())
    assert lines[0].startswith("meshcurv backend: numpy (numba cannot be imported: No module named 'numba')")
    assert "pip install numba" in lines[0]


def test_a_plain_install_is_the_fast_tool():
    # numba and click are dependencies of the package itself, not extras
    dependencies = tomllib.loads(PYPROJECT.read_text())["project"]["dependencies"]
    assert any(requirement.startswith("numba") for requirement in dependencies)
    assert any(requirement.startswith("click") for requirement in dependencies)
    assert "pip install numba" in _backend.MISSING_MESSAGE


def test_asking_for_numba_without_it_says_how_to_install_it(no_numba, monkeypatch):
    monkeypatch.setenv("MESHCURV_BACKEND", "numba")
    with pytest.raises(MissingDependencyError, match=r"the numba backend needs numba .*pip install numba"):
        numba_kernels("geometry")
    with use_backend("numba"), pytest.raises(MissingDependencyError, match=r"pip install numba"):
        numba_kernels("geometry")
    assert no_numba.attempts == 1


def test_the_numba_backend_is_announced_once(fresh_backend, caplog):
    numba = pytest.importorskip("numba")
    with caplog.at_level(logging.INFO, logger="meshcurv"):
        first, second = numba_kernels("geometry"), numba_kernels("geometry")
    assert first is second is not None
    lines = [r.getMessage() for r in caplog.records if r.getMessage().startswith("meshcurv backend:")]
    assert lines == [f"meshcurv backend: numba {numba.__version__} (the fast kernels)"]


def test_use_backend_overrides_the_environment_and_nests(fresh_backend, monkeypatch):
    monkeypatch.setenv("MESHCURV_BACKEND", "numpy")
    assert numba_kernels("geometry") is None and backend_name() == "numpy"
    with use_backend("auto"):
        assert backend_name() == ("numba" if _importable("numba") else "numpy")
        with use_backend("numpy"):
            assert numba_kernels("geometry") is None
        assert backend_name() == ("numba" if _importable("numba") else "numpy")
    assert numba_kernels("geometry") is None  # the environment again once the block is left


def test_unknown_backends_are_refused(fresh_backend, monkeypatch):
    with pytest.raises(InvalidOptionError, match=r"unknown backend 'gpu'; choose one of auto, numpy, numba"):
        with use_backend("gpu"):
            pass
    monkeypatch.setenv("MESHCURV_BACKEND", "cuda")
    with pytest.raises(InvalidOptionError, match=r"unknown backend 'cuda' \(MESHCURV_BACKEND\)"):
        numba_kernels("geometry")


def _interrupted_kernel(*args):
    """What CPython makes of Ctrl-C inside a compiled call: a SystemError caused by the KeyboardInterrupt."""
    try:
        raise KeyboardInterrupt
    except KeyboardInterrupt as interrupt:
        raise SystemError("<CPUDispatcher(fit_jets)> returned a result with an exception set") from interrupt


def _broken_kernel(*args):
    raise SystemError("a genuine SystemError")


def test_ctrl_c_inside_a_kernel_is_a_keyboard_interrupt():
    with pytest.raises(KeyboardInterrupt):
        _backend._locked(_interrupted_kernel)(np.zeros(3))
    with pytest.raises(SystemError, match="a genuine SystemError"):
        _backend._locked(_broken_kernel)(np.zeros(3))


def _importable(name: str) -> bool:
    try:
        __import__(name)
    except ImportError:
        return False
    return True


@pytest.mark.parametrize("method", meshcurv.METHODS)
def test_without_numba_every_method_gives_the_numpy_paths_values(no_numba, method):
    sphere = shapes.icosphere(6)  # radius 1
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshQualityWarning)
        hidden = meshcurv.principal_curvatures(sphere.vertices, sphere.faces, method=method)
        with use_backend("numpy"):
            reference = meshcurv.principal_curvatures(sphere.vertices, sphere.faces, method=method)
    assert no_numba.attempts == 1
    np.testing.assert_array_equal(hidden.valid, reference.valid)
    np.testing.assert_array_equal(hidden.k_max, reference.k_max)
    assert hidden.valid.any()


def test_without_numba_point_clouds_take_the_numpy_path(no_numba):
    from meshcurv.pointcloud import point_cloud_curvatures

    rng = np.random.default_rng(0)
    points = rng.normal(size=(2000, 3))
    points = 2.0 * points / np.linalg.norm(points, axis=1, keepdims=True)  # radius 2: k = 0.5
    hidden = point_cloud_curvatures(points)
    with use_backend("numpy"):
        reference = point_cloud_curvatures(points)
    assert no_numba.attempts == 1
    np.testing.assert_array_equal(hidden.k_max, reference.k_max)
    assert abs(np.median(hidden.mean) - 0.5) < 0.005  # 1% (measured 0.03%): a median over 2000 points


def test_use_backend_holds_in_its_own_thread_only(fresh_backend, monkeypatch):
    # the override is a context variable: a block on NumPy in one thread leaves another thread on its backend
    monkeypatch.delenv("MESHCURV_BACKEND", raising=False)
    import threading

    seen = {}
    entered, release = threading.Event(), threading.Event()

    def on_numpy():
        with use_backend("numpy"):
            entered.set()
            release.wait(10)
            seen["inside"] = backend_name()

    worker = threading.Thread(target=on_numpy)
    worker.start()
    entered.wait(10)
    seen["other"] = backend_name()
    release.set()
    worker.join()
    assert seen["inside"] == "numpy"
    assert seen["other"] == ("numba" if _importable("numba") else "numpy")
