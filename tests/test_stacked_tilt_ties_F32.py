"""The tilt that widens the reach of two stacked sheets is not chosen by the order of tied neighbours (issue 29;
fuzz_api 660/37).

``_pointcloud_normals._stacked`` lets a neighbour count as a sheet stacked on a point's only when both lie farther off
each other's tangent plane than a reach that grows with the tilt of the point's normal: the median angle to its
``GRAPH_NEIGHBOURS`` (6) nearest neighbours' normals. On ogre's cloud a point's 6th and 7th neighbours lay at one
distance, and the k-d tree's order, which a rigid motion changes by round-off, put one or the other in the ring:
tilts 0.449 and 0.046, one more point with two stacked neighbours oriented alike in one pose, 6 points ``alike``,
then 22 points' reasons apart (9/11 -> 8). The neighbours tied with the next beyond the ring are now dropped whole,
as :func:`whole_ties` drops them at every cut of a neighbour search.

Oracles: the invariance under the order of tied neighbours (both backends), and the contract's value worked by hand.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import chosen_backend


def _ring(tilts):
    """A point at the origin with normal z; its neighbours 1-5 at distinct distances, 6 and 7 at one distance (0.15,
    with coordinates of equal squares), then 8 on a sheet 0.2 above, 0.3 along x, its normal z. Neighbour ``i``'s
    normal is tilted by ``tilts[i - 1]`` radians."""
    points = np.array(
        [
            [0.0, 0.0, 0.0],
            [0.10, 0.0, 0.0],
            [0.0, 0.11, 0.0],
            [-0.12, 0.0, 0.0],
            [0.0, -0.13, 0.0],
            [0.14, 0.0, 0.0],
            [0.09, 0.12, 0.0],
            [-0.12, -0.09, 0.0],
            [0.3, 0.0, 0.2],
        ]
    )
    angles = np.concatenate([[0.0], tilts, [0.0]])
    normals = np.stack([np.sin(angles), np.zeros_like(angles), np.cos(angles)], axis=1)
    return points, normals


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_tied_neighbours_at_the_tilts_cut_do_not_decide(backend):
    from meshcurv._pointcloud_normals import _stacked

    points, normals = _ring([0.0, 0.0, 0.01, 1.0, 1.5, 0.9, 0.08])
    usable = np.ones(9, dtype=bool)
    queries = np.array([0])
    one = np.array([[0, 1, 2, 3, 4, 5, 6, 7, 8]])
    other = np.array([[0, 1, 2, 3, 4, 5, 7, 6, 8]])  # (6 and 7 tied: the search's order)
    assert np.linalg.norm(points[6]) == np.linalg.norm(points[7])
    with chosen_backend(backend):
        here = _stacked(points, normals, usable, 1.0, queries, one, alike=True, offset=0.15)
        there = _stacked(points, normals, usable, 1.0, queries, other, alike=True, offset=0.15)
    # (6 in the ring: tilt 0.45, reach 0.15 + 2 * 0.45 * 0.36 = 0.47 > 0.2; 7: tilt 0.045, reach 0.18 < 0.2)
    assert here[0, 8] == there[0, 8]
    # both dropped: the median of 0, 0, 0.01, 1.0, 1.5 is 0.01, the reach 0.15 + 2 * 0.01 * 0.36 = 0.157 < 0.2
    assert here[0, 8]
    assert not here[0, :8].any()


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_a_ring_of_ties_keeps_its_cut(backend):
    # every neighbour of the ring and the next at one distance: dropping them would leave fewer than TIE_LEAST, so the
    # ring is the search's first six, as before (a point amid a ring of neighbours: the pole of a uv sphere)
    from meshcurv._pointcloud_normals import _stacked

    turns = np.linspace(0.0, 2.0 * np.pi, 8)[:7]
    points = np.zeros((9, 3))
    points[1:8, 0], points[1:8, 1] = 0.1 * np.cos(turns), 0.1 * np.sin(turns)
    points[8] = [0.3, 0.0, 0.2]
    normals = np.tile([0.0, 0.0, 1.0], (9, 1))
    with chosen_backend(backend):
        near = np.arange(9)[None]
        out = _stacked(points, normals, np.ones(9, dtype=bool), 1.0, np.array([0]), near, alike=True, offset=0.15)
    assert out[0, 8] and not out[0, :8].any()  # (tilt 0: the reach 0.15 < 0.2)
