"""method="matgeom" on both backends where its normal is undefined (issue 29, class 10).

matGeom's normal is the eigenvector of the tensor's smallest-magnitude eigenvalue. Where that
eigenvalue equals the next one the eigenvector is any vector of a plane, and which one the solver
returns is decided by round-off (LAPACK on the NumPy path, cyclic Jacobi on the compiled one): a
closed sphere smoothed 10000 times (every tensor becomes the mean tensor, a multiple of the
identity: the fuzzer's seed 316 case 10124, normals up to 0.995 apart), and a surface whose
coordinates are quantised at round-off (translated by 1e15: a staircase of rank-1 tensors, seed 1515
case 4914). There both backends give a NaN normal and ``valid=False``; elsewhere they agree within
1e-6 as everywhere (tests/test_backend_parity.py).
"""

from __future__ import annotations

import inspect
import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes
from meshcurv._backend import use_backend
from meshcurv.defects import UNDEFINED
from meshcurv.errors import MeshQualityWarning
from meshcurv.estimators import matgeom

from conftest import DATA

pytest.importorskip("numba")

#: Relative agreement of the two backends (tests/test_backend_parity.py's).
RTOL = 1e-6


def both(vertices, faces, **options):
    """``{backend: result}`` of method="matgeom" on each backend, warnings kept."""
    results, messages = {}, {}
    for backend in ("numba", "numpy"):
        with use_backend(backend), warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            results[backend] = meshcurv.principal_curvatures(vertices, faces, method="matgeom", **options)
        messages[backend] = [str(w.message) for w in caught if issubclass(w.category, MeshQualityWarning)]
    return results, messages


def assert_backends_agree(results) -> None:
    """The same valid vertices and reasons, curvatures within RTOL of the largest |k|, valid normals up to sign."""
    a, b = results["numba"], results["numpy"]
    np.testing.assert_array_equal(a.valid, b.valid)
    np.testing.assert_array_equal(a.invalid_reason, b.invalid_reason)
    np.testing.assert_array_equal(np.isnan(a.normals), np.isnan(b.normals))
    scale = float(np.nanmax(np.abs(np.concatenate([a.k_min, a.k_max])))) or 1.0
    for field in ("k_min", "k_max"):
        np.testing.assert_allclose(getattr(b, field), getattr(a, field), rtol=0, atol=RTOL * scale)
    na, nb = a.normals[a.valid], b.normals[a.valid]
    nb = nb * np.where(np.einsum("ij,ij->i", na, nb) < 0, -1.0, 1.0)[:, None]  # an eigenvector: up to sign
    np.testing.assert_allclose(nb, na, rtol=0, atol=RTOL)


def test_a_sphere_smoothed_into_the_identity_has_no_normal_on_either_backend():
    # 10000 passes over an icosphere of 362 vertices average every tensor over the whole sphere: the
    # mean of a sphere's edge tensors is isotropic (its three eigenvalues equal to round-off), so no
    # eigenvector is the normal; the curvatures are that one eigenvalue on both backends
    sphere = shapes.icosphere(6)
    results, messages = both(sphere.vertices, sphere.faces, smoothing_steps=10_000)
    assert_backends_agree(results)
    for backend, result in results.items():
        assert not result.valid.any(), backend
        assert np.isnan(result.normals).all(), backend
        np.testing.assert_allclose(result.k_min, result.k_max, rtol=1e-12)  # isotropic: one eigenvalue
        assert (result.invalid_reason == UNDEFINED).all(), backend
        assert len(messages[backend]) == 1 and "362 vertices have no normal" in messages[backend][0], backend


def test_a_few_smoothing_passes_keep_every_normal_of_a_sphere():
    # the default: the tensors are far from isotropic, every vertex valid, the normal radial (to 1e-3)
    sphere = shapes.icosphere(6)
    results, messages = both(sphere.vertices, sphere.faces, smoothing_steps=3)
    assert_backends_agree(results)
    radial = sphere.vertices / np.linalg.norm(sphere.vertices, axis=1, keepdims=True)
    for backend, result in results.items():
        assert result.valid.all(), backend
        assert messages[backend] == [], backend
        assert (np.abs(np.einsum("ij,ij->i", result.normals, radial)) > 1 - 1e-3).all(), backend


@pytest.mark.parametrize("smoothing_steps", [0, 3])
def test_a_saddle_quantised_at_round_off_is_measured_alike(smoothing_steps):
    # the saddle translated by 1e15: its coordinates (2 wide) on a grid of 1/8, its faces a staircase of
    # coplanar runs whose tensors are rank 1 or zero; the same valid vertices, reasons and values on both
    # backends (the other methods measure it too, with no warning about the translation: no precision
    # check of coordinates exists for any of them)
    saddle = shapes.saddle(spacing=0.2)  # the fuzzer's: 11 x 11 vertices
    vertices = saddle.vertices + 1e15
    results, _ = both(vertices, saddle.faces, smoothing_steps=smoothing_steps)
    assert_backends_agree(results)
    result = results["numpy"]
    no_normal = np.isnan(result.normals).any(axis=1) & ~np.isnan(result.k_max)
    assert not result.valid[no_normal].any()
    if smoothing_steps == 0:  # the staircase's own tensors (smoothed, they mix and the ties go)
        assert no_normal.any()


@pytest.mark.parametrize("smoothing_steps", [0, 3])
def test_a_rotated_cube_has_no_normal_on_its_edges(smoothing_steps):
    # a cube's edge vertex has a rank-1 tensor (its two smallest eigenvalues 0): the normal is any vector
    # of a plane. Axis-aligned, both solvers return the same axis (matGeom's reference outputs,
    # tests/test_matgeom_parity.py, mask these vertices as `flat`); rotated, each returns its own
    with np.load(DATA / "matgeom" / "cube_sub4.npz") as case:
        vertices, faces = case["vertices"], case["faces"]
    rotation = np.array([[0.36, 0.48, -0.8], [-0.8, 0.6, 0.0], [0.48, 0.64, 0.6]])  # orthogonal, exact
    results, _ = both(vertices @ rotation.T, faces, smoothing_steps=smoothing_steps)
    assert_backends_agree(results)
    assert np.isnan(results["numpy"].normals).any()


def test_the_kernels_default_gap_is_the_estimators():
    from meshcurv._kernels import matgeom as kernels

    for kernel in (kernels.matgeom_principal, kernels.matgeom_finish):
        assert inspect.signature(kernel.py_func).parameters["gap"].default == matgeom.NORMAL_GAP
