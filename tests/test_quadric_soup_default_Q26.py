"""``quadric`` at its default radius by the cracks of a fine soup (issue 29, fuzz 490/29).

A share of the faces of a fine unit sphere detached by a few hundredths of an edge length: the weld joins part of
the cracks back (``meshcurv.weld.CRACK_TOLERANCE_RATIO``), and the corners it leaves apart lie that far from their
other side, in a random direction. Most vertices are in place, so the noise level reads below the gate
(``quadric.NOISE_GATE``) at most balls by a crack, which kept their jets of degree 4; the scatter check
(``quadric._scatter_check``) held only the ball's quadric to the crack, and a jet's higher terms followed the copies'
offsets (490/29: ``icosphere(40)`` half detached by 0.049 edges, H 0.18-1.94 where the ball's quadric read
0.74-1.26; 296 of 56,125 valid vertices off). Now every ball by a crack of a soup (a mesh welded across cracks) is
checked, and the fit kept there is its quadric, the fit that the checks hold to the crack.

Oracle: the exact mean curvature of the unit sphere (H = 1, the sign the orientation's): a valid vertex off by more
than half of the largest exact ``|k|`` is a lie (the fuzzer's bar, ``DETACHED_TOLERANCE``); the vertices not valid
have a reason. The clean sphere keeps every vertex valid.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes

from test_double_sided_welds_D24 import _detached


def _quadric(vertices, faces, backend):
    if backend == "numba":
        pytest.importorskip("numba")
    from meshcurv._backend import use_backend

    with use_backend(backend), warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the defects' warning (boundaries, welds, loose faces): not the point here
        return meshcurv.principal_curvatures(vertices, faces, method="quadric")


def assert_no_lie(result):
    """Every valid H within half of the unit sphere's |H| = 1, on one side (the orientation's)."""
    mean = result.mean[result.valid]
    side = np.sign(np.median(mean))
    off = ~(np.abs(side * mean - 1.0) <= 0.5)
    assert not off.any(), f"{int(off.sum())} valid vertices off H = 1 by more than 0.5: {mean[off]}"
    assert (result.invalid_reason[~result.valid] > 0).all()


@pytest.mark.parametrize("backend", ["numba", pytest.param("numpy", marks=pytest.mark.slow)])
@pytest.mark.parametrize(("share", "gap", "seed"), [(0.2, 0.05, 0), (0.2, 0.07, 1), (0.5, 0.04, 1)])
def test_icosphere_24_soup_at_the_default(backend, share, gap, seed):
    """``icosphere(24)`` (5,762 vertices) with a share of its faces detached. Before: 7, 4 and 9 valid vertices off
    (up to 0.74); now none, and as many valid (90-97%)."""
    sphere = shapes.icosphere(subdivisions=24)
    vertices, faces = _detached(sphere.vertices, sphere.faces, share, gap, seed)
    result = _quadric(vertices, faces, backend)
    assert_no_lie(result)
    assert result.valid.mean() > 0.85  # the jets away from the cracks kept, the quadrics by them valid


@pytest.mark.parametrize("backend", ["numba", "numpy"])
def test_clean_sphere_keeps_its_jets(backend):
    """No crack, no change: the clean icosphere's vertices all valid, H within 1% of 1 (its jets, not quadrics)."""
    sphere = shapes.icosphere(subdivisions=24)
    result = _quadric(sphere.vertices, sphere.faces, backend)
    assert result.valid.all()
    np.testing.assert_allclose(result.mean, 1.0, rtol=0.01)
