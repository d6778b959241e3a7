"""The rules every kernel shares, each in one place: the JIT options, an edge's length, a face's cross
product, the degenerate-face test, the cancellation of a normal sum, the tangent frame of a normal, and
the threads that run a kernel's chunks (:func:`run_chunks`, :func:`run_slots`).
"""

from __future__ import annotations

import math
import os
import threading
from concurrent.futures import ThreadPoolExecutor, wait
from typing import Literal, TypedDict, cast

import numba as nb
import numpy as np

from . import load_numba_registries


load_numba_registries()  # before the first kernel: numba's registries without scipy.linalg (see there)


class _JitOptions(TypedDict):
    """The keywords of ``numba.njit`` the kernels set (typed, so that ``njit(**_JIT)`` type-checks)."""

    cache: bool
    nogil: bool
    fastmath: bool | set[str]
    error_model: Literal["python", "numpy"]


#: The options of every kernel: cached on disk, no GIL, IEEE arithmetic (NaN and inf keep their meaning), no C
#: function wrapper (what lets a compiled function be passed to another as a first-class function, which no
#: kernel does: numba builds one for every function it compiles otherwise, 10-20% of a small kernel's compile
#: time on a cold cache, issue 31).
_JIT: _JitOptions = cast(  # numba's stub of njit does not name no_cfunc_wrapper (numba.core.options has it)
    _JitOptions,
    {"cache": True, "nogil": True, "fastmath": False, "error_model": "numpy", "no_cfunc_wrapper": True},
)


_TINY = np.finfo(np.float64).tiny

#: Indices known to be >= 0 are cast to this type where a kernel reads arrays with them: numba indexes with an
#: unsigned integer without its code for negative indices (a shift, a mask and an add on the path of every load;
#: a third to a half of the instructions of the walks of the balls, issue 31). Arithmetic on them stays unsigned:
#: ``a + _ONE``, never ``a + 1`` (an int64 and a uint64 make a float64 in numba).
_UNSIGNED = np.uint64
_ONE = np.uint64(1)


#: Sums that may be reassociated (vectorized); no other fast-math assumption (NaN and inf stay meaningful).
_JIT_REASSOC: _JitOptions = {**_JIT, "fastmath": {"reassoc", "contract"}}

#: The options of a function called only from compiled kernels, never from Python: no Python wrapper either (the
#: code that unboxes each argument and boxes the result, compiled for every function otherwise; issue 31).
_JIT_INNER: _JitOptions = cast(_JitOptions, {**_JIT, "no_cpython_wrapper": True})
_JIT_INNER_REASSOC: _JitOptions = cast(_JitOptions, {**_JIT_REASSOC, "no_cpython_wrapper": True})


@nb.njit(inline="always", **_JIT)
def _edge_length(vertices, p, q):
    x = vertices[q, 0] - vertices[p, 0]
    y = vertices[q, 1] - vertices[p, 1]
    z = vertices[q, 2] - vertices[p, 2]
    return math.sqrt(x * x + y * y + z * z)


@nb.njit(inline="always", **_JIT)
def _face_cross(vertices, a, b, c):
    """cross(b - a, c - a): the face normal times twice its area."""
    ux = vertices[b, 0] - vertices[a, 0]
    uy = vertices[b, 1] - vertices[a, 1]
    uz = vertices[b, 2] - vertices[a, 2]
    wx = vertices[c, 0] - vertices[a, 0]
    wy = vertices[c, 1] - vertices[a, 1]
    wz = vertices[c, 2] - vertices[a, 2]
    return uy * wz - uz * wy, uz * wx - ux * wz, ux * wy - uy * wx


@nb.njit(inline="always", **_JIT)
def _degenerate(a, b, c, half_area, threshold):
    """A face that repeats a vertex or whose area is at most ``threshold`` (``geometry.degenerate_faces``)."""
    return a == b or b == c or c == a or half_area <= threshold


@nb.njit(inline="always", **_JIT)
def _unit(x, y, z):
    """``(x, y, z) / |(x, y, z)|`` and True, or NaNs and False where the sum (nearly) cancels.

    The rule of ``geometry.normalize_normal_sums``: a sum whose norm is at most
    ``1e-12`` of its largest component (or of the smallest normal float) has
    no direction.
    """
    norm = math.sqrt(x * x + y * y + z * z)
    # max(max(abs(x), abs(y), abs(z)), _TINY) written out: numba compiles max once per caller's options (issue 31)
    largest = abs(x)
    largest = abs(y) if abs(y) > largest else largest
    largest = abs(z) if abs(z) > largest else largest
    if norm > 1e-12 * (_TINY if _TINY > largest else largest):
        return x / norm, y / norm, z / norm, True
    return np.nan, np.nan, np.nan, False


@nb.njit(**_JIT_INNER)
def _tangent_frame(nx, ny, nz):
    """Unit tangents ``t1, t2`` with ``(t1, t2, n)`` right-handed, ``t1 = cross(n, e)`` for the axis ``e``
    least aligned with ``n`` (the frame of ``_tensors.tangent_basis``)."""
    ax, ay, az = abs(nx), abs(ny), abs(nz)
    # cross(n, axis) with the axis least aligned with n (first minimum, as np.argmin)
    if ax <= ay and ax <= az:
        tx, ty, tz = 0.0, nz, -ny
    elif ay <= az:
        tx, ty, tz = -nz, 0.0, nx
    else:
        tx, ty, tz = ny, -nx, 0.0
    norm = math.sqrt(tx * tx + ty * ty + tz * tz)
    tx /= norm
    ty /= norm
    tz /= norm
    return tx, ty, tz, ny * tz - nz * ty, nz * tx - nx * tz, nx * ty - ny * tx


def threaded(function):
    """Mark a kernel written in Python that runs compiled chunks on threads (:func:`run_chunks`).

    :mod:`meshcurv._backend` runs such a kernel as a compiled one: on one
    thread when its arrays are small (``_backend._small``).
    """
    function.runs_chunks = True
    return function


def run_chunks(chunk, n_items, n_chunks, *args) -> None:
    """Call ``chunk(lo, hi, *args)`` for ``n_chunks`` consecutive ranges ``[lo, hi)`` covering ``range(n_items)``.

    The ranges are those of ``numba.prange`` over the chunks (``lo = c * n_items // n_chunks``), at most
    ``n_items`` of them and at least one. ``chunk`` is a compiled function without the GIL (``nogil``)
    that writes its range's rows of arrays in ``args``; the ranges run on ``numba.get_num_threads()``
    threads: the calling thread and workers of one pool kept between calls (:func:`_pool`), the calling
    thread alone when that is 1 (as ``numba.set_num_threads`` or ``NUMBA_NUM_THREADS`` make it). Each
    thread takes the next range left until none is; the call returns when every range is written.

    Why threads rather than ``parallel=True``: numba's parallel pipeline compiles the body of a parallel
    loop twice and optimises the functions it calls again in the loop's module; for the jet fits that was
    4.7 of 9.6 s of CPU on a cold cache (issue 31), for the same machine code. The results do not depend
    on the number of threads: each range writes its own rows.
    """
    _run_ranges(chunk, n_items, n_chunks, args)


def run_slots(chunk, n_items, n_chunks, n_slots, *args) -> None:
    """:func:`run_chunks` whose chunks also get the slot of the thread that runs them: ``chunk(lo, hi, slot,
    *args)``, ``slot`` in ``range(n_slots)``, never that of two threads at once in one call (at most
    ``n_slots`` threads run the call).

    For kernels whose ranges need a scratch as large as the mesh (the stamps of a breadth-first walk): one
    row of it per slot, reused by every range its thread takes, so that the ranges can be many (a thread
    that finishes early takes more of them: on a busy machine, or where the work per item varies across the
    mesh) without a scratch each.
    """
    _run_ranges(chunk, n_items, n_chunks, args, max(int(n_slots), 1))


def _run_ranges(chunk, n_items, n_chunks, args, slots: int = 0) -> None:
    """:func:`run_chunks` (``slots`` 0) and :func:`run_slots` (at most ``slots`` threads)."""
    n_chunks = max(min(int(n_items), int(n_chunks)), 1)
    bounds = iter([(c * n_items // n_chunks, (c + 1) * n_items // n_chunks) for c in range(n_chunks)])
    threads = min(nb.get_num_threads(), n_chunks, slots or n_chunks)

    def work(slot):
        for lo, hi in bounds:  # a list iterator hands out each range once, whatever the thread
            if slots:
                chunk(lo, hi, slot, *args)
            else:
                chunk(lo, hi, *args)

    if threads <= 1:
        work(0)
        return
    helpers = [_pool().submit(work, slot) for slot in range(1, threads)]
    try:
        work(0)
    finally:
        # a helper not started yet (the pool busy with another call's ranges) has nothing left to do: it is
        # cancelled rather than waited for, so that a call never waits on the queue of another; the others
        # are waited for, all of them, before any error of theirs is raised
        started = [future for future in helpers if not future.cancel()]
        wait(started)
    for future in started:
        future.result()


_POOL: ThreadPoolExecutor | None = None
_POOL_LOCK = threading.Lock()


def _pool() -> ThreadPoolExecutor:
    """The workers of :func:`run_chunks`: one pool per process, made on first use with
    ``NUMBA_NUM_THREADS - 1`` threads (the most ``numba.set_num_threads`` allows, less the calling thread).

    Its idle threads wait on a queue; ``concurrent.futures`` joins them at the interpreter's exit. A child
    made by ``fork`` (which has the pool's object but not its threads) makes its own (:func:`_forget_pool`).
    """
    global _POOL
    with _POOL_LOCK:
        if _POOL is None:
            threads = nb.config.NUMBA_NUM_THREADS  # type: ignore[attr-defined]
            _POOL = ThreadPoolExecutor(max(threads - 1, 1), thread_name_prefix="meshcurv-kernel")
        return _POOL


def _forget_pool() -> None:
    global _POOL, _POOL_LOCK
    _POOL, _POOL_LOCK = None, threading.Lock()


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_forget_pool)
