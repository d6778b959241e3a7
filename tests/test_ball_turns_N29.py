"""The reach check of the default balls (``meshcurv.radius._ball_turns``) compiled, and ``normal_cycle_ball``'s edge
values summed once (issue 29: ``normal_cycle_ball`` on ogre 5.2 -> 7.0 CPU s for 10 values, 2.9 s of it in NumPy
pair lists over every candidate ball, and the edge values and hole search of the sums done a second time).

Oracles: the NumPy twin (``radius.ball_turn_extremes.numpy``), to the bit; the angles of a sphere and a cylinder in
closed form; the results of both estimators on both backends against each other.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import radius, shapes
from meshcurv._backend import use_backend


def _inputs(mesh, scale=2.5, seed=0):
    """``(vertices, normals, radii, centres, pool, creases)`` of a mesh: area-weighted normals, radii of ``scale``
    mean edges times 0.5-1.5, every other vertex a centre."""
    from meshcurv import geometry

    vertices = np.ascontiguousarray(mesh[0], dtype=np.float64)
    faces = np.asarray(mesh[1], dtype=np.int64)
    with use_backend("numpy"):
        normals = geometry.vertex_normals(vertices, faces)
    edges = np.unique(np.sort(faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1), axis=0)
    edge = float(np.mean(np.linalg.norm(vertices[edges[:, 0]] - vertices[edges[:, 1]], axis=1)))
    rng = np.random.default_rng(seed)
    radii = scale * edge * rng.uniform(0.5, 1.5, vertices.shape[0])
    centres = np.arange(0, vertices.shape[0], 2, dtype=np.int64)
    pool = np.arange(vertices.shape[0], dtype=np.int64)
    creases = radius._edge_turns(normals, edges, vertices.shape[0])
    return vertices, normals, radii, centres, pool, creases


def _meshes():
    torus = shapes.torus(2.0, 1.0, 16, 16)
    sphere = shapes.icosphere(6)
    noisy = shapes.with_normal_noise(shapes.icosphere(8), 0.3, seed=1)
    # a coincident copy of a vertex that one face uses (unwelded: apart 0)
    doubled = sphere.vertices[np.r_[np.arange(sphere.vertices.shape[0]), 0]]
    faces = np.array(sphere.faces, dtype=np.int64)
    first = np.flatnonzero((faces == 0).any(axis=1))[0]
    faces[first][faces[first] == 0] = doubled.shape[0] - 1
    return {
        "coarse torus": (torus.vertices, torus.faces),
        "noisy sphere": (noisy.vertices, noisy.faces),
        "doubled": (doubled, faces),
    }


@pytest.mark.parametrize("name", list(_meshes()))
def test_the_compiled_extremes_are_the_numpy_twins_to_the_bit(name):
    pytest.importorskip("numba")
    from meshcurv._kernels import turns

    vertices, normals, radii, centres, pool, creases = _inputs(_meshes()[name])
    if name == "doubled":  # the copy a centre, and a vertex with no normal (NaN): it adds nothing
        normals = normals.copy()
        normals[5] = np.nan
        centres = np.r_[centres, vertices.shape[0] - 1]
    expected = radius.ball_turn_extremes.numpy(vertices, normals, radii, centres, pool, creases)
    got = turns.ball_turn_extremes(vertices, normals, radii, centres, pool, creases)
    for a, b in zip(got, expected):
        np.testing.assert_array_equal(a, b)
    known = np.isfinite(normals[centres]).all(axis=1)
    assert (expected[0][known] < 1).all() and (expected[1][known] > 0).all()  # every ball held other points


def test_the_turns_of_a_sphere_are_its_chords():
    # on a sphere of radius R the normal is the position over R: across a ball of radius r the normals turn by
    # 2 asin(r / 2R) at most, and |n_j - n_v| / |x_j - x_v| is 1 / R for every pair
    sphere = shapes.icosphere(8)
    vertices = np.asarray(sphere.vertices, dtype=np.float64) * 3.0
    normals = vertices / np.linalg.norm(vertices, axis=1)[:, None]
    n = vertices.shape[0]
    radii = np.full(n, 1.2)
    centres = np.arange(n, dtype=np.int64)
    for backend in ("numpy", "numba"):
        if backend == "numba":
            pytest.importorskip("numba")
        with use_backend(backend):
            turns, bends, sharpest = radius._ball_turns(vertices, normals, radii, centres, centres, np.zeros(n))
        assert (turns <= 2 * np.arcsin(1.2 / 6.0) + 1e-12).all()
        assert turns.min() > 0.7 * 2 * np.arcsin(1.2 / 6.0)  # vertices near the rim of every ball (0.78 of it)
        np.testing.assert_allclose(bends, 1 / 3.0, rtol=1e-9)
        assert (sharpest == 0).all()


def test_the_compiled_backend_searches_no_numpy_pairs(monkeypatch):
    pytest.importorskip("numba")
    from meshcurv import neighborhoods

    def refused(*args, **kwargs):
        raise AssertionError("the NumPy pair search ran on the compiled backend")

    vertices, normals, radii, centres, pool, creases = _inputs(_meshes()["coarse torus"])
    monkeypatch.setattr(neighborhoods, "_ball_pairs", refused)
    monkeypatch.setattr(radius, "_ball_pairs", refused)
    with use_backend("numba"):
        turns, bends, _ = radius._ball_turns(vertices, normals, radii, centres, pool, creases)
    assert (turns > 0).all() and (bends > 0).all()


def test_the_edge_values_are_computed_once_per_call(monkeypatch):
    from meshcurv.estimators import normal_cycle_ball

    calls = []
    original = normal_cycle_ball._edge_values

    def counted(*args):
        calls.append(1)
        return original(*args)

    monkeypatch.setattr(normal_cycle_ball, "_edge_values", counted)
    torus = shapes.torus(2.0, 1.0, 16, 16)  # every default ball reaches round the tube: made smaller
    result = meshcurv.principal_curvatures(torus.vertices, torus.faces, method="normal_cycle_ball")
    assert (np.asarray(result.radius) < result.parameters["radius"]).any()
    assert len(calls) == 1


@pytest.mark.parametrize("method", ["normal_cycle_ball", "quadric"])
def test_the_reach_check_is_the_same_on_both_backends(method):
    pytest.importorskip("numba")
    torus = shapes.torus(3.0, 1.0, 12, 24, jitter=0.2, seed=3)
    results = []
    for backend in ("numba", "numpy"):
        with use_backend(backend), warnings.catch_warnings():
            warnings.simplefilter("ignore")  # (its NaN'd vertices' warning: not what is tested)
            results.append(meshcurv.principal_curvatures(torus.vertices, torus.faces, method=method))
    numba_result, numpy_result = results
    np.testing.assert_array_equal(numba_result.valid, numpy_result.valid)
    np.testing.assert_array_equal(np.asarray(numba_result.radius), np.asarray(numpy_result.radius))
    np.testing.assert_allclose(numba_result.k_max, numpy_result.k_max, rtol=1e-6, atol=0)
    np.testing.assert_allclose(numba_result.k_min, numpy_result.k_min, rtol=1e-6, atol=0)
