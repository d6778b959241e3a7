"""``quadric`` at its default on fine soups: never a valid wrong number (issue 29, fuzz 730/1, 400/78, 690/72).

Two causes, both on ``icosphere(24)`` (a unit sphere: H = 1 exactly; a corner moved 0.1 edge lengths stays within
0.1% of it) with faces detached as the fuzzer detaches them (``benchmarks/fuzz_api.py``'s ``_detach``):

- half of the faces detached by 0.03 edge lengths: the weld joins almost every copy back across its crack, at one
  copy's point, and leaves no crack to show the noise it carries; the level reads clean, no check ran, and the jets of
  degree 4 over the 19 points of a default ball followed the copies' offsets (fuzz 730/1 on ``icosphere(40)``: H 0.03
  and 1.69, valid). Such welded vertices are now taken as a crack's corners (``quadric._welded_groups``);
- every face detached by 0.1 edge lengths: a ball of scatter was grown only until its quadric's spread was just
  within ``NOISE_REACH`` (0.3) of its curvature, where the farthest of 10^5 balls lies 2.3 spreads off (fuzz 400/78,
  690/72: H 0.49 and 1.53). Over cracks it is now grown to ``GROWN_REACH`` (0.15).

The tolerance is the fuzzer's (``fuzz_api.DETACHED_TOLERANCE``): a valid H off the exact one by more than half of
the largest exact ``|k|`` is a lie. The share of valid vertices is held too, so that no fix drops the soup.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes

from conftest import chosen_backend
from test_quadric_cracks_W19 import detached

#: Largest |H - H_exact| of a valid vertex, as a share of the largest exact |k| (``fuzz_api.DETACHED_TOLERANCE``).
TOLERANCE = 0.5


def _soup_errors(share: float, gap: float, seed: int, backend: str):
    """``(errors, cover)``: |H - 1| at the valid vertices of ``icosphere(24)`` with a ``share`` of its faces detached
    by ``gap`` edge lengths (draw ``seed``), at the default options, and the share of its referenced vertices
    valid."""
    vertices, faces, _ = detached(shapes.icosphere(24), share, gap, seed)
    with chosen_backend(backend), warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the weld's and the defects' warnings: not tested here
        result = meshcurv.principal_curvatures(vertices, faces, method="quadric")
    referenced = np.zeros(len(vertices), dtype=bool)
    referenced[faces] = True
    valid = result.valid & referenced
    return np.abs(result.mean[valid] - 1.0), valid.sum() / referenced.sum()


@pytest.mark.parametrize("backend", ["numba", pytest.param("numpy", marks=pytest.mark.slow)])
@pytest.mark.parametrize("seed", [2, 3])
def test_half_detached_and_welded_back(backend, seed):
    """Half of the faces detached by 0.03 edges: before, 6 valid vertices off by 0.84 (seed 2) and 0.98 (seed 3)."""
    errors, cover = _soup_errors(0.5, 0.03, seed, backend)
    assert cover > 0.95  # (about 99%: the rim's corners of the few cracks left open are not all fitted)
    assert (errors <= TOLERANCE).all(), (
        f"{int((errors > TOLERANCE).sum())} valid vertices off, up to {errors.max():.3g}"
    )


@pytest.mark.slow
@pytest.mark.parametrize("backend", ["numba", "numpy"])
def test_every_face_detached(backend):
    """Every face detached by 0.1 edges (this draw): before, 4 valid vertices off by up to 0.515."""
    errors, cover = _soup_errors(1.0, 0.1, 0, backend)
    assert cover > 0.95  # (every corner is valid)
    assert (errors <= TOLERANCE).all(), (
        f"{int((errors > TOLERANCE).sum())} valid vertices off, up to {errors.max():.3g}"
    )
