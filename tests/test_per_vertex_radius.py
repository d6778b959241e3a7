"""A radius per vertex (or per centre) and nested radii in one walk, through the ball machinery (issue 30).

Oracles: the float call (a per-vertex radius equals, at each vertex, the call
with that vertex's radius as a number; an array of equal radii equals the
float call exactly), and R separate calls for the nested sums. The compiled
kernels do the same operations in the same order as the float call at each
centre, so they are compared to the bit; the NumPy path takes the centres in
another order (by radius), so its pairs are summed in another order: within
``(terms - 1) eps sum|term|`` (Higham 2002, sec. 4.2). The twins (compiled
against NumPy) are in tests/test_kernel_twins.py.
"""

from __future__ import annotations

import numpy as np
import pytest

from meshcurv import shapes
from meshcurv._backend import use_backend
from meshcurv.errors import InvalidMeshError, InvalidOptionError
from meshcurv.jets import fit_jet_normals, fit_jets
from meshcurv.neighborhoods import (
    ball_edge_sums,
    ball_face_sums,
    ball_face_sums_nested,
    call_ranges,
    centre_radii,
    estimate_ball_pairs,
)
from meshcurv.topology import MeshTopology

EPS = np.finfo(float).eps
BACKENDS = [
    "numpy",
    pytest.param(
        "numba",
        marks=pytest.mark.skipif(__import__("importlib").util.find_spec("numba") is None, reason="numba not installed"),
    ),
]


def _mesh(name):
    made = {
        "ellipsoid": lambda: shapes.ellipsoid(subdivisions=6),
        # thinner than the larger balls: the other sheet is inside them, reached only round the rim
        "flat": lambda: shapes.ellipsoid((3.0, 3.0, 0.15), subdivisions=12),
    }[name]()
    vertices, faces = np.ascontiguousarray(made.vertices), np.ascontiguousarray(made.faces)
    topology = MeshTopology.from_faces(faces, vertices.shape[0])
    edges = vertices[topology.edges]
    h = float(np.linalg.norm(edges[:, 0] - edges[:, 1], axis=1).mean())
    return vertices, faces, topology, h


def _values(faces):
    return np.random.default_rng(3).uniform(-1.0, 1.0, (faces.shape[0], 4))


def _close_sums(actual, desired, magnitude, terms):
    """The same terms summed in another order: within (terms - 1) eps sum|term|."""
    assert np.all(np.abs(actual - desired) <= max(terms - 1, 1) * EPS * magnitude)


@pytest.mark.parametrize("backend", BACKENDS)
def test_equal_radii_array_is_the_float_call(backend):
    vertices, faces, topology, h = _mesh("ellipsoid")
    values = _values(faces)
    n = vertices.shape[0]
    normals = vertices / np.linalg.norm(vertices, axis=1, keepdims=True)
    centres = np.arange(0, n, 3)
    with use_backend(backend):
        np.testing.assert_array_equal(
            ball_face_sums(vertices, faces, np.full(n, 2 * h), values, connected=True),
            ball_face_sums(vertices, faces, 2 * h, values, connected=True),
        )
        for adjacency in (topology.neighbour_lists, None):
            got = fit_jets(
                vertices,
                normals,
                np.full(centres.size, 3 * h),
                degree=3,
                centres=centres,
                adjacency=adjacency,
                compact=True,
            )
            expected = fit_jets(vertices, normals, 3 * h, degree=3, centres=centres, adjacency=adjacency, compact=True)
            np.testing.assert_array_equal(got[0], expected[0])
            np.testing.assert_array_equal(got[2], expected[2])
        np.testing.assert_array_equal(
            fit_jet_normals(vertices, normals, np.full(n, 3 * h), degree=3, adjacency=topology.neighbour_lists),
            fit_jet_normals(vertices, normals, 3 * h, degree=3, adjacency=topology.neighbour_lists),
        )


def _radius_classes(n, h):
    """Three radii spread over the vertices at random: (V,) radii and the three values."""
    levels = np.array([1.0, 1.7, 2.6]) * h
    return levels[np.random.default_rng(5).integers(0, 3, n)], levels


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("name", ["ellipsoid", "flat"])
def test_per_vertex_radius_is_the_float_call_at_each_vertex(backend, name):
    vertices, faces, topology, h = _mesh(name)
    values, n = _values(faces), vertices.shape[0]
    radii, levels = _radius_classes(n, h)
    with use_backend(backend):
        got = ball_face_sums(vertices, faces, radii, values, connected=True)
        for level in levels:
            at = radii == level
            expected = ball_face_sums(vertices, faces, level, values, connected=True)
            if backend == "numba":  # the same walk and additions as the float call at that radius
                np.testing.assert_array_equal(got[at], expected[at])
            else:
                magnitude = ball_face_sums(vertices, faces, level, np.abs(values), connected=True)
                _close_sums(got[at], expected[at], magnitude[at], faces.shape[0])


@pytest.mark.parametrize("backend", BACKENDS)
def test_per_centre_jet_radius_is_the_float_fit_at_each_centre(backend):
    vertices, faces, topology, h = _mesh("flat")
    n = vertices.shape[0]
    normals = np.where(vertices[:, 2:] >= 0, [0.0, 0.0, 1.0], [0.0, 0.0, -1.0])
    centres = np.arange(1, n, 2)
    radii, levels = _radius_classes(centres.size, 1.5 * h)
    with use_backend(backend):
        for adjacency in (topology.neighbour_lists, None):
            got = fit_jets(vertices, normals, radii, degree=3, centres=centres, adjacency=adjacency, compact=True)
            for level in levels:
                at = radii == level
                expected = fit_jets(
                    vertices, normals, level, degree=3, centres=centres[at], adjacency=adjacency, compact=True
                )
                np.testing.assert_array_equal(got[2][at], expected[2])  # the same balls
                if backend == "numba" and adjacency is not None:  # the same walk and fit as the float call
                    np.testing.assert_array_equal(got[0][at], expected[0])
                else:
                    # the members in another order (the compiled grid's cells are as wide as the largest ball;
                    # the NumPy chunks hold other centres): moments summed in another order, each within
                    # n eps relative, times the condition number of the scaled normal matrix, up to 1e8
                    # for the degree-3 fits over the 10-20 points of the smallest balls (in units of the radius)
                    np.testing.assert_allclose(got[0][at], expected[0], rtol=0, atol=1e-6)
        full = np.random.default_rng(2).choice(levels, n)
        fitted = fit_jet_normals(vertices, normals, full, degree=3, adjacency=topology.neighbour_lists)
        for level in levels:
            at = full == level
            expected = fit_jet_normals(vertices, normals, level, degree=3, adjacency=topology.neighbour_lists)
            np.testing.assert_allclose(fitted[at], expected[at], rtol=0, atol=0 if backend == "numba" else 1e-9)


@pytest.mark.slow
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("name", ["ellipsoid", "flat"])
def test_nested_sums_are_separate_calls(backend, name):
    vertices, faces, topology, h = _mesh(name)
    values, n = _values(faces), vertices.shape[0]
    usable = np.random.default_rng(4).random(faces.shape[0]) > 0.1
    per_vertex = np.random.default_rng(6).uniform(0.8, 1.2, n)
    for radii in (
        np.array([1.0, 2.0, 4.0]) * h,
        np.array([1.0, 2.0, 4.0])[:, None] * h * per_vertex,
        np.array([2.0]) * h,
        np.array([1.0, 1.0, 3.0]) * h,
    ):
        with use_backend(backend):
            got = ball_face_sums_nested(vertices, faces, radii, values, usable=usable)
            assert got.shape == (radii.shape[0], n, values.shape[1])
            for r, radius in enumerate(radii):
                expected = ball_face_sums(vertices, faces, radius, values, usable=usable, connected=True)
                magnitude = ball_face_sums(vertices, faces, radius, np.abs(values), usable=usable, connected=True)
                _close_sums(got[r], expected, magnitude, faces.shape[0])
                if r == radii.shape[0] - 1 and backend == "numba":  # the walk is the largest ball's alone
                    np.testing.assert_array_equal(got[r], expected)
    sets = np.stack([values, 3.0 * values[::-1]])  # one set of values per radius (the measures of each scale)
    with use_backend(backend):
        got = ball_face_sums_nested(vertices, faces, [h, 3 * h], sets)
        for r, radius in enumerate((h, 3 * h)):
            expected = ball_face_sums(vertices, faces, radius, sets[r], connected=True)
            magnitude = ball_face_sums(vertices, faces, radius, np.abs(sets[r]), connected=True)
            _close_sums(got[r], expected, magnitude, faces.shape[0])


def test_nested_sums_keep_the_other_sheet_out_of_the_smaller_balls():
    """On a flat ellipsoid the largest ball reaches the other side round the rim: the smaller balls that
    hold points of the other side but no path to it inside them still leave it out."""
    vertices, faces, topology, h = _mesh("flat")
    values = np.ones((faces.shape[0], 1))  # the share of the faces: the area-free count of the ball
    radii = np.array([2.0, 8.0]) * h
    nested = ball_face_sums_nested(vertices, faces, radii, values)
    small_connected = ball_face_sums(vertices, faces, radii[0], values, connected=True)
    small_euclidean = ball_face_sums(vertices, faces, radii[0], values)
    large_connected = ball_face_sums(vertices, faces, radii[1], values, connected=True)
    large_euclidean = ball_face_sums(vertices, faces, radii[1], values)
    other_side = small_euclidean[:, 0] > small_connected[:, 0] + 0.5  # ball 0 holds faces it does not reach
    round_the_rim = np.isclose(large_connected[:, 0], large_euclidean[:, 0], rtol=1e-12)  # ball 1 reaches all
    tested = other_side & round_the_rim
    assert tested.sum() > 10
    np.testing.assert_allclose(nested[0][tested], small_connected[tested], rtol=1e-12)


def test_call_ranges_split_the_weight_evenly():
    n = 1000
    weights = np.r_[np.full(500, 1.0), np.full(500, 100.0)]
    ranges = call_ranges(n, 2e6, weights)  # 2e9 pairs: 20 calls
    assert ranges[0][0] == 0 and ranges[-1][1] == n
    assert all(a < b for a, b in ranges) and all(b == c for (_, b), (c, _) in zip(ranges, ranges[1:]))
    sums = [weights[a:b].sum() for a, b in ranges]
    assert max(sums) <= 1.05 * weights.sum() / len(ranges) + weights.max()
    assert ranges[0][1] > 400  # the light half in about one call
    assert call_ranges(n, 10.0, weights) == [(0, n)]


def test_estimate_ball_pairs_with_a_radius_per_centre_is_exact_on_a_small_cloud():
    rng = np.random.default_rng(1)
    points = rng.random((30, 3))  # no more centres than the sample (32): every one is probed
    radii = rng.uniform(0.2, 0.8, 30)
    inside = (np.linalg.norm(points[:, None] - points[None], axis=2) <= radii[:, None]).sum(axis=1)
    mean, largest = estimate_ball_pairs(points, radii)
    assert mean == pytest.approx(inside.mean(), rel=1e-12)
    assert largest == inside.max()


def test_radius_arrays_are_checked():
    vertices, faces, topology, h = _mesh("ellipsoid")
    n = vertices.shape[0]
    values = _values(faces)
    with pytest.raises(InvalidOptionError, match=rf"shape \({n},\): one radius per centre; got shape \(3,\)"):
        ball_face_sums(vertices, faces, np.ones(3), values, connected=True)
    with pytest.raises(InvalidOptionError, match="positive finite radii; 2 of"):
        ball_face_sums(vertices, faces, np.r_[np.nan, -1.0, np.ones(n - 2)], values, connected=True)
    with pytest.raises(InvalidOptionError, match="a number or an array"):
        centre_radii(np.array(["a", "b"], dtype=object), 2)
    with pytest.raises(InvalidOptionError, match="per vertex takes the surface-connected balls"):
        ball_face_sums(vertices, faces, np.full(n, h), values)
    with pytest.raises(InvalidOptionError, match="per vertex takes the surface-connected balls"):
        ball_edge_sums(vertices, topology.edges, np.full(n, h), np.ones((topology.edges.shape[0], 1)))
    normals = vertices / np.linalg.norm(vertices, axis=1, keepdims=True)
    with pytest.raises(InvalidOptionError, match="vertex 4, listed twice in `centres`, two radii"):
        fit_jets(vertices, normals, np.array([h, 2 * h, 3 * h]), centres=np.array([4, 5, 4]))
    with pytest.raises(InvalidOptionError, match=rf"shape \({n},\)"):
        fit_jet_normals(vertices, normals, np.ones(2), adjacency=topology.neighbour_lists)


def test_nested_radii_are_checked():
    vertices, faces, topology, h = _mesh("ellipsoid")
    values = _values(faces)
    with pytest.raises(InvalidOptionError, match=r"shape \(R,\) or \(R, \d+\) with R >= 1; got \(0,\)"):
        ball_face_sums_nested(vertices, faces, [], values)
    with pytest.raises(InvalidOptionError, match=r"got \(2, 5\)"):
        ball_face_sums_nested(vertices, faces, np.ones((2, 5)), values)
    with pytest.raises(InvalidOptionError, match="positive finite radii"):
        ball_face_sums_nested(vertices, faces, [h, np.inf], values)
    with pytest.raises(InvalidOptionError, match="must not decrease"):
        ball_face_sums_nested(vertices, faces, [2 * h, h], values)
    with pytest.raises(InvalidOptionError, match="increasing sequence of positive radii"):
        ball_face_sums_nested(vertices, faces, ["a", None], values)
    with pytest.raises(InvalidMeshError, match=r"\(F, k\) or \(2, F, k\): one set per radius; got \(3, "):
        ball_face_sums_nested(vertices, faces, [h, 2 * h], np.stack([values] * 3))
