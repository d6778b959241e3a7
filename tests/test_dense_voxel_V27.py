"""Costs of icc's default on dense voxel surfaces that do not scale with the surface (issue 30).

Oracles: NumPy's ``unique`` over rows (the groups the coarse level's packed keys must reproduce) and the
definition of the voxel default (its radius is derived from the surface, never refused as a given one is).
"""

from __future__ import annotations

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes


def test_coarse_level_rows_fit_one_key(monkeypatch):
    # the coarse level's rows: three cube indices and a side code of 0 to 26; fixed widths of 20, 20, 20 and 5 bits
    # (65) never fitted one int64, so every coarse level sorted rows (6 ms on a 10,172-vertex sphere, not 0.3)
    from meshcurv.estimators import icc

    rng = np.random.default_rng(3)
    rows = np.column_stack([rng.integers(0, 40, 6000) for _ in range(3)] + [rng.integers(0, 27, 6000)])
    rows[3000:] = rows[:3000]
    expected = np.unique(rows, axis=0, return_inverse=True)[1].ravel()
    unique = np.unique
    sorted_rows = []

    def spy(values, *args, **kwargs):
        if kwargs.get("axis") is not None:
            sorted_rows.append(values.shape)
        return unique(values, *args, **kwargs)

    monkeypatch.setattr(np, "unique", spy)
    np.testing.assert_array_equal(icc._row_groups(rows), expected)
    assert not sorted_rows


def test_wide_rows_still_match_unique():
    from meshcurv.estimators import icc

    rng = np.random.default_rng(4)
    rows = np.column_stack([rng.integers(0, 2**40, 500) for _ in range(2)])  # 80 bits: the rows' own unique
    rows[250:] = rows[:250]
    np.testing.assert_array_equal(icc._row_groups(rows), np.unique(rows, axis=0, return_inverse=True)[1].ravel())


def test_voxel_default_computes_no_enclosing_ball(monkeypatch):
    # the check of a given radius reads the smallest enclosing ball (29 ms of a 250 ms call on a voxel sphere of
    # 10,172 vertices); the voxel default's radius is derived from the surface and never refused
    pytest.importorskip("skimage")
    from meshcurv import radius

    mesh = shapes.voxel_sphere(3.0, (0.5, 0.2, 0.2), seed=0)
    faces = mesh.faces[:, ::-1]
    before = meshcurv.principal_curvatures(mesh.vertices, faces)
    assert before.parameters.get("scale") == "voxel"

    def refused(points):
        raise AssertionError("the voxel default computed an enclosing ball")

    monkeypatch.setattr(radius, "enclosing_ball", refused)
    after = meshcurv.principal_curvatures(mesh.vertices, faces)
    np.testing.assert_array_equal(after.k_max, before.k_max)
