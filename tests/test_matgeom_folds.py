"""``matgeom`` at a fold: an edge whose two faces lie on each other (issue 29, fuzz_api 433/68).

matGeom's dihedral angle is ``arccos(n1 . n2) * sign((n1 x n2) . e)``: at an exact fold the side is 0 and the edge
adds nothing. A fold lying in a coordinate plane is exact; turned, its side is a few last bits of either sign and the
edge added ``+-pi`` at random (ogre.obj turned and shifted: 84 vertices by up to 0.032 of the largest |k|). An angle
within ``FOLD_ANGLE`` of ``pi`` now reads 0 in every pose, as the exact fold does (CONVENTIONS.md, 10).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv._backend import use_backend

from conftest import random_rotation


def flat_rimmed_pillow(n: int = 17) -> tuple[np.ndarray, np.ndarray]:
    """A closed pillow over the square [-1, 1]^2: two layers that share the rim's vertices, bulging to
    ``+-0.4 (1 - r^2)^2`` inside the disc r < 0.7 and flat beyond it, so that the faces along the rim lie on each other
    in the plane z = 0 (exact folds, the normals of the two layers opposite) beside a curved part."""
    x = np.linspace(-1.0, 1.0, n)
    gx, gy = np.meshgrid(x, x, indexing="ij")
    r2 = (gx**2 + gy**2) / 0.49
    bulge = np.where(r2 < 1.0, 0.4 * (1.0 - r2) ** 2, 0.0).ravel()
    top = np.column_stack([gx.ravel(), gy.ravel(), bulge])
    index = np.arange(n * n).reshape(n, n)
    rim = np.zeros((n, n), dtype=bool)
    rim[[0, -1], :] = rim[:, [0, -1]] = True
    inner = np.flatnonzero(~rim.ravel())
    lower = index.ravel().copy()  # a bottom vertex: the rim's own, or a new one below the top's
    lower[inner] = n * n + np.arange(inner.size)
    vertices = np.concatenate([top, top[inner] * [1.0, 1.0, -1.0]])
    a, b, c, d = (index[:-1, :-1].ravel(), index[1:, :-1].ravel(), index[1:, 1:].ravel(), index[:-1, 1:].ravel())
    # each cell split through the square's corner where it has one (no face with three corners on the rim)
    other = (b == index[-1, 0]) | (d == index[0, -1])
    first = np.where(other[:, None], np.column_stack([a, b, d]), np.column_stack([a, b, c]))
    second = np.where(other[:, None], np.column_stack([b, c, d]), np.column_stack([a, c, d]))
    upper_faces = np.concatenate([first, second])
    lower_faces = lower[upper_faces][:, ::-1]
    return vertices, np.concatenate([upper_faces, lower_faces])


@pytest.mark.parametrize("backend", ["numpy", "numba"])
@pytest.mark.parametrize("seed", range(4))
def test_a_fold_turned_and_shifted_keeps_matgeoms_curvatures(seed, backend):
    if backend == "numba":
        pytest.importorskip("numba")
    vertices, faces = flat_rimmed_pillow()
    moved = vertices @ random_rotation(seed).T + np.random.default_rng(seed).uniform(-10.0, 10.0, size=3)
    with use_backend(backend), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        before = meshcurv.principal_curvatures(vertices, faces, method="matgeom")
        after = meshcurv.principal_curvatures(moved, faces, method="matgeom")
    np.testing.assert_array_equal(before.valid, after.valid)
    valid = before.valid
    assert valid.sum() > len(vertices) / 4
    unit = float(np.abs(np.concatenate([before.k_min[valid], before.k_max[valid]])).max())
    assert unit > 0.01  # the bulge is curved: a zero here would compare nothing
    fields = ("k_min", "k_max", "mean")
    got, expected = (np.stack([getattr(r, name)[valid] for name in fields]) for r in (after, before))
    np.testing.assert_allclose(got, expected, rtol=0.0, atol=1e-6 * unit)
