"""The pair estimate of every ball computation (``neighborhoods.estimate_ball_pairs``), compiled: the same counts
as the NumPy blocks, to the bit (issue 30). The estimate decides a computation's path (balls of 800 faces or more
are summed on clusters, ``neighborhoods.CLUSTER_MIN_FACES``) and refuses the largest, so both backends must read
the same numbers; here on clouds larger than the sample (its evenly spaced points scaled to the whole cloud) and
on a lattice whose distances fall on the radius itself (a tie decided by the same operations)."""

from __future__ import annotations

import numpy as np
import pytest

from meshcurv import neighborhoods
from conftest import chosen_backend

pytest.importorskip("numba")


def _both(points, radius, centres):
    with chosen_backend("numba"):
        compiled = neighborhoods.estimate_ball_pairs(points, radius, centres)
    with chosen_backend("numpy"):
        plain = neighborhoods.estimate_ball_pairs(points, radius, centres)
    return compiled, plain


@pytest.mark.parametrize("per_centre", [False, True])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_compiled_pair_estimates_are_the_numpy_ones(per_centre, seed):
    rng = np.random.default_rng(seed)
    points = rng.random((20000, 3)) * [10.0, 4.0, 1.0] + 1e3 * seed
    centres = points[rng.integers(0, points.shape[0], 500)]
    radius = rng.uniform(0.2, 2.0, centres.shape[0]) if per_centre else 0.7
    compiled, plain = _both(points, radius, centres)
    assert compiled == plain
    assert compiled[0] > 0


def test_lattice_ties_are_counted_alike():
    # a unit lattice scaled by 0.1: many points at the radius itself, in or out by the rounding of the same
    # operations on both backends
    axis = np.arange(30) * 0.1
    points = np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), axis=-1).reshape(-1, 3)
    for radius in (0.1, 0.2, 0.3, np.sqrt(0.02)):
        compiled, plain = _both(points, radius, points[::7])
        assert compiled == plain
