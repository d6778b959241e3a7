"""icc's check of thin parts over a wider ball leaves ordinary meshes as they were, on both backends (issue 29, T71).

T70 read the sums of a thin part's vertices again over a ball ``sqrt(2)`` wider and made them undefined where that
ball reached round the part or moved H by more than half of their largest ``|k|``. The second test read ordinary
meshes' features as thin rims: one vertex of ``spot`` (the README's example, a nostril: H 0.96 over the ball, 0.71 to
1.17 by the pointwise estimators, -0.02 over the wider ball) came out undefined with a warning; on fandisk, 498
vertices, most of them on flat faces beside a crease, where ``|k|`` is round-off and the step over it was round-off
too: the NumPy and numba valid masks differed at 10 vertices (fuzz 800/31). Expected: both meshes at their default
with every vertex valid and no warning (their first fits are made again over their own side at 249 and 1,453
vertices: the wider ball is read there), the backends' masks equal and their values within 1e-6 of the largest
``|k|``. The same files' matGeom references (``tests/data/matgeom``): every vertex defined there too.
"""

import warnings
from pathlib import Path

import numpy as np
import pytest
from conftest import chosen_backend

import meshcurv

DATA = Path(__file__).parent / "data" / "matgeom"


def _default(name, backend):
    vertices, faces = meshcurv.read_mesh(DATA / f"{name}.npz")
    with chosen_backend(backend), warnings.catch_warnings():
        warnings.simplefilter("error")  # no MeshQualityWarning: every vertex defined
        return meshcurv.principal_curvatures(vertices, faces)


@pytest.mark.parametrize("backend", ["numpy", "numba"])
@pytest.mark.parametrize("name", ["spot", "fandisk"])
def test_ordinary_meshes_default_every_vertex_valid(name, backend):
    with np.load(DATA / f"{name}.npz") as reference:
        assert np.all(np.isfinite(reference["H"]))  # matGeom defines every vertex
    result = _default(name, backend)
    assert np.all(result.valid), np.flatnonzero(~result.valid)


@pytest.mark.slow
def test_fandisk_default_one_estimator_on_both_backends():
    numba_result, numpy_result = (_default("fandisk", backend) for backend in ("numba", "numpy"))
    np.testing.assert_array_equal(numba_result.valid, numpy_result.valid)
    scale = np.nanmax(np.abs(np.r_[numpy_result.k_min, numpy_result.k_max]))
    for field in ("k_min", "k_max"):
        np.testing.assert_allclose(
            getattr(numba_result, field), getattr(numpy_result, field), rtol=0, atol=1e-6 * scale
        )
