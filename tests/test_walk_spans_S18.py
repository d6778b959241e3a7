"""The walks of the normal fits' balls leave out far vertices at the first look (issue 31): the same members.

``_connected_members`` and ``_connected_walk_levels`` (``meshcurv._kernels.neighborhoods``) take the longest
edge at each vertex (``_vertex_spans``) and stamp a vertex reached from outside the ball that lies farther from
it than that edge, instead of testing each of its edges' segments. No edge of such a vertex meets the ball, so
the walk never queued it: the members, their order, and the levels of the nested walk must be exactly those of
the walk without spans, on meshes with irregular edges, long spikes and edges that cross the ball with both ends
outside.
"""

from __future__ import annotations

import numpy as np
import pytest

from meshcurv import shapes
from meshcurv.topology import MeshTopology

neighborhoods = pytest.importorskip("meshcurv._kernels.neighborhoods")


def _meshes():
    rng = np.random.default_rng(7)
    sphere = shapes.icosphere(6)
    yield "icosphere", sphere.vertices, sphere.faces
    jittered = sphere.vertices + rng.normal(scale=0.03, size=sphere.vertices.shape)
    yield "jittered", jittered, sphere.faces
    spiked = sphere.vertices.copy()
    spiked[rng.choice(len(spiked), 12, replace=False)] *= 3.0  # spikes: edges far longer than the balls
    yield "spiked", spiked, sphere.faces
    torus = shapes.torus(n_major=24, n_minor=12)
    yield "torus", np.asarray(torus.vertices, float), torus.faces
    # a fan of long thin triangles around a vertex: their far edges cross small balls with both ends outside
    angles = np.linspace(0.0, 2.0 * np.pi, 9)[:-1]
    rim = np.column_stack([np.cos(angles), np.sin(angles), np.zeros(8)])
    fan = np.vstack([[0.0, 0.0, 0.0], rim * 10.0, rim * 10.0 + [[0.0, 0.0, 0.5]]])
    fan_faces = [[0, 1 + k, 1 + (k + 1) % 8] for k in range(8)] + [[1 + k, 9 + k, 1 + (k + 1) % 8] for k in range(8)]
    yield "fan", fan, np.array(fan_faces)


def _walk(vertices, lists, radius, spans):
    indptr, indices = lists
    n = vertices.shape[0]
    allowed = np.ones(n, dtype=bool)
    mark = np.full(n, -1, dtype=np.int64)
    members = np.empty(n, dtype=np.int64)
    queue = np.empty(n, dtype=np.int64)
    found = []
    stamped = 0
    for v in range(n):
        if spans is None:
            size = neighborhoods._connected_members(
                vertices, indptr, indices, allowed, v, radius, mark, v, members, queue
            )
        else:
            size = neighborhoods._connected_members(
                vertices, indptr, indices, allowed, v, radius, mark, v, members, queue, spans
            )
        found.append(members[:size].copy())
        stamped += int((mark == v).sum())
    return found, stamped


@pytest.mark.parametrize("scale", [0.5, 1.0, 3.0, 6.0])
@pytest.mark.parametrize(("name", "vertices", "faces"), list(_meshes()), ids=[m[0] for m in _meshes()])
def test_members_with_spans_are_those_without(name, vertices, faces, scale):
    lists = MeshTopology.from_faces(faces, vertices.shape[0]).neighbour_lists
    indptr, indices = (np.ascontiguousarray(a, dtype=np.int64) for a in lists)
    edge = np.median(
        np.linalg.norm(vertices[indices] - vertices[np.repeat(np.arange(len(indptr) - 1), np.diff(indptr))], axis=1)
    )
    spans = neighborhoods._vertex_spans(vertices, indptr, indices)
    plain, queued = _walk(vertices, (indptr, indices), scale * edge, None)
    pruned, stamped = _walk(vertices, (indptr, indices), scale * edge, spans)
    assert all(np.array_equal(a, b) for a, b in zip(plain, pruned))
    assert stamped >= queued  # the queued vertices, and the far ones stamped on the way
    if name == "icosphere" and scale == 3.0:
        assert stamped > queued  # the far vertices were met and left out at the first look


def test_spans_are_the_longest_edges():
    vertices = np.array([[0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [0.0, 4.0, 0.0], [9.0, 9.0, 9.0]])
    indptr = np.array([0, 2, 4, 6, 6])
    indices = np.array([1, 2, 0, 2, 0, 1])
    np.testing.assert_allclose(neighborhoods._vertex_spans(vertices, indptr, indices), [4.0, 5.0, 5.0, 0.0])


@pytest.mark.parametrize(("name", "vertices", "faces"), list(_meshes()), ids=[m[0] for m in _meshes()])
def test_nested_walk_with_spans_is_the_walk_without(name, vertices, faces):
    lists = MeshTopology.from_faces(faces, vertices.shape[0]).neighbour_lists
    indptr, indices = (np.ascontiguousarray(a, dtype=np.int64) for a in lists)
    edge = np.median(
        np.linalg.norm(vertices[indices] - vertices[np.repeat(np.arange(len(indptr) - 1), np.diff(indptr))], axis=1)
    )
    cutoffs2 = (np.array([1.0, 2.0, 4.0]) * edge) ** 2
    spans = neighborhoods._vertex_spans(vertices, indptr, indices)
    n = vertices.shape[0]
    allowed = np.ones(n, dtype=bool)
    for v in range(0, n, 3):
        outputs = []
        for extra in ((), (spans,)):
            mark = np.full(n, -1, dtype=np.int64)
            walk = tuple(np.zeros(n, dtype=np.int64) for _ in range(4)) + (np.zeros(n),)
            members = np.zeros(n, dtype=np.int64)
            size, n_inner = neighborhoods._connected_walk_levels(
                vertices, indptr, indices, allowed, v, cutoffs2, mark, 0, walk, members, *extra
            )
            outputs.append((members[:size].copy(), *(a[:n_inner].copy() for a in walk[2:])))
        for plain, pruned in zip(*outputs):
            np.testing.assert_array_equal(plain, pruned)
