"""``normal_cycle_ball`` at a fold: an edge whose two faces lie on each other (issue 29, fuzz_api 421/64).

The dihedral angle of a fold is ``+-pi``: ``pi - epsilon`` for a fin, ``-(pi - epsilon)`` for a slit, and an exact
fold (a sine of zero) reads ``pi`` (tests/test_exact_folds.py). A fold lying in a coordinate plane is exact; turned,
the sine is a few last bits of either sign and the angle jumped by ``2 pi`` at random, moving every ball that holds
the edge (ogre.obj turned and shifted by 5.7 sizes: 181 vertices, up to 0.11 of the largest |k|). An angle within
``FOLD_ANGLE`` of ``+-pi`` now reads ``pi``: the estimate is invariant to rigid motion (CONVENTIONS.md, 10).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv._backend import use_backend

#: Relative agreement of two poses, of the largest |k|: far above round-off (1e-14 here), far below a fold's
#: flipped sign (0.9 of the largest |k| before the fix).
RTOL = 1e-6


def _rotation(seed: int) -> np.ndarray:
    q, r = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else q[:, [1, 0, 2]]


def folded_sheet(n: int = 12) -> tuple[np.ndarray, np.ndarray]:
    """A unit square sheet in the plane z = 0 folded back onto itself along x = 1 (the second layer's columns
    between the first's, so that no vertex is welded to another), consistently wound: its fold edges' faces lie on
    each other, their normals opposite."""
    x = np.linspace(0.0, 1.0, n)
    columns = np.concatenate([x, 1.0 - 0.85 * x[1:]])  # the unfolded sheet on [0, 1.85], folded at x = 1
    gx, gy = np.meshgrid(columns, x, indexing="ij")
    vertices = np.column_stack([gx.ravel(), gy.ravel(), np.zeros(gx.size)])
    index = np.arange(columns.size * n).reshape(columns.size, n)
    a, b, c, d = (index[:-1, :-1].ravel(), index[1:, :-1].ravel(), index[1:, 1:].ravel(), index[:-1, 1:].ravel())
    return vertices, np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])


def test_fold_angles_read_a_fold_within_the_band_as_pi():
    from meshcurv._geometry import FOLD_ANGLE, fold_angles

    beta = np.array([np.pi, -np.pi, np.pi - 1e-11, -np.pi + 2e-11, -(np.pi - 1e-3), np.pi - 1e-3, 0.5, -0.5])
    got = fold_angles(beta)
    np.testing.assert_array_equal(got[:4], np.pi)
    np.testing.assert_array_equal(got[4:], beta[4:])  # a knife edge of 0.06 degrees keeps its sign
    assert FOLD_ANGLE < 1e-3


@pytest.mark.parametrize("method", ["normal_cycle_ball", "normal_cycle"])
@pytest.mark.parametrize("backend", ["numpy", "numba"])
@pytest.mark.parametrize("seed", range(4))
def test_a_fold_turned_and_shifted_keeps_its_curvatures(seed, backend, method):
    if backend == "numba":
        pytest.importorskip("numba")
    vertices, faces = folded_sheet()
    moved = vertices @ _rotation(seed).T + np.random.default_rng(seed).uniform(-10.0, 10.0, size=3)
    with use_backend(backend), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        before = meshcurv.principal_curvatures(vertices, faces, method=method, orient="keep")
        after = meshcurv.principal_curvatures(moved, faces, method=method, orient="keep")
    np.testing.assert_array_equal(before.valid, after.valid)
    valid = before.valid
    assert valid.sum() > len(vertices) / 2  # (normal_cycle: the rim's vertices are undefined)
    unit = float(np.abs(np.concatenate([before.k_min[valid], before.k_max[valid]])).max())
    assert unit > 1.0  # the fold is curved: a zero here would compare nothing
    for field in ("k_min", "k_max", "mean"):
        gap = float(np.abs(getattr(before, field)[valid] - getattr(after, field)[valid]).max())
        assert gap <= RTOL * unit, (field, gap, unit)
