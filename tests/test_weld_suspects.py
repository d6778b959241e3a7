"""The edges drop_double_sided looks at: the compiled pass against the NumPy definition (issue 31)."""

from __future__ import annotations

import numpy as np
import pytest

from meshcurv import shapes
from meshcurv._backend import use_backend
from meshcurv.topology import MeshTopology
from meshcurv.weld import _suspect_edges, drop_double_sided


def _meshes():
    sphere = shapes.icosphere(4)
    faces = np.asarray(sphere.faces, np.int64)
    n = sphere.vertices.shape[0]
    rng = np.random.default_rng(31)
    # every face twice, alternately wound
    yield "double-sided sphere", n, np.vstack([faces, faces[:, ::-1]])
    # one lone triangle stored with both windings beside the sphere: a pillow of three manifold edges
    yield "sphere and a pillow", n + 3, np.vstack([faces, [[n, n + 1, n + 2], [n, n + 2, n + 1]]])
    # a third face on some edges (non-manifold), some faces reversed (inconsistent), repeated corners
    extra = faces[rng.choice(faces.shape[0], 20, replace=False)][:, [1, 0, 2]]
    extra[:, 2] = rng.integers(0, n, 20)
    flipped = faces.copy()
    flipped[::7] = flipped[::7, ::-1]
    yield "defective", n, np.vstack([flipped, extra, [[0, 0, 1]]])
    yield "clean sphere", n, faces


@pytest.mark.parametrize("name, n_vertices, faces", list(_meshes()), ids=lambda value: str(value)[:24])
def test_compiled_suspects_are_those_of_the_definition(name, n_vertices, faces):
    pytest.importorskip("numba")
    with use_backend("numpy"):
        topology = MeshTopology.from_faces(faces, n_vertices)
        expected = _suspect_edges(topology)
    with use_backend("numba"):
        got = _suspect_edges(topology)
    np.testing.assert_array_equal(got, expected)
    assert got.any() == (name != "clean sphere")


def test_a_double_sided_pillow_keeps_one_side_on_both_backends():
    pytest.importorskip("numba")
    sphere = shapes.icosphere(3)
    n = sphere.vertices.shape[0]
    vertices = np.vstack([sphere.vertices, [[3.0, 0, 0], [4.0, 0, 0], [3.0, 1.0, 0]]])
    faces = np.vstack([sphere.faces, [[n, n + 1, n + 2], [n, n + 2, n + 1]]])
    dropped = []
    for backend in ("numpy", "numba"):
        with use_backend(backend):
            dropped.append(drop_double_sided(vertices, MeshTopology.from_faces(faces, n + 3)).dropped)
    np.testing.assert_array_equal(dropped[0], dropped[1])
    assert dropped[1].sum() == 1 and dropped[1][-2:].any()
