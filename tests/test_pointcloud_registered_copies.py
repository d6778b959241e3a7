"""Near copies with a registration error (issue 29, class 2, beyond round-off).

Merged scans and overlapping tiles hold each point several times; the copies differ by the scans'
registration error, a small fraction of the point spacing, not only by round-off. The copies closer
than ``pointcloud.COPY_GAP`` (1e-3) times the distance to the next point are merged; copies a few
thousandths to hundredths of a spacing apart are not, and then the spacing is measured between the
copies of one point, the radius shrinks to a fraction of the true spacing and the fits read the
registration error as the surface (found by ``benchmarks/fuzz_api.py --point-clouds`` with its
registration strategy, helper R11). The truth: a unit sphere, H = 1 at every point; a valid point
off by more than half of it is a wrong number marked valid (the fuzzer's bar).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from meshcurv.pointcloud import point_cloud_curvatures

#: A valid point is a lie when its H is off by more than this share of the exact 1 / r.
TOLERANCE = 0.5


def _registered_copies(copies: int, shift: float, seed: int = 0) -> np.ndarray:
    """``copies`` copies of 1,000 random points of the unit sphere, copy ``c`` moved by ``c * shift`` spacings."""
    rng = np.random.default_rng(seed)
    unit = rng.normal(size=(1000, 3))
    unit /= np.linalg.norm(unit, axis=1, keepdims=True)
    spacing = np.sqrt(4 * np.pi / unit.shape[0])
    direction = np.array([1.0, 0.3, -0.2]) / np.linalg.norm([1.0, 0.3, -0.2])
    return np.concatenate([unit + c * shift * spacing * direction for c in range(copies)])


@pytest.mark.xfail(
    strict=True,
    raises=AssertionError,
    reason="open: near copies 2e-3 to 1e-2 spacings apart are not merged; the spacing is read between them",
)
@pytest.mark.parametrize("shift", [0.002, 0.01])
@pytest.mark.parametrize("copies", [3, 5])
def test_copies_moved_by_a_registration_error_give_no_wrong_curvature(copies, shift):
    points = _registered_copies(copies, shift)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the copies, the uneven density: one warning, not what is tested
        result = point_cloud_curvatures(points)
    error = np.abs(result.mean[result.valid] - 1.0)
    assert (error <= TOLERANCE).all(), f"{int((error > TOLERANCE).sum())} of {error.size} valid points off"
