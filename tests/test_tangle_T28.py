"""Coincident copies of one part left unwelded in a tangle of overlapping faces: no valid value there (issue 29).

Fuzz 557/23: a thin plate given as a triangle soup, its faces chained into one part by polygons of the corners of
two consecutive faces (the fan triangulation adds a face across the two), some faces given twice, and
``weld=False``: six unwelded copies at each point, their faces overlapping. ``icc`` kept 839 boundary vertices
valid, H median 0.012 (NumPy) and 0.031 (numba) where the plate's is 1.27. The same tangle is built here from a
sphere of radius 1 (exact H = 1, outward normals); a seam split open (texture seams of a file read unwelded), the
copies of a closed surface stored twice and a plain soup keep their results (:func:`meshcurv.weld.tangled_vertices`:
the copies the weld would join, joined within each part, on a non-manifold edge or a bow-tie).
"""

from __future__ import annotations

import importlib.util
import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes
from meshcurv._backend import use_backend
from meshcurv.defects import FRAGMENT, INVALID_REASONS, TANGLE, UNDEFINED, defect_codes
from meshcurv.errors import InvalidMeshError, MeshQualityWarning
from meshcurv.topology import MeshTopology
from meshcurv.weld import tangled_vertices

BACKENDS = ("numpy", "numba") if importlib.util.find_spec("numba") else ("numpy",)

#: The methods that keep boundary vertices: the copies of a tangle are boundary vertices of their faces (the
#: others leave every boundary vertex undefined whatever the tangle).
BALL_METHODS = ("icc", "normal_cycle_ball", "rusinkiewicz", "matgeom", "quadric")


def _tangle(mesh, every: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """``mesh`` as a soup (each face with corners of its own) whose consecutive faces are joined by a face across
    the two (first and last corners of one, first of the next; ``every``: one join in so many), one face in four
    given twice: what fuzz_api's polygons of a soup become once fan-triangulated."""
    corners = np.asarray(mesh.faces)
    vertices = np.asarray(mesh.vertices, dtype=float)[corners.ravel()]
    soup = np.arange(corners.size).reshape(-1, 3)
    joins = np.column_stack([soup[:-1, 0], soup[:-1, 2], soup[1:, 0]])
    return vertices, np.concatenate([soup, joins[::every], soup[::4]])


def _errors(result, vertices: np.ndarray) -> np.ndarray:
    """(V,) |H n - H_exact n_exact| on the unit sphere (exact H = 1, n = the position): relative to H = 1, and
    free of the normal's sign (a flipped normal flips H too)."""
    return np.linalg.norm(result.mean[:, None] * result.normals - vertices, axis=1)


@pytest.mark.parametrize("method", BALL_METHODS)
@pytest.mark.parametrize("every", [1, 3])
def test_a_tangle_of_unwelded_copies_gives_no_wrong_valid_value(method, every):
    # every = 1: one part (icc kept 210 of 1,920 vertices valid, 117 of them more than 50% off in H; 557/23's
    # class); every = 3: parts of a few soup faces whose one vertex off the boundary sits between a face and its
    # copy (a pillow, no ring of faces: icc kept 40 valid, H = 0 for 1)
    vertices, faces = _tangle(shapes.icosphere(3), every)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshQualityWarning)
        # numpy's warnings are errors: quadric's default radius divided by the distance to a coincident copy, 0
        # (radius._ball_turns: a RuntimeWarning reached the caller, fuzz_api 573/70)
        warnings.simplefilter("error", RuntimeWarning)
        result = meshcurv.principal_curvatures(vertices, faces, method=method, weld=False)
    far = result.valid & ~(_errors(result, vertices) < 0.5)  # NaN counts as far
    assert not far.any(), f"{far.sum()} valid vertices more than 50% off in H"


def test_the_tangle_has_its_own_reason_and_one_warning():
    vertices, faces = _tangle(shapes.icosphere(3))
    topology = MeshTopology.from_faces(faces, len(vertices))
    tangled = tangled_vertices(vertices, topology)
    assert tangled.sum() > len(vertices) // 2
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = meshcurv.principal_curvatures(vertices, faces, method="icc", weld=False)
    assert not result.valid.any()
    assert (result.invalid_reason == TANGLE).sum() >= len(vertices) // 2  # the rest: on non-manifold edges, bow-ties
    assert INVALID_REASONS[TANGLE].startswith("coincident with other vertices of its part, not welded")
    assert UNDEFINED == len(INVALID_REASONS) - 1 == TANGLE + 1  # the new code before the undefined estimate
    assert len(caught) == 1 and issubclass(caught[0].category, MeshQualityWarning)
    message = str(caught[0].message)
    assert f"{tangled.sum()} vertices coincident with others of their part, not welded (weld=False)" in message
    assert "vertices are NaN with valid=False" in message


@pytest.mark.parametrize("every", [1, 3])
def test_both_backends_give_the_same_tangle(every):
    vertices, faces = _tangle(shapes.ellipsoid((1.0, 0.6, 0.03), subdivisions=4), every)  # 557/23's thin plate, coarser
    results = []
    for backend in BACKENDS:
        with use_backend(backend), warnings.catch_warnings():
            warnings.simplefilter("ignore", MeshQualityWarning)
            results.append(meshcurv.principal_curvatures(vertices, faces, method="icc", weld=False))
    for result in results:
        assert not result.valid.any()
        np.testing.assert_array_equal(result.invalid_reason, results[0].invalid_reason)


def _seamed_sphere(n_longitude: int = 32, n_latitude: int = 16) -> tuple[np.ndarray, np.ndarray]:
    """A uv sphere split open along a meridian (the faces across it take copies of its vertices) and at its poles
    (each pole face a pole of its own): seams of one part whose copies, joined, make the sphere."""
    sphere = shapes.uv_sphere(n_longitude, n_latitude)
    vertices, faces = np.asarray(sphere.vertices), np.asarray(sphere.faces).copy()
    column = (np.arange(len(vertices)) - 1) % n_longitude
    column[[0, -1]] = -1  # the poles
    across = (column[faces] == n_longitude - 1).any(axis=1) & (column[faces] == 0).any(axis=1)
    first = np.flatnonzero(column == 0)
    copy = np.full(len(vertices), -1)
    copy[first] = len(vertices) + np.arange(first.size)
    faces[across] = np.where(column[faces[across]] == 0, copy[faces[across]], faces[across])
    vertices = np.vstack([vertices, vertices[first]])
    for pole in (0, len(sphere.vertices) - 1):
        rows = np.flatnonzero((faces == pole).any(axis=1))
        own = len(vertices) + np.arange(rows.size)
        faces[rows] = np.where(faces[rows] == pole, own[:, None], faces[rows])
        vertices = np.vstack([vertices, np.repeat(vertices[pole : pole + 1], rows.size, axis=0)])
    return vertices, faces


@pytest.mark.parametrize("method", ["icc", "normal_cycle_ball", "rusinkiewicz", "quadric"])
def test_a_seam_split_open_keeps_its_values(method):
    vertices, faces = _seamed_sphere()
    topology = MeshTopology.from_faces(faces, len(vertices))
    assert topology.n_components == 1 and topology.boundary_edges.sum() == 156
    assert not tangled_vertices(vertices, topology).any()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshQualityWarning)  # the two poles left unreferenced
        result = meshcurv.principal_curvatures(vertices, faces, method=method, weld=False)
    referenced = topology.referenced_vertices
    assert result.valid[referenced].all()  # the copies on the seams too: half a neighbourhood each
    np.testing.assert_allclose(result.mean[referenced], 1.0, atol=0.07)  # icc's widest: 5.2% (32 x 16 sphere)


def test_copies_in_parts_of_their_own_are_no_tangle():
    sphere = shapes.icosphere(2)
    n = len(sphere.vertices)
    vertices = np.vstack([sphere.vertices, sphere.vertices])
    faces = np.vstack([sphere.faces, sphere.faces + n])  # two closed copies: no boundary, nothing looked at
    topology = MeshTopology.from_faces(faces, 2 * n)
    assert not tangled_vertices(vertices, topology).any()
    # a soup: every face a part of its own, its copies in other parts (a fragment, not a tangle)
    soup = np.asarray(sphere.vertices)[np.asarray(sphere.faces).ravel()]
    topology = MeshTopology.from_faces(np.arange(len(soup)).reshape(-1, 3), len(soup))
    assert not tangled_vertices(soup, topology).any()
    codes, counts = defect_codes(
        topology, np.zeros(topology.n_faces, dtype=bool), tangled=tangled_vertices(soup, topology)
    )
    assert (codes == FRAGMENT).all() and counts["tangled_vertices"] == 0


def test_copies_a_rounding_apart_are_copies():
    # the copies the weld would join (within 1e-5 median edge lengths): coordinates written with fewer digits
    # do not take a tangle apart
    vertices, faces = _tangle(shapes.icosphere(3))
    topology = MeshTopology.from_faces(faces, len(vertices))
    moved = vertices + np.random.default_rng(0).normal(scale=1e-7 * 0.4, size=vertices.shape)  # edges 0.4
    np.testing.assert_array_equal(tangled_vertices(moved, topology), tangled_vertices(vertices, topology))


def _grid_sphere(n_longitude: int = 32, n_latitude: int = 16) -> tuple[np.ndarray, np.ndarray]:
    """MATLAB's ``sphere`` through ``surf2patch`` (matGeom's own input): a (latitude + 1) x (longitude + 1) grid
    of points, its seam column and its pole rows copies, its quads split in two, so that each pole quad gives one
    zero-area face (two corners copies of the pole)."""
    polar = np.pi * np.arange(n_latitude + 1) / n_latitude
    azimuth = 2.0 * np.pi * np.arange(n_longitude + 1) / n_longitude
    theta, phi = np.meshgrid(polar, azimuth, indexing="ij")
    vertices = np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], -1).reshape(-1, 3)
    vertices[np.abs(vertices) < 1e-15] = 0.0  # the pole rows exact copies
    grid = np.arange(len(vertices)).reshape(n_latitude + 1, n_longitude + 1)
    a, b, c, d = grid[:-1, :-1], grid[1:, :-1], grid[1:, 1:], grid[:-1, 1:]
    faces = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    return vertices, faces


def test_a_grid_sphere_with_zero_area_pole_faces_is_no_tangle():
    # R28: its zero-area pole faces, their corners joined, stood as third faces on the pole's edges: 130 corners
    # read as a tangle (not "corner of a zero-area face"), 2 right seam vertices lost
    vertices, faces = _grid_sphere()
    topology = MeshTopology.from_faces(faces, len(vertices))
    assert not tangled_vertices(vertices, topology).any()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshQualityWarning)
        result = meshcurv.principal_curvatures(vertices, faces, method="icc", weld=False)
    assert TANGLE not in result.invalid_reason
    area = np.linalg.norm(np.cross(*(vertices[faces[:, i]] - vertices[faces[:, 0]] for i in (1, 2))), axis=1)
    degenerate = np.zeros(len(vertices), dtype=bool)
    degenerate[faces[area == 0].ravel()] = True
    assert result.valid[~degenerate].all()  # every vertex off the zero-area faces, the seam's copies too
    np.testing.assert_allclose(result.mean[result.valid], 1.0, atol=0.05)


def test_bad_arguments_are_named():
    sphere = shapes.icosphere(1)
    topology = MeshTopology.from_faces(sphere.faces, len(sphere.vertices))
    with pytest.raises(InvalidMeshError, match="`topology` must be a MeshTopology; got ndarray"):
        tangled_vertices(sphere.vertices, sphere.faces)
    with pytest.raises(InvalidMeshError, match="`vertices` has 11 rows but the topology has 12 vertices"):
        tangled_vertices(sphere.vertices[:-1], topology)
    with pytest.raises(InvalidMeshError, match="tangled"):
        defect_codes(topology, np.zeros(len(sphere.faces), dtype=bool), tangled=np.zeros(3, dtype=bool))
