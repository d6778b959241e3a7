"""A part left out of a cloud's estimate gives the call's one warning, on both backends (fuzz round 15, seed 253
case 967): the NumPy path of the neighbours' check divided by the spacing 0 of the left-out points and let a
``RuntimeWarning: divide by zero`` out beside it."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from meshcurv import shapes
from meshcurv._backend import use_backend
from meshcurv.errors import MeshcurvWarning
from meshcurv.pointcloud import point_cloud_curvatures


@pytest.mark.parametrize("backend", ["numba", "numpy"])
def test_a_subnormal_part_beside_a_large_one_gives_one_warning(backend):
    if backend == "numba":
        pytest.importorskip("numba")
    tiny = shapes.uv_sphere(n_longitude=12, n_latitude=8).vertices * 1e-312  # spaced below what a float resolves
    large = shapes.cylinder(n_around=12, n_along=6).vertices * 1e12 + 5e12
    with use_backend(backend), warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = point_cloud_curvatures(np.concatenate([tiny, large]))
    assert [type(w.message) for w in caught if not issubclass(w.category, MeshcurvWarning)] == []
    assert len(caught) == 1 and "left out" in str(caught[0].message)
    assert not result.valid[: tiny.shape[0]].any()
    assert result.valid[tiny.shape[0] :].mean() > 0.8
