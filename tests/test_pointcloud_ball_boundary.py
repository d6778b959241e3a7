"""Points on a ball's sphere: one rule for both backends (issue 29, class 10; seed 143 case 151 of the API fuzzer).

On a lattice (a mesh's vertices as a cloud, a gridded scan) many points lie at
exactly the ball's radius from its centre. Both backends take them into the
ball (squared distance at most the squared radius); a jet's weight
``(1 - |d / r|^2)^2`` is then 0 or round-off, and whether such a point counts
(in the facing check that refuses a ball holding the other side, and among the
points a fit needs) must be decided by the same operations on both: the
compiled kernel sums ``x^2 + y^2 + z^2`` in that order, and the NumPy path must
too. The vertices of a 12 x 8 cylinder have pairs exactly 1 and sqrt(2) apart
(checked below): with ``numpy.einsum`` for the sum the two backends shrank
different balls (``shrunk`` 0.037 against 0.093 at radius sqrt(2)) and kept
different points valid (104 against 98 at radius 1).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from meshcurv import shapes
from meshcurv._backend import use_backend
from meshcurv.pointcloud import point_cloud_curvatures
from test_backend_parity import assert_same

pytest.importorskip("numba")


def on_both(points: np.ndarray, **options):
    """The call compiled and on the NumPy path (its warnings, the same on both, not under test here)."""
    results = []
    for backend in ("numba", "numpy"):
        with use_backend(backend), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            results.append(point_cloud_curvatures(points, **options))
    return results


# (radius, least share of the points valid): at sqrt(2), beyond the radius of curvature, none is (the parameter
# ``shrunk``, the share of balls that held the other side, is what differed there)
@pytest.mark.parametrize(("radius", "least"), [(1.0, 0.9), (2.0**0.5, 0.0)])
def test_jets_on_a_lattice_with_points_on_the_ball_sphere_agree(radius, least):
    points = shapes.cylinder(n_around=12, n_along=8).vertices
    squared = ((points[:, None, :] - points[None, :, :]) ** 2).sum(axis=2)
    assert (squared == radius * radius).any()  # the premise: points exactly on some ball's sphere
    compiled, numpy_path = on_both(points, method="jets", radius=radius)
    assert_same(compiled, numpy_path, f"jets at radius {radius:g} on a cylinder lattice")
    # and the estimate is the cylinder's (k_max = 1 around, k_min = 0 along), so both cannot agree on nonsense
    valid = compiled.valid
    assert valid.sum() >= least * valid.size
    np.testing.assert_allclose(compiled.mean[valid], 0.5, atol=0.05)
