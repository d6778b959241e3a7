"""Choice between the pure-NumPy code paths and the compiled (numba) kernels.

The NumPy paths are always there and are the reference; the numba kernels
(:mod:`meshcurv._numba_kernels`) compute the same quantities in single passes
without temporaries. They are used when numba is installed
(``pip install 'meshcurv[fast]'``) unless ``MESHCURV_BACKEND=numpy`` is set in
the environment. numba is imported on first use, never by ``import meshcurv``;
compiled kernels are cached on disk, so only the first process pays the
compilation.
"""

from __future__ import annotations

import contextlib
import os

from .errors import InvalidOptionError, MissingDependencyError

BACKENDS = ("auto", "numpy", "numba")
_override: str | None = None


def _requested() -> str:
    choice = _override or os.environ.get("MESHCURV_BACKEND", "auto")
    if choice not in BACKENDS:
        raise InvalidOptionError(
            f"unknown backend {choice!r} (MESHCURV_BACKEND); choose one of {', '.join(BACKENDS)}"
        )
    return choice


def numba_kernels():
    """The numba kernels module, or None when the NumPy paths are to be used."""
    choice = _requested()
    if choice == "numpy":
        return None
    try:
        from . import _numba_kernels
    except ImportError:
        if choice == "numba":
            raise MissingDependencyError(
                "the numba backend needs numba: pip install 'meshcurv[fast]'"
            ) from None
        return None
    return _numba_kernels


@contextlib.contextmanager
def use_backend(name: str):
    """Run a block with the given backend (``'numpy'``, ``'numba'`` or ``'auto'``)."""
    global _override
    if name not in BACKENDS:
        raise InvalidOptionError(f"unknown backend {name!r}; choose one of {', '.join(BACKENDS)}")
    previous, _override = _override, name
    try:
        yield
    finally:
        _override = previous
