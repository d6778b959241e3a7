"""Supports that lost most of their elements (issue 29, wide cracks: fuzz 366/6945 and 357/680).

Half of the faces of a unit sphere detached by cracks wider than the weld leave valid vertices whose support
holds a few elements: ``normal_cycle``'s smoothing region one or two cells and their fragment (fuzz_api
``--wide-cracks 1 --seed 366 --replay 6945``: a vertex of three faces read H 3.04), ``normal_cycle_ball``'s ball
three or four edges with a dihedral angle (``--seed 357 --replay 680``: H 0.36-0.38). On a random mesh the few
left carry the tessellation's scatter, about H itself; on a regular one they read the surface. Such a vertex is
now undefined where the scatter over the square root of the elements' effective number exceeds
``FEW_ELEMENTS_SPREAD`` of the mesh's curvature.

Oracles: the exact curvature of the unit sphere (H = 1: a valid vertex off by more than half of it is a lie, the
fuzzer's bar), and the rule's own statement: on a regular icosphere, whose cells read the sphere, it takes
nothing (the same valid vertices as with the rule switched off).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes
from meshcurv.defects import UNDEFINED
from meshcurv.estimators import normal_cycle_ball

from test_wide_cracks_R18 import half_detached

#: The cracks' width in mean edge lengths: beyond the weld across cracks (0.05), so no face is welded back.
GAP = 0.09


def _curvatures(vertices, faces, **options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the defects' warning (boundaries, fragments): counted, not tested here
        return meshcurv.principal_curvatures(vertices, faces, **options)


def _lies(result) -> np.ndarray:
    return result.valid & ~(np.abs(result.mean - 1.0) <= 0.5)


@pytest.mark.parametrize("seed", [0, 3, 7, 12])
def test_region_of_few_cells_undefined(seed):
    # before: 1-2 valid vertices off H = 1 by more than 0.5 (a region of a few cells of a fragment; of seeds 0-19,
    # 16 had 1-3 such vertices; now 5 have 1-3: open)
    vertices, faces, _ = half_detached(shapes.random_sphere(n_vertices=200), seed, GAP)
    result = _curvatures(vertices, faces, method="normal_cycle")
    assert not _lies(result).any(), result.mean[_lies(result)]
    assert (result.invalid_reason == UNDEFINED).any()
    assert (result.invalid_reason[~result.valid] > 0).all()


def test_warning_names_the_vertices_undefined_for_few_elements():
    vertices, faces, _ = half_detached(shapes.random_sphere(n_vertices=200), 0, GAP)
    with pytest.warns(UserWarning, match=r"\d+ vertices are NaN \(estimate undefined\): their smoothing region "):
        meshcurv.principal_curvatures(vertices, faces, method="normal_cycle")


@pytest.mark.parametrize("method", ["normal_cycle", "normal_cycle_ball"])
def test_regular_icosphere_keeps_its_vertices(method, monkeypatch):
    # a regular mesh's elements read the sphere: the rule leaves every vertex as it was
    vertices, faces, _ = half_detached(shapes.icosphere(subdivisions=4), 3, GAP)
    result = _curvatures(vertices, faces, method=method)
    monkeypatch.setattr(normal_cycle_ball, "FEW_ELEMENTS_SPREAD", np.inf)
    unruled = _curvatures(vertices, faces, method=method)
    assert result.valid.sum() > 0
    np.testing.assert_array_equal(result.valid, unruled.valid)
    assert not _lies(result).any()


@pytest.mark.parametrize("method", ["normal_cycle", "normal_cycle_ball"])
def test_backends_agree_on_few_elements(method):
    pytest.importorskip("numba")
    from meshcurv._backend import use_backend

    vertices, faces, _ = half_detached(shapes.random_sphere(n_vertices=200), 2, GAP)
    with use_backend("numpy"):
        reference = _curvatures(vertices, faces, method=method)
    with use_backend("numba"):
        compiled = _curvatures(vertices, faces, method=method)
    np.testing.assert_array_equal(reference.valid, compiled.valid)
    np.testing.assert_allclose(compiled.mean, reference.mean, rtol=0, atol=1e-9, equal_nan=True)
