"""``quadric`` never reports a wrong number as valid at its default radius on noise, nor at a steep rim (issue 29).

Before: the noise's reach (``quadric._noise_reach``) was checked at a given radius only, against the median
curvedness of the noise fits over two edge lengths, which read noise as curvature (4.9 on a unit sphere with Gaussian
noise of 0.3 edge lengths along its normals). At the default radius (grown with the noise, capped by the curvature)
a fifth of the vertices of such spheres, tori and ellipsoids were valid and off by more than half of H; a unit
icosphere with half of its faces detached kept 80-115 such vertices per draw (``benchmarks/quadric_default_off.py``);
and at a given 1.5 edge lengths, the steep rims of ``z = x^2 - y^2`` held balls of two rows of points, 16 of whose
vertices were off (clean). Now the default radius is checked too (grown where a ball within the curvature holds the
noise), and a rim vertex's fit is checked against a wider ball's.

Expected values are the exact curvatures of the unperturbed surfaces (unit sphere: H = 1; torus R 3, r 1, saddle:
``meshcurv.shapes``); "off" is an H error above half of the largest exact ``|k|`` at the vertex (the fuzzer's
tolerance); the cover floors are about 10 points below the cover measured after the change.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes
from meshcurv._backend import use_backend

#: Gaussian noise along the exact normals, in mean edge lengths.
NOISE = 0.3


def _quadric(vertices, faces, radius=None):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the noisy balls' and the detached faces' warnings: not tested here
        return meshcurv.principal_curvatures(vertices, faces, method="quadric", radius=radius)


def _mean_edge(vertices, faces) -> float:
    return float(np.mean(np.linalg.norm(vertices[faces[:, 0]] - vertices[faces[:, 1]], axis=1)))


def _noisy(mesh, seed):
    noise = np.random.default_rng(seed).normal(0.0, NOISE * _mean_edge(mesh.vertices, mesh.faces), len(mesh.vertices))
    return mesh.vertices + noise[:, None] * mesh.normals


def _off(result, k_min, k_max):
    """(V,) bool: valid vertices whose H is off the exact one by more than half of the largest exact |k|."""
    scale = np.maximum(np.abs(k_min), np.abs(k_max))
    with np.errstate(invalid="ignore"):
        return result.valid & (np.abs(result.mean - (k_min + k_max) / 2) > 0.5 * scale)


#: Open (issue 29): W20's checks (d19e8f4) passed these but were reverted by the lead the same day: they broke three
#: tests of the suite (a hole and fan-triangulated polygons warned or lost cover, detached faces' cover 0.945 < 0.95),
#: cost 2-4.7x CPU on real meshes and read creases as noise (fandisk 80 -> 57% valid). Kept as the open defect. Q21's
#: scatter check (the residuals at two scales) passes the half-detached icosphere and leaves 3-9 of 2,562 (icosphere) and
#: 24-45 of 3,072 (torus) off at 0.3 h: noise read as structure where the wider ball reaches the curvature. The steep
#: rims at a given radius are another class.
OPEN = pytest.mark.xfail(strict=True, reason="open: quadric at its default radius and at steep rims (W20 reverted)")


@OPEN
@pytest.mark.parametrize(
    ("name", "cover"),
    [
        # before: 508 of 2562 valid vertices off (all valid); after: none, 99% valid
        ("icosphere", 0.9),
        # before: 436 of 3072 off; after: none, 90% valid
        ("torus", 0.8),
    ],
)
def test_gaussian_noise_default_radius(name, cover):
    mesh = shapes.icosphere(16) if name == "icosphere" else shapes.torus(3.0, 1.0, 96, 32)
    result = _quadric(_noisy(mesh, seed=1), mesh.faces)
    assert not _off(result, mesh.k_min, mesh.k_max).any()
    assert result.valid.mean() > cover


def test_half_detached_icosphere_default_radius():
    # passes since Q21's scatter check (the jets that depart from their ball's quadric by more than its spread take it)
    # icosphere(32): 10,242 vertices and 30,720 detached corners; before, 11 of 35,468 valid vertices off (up to
    # 0.67), none off at icosphere(24), whose curvature is larger against the corners' offset of 0.054 edge lengths
    pytest.importorskip("numba")  # minutes with the numpy backend
    from test_orient_holey_inward import _holey

    sphere = shapes.icosphere(32)
    vertices, faces = _holey(sphere.vertices, sphere.faces, seed=1, detach=True)
    result = _quadric(vertices, faces)
    ones = np.ones(len(vertices))
    # unit sphere: |H - 1| <= 0.5 at every valid vertex
    assert not _off(result, ones, ones).any()
    referenced = np.zeros(len(vertices), dtype=bool)
    referenced[faces.ravel()] = True
    assert result.valid[referenced].mean() > 0.75


@OPEN
def test_steep_saddle_rim_given_radius():
    # z = x^2 - y^2 on [-1, 1]^2, step 0.1, a radius of 1.5 mean edge lengths: the balls of the rims at y = +-1
    # (slope 2 across them) held two rows of points; 16 vertices read k_min -1.09 for -0.50 (off by 0.66-1.0 of
    # the largest |k|), 90% valid; now none off, 82% valid
    mesh = shapes.saddle(1.0, 0.1)
    result = _quadric(mesh.vertices, mesh.faces, radius=1.5 * _mean_edge(mesh.vertices, mesh.faces))
    assert not _off(result, mesh.k_min, mesh.k_max).any()
    assert result.valid.mean() > 0.75


@OPEN
def test_steep_saddle_rim_warns():
    mesh = shapes.saddle(1.0, 0.1)
    with pytest.warns(UserWarning, match="departs from a 2 times wider ball"):
        meshcurv.principal_curvatures(
            mesh.vertices, mesh.faces, method="quadric", radius=1.5 * _mean_edge(mesh.vertices, mesh.faces)
        )


def test_clean_meshes_unchanged_by_the_checks():
    # no noise: the default radius is 2.5 edge lengths everywhere and every vertex valid, as before
    for mesh in (shapes.icosphere(16), shapes.torus(3.0, 1.0, 96, 32), shapes.saddle(1.0, 0.05)):
        result = _quadric(mesh.vertices, mesh.faces)
        assert result.valid.all()
        assert not _off(result, mesh.k_min, mesh.k_max).any()


def test_backends_agree_on_the_noisy_default():
    pytest.importorskip("numba")
    mesh = shapes.icosphere(8)
    vertices = _noisy(mesh, seed=2)
    with use_backend("numba"):
        fast = _quadric(vertices, mesh.faces)
    with use_backend("numpy"):
        slow = _quadric(vertices, mesh.faces)
    np.testing.assert_array_equal(fast.valid, slow.valid)
    np.testing.assert_allclose(fast.radius, slow.radius, rtol=1e-9)
    np.testing.assert_allclose(fast.mean[fast.valid], slow.mean[fast.valid], rtol=1e-6, atol=1e-9)
