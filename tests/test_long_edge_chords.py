"""The length of an edge inside a ball, for edges far longer than the ball (issue 29, class 10).

A spike (a vertex flung 1e10 away) or a part far larger than the rest leaves
edges of length 1e8 to 1e10 that pass through the balls of ``normal_cycle_ball``. The quadratic formula
``b^2 - 4ac`` of the chord loses every digit there (both terms ~1e40, their
difference ~1e20), so the NumPy path and the compiled kernel, rounding their
sums in different orders, gave different chords, and the two backends
different curvatures (up to the largest |k|) on the same mesh. Expected values
are the chords of a line at distance ``h`` from the centre of a ball of
radius ``r``: ``2 sqrt(r^2 - h^2)``, or from an end inside the ball.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes
from meshcurv._backend import use_backend
from meshcurv.neighborhoods import _segments_meet_ball, ball_edge_sums, segment_in_ball_lengths

#: The ends lie 1e10 away: their coordinates carry some 2e-6 of rounding (one unit in the last place),
#: so the chords are known to about that, not to the 1e-16 of a short edge.
FAR = 1e10
CHORD_RTOL = 1e-5


def _backends():
    numba = pytest.param("numba", marks=pytest.mark.skipif(not _has_numba(), reason="numba not installed"))
    return ["numpy", numba]


def _has_numba() -> bool:
    try:
        import numba  # noqa: F401
    except ImportError:
        return False
    return True


def _crossing_segments():
    """Segments through the unit ball at the origin, both ends ``FAR`` away, and their exact chords."""
    rng = np.random.default_rng(7)
    directions = rng.normal(size=(12, 3))
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    offsets = rng.normal(size=(12, 3))
    offsets -= np.einsum("ij,ij->i", offsets, directions)[:, None] * directions  # orthogonal to the line
    h = np.linspace(0.0, 0.95, 12)
    offsets *= (h / np.maximum(np.linalg.norm(offsets, axis=1), 1e-300))[:, None]
    starts = offsets - FAR * directions
    ends = offsets + FAR * 0.7 * directions  # the ball not at the middle of the segment
    return starts, ends, 2.0 * np.sqrt(1.0 - h * h)


def test_chords_of_long_segments_are_exact():
    starts, ends, chords = _crossing_segments()
    centres = np.zeros_like(starts)
    np.testing.assert_allclose(segment_in_ball_lengths(starts, ends, centres, 1.0), chords, rtol=CHORD_RTOL)
    # the chord is that of the segment, whichever end comes first
    np.testing.assert_allclose(segment_in_ball_lengths(ends, starts, centres, 1.0), chords, rtol=CHORD_RTOL)


def test_chords_of_long_segments_from_an_end_inside():
    starts = np.array([[0.0, 0.0, 0.0], [-0.5, 0.3, 0.0], [0.0, 0.0, 2.0], [0.0, 0.6, 0.0]])
    ends = np.array([[FAR, 0.0, 0.0], [FAR, 0.3, 0.0], [FAR, 0.0, 2.0], [0.0, 0.6, -FAR]])
    expected = [1.0, 0.5 + np.sqrt(0.91), 0.0, 0.8]
    lengths = segment_in_ball_lengths(starts, ends, np.zeros((4, 3)), 1.0)
    np.testing.assert_allclose(lengths, expected, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("backend", _backends())
def test_ball_edge_sums_of_long_edges_on_each_backend(backend):
    starts, ends, chords = _crossing_segments()
    n = starts.shape[0]
    # each long edge alone with a vertex at the centre of the unit ball: the sum at that vertex is the chord
    vertices = np.concatenate([np.zeros((1, 3)), starts, ends])
    edges = np.column_stack([1 + np.arange(n), 1 + n + np.arange(n)])
    with use_backend(backend):
        sums = ball_edge_sums(vertices, edges, 1.0, np.eye(n))
    np.testing.assert_allclose(sums[0], chords, rtol=CHORD_RTOL)


@pytest.mark.parametrize("backend", _backends())
def test_long_segments_meet_the_ball_where_their_line_does(backend):
    """The walk's test of a segment through a ball (both ends outside): on segments 1e10 long it
    was a coin toss (976 of 2,000 wrong; ``|a|^2 |d|^2 - (a.d)^2`` cancels). Expected: the line's
    distance ``h`` to the centre, away from the sphere itself (h not within 0.1 of the radius)."""
    rng = np.random.default_rng(11)
    n = 400
    directions = rng.normal(size=(n, 3))
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    offsets = rng.normal(size=(n, 3))
    offsets -= np.einsum("ij,ij->i", offsets, directions)[:, None] * directions
    h = np.where(np.arange(n) % 2 == 0, rng.uniform(0.0, 0.9, n), rng.uniform(1.1, 2.0, n))
    offsets *= (h / np.linalg.norm(offsets, axis=1))[:, None]
    a, b = offsets - FAR * directions, offsets + 0.7 * FAR * directions
    if backend == "numpy":
        met = _segments_meet_ball(tuple(a.T), tuple(b.T), 1.0)
    else:
        from meshcurv._kernels.neighborhoods import _segment_meets_ball

        met = np.array([_segment_meets_ball(*p, *q, 1.0) for p, q in zip(a, b)])
    np.testing.assert_array_equal(met, h < 1.0)


def _sphere_and_large_square(height: float):
    """A UV sphere (radius 1) and a square of two faces, 2e8 a side, in the plane ``z = height``: the
    square's diagonal, 2.8e8 long, passes through the balls of the sphere's vertices near it."""
    mesh = shapes.uv_sphere(16, 8)
    side = 1e8
    square = np.array([[-side, -side, height], [side, -side, height], [side, side, height], [-side, side, height]])
    n = mesh.vertices.shape[0]
    vertices = np.concatenate([mesh.vertices, square])
    faces = np.concatenate([mesh.faces, n + np.array([[0, 1, 2], [0, 2, 3]])])
    return vertices, faces


@pytest.mark.skipif(not _has_numba(), reason="numba not installed")
@pytest.mark.parametrize("height", [0.3, 0.7])
def test_normal_cycle_ball_with_long_edges_is_one_estimator(height):
    """Both backends give the same valid vertices and curvatures (1e-6 of the largest |k|, as
    tests/test_backend_parity.py) where edges far longer than the balls pass through them."""
    vertices, faces = _sphere_and_large_square(height)
    results = {}
    for backend in ("numpy", "numba"):
        with use_backend(backend), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            results[backend] = meshcurv.principal_curvatures(vertices, faces, method="normal_cycle_ball")
    a, b = results["numpy"], results["numba"]
    np.testing.assert_array_equal(a.valid, b.valid)
    assert a.valid.any()
    scale = max(np.abs(a.k_min[a.valid]).max(), np.abs(a.k_max[a.valid]).max())
    for name in ("k_min", "k_max", "mean"):
        x, y = getattr(a, name)[a.valid], getattr(b, name)[a.valid]
        np.testing.assert_allclose(x, y, rtol=0, atol=1e-6 * scale, err_msg=name)
