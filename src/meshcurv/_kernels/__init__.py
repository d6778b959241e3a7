"""The compiled kernels (numba), one module beside each module of NumPy code they serve.

``_kernels.geometry`` holds the compiled twins of :mod:`meshcurv.geometry`,
``_kernels.jets`` those of :mod:`meshcurv.jets`, and so on; a kernel has the
name of the NumPy function it mirrors (``face_measures`` in ``_kernels.icc``
for :func:`meshcurv.measures.face_measures`), computes exactly what it
computes, in one pass over the elements and without (N, 3, 3) temporaries,
and is tested against it directly (``tests/test_kernel_twins.py``). The rules
every kernel shares (degenerate faces, the cancellation of a normal sum, the
tangent frame) are written once, in ``_kernels._common``.

Importing this package imports numba: :mod:`meshcurv._backend` decides once
per process whether to, and hands out the modules with
``numba_kernels("geometry")``. Each module is imported on first use; numba
compiles a kernel on its first call (only the kernels a call reaches) and
caches the machine code on disk (``cache=True``). Before the first module's
kernels, ``_kernels._common`` has numba load its registries
(:func:`load_numba_registries`).
"""

import importlib
import importlib.machinery
import os
import sys
from typing import Any

import numba  # noqa: F401  (the package is importable exactly when numba is)


def load_numba_registries() -> None:
    """Have numba load its registries of implementations now, its check for BLAS made without importing
    :mod:`scipy.linalg`; once per process (later calls find them loaded).

    numba loads them (``refresh``: some 60 of its modules) before the first kernel it compiles or loads
    from its cache. One of them, ``numba.np.arraymath``, checks at import whether ``np.dot`` has BLAS by
    importing ``scipy.linalg.cython_blas``, which imports the whole of :mod:`scipy.linalg` (and, through
    scipy's array-API layer, ``numpy.f2py`` and ``numpy.testing``): some 0.22 s of CPU, an eighth of a
    fresh process's warm start on spot.obj (issue 31), for a module no kernel of meshcurv uses. While the
    registries load here, numba's ``ensure_blas`` first looks for that module on disk
    (:func:`_blas_found`); where it is there, the check passes without the import. The registries, and
    the order in which numba fills them, are numba's own: only the moment changes (here rather than in
    the first kernel's call), and the kernels compile as before.

    Nothing here can fail a call or change a result: where anything of it goes wrong (another numba whose
    modules are laid out otherwise, a scipy not found on disk), numba's own check runs, or numba loads
    the registries itself at the first kernel, as it did before. numba's ``ensure_blas`` is back in place
    once the registries are loaded (a compiled ``np.dot`` imports :mod:`scipy.linalg` as before).
    """
    finder = _BlasCheckWithoutLinalg()
    sys.meta_path.insert(0, finder)
    try:
        _refresh()
    except Exception:  # numba loads them at the first kernel, in its own way (and raises there if it must)
        pass
    finally:
        sys.meta_path.remove(finder)
        finder.restore()


def _refresh() -> None:
    """numba's loading of its registries (``refresh`` of its CPU target; once per process, then incremental)."""
    from numba.core.registry import cpu_target

    cpu_target.target_context.refresh()


def _blas_found() -> bool:
    """Whether numba's check for BLAS would pass: scipy's ``cython_blas`` module is installed (found on
    disk, not imported) and, where numba checks it (0.68 on), of the integer width numba was built for."""
    from numba.np import linalg

    scipy = sys.modules.get("scipy") or importlib.import_module("scipy")
    folders = [os.path.join(folder, "linalg") for folder in scipy.__path__]
    if importlib.machinery.PathFinder.find_spec("scipy.linalg.cython_blas", folders) is None:
        return False
    width_check = getattr(linalg, "_check_lapack_int_width", None)
    if width_check is not None:
        width_check()  # raises where the widths differ: numba's own check then says so
    return True


def _checked_on_disk(ensure_blas):
    """numba's ``ensure_blas``, which returns at once where :func:`_blas_found` says it would pass."""

    def ensure_blas_on_disk():
        try:
            found = _blas_found()
        except Exception:
            found = False
        if not found:
            ensure_blas()  # numba's own: its import of scipy.linalg, its answer, its error

    ensure_blas_on_disk.numba_ensure_blas = ensure_blas  # type: ignore[attr-defined]
    return ensure_blas_on_disk


class _BlasCheckWithoutLinalg:
    """A finder of :data:`sys.meta_path` that finds nothing: on the import of ``numba.np.arraymath`` (which
    runs numba's check for BLAS as it loads), it hands ``numba.np.linalg`` :func:`_checked_on_disk`'s
    ``ensure_blas`` first; :meth:`restore` puts numba's back."""

    def __init__(self) -> None:
        self.original = None

    def find_spec(self, fullname, path=None, target=None):
        if fullname == "numba.np.arraymath" and self.original is None:
            try:
                linalg: Any = sys.modules["numba.np.linalg"]
                original = linalg.ensure_blas
                linalg.ensure_blas = _checked_on_disk(original)
                self.original = original
            except Exception:  # numba's check runs as it is
                pass
        return None

    def restore(self) -> None:
        """numba's ``ensure_blas`` back wherever the checked one went (``numba.np.arraymath`` imports it)."""
        for name in ("numba.np.linalg", "numba.np.arraymath"):
            module: Any = sys.modules.get(name)
            if hasattr(getattr(module, "ensure_blas", None), "numba_ensure_blas"):
                module.ensure_blas = module.ensure_blas.numba_ensure_blas
