"""The compiled kernels' first use imports no :mod:`scipy.linalg` (issue 31's warm start), and nothing of how it
avoids it can fail a call or change a number.

numba loads its registries of implementations before the first kernel it compiles or loads from its cache;
one of them, ``numba.np.arraymath``, checks at import whether BLAS is there for ``np.dot`` by importing
``scipy.linalg.cython_blas``, hence the whole of :mod:`scipy.linalg` and, through scipy's array-API layer,
``numpy.f2py`` and ``numpy.testing``: about 0.22 s of CPU of a fresh process, for a module no kernel uses.
meshcurv has numba load the registries before its first kernel, the check finding scipy's ``cython_blas`` on
disk instead (``meshcurv._kernels.load_numba_registries``). Each case runs in a fresh process (in this one,
scipy.linalg and numba's registries were loaded long ago by other tests), where a kernel runs: as it is, and
with each part of that mechanism made to raise (as another numba's internals could), where numba's own path
must take over with the same numbers.
"""

from __future__ import annotations

import functools
import json
import os
import subprocess
import sys
import textwrap
import types

import numpy as np
import pytest

_FIRST_USE = textwrap.dedent(
    """
    import json
    import sys

    import numpy as np

    import meshcurv
    import meshcurv._kernels as kernels
    from meshcurv import _backend


    def raising(*args, **kwargs):
        raise RuntimeError("a numba laid out otherwise")


    broken = sys.argv[1]
    if broken == "probe":  # the look on disk
        kernels._blas_found = raising
    elif broken == "finder":  # the hook on numba's import of numba.np.arraymath
        kernels._BlasCheckWithoutLinalg.find_spec = raising
    elif broken == "refresh":  # numba's loading of its registries, from meshcurv
        kernels._refresh = raising

    mesh = meshcurv.shapes.icosphere(2)
    sides = np.concatenate([mesh.faces[:, [0, 1]], mesh.faces[:, [1, 2]], mesh.faces[:, [2, 0]]])
    edges = np.unique(np.sort(sides, axis=1), axis=0)
    with _backend.use_backend("numba"):
        lengths = meshcurv.geometry.edge_lengths(mesh.vertices, edges)  # a kernel loaded or compiled, and run
    linalg_imported = "scipy.linalg" in sys.modules

    from numba.np import arraymath, linalg

    print(json.dumps({
        "lengths": lengths.tobytes().hex(),
        "edges": edges.tolist(),
        "scipy.linalg imported": linalg_imported,
        "numba's ensure_blas back": linalg.ensure_blas.__module__ == "numba.np.linalg"
        and arraymath.ensure_blas is linalg.ensure_blas,
        "no finder left": not any(type(f).__name__ == "_BlasCheckWithoutLinalg" for f in sys.meta_path),
        "numba's BLAS flag": arraymath._HAVE_BLAS,
    }))
    """
)


@functools.cache
def _first_use(broken: str) -> dict:
    """The fresh process's report, with ``broken`` ("none", "probe", "finder", "refresh") made to raise."""
    # the session's numba cache: one small kernel, compiled (about a second) where no test compiled it before
    environment = {**os.environ, "MESHCURV_BACKEND": "numba"}
    run = subprocess.run(
        [sys.executable, "-c", _FIRST_USE, broken], capture_output=True, text=True, env=environment, check=False
    )
    assert run.returncode == 0, run.stderr
    return json.loads(run.stdout.splitlines()[-1])


def test_first_kernel_imports_no_scipy_linalg():
    pytest.importorskip("numba")
    pytest.importorskip("scipy.linalg")
    report = _first_use("none")
    assert not report["scipy.linalg imported"]  # numba's own check imported it before its first kernel
    assert report["numba's BLAS flag"]  # scipy is installed whole: numba's np.dot has BLAS, as with its check
    assert report["numba's ensure_blas back"] and report["no finder left"]
    vertices = np.asarray(__import__("meshcurv").shapes.icosphere(2).vertices)
    edges = np.array(report["edges"])
    expected = np.sqrt(((vertices[edges[:, 1]] - vertices[edges[:, 0]]) ** 2).sum(axis=1))
    lengths = np.frombuffer(bytes.fromhex(report["lengths"]), dtype=np.float64)
    np.testing.assert_allclose(lengths, expected, rtol=4e-16, atol=0)  # a few roundings of a 3-term sum's root


@pytest.mark.parametrize("broken", ["probe", "finder", "refresh"])
def test_a_failing_check_falls_back_to_numbas_own(broken):
    pytest.importorskip("numba")
    pytest.importorskip("scipy.linalg")
    report, reference = _first_use(broken), _first_use("none")
    assert report["lengths"] == reference["lengths"]  # the same numbers, to the bit
    assert report["scipy.linalg imported"]  # numba's own check ran: the import it makes
    assert report["numba's BLAS flag"]
    assert report["numba's ensure_blas back"] and report["no finder left"]


def test_blas_check_refuses_a_scipy_without_cython_blas(tmp_path, monkeypatch):
    pytest.importorskip("numba")
    import meshcurv._kernels as kernels

    (tmp_path / "linalg").mkdir()  # a scipy whose linalg holds no cython_blas module
    monkeypatch.setitem(sys.modules, "scipy", types.SimpleNamespace(__path__=[str(tmp_path)]))
    assert not kernels._blas_found()
    calls = []
    kernels._checked_on_disk(lambda: calls.append("numba's"))()
    assert calls == ["numba's"]  # numba's own check decides (and raises: no scipy.linalg.cython_blas there)
