"""What a call does around its kernels: no copies of the kernels' arrays, one compiled signature per kernel.

Regressions of issue 31 (the default's time outside its kernels, first use).
"""

from __future__ import annotations

import dataclasses
import inspect

import numpy as np
import pytest

from meshcurv import principal_curvatures, shapes
from meshcurv._backend import numba_kernels
from meshcurv.result import CurvatureResult
from meshcurv.topology import MeshTopology

numba = pytest.importorskip("numba")


def test_a_result_keeps_the_arrays_a_kernel_allocated():
    """An array a compiled kernel returned (its base numba's buffer, not an ndarray) is taken as it is: the
    default call copied six (V,) and (V, 3) arrays twice (0.16 s at a million vertices)."""
    sphere = shapes.icosphere(4)
    topology = MeshTopology.from_faces(sphere.faces)
    lengths = numba_kernels("geometry").edge_lengths(sphere.vertices, topology.edges)
    assert not lengths.flags.owndata  # numba's MemInfo owns the buffer
    n = lengths.size
    fields = {
        "k_min": lengths,
        "k_max": np.ones(n),
        "dir_min": np.zeros((n, 3)),
        "dir_max": np.zeros((n, 3)),
        "normals": np.zeros((n, 3)),
        "valid": np.ones(n, dtype=bool),
    }
    result = CurvatureResult._of_arrays(method="test", **fields)
    assert result.k_min is lengths and not lengths.flags.writeable
    again = dataclasses.replace(result, parameters={"radius": 1.0})
    assert again.k_min is lengths
    # a view of another array is still copied: its base could be written through
    view = np.ones(2 * n)[:n]
    assert CurvatureResult(method="test", **{**fields, "k_min": view}).k_min is not view


def test_the_default_call_types_its_jet_fits_once(monkeypatch):
    """The noise fits and the normal fits reach the compiled jet fits with the same argument types, so numba
    compiles them once on a cold cache (the normals were read-only in one and writable in the other: two
    signatures, 8-10 s of CPU each)."""
    from meshcurv._kernels import jets

    original = jets._connected_chunk
    seen = []

    def recording(*args):
        seen.append(tuple(str(numba.typeof(a)) for a in args))
        return original(*args)

    monkeypatch.setattr(jets, "_connected_chunk", recording)
    sphere = shapes.icosphere(8)
    principal_curvatures(sphere.vertices, sphere.faces)
    assert len(seen) >= 2  # the noise fits and the normal fits
    assert len(set(seen)) == 1
    general = list(inspect.signature(original.py_func).parameters).index("general")
    assert seen[0][general] == "none"  # fits of degree 3 or less: no code of the general moments compiled


def test_the_default_call_types_its_ball_sums_once(monkeypatch):
    """The default's ball sums run their compiled chunk with one set of argument types (one compilation on a
    cold cache), the one-ball kernel's, not the nested one's (issue 31)."""
    from meshcurv._kernels import neighborhoods

    original = neighborhoods._face_sums_chunk
    seen = []

    def recording(*args):
        seen.append(tuple(str(numba.typeof(a)) for a in args[2:]))
        return original(*args)

    monkeypatch.setattr(neighborhoods, "_face_sums_chunk", recording)
    sphere = shapes.icosphere(8)
    principal_curvatures(sphere.vertices, sphere.faces)
    assert seen  # the ball sums of the default ran the one-ball chunk
    assert len(set(seen)) == 1
