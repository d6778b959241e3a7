"""Parts with no interior vertex (isolated faces, strips): no valid flat value for a curved surface (issue 29).

A triangle soup whose faces do not touch (each detached from its neighbours by more than the weld across
cracks reaches) gave every method that walks the surface a flat part per face: H = 0, valid, on a unit
hemisphere (rusinkiewicz and normal_cycle_ball at every vertex, icc at a third). The expected values are the
unit hemisphere's H = 1 and the invariance of the rest of a mesh under an added stray face.
"""

import warnings

import numpy as np
import pytest

from meshcurv import principal_curvatures, shapes
from meshcurv.defects import FRAGMENT, INVALID_REASONS, defect_codes
from meshcurv.errors import MeshQualityWarning
from meshcurv.topology import MeshTopology

SURFACE_WALKERS = ("icc", "rusinkiewicz", "normal_cycle_ball", "normal_cycle", "meyer")


def _soup(mesh, gap: float, seed: int = 0):
    """Every face of ``mesh`` with corners of its own, each moved ``gap`` mean edge lengths in a random
    direction (beyond the weld across cracks for ``gap`` >= 0.05)."""
    v, f = mesh.vertices, mesh.faces
    edge = np.mean(np.linalg.norm(v[f[:, 0]] - v[f[:, 1]], axis=1))
    corners = v[f].reshape(-1, 3)
    direction = np.random.default_rng(seed).normal(size=corners.shape)
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    return corners + gap * edge * direction, np.arange(corners.shape[0]).reshape(-1, 3)


def _quiet(vertices, faces, **options):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = principal_curvatures(vertices, faces, **options)
    return result, [str(w.message) for w in caught if issubclass(w.category, MeshQualityWarning)]


@pytest.mark.parametrize("gap", [0.06, 0.2])
@pytest.mark.parametrize("method", SURFACE_WALKERS)
def test_detached_faces_have_no_valid_flat_value(method, gap):
    vertices, faces = _soup(shapes.hemisphere(subdivisions=6), gap)
    result, messages = _quiet(vertices, faces, method=method)
    off = result.valid & (np.abs(result.mean - 1.0) > 0.5)  # exact H = 1 on the unit hemisphere
    assert not off.any(), f"{off.sum()} valid vertices off, H {np.unique(np.round(result.mean[off], 3))[:5]}"
    assert (result.invalid_reason == FRAGMENT).all()
    assert any("parts with no interior vertex" in m for m in messages)


@pytest.mark.parametrize("gap", [0.06, 0.2])
def test_quadric_keeps_detached_faces(gap):
    """Its fits take the Euclidean neighbours of every part: the soup is measured as the hemisphere."""
    vertices, faces = _soup(shapes.hemisphere(subdivisions=6), gap)
    result, _ = _quiet(vertices, faces, method="quadric")
    assert result.valid.mean() > 0.95
    assert abs(np.median(result.mean[result.valid]) - 1.0) < 0.1
    assert not (result.invalid_reason == FRAGMENT).any()


@pytest.mark.parametrize(
    "method, options", [("icc", {"radius": 0.3}), ("rusinkiewicz", {}), ("normal_cycle_ball", {"radius": 0.3})]
)
def test_a_stray_face_leaves_the_rest_alone(method, options):
    """A sphere with one face far from it: the face's corners invalid for their reason, the sphere as alone
    (at a given radius: the default's statistics take in the stray face's edges)."""
    sphere = shapes.icosphere(subdivisions=8)
    stray = np.array([[5.0, 0.0, 0.0], [5.1, 0.0, 0.0], [5.0, 0.1, 0.0]])
    n = sphere.vertices.shape[0]
    vertices = np.concatenate([sphere.vertices, stray])
    faces = np.concatenate([sphere.faces, [[n, n + 1, n + 2]]])
    alone, _ = _quiet(sphere.vertices, sphere.faces, method=method, **options)
    both, messages = _quiet(vertices, faces, method=method, **options)
    assert INVALID_REASONS[FRAGMENT].startswith("on a part with no interior vertex")
    assert (both.invalid_reason[n:] == FRAGMENT).all() and not both.valid[n:].any()
    assert (both.valid[:n] == alone.valid).all()
    np.testing.assert_allclose(both.mean[:n], alone.mean, rtol=1e-9, atol=1e-12)
    assert any("3 vertices on parts with no interior vertex" in m for m in messages)


def test_a_strip_is_a_fragment_and_a_cap_is_not():
    """A band of triangles one face wide round a cylinder has no interior vertex; a hemisphere and a closed
    sphere do, and carry no fragment code."""
    angles = np.linspace(0.0, 2 * np.pi, 24, endpoint=False)
    ring = np.column_stack([np.cos(angles), np.sin(angles), np.zeros_like(angles)])
    vertices = np.concatenate([ring, ring + [0.0, 0.0, 0.3]])
    i = np.arange(24)
    j = (i + 1) % 24
    faces = np.concatenate([np.column_stack([i, j, i + 24]), np.column_stack([j, j + 24, i + 24])])
    strip = MeshTopology.from_faces(faces, n_vertices=48)
    codes, counts = defect_codes(strip, np.zeros(len(faces), dtype=bool))
    assert (codes == FRAGMENT).all() and counts["fragment_vertices"] == 48
    result, _ = _quiet(vertices, faces, method="icc")
    assert not result.valid.any() and (result.invalid_reason == FRAGMENT).all()
    for mesh in (shapes.hemisphere(subdivisions=6), shapes.icosphere(subdivisions=4)):
        topology = MeshTopology.from_faces(mesh.faces, n_vertices=mesh.vertices.shape[0])
        codes, counts = defect_codes(topology, np.zeros(topology.n_faces, dtype=bool))
        assert not (codes == FRAGMENT).any() and counts["fragment_vertices"] == 0
