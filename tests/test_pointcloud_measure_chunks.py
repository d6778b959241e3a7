"""``method="corrected_measures"`` over its balls in chunks of bounded size (issue 29, memory).

The NumPy path summed the random triangles of all the balls of up to 32,768 centres at once: some 1 KiB per
triangle, 1 GiB at 32,000 points (``benchmarks/memory_pointcloud.md``). It now takes
``TRIANGLE_CHUNK // TRIANGLES`` centres at a time, and the compiled path :data:`MEASURE_CHUNK` centres (their
balls). Each centre's sums are those of its own triangles in the same order, so the chunk size changes no
number: the results with chunks of a few centres equal, bit for bit, those of one chunk holding every centre.

Oracle: the unit sphere sampled at random with its exact (outward) normals: H = 1 at every point. The check of
the values is coarse (the median of the valid points within 5%: clean samples give under 1%,
``benchmarks/pointcloud.md``); it only rules out that the chunks agree on a wrong answer.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import meshcurv._pointcloud_estimators as estimators
from meshcurv._backend import use_backend
from meshcurv.pointcloud import point_cloud_curvatures

#: Centres per chunk of the small chunks: prime, so that no chunk boundary falls on a round count.
FEW = 7


def _sphere(n: int = 1500, seed: int = 3) -> np.ndarray:
    u = np.random.default_rng(seed).normal(size=(n, 3))
    return u / np.linalg.norm(u, axis=1, keepdims=True)


def _measured(points: np.ndarray):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # (the counts of NaN points, if any; the comparison is the test)
        return point_cloud_curvatures(points, method="corrected_measures", normals=points)


def _same(first, second) -> None:
    for name in ("k_min", "k_max", "dir_min", "dir_max", "valid"):
        np.testing.assert_array_equal(getattr(first, name), getattr(second, name), err_msg=name)


def _check_sphere(result) -> None:
    assert result.valid.mean() > 0.9
    mean = 0.5 * (result.k_min + result.k_max)[result.valid]
    assert abs(np.median(mean) - 1.0) < 0.05


def test_numpy_triangles_in_bounded_chunks_same_numbers(monkeypatch):
    points = _sphere()
    with use_backend("numpy"):
        monkeypatch.setattr(estimators, "TRIANGLE_CHUNK", 10**9, raising=False)
        whole = _measured(points)
        sizes: list[int] = []
        triangle_sums = estimators._triangle_sums

        def recording(points, normals, index, counts, pattern):
            sizes.append(index.shape[0] * pattern.shape[0])  # the triangles drawn at once
            return triangle_sums(points, normals, index, counts, pattern)

        monkeypatch.setattr(estimators, "_triangle_sums", recording)
        monkeypatch.setattr(estimators, "TRIANGLE_CHUNK", FEW * estimators.TRIANGLES, raising=False)
        chunked = _measured(points)
    # never more than the chunk's triangles at once (before: every ball's, 1500 x 32 and more)
    assert sizes and max(sizes) <= FEW * estimators.TRIANGLES
    _same(whole, chunked)
    _check_sphere(chunked)


def test_compiled_balls_in_bounded_chunks_same_numbers(monkeypatch):
    pytest.importorskip("numba")
    points = _sphere()
    with use_backend("numba"):
        monkeypatch.setattr(estimators, "MEASURE_CHUNK", 10**9, raising=False)
        whole = _measured(points)
        kernels = estimators.numba_kernels("pointcloud")
        rows: list[int] = []

        class Recording:
            def __getattr__(self, name):
                return getattr(kernels, name)

            def ball_triangle_sums(self, points, normals, index, *args):
                rows.append(index.shape[0])
                return kernels.ball_triangle_sums(points, normals, index, *args)

        recorded_kernels = Recording()
        original = estimators.numba_kernels
        monkeypatch.setattr(
            estimators, "numba_kernels", lambda module: recorded_kernels if module == "pointcloud" else original(module)
        )
        monkeypatch.setattr(estimators, "MEASURE_CHUNK", FEW, raising=False)
        chunked = _measured(points)
    assert rows and max(rows) <= FEW
    _same(whole, chunked)
    _check_sphere(chunked)
