"""``normal_cycle_ball`` on a uv sphere with half of its faces detached by 0.038 edges (issue 29, fuzz_api 415/67).

The backends compute the same estimator there (class 10): this is checked. What is left open (N22's report): a few
valid vertices by the poles read H about 0.45 for 1. The weld joins the detached faces back, but not evenly across
the uv sphere's edge directions (short parallel edges kept at 0.56, diagonals and meridians at 0.78 and 0.82), so a
holed ball reads a direction-biased subset of the edges (with the clean angles: H 0.93 on average, 0.90 by the
poles), and the welded faces' tilts scatter each edge's angle by more than its mean (0.071 against 0.054): the ball's
scatter test (``few_elements``) sees the scatter but not the bias.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes
from meshcurv._backend import use_backend

#: Relative agreement of the backends, of the largest |k| (tests/test_backend_parity.py).
RTOL = 1e-6


def half_detached_uv_sphere(seed: int, gap: float = 0.038) -> tuple[np.ndarray, np.ndarray]:
    """The unit uv sphere (64 x 32) with about half of its faces given corners of their own, each corner moved
    ``gap`` mean edge lengths in a random direction (benchmarks/fuzz_api.py's detached faces)."""
    sphere = shapes.uv_sphere(n_longitude=64, n_latitude=32)
    vertices, faces = np.asarray(sphere.vertices, dtype=float), np.asarray(sphere.faces)
    edge = float(np.mean(np.linalg.norm(vertices[faces[:, 0]] - vertices[faces[:, 1]], axis=1)))
    rng = np.random.default_rng(seed)
    picked = rng.random(len(faces)) < 0.5
    corners = vertices[faces[picked]].reshape(-1, 3)
    directions = rng.normal(size=corners.shape)
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    faces = faces.copy()
    faces[picked] = len(vertices) + np.arange(corners.shape[0]).reshape(-1, 3)
    return np.concatenate([vertices, corners + directions * gap * edge]), faces


def test_both_backends_compute_the_same_estimate_on_a_half_detached_uv_sphere():
    pytest.importorskip("numba")
    vertices, faces = half_detached_uv_sphere(6)
    results = {}
    for backend in ("numba", "numpy"):
        with use_backend(backend), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            results[backend] = meshcurv.principal_curvatures(vertices, faces, method="normal_cycle_ball")
    compiled, reference = results["numba"], results["numpy"]
    np.testing.assert_array_equal(compiled.valid, reference.valid)
    valid = reference.valid
    # a share that makes the comparison mean something (3,661 of 7,905 since the grown balls that lost much of their
    # area to open cracks are undefined, normal_cycle_ball.CRACKED_LOST_BIAS; more than half before)
    assert valid.sum() > 0.4 * len(vertices)
    for field in ("k_min", "k_max", "mean"):
        gap = float(np.abs(getattr(compiled, field)[valid] - getattr(reference, field)[valid]).max())
        assert gap <= RTOL, field  # the unit sphere: its largest |k| is about 1


def test_no_valid_vertex_of_a_half_detached_uv_sphere_is_off_by_half_of_h():
    vertices, faces = half_detached_uv_sphere(6)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = meshcurv.principal_curvatures(vertices, faces, method="normal_cycle_ball")
    off = np.abs(result.mean[result.valid] - 1.0)  # the unit sphere, outward: H = 1
    assert (off <= 0.5).all(), (int((off > 0.5).sum()), float(off.max()))
