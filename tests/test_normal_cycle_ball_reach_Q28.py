"""``normal_cycle_ball`` at its default radius where the ball reaches round the surface (issue 29).

The default radius is 2.5 mean edge lengths. On a torus whose ring's edges are far longer than its tube's, the ball
reaches round the tube (``torus(4, 1, 20, 20)``: a ball of 2.38 for a tube of radius 1), and its tensor, the mean of
the shape operator over the ball, mixes the tube's outer and inner sides: every vertex was valid with ``k_min`` up to
36% of the largest ``|k|`` off (``torus(3, 1, 12, 24)`` 63%, ``torus(2, 1, 16, 16)`` 82%). A default ball that turns
past ``meshcurv.radius.BALL_TURN_CAP`` with no crease in it is now summed again over a smaller ball (to where a circle
through its rim turns by ``normal_cycle_ball.ROUND_TURN``, no smaller than ``MIN_RADIUS_SCALES`` length scales),
its default kept where the smaller ball reproduces it, or NaN with the reason ``defects.REACH``.

Oracle: the exact curvatures of the torus (``meshcurv.shapes``), the errors over its largest ``|k|``. The bounds: the
measured errors with a margin; ``torus(2, 1, 16, 16)``'s inner side (``k_min`` -0.86, a ball of 0.81 over -1 to -0.5)
stays 33% off at the smallest ball of the surface, where the one-ring ``normal_cycle`` is 44% off and ``icc`` 57%:
the mesh's own resolution.
"""

from __future__ import annotations

import numpy as np
import pytest

from meshcurv import shapes
from meshcurv.defects import REACH
from test_quadric_coarse_Q28 import estimate, largest_error

BACKENDS = ["numba", "numpy"]


def _ball(mesh, backend):
    return estimate(mesh.vertices, mesh.faces, backend, method="normal_cycle_ball")


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize(
    ("counts", "bound"),
    [
        ((4.0, 1.0, 20, 20), 0.15),  # before: 36% (now 10%)
        ((3.0, 1.0, 12, 24), 0.25),  # 63% (17%)
        ((2.0, 1.0, 16, 16), 0.4),  # 82% (33%)
        ((10.0, 3.0, 30, 30), 0.18),  # 23% (14%)
        ((4.0, 1.0, 40, 12), 0.15),  # 21% (11%)
    ],
)
def test_a_ball_round_a_coarse_tube_is_made_smaller(backend, counts, bound):
    torus = shapes.torus(*counts)
    result, _ = _ball(torus, backend)
    assert result.valid.all()
    assert largest_error(result, torus) < bound
    assert (np.asarray(result.radius) < result.parameters["radius"]).any()  # balls made smaller than the default


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_ball_that_no_smaller_ball_reproduces_is_invalid_with_its_reason(backend):
    # a tube of radius 1 and 12 quads round it under a ball of 2.9: the smaller balls stop at the surface's own
    # (one length scale), where 80 still turn past the cap and read the tube otherwise than their default: NaN with
    # their reason. (A loss, open: those 80, the tube's top and bottom, read within 2.6% by their default ball, as
    # on the jittered torus where they stay valid; R28. Their count is not asserted: a fix keeps them.)
    torus = shapes.torus(10.0, 1.0, 40, 12)
    result, message = _ball(torus, backend)
    assert result.valid.any()
    assert (result.invalid_reason[~result.valid] == REACH).all()
    assert result.valid.all() or "reaches round the surface" in message
    assert largest_error(result, torus) < 0.15  # the defaults kept: 11%


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_well_sampled_torus_keeps_its_default_balls(backend):
    torus = shapes.torus(3.0, 1.0, 48, 16)  # benchmarks/accuracy.py's coarse torus: its ball turns by 1.15 rad
    result, message = _ball(torus, backend)
    assert result.valid.all()
    radii = np.asarray(result.radius)
    assert np.allclose(radii, radii[0])
    assert "reaches round" not in message


def test_the_smaller_balls_are_the_same_on_both_backends():
    torus = shapes.torus(3.0, 1.0, 12, 24)
    numba_result, _ = _ball(torus, "numba")
    numpy_result, _ = _ball(torus, "numpy")
    np.testing.assert_array_equal(numba_result.valid, numpy_result.valid)
    np.testing.assert_allclose(numba_result.k_max, numpy_result.k_max, rtol=0, atol=1e-12)
    np.testing.assert_allclose(numba_result.k_min, numpy_result.k_min, rtol=0, atol=1e-12)
