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
caches the machine code on disk (``cache=True``).
"""

import numba  # noqa: F401  (the package is importable exactly when numba is)
