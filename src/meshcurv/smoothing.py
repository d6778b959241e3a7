"""Smoothing of per-vertex fields over the mesh graph (vertices never move)."""

from __future__ import annotations

import numpy as np

from ._backend import twin
from ._validation import check_int_option
from .errors import InvalidMeshError, InvalidOptionError
from .topology import MeshTopology

__all__ = ["smooth_vertex_field", "MAX_SMOOTHING_STEPS", "check_smoothing_steps"]

#: Most passes accepted. Each pass spreads every value one ring further, and the
#: spread after ``s`` passes is about ``sqrt(s)`` rings (a diffusion): 10000 passes
#: average each value over some 100 rings, far beyond any local curvature estimate,
#: and on a million-vertex mesh they already take minutes. Larger values (a typo,
#: 10**9 would run for days) are refused.
MAX_SMOOTHING_STEPS = 10_000

#: Passes per compiled kernel call: between calls Python gets control back, so that
#: Ctrl-C (KeyboardInterrupt) stops a long smoothing.
STEPS_PER_CALL = 64


def check_smoothing_steps(steps) -> int:
    """Check the ``smoothing_steps`` option of the estimators.

    Parameters
    ----------
    steps : int
        An integer (``operator.index``: a Python or NumPy int, not a bool
        nor a float).

    Returns
    -------
    int
        ``steps``, in ``[0, MAX_SMOOTHING_STEPS]``.

    Raises
    ------
    InvalidOptionError
        Not an integer, negative, or above :data:`MAX_SMOOTHING_STEPS`.
    """
    number = check_int_option(steps, "smoothing_steps", maximum=None)
    if number > MAX_SMOOTHING_STEPS:
        raise InvalidOptionError(
            f"`smoothing_steps` must be at most {MAX_SMOOTHING_STEPS}; got {number} (each pass averages over "
            f"one more ring: {MAX_SMOOTHING_STEPS} passes already spread every value over about "
            f"{int(MAX_SMOOTHING_STEPS**0.5)} rings)"
        )
    return number


def smooth_vertex_field(values, topology: MeshTopology, steps: int) -> np.ndarray:
    """Average a per-vertex field over 1-rings, ``steps`` times.

    One pass replaces the value at each vertex by the plain mean of its own value
    and the values at its distinct edge neighbours, each with weight
    ``1 / (degree + 1)``: matGeom's ``smoothMeshFunction``. A vertex with no edge
    keeps its value.

    Parameters
    ----------
    values : array_like of shape (V,) or (V, k)
        The field; all ``k`` columns are smoothed at once.
    topology : MeshTopology
        The mesh connectivity (its ``adjacency``).
    steps : int
        Number of passes, 0 to :data:`MAX_SMOOTHING_STEPS`; 0 returns a copy.

    Returns
    -------
    ndarray of the same shape as ``values``, float64.

    Raises
    ------
    InvalidMeshError
        ``values`` has not one row per vertex of ``topology``, or is not real.
    InvalidOptionError
        ``steps`` is not an integer in ``[0, MAX_SMOOTHING_STEPS]``.

    Notes
    -----
    NaN spreads one ring per pass, as in matGeom (the sparse product only
    touches neighbours). The compiled path runs :data:`STEPS_PER_CALL` passes per
    kernel call, so that a long smoothing can be interrupted.
    """
    steps = check_smoothing_steps(steps)
    if not isinstance(topology, MeshTopology):
        raise InvalidMeshError(f"`topology` must be a MeshTopology; got {type(topology).__name__}")
    try:
        array = np.asarray(values)
    except (TypeError, ValueError, OverflowError) as exc:
        raise InvalidMeshError(f"`values` must be a real array of shape (V,) or (V, k) ({exc})") from None
    if array.dtype.kind not in "biuf":  # complex (its imaginary part would be dropped), strings, objects
        raise InvalidMeshError(f"`values` must hold real numbers (float, int or bool); got dtype {array.dtype}")
    field = np.array(array, dtype=np.float64, copy=True)
    if field.ndim not in (1, 2) or field.shape[0] != topology.n_vertices:
        raise InvalidMeshError(
            f"`values` must have shape (V,) or (V, k) with V = {topology.n_vertices} (the topology's "
            f"vertices); got {tuple(field.shape)}"
        )
    return _smooth_vertex_field(field, topology, steps)


def _smooth_vertex_field(field: np.ndarray, topology: MeshTopology, steps: int) -> np.ndarray:
    """:func:`smooth_vertex_field` of checked arguments: ``field`` a float64 (V,) or (V, k) array of the
    topology's vertices (a new array is returned; ``field`` itself when ``steps`` is 0), ``steps`` >= 0."""
    if steps <= 0:
        return field
    flat = np.ascontiguousarray(field.reshape(field.shape[0], -1))
    indptr, indices = topology.neighbour_lists
    for done in range(0, steps, STEPS_PER_CALL):
        flat = smooth_over_neighbours(flat, indptr, indices, min(STEPS_PER_CALL, steps - done))
    return flat.reshape(field.shape)


@twin("smoothing")
def smooth_over_neighbours(values: np.ndarray, indptr: np.ndarray, indices: np.ndarray, steps: int) -> np.ndarray:
    """``steps`` passes of the 1-ring mean ``(value + sum of the neighbours') / (degree + 1)``.

    Parameters
    ----------
    values : ndarray of shape (V, k), float64
        The field, C-contiguous; not changed.
    indptr, indices : ndarray of int64
        The neighbours in CSR form (:attr:`meshcurv.topology.MeshTopology.neighbour_lists`).
    steps : int
        Number of passes, at least 1.

    Returns
    -------
    ndarray of shape (V, k), float64
    """
    import scipy.sparse as sp  # imported on use: keeps `import meshcurv` fast

    n = values.shape[0]
    adjacency = sp.csr_matrix((np.ones(indices.size), indices, indptr), shape=(n, n))  # the topology's adjacency
    scale = (1.0 / (np.diff(indptr) + 1.0))[:, None]
    field = values
    for _ in range(steps):
        field = (adjacency @ field + field) * scale
    return field
