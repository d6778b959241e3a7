"""The trusting cores of ``jets`` and ``neighborhoods`` (issue 33): a call is checked once, at the door.

The estimators hand the prepared mesh's arrays (checked by ``prepare_mesh``) to the private cores
(``_fit_jets``, ``_fit_jet_normals``, ``_ball_face_sums``, ``_ball_edge_sums``, ...); the public
functions stay shells that check their inputs, then call the same cores.
"""

from __future__ import annotations

import collections
import sys

import numpy as np
import pytest

import meshcurv
from meshcurv import jets, neighborhoods, shapes
from meshcurv.errors import InvalidMeshError, InvalidOptionError
from meshcurv.topology import MeshTopology

CORES = ("meshcurv.jets", "meshcurv.neighborhoods")


def _validation_entries(call) -> collections.Counter:
    """``(function, caller)`` of each entry into :mod:`meshcurv._validation` from :data:`CORES` during ``call()``."""
    found: collections.Counter = collections.Counter()

    def profile(frame, event, arg):
        if event == "call" and frame.f_globals.get("__name__") == "meshcurv._validation":
            caller = frame.f_back
            if caller is not None and caller.f_globals.get("__name__") in CORES:
                found[(frame.f_code.co_name, caller.f_code.co_name)] += 1

    sys.setprofile(profile)
    try:
        call()
    finally:
        sys.setprofile(None)
    return found


@pytest.mark.parametrize("method", ["icc", "quadric", "normal_cycle_ball"])
def test_a_default_call_checks_nothing_again_in_jets_and_neighborhoods(method):
    # the door (prepare_mesh: as_vertices, as_faces, check_choice) checked the arrays; before, icc passed them
    # through checked_points three times, checked_indices and check_positive_float once each (5 entries)
    sphere = shapes.icosphere(3)  # 642 vertices
    entries = _validation_entries(lambda: meshcurv.principal_curvatures(sphere.vertices, sphere.faces, method=method))
    assert entries == {}, entries


def _sphere():
    sphere = shapes.icosphere(2)
    vertices = np.array(sphere.vertices)
    return vertices, np.asarray(sphere.faces, dtype=np.int64), vertices / np.linalg.norm(vertices, axis=1)[:, None]


def _edges(faces: np.ndarray) -> np.ndarray:
    sides = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    return np.unique(sides, axis=0)


@pytest.mark.parametrize(
    "call",
    [
        lambda v, f, n: jets.fit_jets(v, n, 0.5),
        lambda v, f, n: jets.fit_jet_normals(v, n, 0.5),
        lambda v, f, n: jets.sampled_jet_normals(v, n, 0.5, centres=np.arange(len(v))),
        lambda v, f, n: neighborhoods.ball_face_sums(v, f, 0.5, np.ones((len(f), 1))),
        lambda v, f, n: neighborhoods.ball_face_sums_nested(v, f, [0.5], np.ones((len(f), 1))),
        lambda v, f, n: neighborhoods.coarse_face_sums(v, f, 0.5, np.ones((len(f), 1))),
        lambda v, f, n: neighborhoods.ball_edge_sums(v, _edges(f), 0.5, np.ones((len(_edges(f)), 1))),
    ],
    ids=["fit_jets", "fit_jet_normals", "sampled_jet_normals", "ball_face_sums", "nested", "coarse", "edges"],
)
def test_the_public_shells_still_refuse_non_finite_vertices(call):
    vertices, faces, normals = _sphere()
    vertices[3, 1] = np.nan
    with pytest.raises(InvalidMeshError, match="NaN or infinite coordinates"):
        call(vertices, faces, normals)


@pytest.mark.parametrize("name", ["ball_face_sums", "ball_face_sums_nested", "coarse_face_sums", "ball_edge_sums"])
def test_the_public_sums_still_refuse_indices_out_of_range(name):
    vertices, faces, _ = _sphere()
    cells = _edges(faces) if name == "ball_edge_sums" else faces.copy()
    cells[0, 0] = len(vertices)
    radii = [0.5] if name == "ball_face_sums_nested" else 0.5
    with pytest.raises(InvalidMeshError, match="out of range|must be in|index"):
        getattr(neighborhoods, name)(vertices, cells, radii, np.ones((len(cells), 1)))


@pytest.mark.parametrize("name", ["ball_face_sums", "coarse_face_sums", "ball_edge_sums"])
def test_the_public_sums_still_refuse_a_negative_radius(name):
    vertices, faces, _ = _sphere()
    cells = _edges(faces) if name == "ball_edge_sums" else faces
    with pytest.raises(InvalidOptionError, match="radius"):
        getattr(neighborhoods, name)(vertices, cells, -0.5, np.ones((len(cells), 1)))


def test_the_edge_core_takes_the_topology_s_int32_edges():
    # MeshTopology.edges are int32; the shell hands int64 to the core: the same sums from either, and the
    # edge lengths in a ball larger than the sphere are those of the whole mesh
    vertices, faces, _ = _sphere()
    edges = _edges(faces)
    lengths = np.linalg.norm(vertices[edges[:, 1]] - vertices[edges[:, 0]], axis=1)
    whole = neighborhoods._ball_edge_sums(vertices, edges.astype(np.int32), 3.0, np.ones((len(edges), 1)))
    np.testing.assert_allclose(whole[:, 0], lengths.sum(), rtol=1e-12)
    np.testing.assert_array_equal(whole, neighborhoods.ball_edge_sums(vertices, edges, 3.0, np.ones((len(edges), 1))))


def test_the_normal_core_fits_the_sphere_s_normals():
    # jets of degree 2 through points of a unit sphere: the fitted normals are x / |x| to round-off of the fit
    vertices, faces, normals = _sphere()
    adjacency = MeshTopology.from_faces(faces, len(vertices)).neighbour_lists
    tilted = normals + 0.05 * np.roll(normals, 1, axis=1)
    tilted /= np.linalg.norm(tilted, axis=1)[:, None]
    fitted = jets._fit_jet_normals(vertices, tilted, 0.8, adjacency=adjacency, iterations=3)
    np.testing.assert_allclose(fitted, normals, atol=1e-3)
