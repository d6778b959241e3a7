"""``quadric`` at its default radius where the ball reaches round the surface (issue 29).

The default radius is 2.5 mean edge lengths. On a mesh of long and short edges (a torus of 30 x 30 quads: the ring's
edges up to four times the tube's) the long edges set a ball wider than the radius of curvature along the short ones:
on ``torus(10, 3, 30, 30)`` a ball of 4.09 for a tube of radius 3, whose normals turn by 1.5 rad across it. A height
function over the tangent plane is steep at such a ball's rim, no polynomial follows it, and every vertex came out
valid with ``k_max`` 27-30% off (H 13.5% of the largest ``|k|``); ``torus(10, 3, 24, 64)`` 35-42%,
``torus(4, 1, 40, 12)`` 47% at its 200 valid vertices. A ball that turns past ``meshcurv.radius.BALL_TURN_CAP`` with
no crease in it is now made smaller and fitted again, or NaN with a reason where no smaller ball holds a fit.

Oracle: the exact curvatures of the torus (``meshcurv.shapes``). The bounds: a valid ``k_max`` within 15% of the
largest exact ``|k|`` (the quadric's bias over the smaller balls, whose fits are quadrics: 9-10% measured) and H
within 8%; the vertices not valid carry a reason, and the warning names the class. A well-sampled
torus (``benchmarks/accuracy.py``'s coarse one, whose ball turns by 1.15 rad) keeps every vertex, within 2%.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import meshcurv
from conftest import chosen_backend
from meshcurv import shapes
from meshcurv.defects import REACH

BACKENDS = ["numba", "numpy"]


def _quadric(mesh, backend):
    with chosen_backend(backend), warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = meshcurv.principal_curvatures(mesh.vertices, mesh.faces, method="quadric")
    return result, " ".join(str(w.message) for w in caught)


def _errors(result, mesh):
    """The valid vertices' errors of ``k_max``, ``k_min`` and H over the largest exact ``|k|``."""
    largest = float(np.max(np.abs([mesh.k_min, mesh.k_max])))
    valid = result.valid
    return tuple(
        np.abs(estimate[valid] - exact[valid]) / largest
        for estimate, exact in ((result.k_max, mesh.k_max), (result.k_min, mesh.k_min), (result.mean, mesh.mean))
    )


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("counts", [(30, 30), (24, 64)])
def test_a_ball_wider_than_the_tube_is_made_smaller(backend, counts):
    torus = shapes.torus(10.0, 3.0, *counts)
    result, message = _quadric(torus, backend)
    k_max, k_min, mean = _errors(result, torus)
    # 50% and 27% (83% and 48% before the smaller balls took quadrics over points spread across the tube and turning by
    # 0.9 rad, not 1.0: the balls whose ring neighbours sit near their rim lost, right on this regular mesh by its
    # symmetry only, up to 31-49% off once jittered; tests/test_quadric_coarse_Q28.py)
    assert result.valid.mean() > 0.25
    assert k_max.max() < 0.15 and k_min.max() < 0.15, (k_max.max(), k_min.max())  # before: up to 30% and 42%
    assert mean.max() < 0.08, mean.max()  # before: up to 15% and 22%
    assert (np.asarray(result.radius)[result.valid] < 3.0).all()  # within the tube's radius (before: 4.09, 4.61)
    assert (result.invalid_reason[~result.valid] > 0).all()
    if not result.valid.all():
        assert "reaches round the surface" in message


@pytest.mark.parametrize("backend", BACKENDS)
def test_no_valid_vertex_of_a_coarse_tube_is_far_off(backend):
    # 12 quads round a tube of radius 1, a ball of 1.63: 200 valid vertices with k_max 47% off before; no smaller
    # ball holds a fit there, so every vertex is NaN, with its reason, and the warning names the class
    torus = shapes.torus(4.0, 1.0, 40, 12)
    result, message = _quadric(torus, backend)
    assert not result.valid.any()
    assert (result.invalid_reason > 0).all()
    assert (result.invalid_reason == REACH).sum() > 100  # the class's own code (the others: balls over both sides)
    assert "reaches round the surface" in message


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_jittered_coarse_torus_is_not_far_off(backend):
    # 71 of 874 valid vertices more than 15% off (up to 53%) before the smaller balls took fits over points spread
    # by quadric.ROUND_MIN_SPREAD (degree 3 over points hardly spread across the tube; tests/test_quadric_coarse_Q28.py)
    torus = shapes.torus(10.0, 3.0, 30, 30, jitter=0.1, seed=1)
    result, _ = _quadric(torus, backend)
    k_max, k_min, _ = _errors(result, torus)
    assert k_max.max() < 0.15 and k_min.max() < 0.15, (k_max.max(), k_min.max())


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_well_sampled_torus_keeps_its_default_balls(backend):
    torus = shapes.torus(3.0, 1.0, 48, 16)  # benchmarks/accuracy.py's coarse torus: its ball turns by 1.15 rad
    result, _ = _quadric(torus, backend)
    k_max, k_min, _ = _errors(result, torus)
    assert result.valid.all()
    assert k_max.max() < 0.02 and k_min.max() < 0.02, (k_max.max(), k_min.max())
    radii = np.asarray(result.radius)
    assert np.allclose(radii, radii[0])  # one default radius: no ball made smaller
