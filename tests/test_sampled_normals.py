"""jets.sampled_jet_normals: normal fits at one centre per cube, linear interpolation at the others (issue 30)."""

from __future__ import annotations

import importlib.util

import numpy as np
import pytest

from meshcurv import jets, shapes
from meshcurv._backend import use_backend
from meshcurv.errors import InvalidOptionError
from meshcurv.geometry import vertex_normals
from meshcurv.topology import MeshTopology

#: icc's normal fits: degree 3, two iterations.
OPTIONS = {"degree": 3, "iterations": 2, "min_spread": jets.NORMAL_MIN_SPREAD, "settled": jets.SETTLED_SLOPE}


def _sphere():
    """A unit icosphere of 4,002 vertices (edges of about 0.06), its topology and its exact normals."""
    sphere = shapes.icosphere(subdivisions=20, radius=1.0)
    vertices = np.asarray(sphere.vertices, dtype=np.float64)
    return (
        vertices,
        sphere.faces,
        MeshTopology.from_faces(sphere.faces),
        vertices / np.linalg.norm(vertices, axis=1)[:, None],
    )


def _sampled(vertices, normals, topology, radius=0.4, spacing=0.15):
    """The sampled normals at every vertex, balls the surface-connected pieces."""
    centres = np.arange(vertices.shape[0])
    adjacency = topology.neighbour_lists
    return jets.sampled_jet_normals(
        vertices, normals, radius, centres=centres, spacing=spacing, adjacency=adjacency, **OPTIONS
    )


def _angles(normals, exact):
    return np.arccos(np.clip(np.abs(np.einsum("ij,ij->i", normals, exact)), -1.0, 1.0))


@pytest.mark.parametrize(
    "backend",
    [
        pytest.param(
            "numba",
            marks=pytest.mark.skipif(importlib.util.find_spec("numba") is None, reason="numba is not installed"),
        ),
        "numpy",
    ],
)
def test_sampled_normals_of_a_sphere_are_radial(backend):
    vertices, _, topology, exact = _sphere()
    # cubes of 0.15 (2.5 edges): about one vertex in six is fitted
    assert jets._cube_samples(vertices, 0.15).size < vertices.shape[0] / 4
    with use_backend(backend):
        normals = _sampled(vertices, exact, topology)
    # on a sphere the tangential components of the exact normal x / R are linear in the tangent-plane
    # coordinates, so the interpolation is exact: what is left is the fits' own error, that of a cubic jet over
    # balls of 0.4 on a unit sphere sampled at 0.06 (about 2e-4 rad at most)
    assert _angles(normals, exact).max() < 3e-4
    np.testing.assert_allclose(np.linalg.norm(normals, axis=1), 1.0, rtol=1e-12)


def test_samples_keep_their_own_fits():
    vertices, _, topology, exact = _sphere()
    samples = jets._cube_samples(vertices, 0.15)
    normals = _sampled(vertices, exact, topology)
    coefficients, frame, _ = jets.fit_jets(
        vertices, exact, 0.4, centres=samples, compact=True, adjacency=topology.neighbour_lists, **OPTIONS
    )
    np.testing.assert_allclose(normals[samples], jets.jet_normals(coefficients, frame), rtol=0, atol=1e-14)


def test_dense_voxel_sphere_keeps_the_accuracy_of_fits_everywhere():
    pytest.importorskip("skimage")  # the voxel sphere is marching cubes
    mesh = shapes.voxel_sphere(2.0, (0.2, 0.1, 0.1), seed=0)
    vertices = np.asarray(mesh.vertices, dtype=np.float64)
    topology = MeshTopology.from_faces(mesh.faces)
    centre = vertices.mean(axis=0)
    exact = (vertices - centre) / np.linalg.norm(vertices - centre, axis=1)[:, None]
    start = vertex_normals(vertices, mesh.faces)
    options = {"adjacency": topology.neighbour_lists, **OPTIONS}
    spacing = 0.2  # two voxels: one fit for about 5 vertices
    sampled = jets.sampled_jet_normals(
        vertices, start, 2.0, centres=np.arange(vertices.shape[0]), spacing=spacing, **options
    )
    everywhere = jets.fit_jet_normals(vertices, start, 2.0, **options)
    assert jets._cube_samples(vertices, spacing).size < vertices.shape[0] / 3
    # the staircase of 0.1-0.2 tilts the fitted normals by about half a degree (median) either way; the
    # interpolation over 0.3 averages that jitter rather than adding to it
    assert np.degrees(np.median(_angles(sampled, exact))) < 1.05 * np.degrees(np.median(_angles(everywhere, exact)))
    assert np.degrees(np.median(_angles(sampled, exact))) < 0.6


def test_reindexed_and_moved_points_give_the_same_normals():
    vertices, faces, topology, exact = _sphere()
    n = vertices.shape[0]
    normals = _sampled(vertices, exact, topology)
    order = np.random.default_rng(5).permutation(n)  # new vertex i is old vertex order[i]
    again = _sampled(vertices[order], exact[order], MeshTopology.from_faces(np.argsort(order)[faces]))
    np.testing.assert_allclose(again, normals[order], rtol=0, atol=1e-12)
    shifted = _sampled(vertices + [3.7, -1.25, 0.5], exact, topology)
    np.testing.assert_allclose(shifted, normals, rtol=0, atol=1e-9)


def test_no_centre_and_no_fit():
    vertices, _, topology, exact = _sphere()
    empty = jets.sampled_jet_normals(vertices, exact, 0.4, centres=np.zeros(0, dtype=np.int64), **OPTIONS)
    assert empty.shape == (0, 3)
    # balls of a hundredth of an edge hold their centre only: no jet, NaN everywhere
    none = jets.sampled_jet_normals(vertices, exact, 1e-3, centres=np.arange(50), spacing=0.15, **OPTIONS)
    assert none.shape == (50, 3) and np.isnan(none).all()


@pytest.mark.parametrize("spacing", [0.0, -1.0, np.nan, np.inf])
def test_bad_spacing_is_refused(spacing):
    vertices, _, _, exact = _sphere()
    with pytest.raises(InvalidOptionError, match="`spacing` must be a positive finite length"):
        jets.sampled_jet_normals(vertices, exact, 0.4, centres=np.arange(10), spacing=spacing)


def test_narrow_width_is_refused():
    vertices, _, _, exact = _sphere()
    with pytest.raises(InvalidOptionError, match="`width` must be at least 1"):
        jets.sampled_jet_normals(vertices, exact, 0.4, centres=np.arange(10), spacing=0.1, width=0.5)
