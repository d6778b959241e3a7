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


@pytest.mark.parametrize("shift", [0.002, 0.01])
@pytest.mark.parametrize("copies", [3, 5])
def test_copies_moved_by_a_registration_error_give_no_wrong_curvature(copies, shift):
    points = _registered_copies(copies, shift)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the copies, the uneven density: one warning, not what is tested
        result = point_cloud_curvatures(points)
    error = np.abs(result.mean[result.valid] - 1.0)
    assert (error <= TOLERANCE).all(), f"{int((error > TOLERANCE).sum())} of {error.size} valid points off"


def _quiet(points, **kwargs):
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        result = point_cloud_curvatures(points, **kwargs)
    return result, [str(w.message) for w in record]


@pytest.mark.parametrize("copies", [2, 20])
def test_copies_each_point_moved_its_own_way_are_merged_with_one_warning(copies):
    # the fuzzer's strategy: every point of every copy moved by 0.05 spacings in a direction of its own
    rng = np.random.default_rng(5)
    base = _registered_copies(1, 0.0, seed=5)
    spacing = np.sqrt(4 * np.pi / base.shape[0])
    moved = [base]
    for _ in range(copies - 1):
        direction = rng.normal(size=base.shape)
        moved.append(base + 0.05 * spacing * direction / np.linalg.norm(direction, axis=1, keepdims=True))
    result, messages = _quiet(np.concatenate(moved))
    assert len(messages) == 1 and "registration error" in messages[0]
    error = np.abs(result.mean[result.valid] - 1.0)
    assert result.valid.mean() > 0.9 and (error <= TOLERANCE).all()
    # the radius is the one of the cloud without its copies: the spacing is not read between copies
    single, _ = _quiet(base)
    assert result.parameters["radius"] == pytest.approx(single.parameters["radius"], rel=0.1)


def test_overlapping_tiles_are_merged_where_they_overlap():
    # a third of the sphere scanned twice, the second tile 0.01 spacings off: no wrong curvature, every copy merged
    base = _registered_copies(1, 0.0, seed=6)
    spacing = np.sqrt(4 * np.pi / base.shape[0])
    tile = base[base[:, 0] > 1 / 3] + 0.01 * spacing * np.array([0.0, 0.6, 0.8])
    result, messages = _quiet(np.concatenate([base, tile]))
    assert len(messages) == 1 and "registration error" in messages[0]
    merged = int(messages[0].split(" points are copies")[0].rsplit(" ", 1)[-1])
    assert tile.shape[0] <= merged <= tile.shape[0] + 0.02 * base.shape[0]  # a few random close pairs besides
    error = np.abs(result.mean[result.valid] - 1.0)
    assert (error <= TOLERANCE).all()


@pytest.mark.parametrize("n", [400, 5000])
@pytest.mark.parametrize("noise", [0.0, 0.5])
def test_a_random_sample_is_no_cloud_of_copies(n, noise):
    # random samples have close pairs (about one point in 16 jumps by 4 to its second neighbour): not copies
    rng = np.random.default_rng(n)
    unit = rng.normal(size=(n, 3))
    unit /= np.linalg.norm(unit, axis=1, keepdims=True)
    spacing = np.sqrt(4 * np.pi / n)
    points = unit * (1 + noise * spacing * rng.uniform(-1, 1, size=(n, 1)))
    _, messages = _quiet(points)
    assert not any("copies" in message for message in messages)


def test_points_along_a_curve_are_no_cloud_of_copies():
    # random points along a helix jump from their nearest neighbour to the next as often as copies do (a third of
    # them by 4): their gaps are the curve's, nothing is merged as copies
    t = np.random.default_rng(8).random(3000) * 20
    _, messages = _quiet(np.stack([np.cos(t), np.sin(t), 0.1 * t], axis=1))
    assert not any("registration" in message for message in messages)
