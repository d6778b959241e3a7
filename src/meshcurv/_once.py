"""Arrays derived from the prepared mesh, computed once per call whoever asks for them.

The length scale of each vertex (:func:`meshcurv._geometry.vertex_length_scales`)
and the needle vertices (:func:`meshcurv.defects.needle_vertices`) are read by
the orientation, the defect codes, every default-radius rule and the
diagnosis, each with the same ``vertices`` and topology. Inside
:func:`computed_once` (opened by :func:`meshcurv.principal_curvatures` around
its whole call), the functions that compute them ask :func:`once` first: the
first caller computes, the others get the same read-only array. Only the
vertices that :func:`meshcurv._prepared.prepare_mesh` handed over
(:func:`adopt`) are remembered, with any topology of them (a weak reference:
the topology replaced by the orientation is not kept alive); outside the
scope, or for other arrays, :func:`once` just computes.

The arrays are the library's own (copies made at the door) and never written
in place, so their identity stands for their content during the call.
"""

from __future__ import annotations

import weakref
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Any

import numpy as np

__all__ = ["computed_once", "adopt", "once"]


class _Memo:
    """The vertices adopted by the call and the arrays derived from them, by name and topology."""

    def __init__(self) -> None:
        self.vertices: np.ndarray | None = None
        self.values: dict[tuple, tuple[weakref.ref, tuple, Any]] = {}


_MEMO: ContextVar[_Memo | None] = ContextVar("meshcurv_once", default=None)


@contextmanager
def computed_once() -> Iterator[None]:
    """A scope in which :func:`once` remembers what it computes for the adopted vertices (a call made inside
    another, e.g. on a pilot mesh, has its own; the outer one's comes back after it)."""
    token = _MEMO.set(_Memo())
    try:
        yield
    finally:
        _MEMO.reset(token)


def adopt(vertices: np.ndarray) -> None:
    """Remember, in the open scope (if any), what is derived from ``vertices``: the prepared mesh's vertices."""
    memo = _MEMO.get()
    if memo is not None and memo.vertices is not vertices:
        memo.vertices = vertices
        memo.values.clear()


def once(name: str, vertices: np.ndarray, topology, compute: Callable[[], Any], *inputs: np.ndarray) -> Any:
    """``compute()``, remembered under ``name`` for ``vertices``, ``topology`` and the other ``inputs``
    (compared by identity) when ``vertices`` are the adopted ones; an array result is made read-only
    unless ``name`` ends with ``"!"`` (an array handed to compiled kernels compiled for writable arrays)."""
    memo = _MEMO.get()
    if memo is None or vertices is not memo.vertices:
        return compute()
    key = (name, id(topology))
    known = memo.values.get(key)
    if (
        known is not None
        and known[0]() is topology
        and len(known[1]) == len(inputs)
        and all(a is b for a, b in zip(known[1], inputs))
    ):
        return known[2]
    value = compute()
    if isinstance(value, np.ndarray) and not name.endswith("!"):
        value.flags.writeable = False
    memo.values[key] = (weakref.ref(topology), inputs, value)
    return value
