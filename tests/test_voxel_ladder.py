"""The ladder of icc's default on voxel surfaces (issue 30, round 5): each vertex's H at ``r_v`` or ``sqrt(2) r_v``.

Oracles: the closed form of the rungs (:func:`meshcurv.radius.voxel_ladder`); the
exact curvature of a voxelised sphere (``1 / r`` at every vertex); and the
default with its ladder cut to the first rung (``icc.VOXEL_LADDER_TOP = 0``, the
rule before the ladder), which must give the same normals, radii ``r_v`` and Gaussian curvature.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes
from meshcurv.errors import MeshQualityWarning
from meshcurv.estimators import icc
from meshcurv.radius import VOXEL_LADDER, VOXEL_LADDER_TOP, voxel_ladder


def quiet(vertices, faces, **options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshQualityWarning)
        return meshcurv.principal_curvatures(vertices, faces, **options)


def test_the_rungs_in_closed_form():
    radii = np.array([1.0, 2.0, 5.0])
    rungs = voxel_ladder(radii, 6.0)
    s = np.sqrt(2.0)
    assert VOXEL_LADDER == (1.0, s, 2.0) and VOXEL_LADDER_TOP == 1
    np.testing.assert_allclose(rungs, [[1.0, 2.0, 5.0], [s, 2 * s, 6.0], [2.0, 4.0, 6.0]], rtol=1e-15)


@pytest.fixture(scope="module")
def sphere():
    pytest.importorskip("skimage")
    mesh = shapes.voxel_sphere(10.0, (1.0, 1.0, 1.0), seed=0)
    return np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces)


def test_each_vertex_takes_its_radius_or_the_next_rung(sphere, monkeypatch):
    vertices, faces = sphere
    ladder = quiet(vertices, faces)
    monkeypatch.setattr(icc, "VOXEL_LADDER_TOP", 0)
    first = quiet(vertices, faces)
    assert ladder.parameters["scale"] == "voxel" and "least change" in ladder.parameters["scale_rule"]
    np.testing.assert_array_equal(ladder.normals, first.normals)  # one normal fit, whatever the rung
    ratio = ladder.radius / first.radius
    upper = np.isclose(ratio, np.sqrt(2.0), rtol=1e-12)
    assert np.all(upper | (ratio == 1.0))
    assert 0.1 < upper.mean() < 0.9  # both rungs are taken on this sphere
    # where a vertex keeps its first rung, its curvatures are those of the rule without the ladder (to
    # round-off: its mu_1 is rescaled by mu_0 / mu_0)
    np.testing.assert_allclose(ladder.mean[~upper], first.mean[~upper], rtol=1e-12)
    # the Gaussian curvature stays that of r_v wherever both mean curvatures leave real principal curvatures
    # (H^2 > K; otherwise k_min = k_max = H, and the K reported is H^2)
    real = (ladder.k_max > ladder.k_min) & (first.k_max > first.k_min)
    assert real.mean() > 0.3
    np.testing.assert_allclose(ladder.gaussian[real], first.gaussian[real], rtol=1e-9, atol=1e-15)


def test_the_ladder_brings_a_voxel_sphere_closer_to_its_curvature(sphere, monkeypatch):
    # sphere r 10 at voxel 1: median |H - 1/r| / (1/r) 0.99% at r_v alone (the accuracy_voxel.md row), about
    # half of it with the ladder (benchmarks/smoothed_isosurfaces.md, round 5): a sphere's ball has no bias, and
    # the vertices whose estimates settle above r_v take sqrt(2) r_v
    vertices, faces = sphere
    exact = 1.0 / 10.0
    ladder = quiet(vertices, faces)
    monkeypatch.setattr(icc, "VOXEL_LADDER_TOP", 0)
    first = quiet(vertices, faces)
    error_ladder = float(np.median(np.abs(ladder.mean - exact) / exact))
    error_first = float(np.median(np.abs(first.mean - exact) / exact))
    assert error_ladder < 0.75 * error_first
    assert error_ladder < 0.007
