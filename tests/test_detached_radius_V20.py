"""icc's default radius beside cracks and detached faces (issue 29, "never a wrong number marked valid").

With half of the faces of a unit icosphere(40) detached (each given its own corners, moved 0.054 edge lengths in
random directions; the weld joins those within its crack tolerance), most of the surface left is faces hanging by one
or two corners and welded kinks. At the group's radius (one edge length: the mesh is clean almost everywhere) the ball
of a hanging face's free corner holds a piece of that face alone, and a welded corner's a disc of kinked faces: 20-60
valid vertices read H off by more than half of it, some with the wrong sign. The exact mean curvature of the unit
sphere is 1 everywhere; a ball of 1.5 edge lengths or more errs by a few percent there, so no valid vertex may be off
by half of it. A rim (nothing beyond its boundary edges) and a closed mesh keep their radii.
"""

import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes

sys.path.insert(0, str(Path(__file__).parent))
from test_orient_holey_inward import _holey  # noqa: E402

#: Half of the exact mean curvature (1 on the unit sphere): an estimate beyond it is a wrong number.
OFF = 0.5


def _default(vertices, faces):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the loose faces and welds are reported: not the point here
        return meshcurv.principal_curvatures(vertices, faces)


@pytest.mark.parametrize("reverse", [False, True], ids=["as_made", "reversed"])
def test_half_detached_icosphere_has_no_wrong_valid_vertex(reverse):
    sphere = shapes.icosphere(40)
    faces = sphere.faces[:, ::-1] if reverse else sphere.faces
    vertices, faces = _holey(sphere.vertices, faces, seed=0, detach=True)
    result = _default(vertices, faces)
    mean = (result.k_min + result.k_max) / 2
    valid = result.valid
    assert valid.sum() > 0.15 * len(vertices)  # ~17% before and after: the loose corners are undefined
    assert np.all(mean[valid] > 0)  # the sphere's sign
    assert np.abs(mean[valid] - 1.0).max() < OFF
    assert result.parameters["scale"] == "local"


def _factor(vertices, faces):
    from meshcurv._prepared import prepare_mesh
    from meshcurv.radius import _holed_factor

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        mesh = prepare_mesh(vertices, faces, orient="auto", weld=True)
    edge = float(
        np.mean(
            np.linalg.norm(mesh.vertices[mesh.topology.edges[:, 0]] - mesh.vertices[mesh.topology.edges[:, 1]], axis=1)
        )
    )
    base = np.full(mesh.vertices.shape[0], edge)
    return _holed_factor(mesh, base, mesh.vertex_normals)


@pytest.mark.parametrize(
    "make",
    [
        lambda: shapes.hemisphere(16),
        lambda: shapes.hemisphere(16, irregular=True, seed=0),
        lambda: shapes.saddle(1.0, 0.1, jitter=0.35, seed=0),
        lambda: shapes.cylinder(),
        lambda: shapes.icosphere(8),
    ],
    ids=["hemisphere", "irregular_hemisphere", "irregular_saddle", "cylinder", "closed"],
)
def test_rims_and_closed_meshes_keep_their_radius(make):
    """Nothing lies beyond a rim's edges (the hemisphere's zig-zag rim included): no ball grows."""
    mesh = make()
    factor = _factor(mesh.vertices, mesh.faces)
    assert np.all(factor == 1.0)


def test_hanging_faces_grow_at_most_twice():
    sphere = shapes.icosphere(16)
    vertices, faces = _holey(sphere.vertices, sphere.faces, seed=1, detach=True)
    factor = _factor(vertices, faces)
    assert np.all(factor >= 1.0)
    assert factor.max() == pytest.approx(2.0)  # HOLED_GROWTH: at most twice the group's radius


@pytest.mark.parametrize("seed", [1, 2])
def test_backends_agree_beside_detached_faces(seed):
    pytest.importorskip("numba")
    from meshcurv._backend import use_backend

    sphere = shapes.icosphere(12)
    vertices, faces = _holey(sphere.vertices, sphere.faces, seed=seed, detach=True)
    results = {}
    for backend in ("numpy", "numba"):
        with use_backend(backend):
            results[backend] = _default(vertices, faces)
    a, b = results["numpy"], results["numba"]
    assert np.array_equal(a.valid, b.valid)
    assert np.any(a.radius > np.min(a.radius[a.valid]))  # some balls grew
    np.testing.assert_allclose(a.radius, b.radius, rtol=1e-12, atol=0)
    for field in ("k_min", "k_max"):
        np.testing.assert_allclose(getattr(a, field)[a.valid], getattr(b, field)[b.valid], rtol=1e-6, atol=1e-6)
