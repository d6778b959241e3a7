"""orient_faces and principal_curvatures(orient=...): consistent, outward, counted.

Expected orientations come from construction: the analytic shapes are wound
outward, so reversing a known set of faces must be undone exactly.
"""

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes
from meshcurv.result import INVALID_REASONS
from meshcurv.errors import InvalidMeshError, InvalidOptionError, MeshQualityWarning
from meshcurv.estimators import ESTIMATORS
from meshcurv.orient import orient_faces
from meshcurv.topology import MeshTopology


def reverse(faces, which):
    out = faces.copy()
    out[which] = out[which][:, [0, 2, 1]]
    return out


def same_orientation(a, b):
    """True when every face of ``a`` is a cyclic rotation of the same face of ``b``."""
    rotations = [b, b[:, [1, 2, 0]], b[:, [2, 0, 1]]]
    return bool(np.any([(a == r).all(axis=1) for r in rotations], axis=0).all())


@pytest.mark.parametrize("fraction", [0.1, 0.5, 0.9, 1.0])
def test_closed_sphere_comes_back_outward_whatever_was_reversed(fraction):
    sphere = shapes.icosphere(4)
    rng = np.random.default_rng(3)
    which = rng.random(sphere.faces.shape[0]) < fraction
    fixed, n_flipped = orient_faces(sphere.vertices, reverse(sphere.faces, which))
    assert n_flipped == which.sum()
    np.testing.assert_array_equal(fixed, sphere.faces)


def test_consistent_only_keeps_the_majority_of_a_closed_mesh():
    sphere = shapes.icosphere(4)
    all_reversed = reverse(sphere.faces, slice(None))
    fixed, n_flipped = orient_faces(sphere.vertices, all_reversed, outward=False)
    assert n_flipped == 0 and (fixed == all_reversed).all()
    which = np.arange(sphere.faces.shape[0]) < 30
    fixed, n_flipped = orient_faces(sphere.vertices, reverse(all_reversed, which), outward=False)
    assert n_flipped == 30 and (fixed == all_reversed).all()


def test_open_patch_keeps_its_majority_and_each_component_is_oriented_on_its_own():
    saddle = shapes.saddle(spacing=0.25)  # open grid, wound upward
    sphere = shapes.icosphere(2, center=(5.0, 0, 0))
    n = saddle.vertices.shape[0]
    vertices = np.vstack([saddle.vertices, sphere.vertices])
    truth = np.vstack([saddle.faces, sphere.faces + n])
    which = np.zeros(truth.shape[0], dtype=bool)
    which[:5] = True  # a few saddle faces
    which[saddle.faces.shape[0] :] = True  # the whole sphere, inward
    fixed, n_flipped = orient_faces(vertices, reverse(truth, which))
    assert n_flipped == which.sum()
    np.testing.assert_array_equal(fixed, truth)


def test_inconsistent_faces_make_curvature_invalid_unless_oriented():
    torus = shapes.torus(n_major=48, n_minor=32)  # fine enough for quadric's ball to stay on one side of the tube
    which = np.arange(torus.faces.shape[0]) % 7 == 0
    n, n_faces = int(which.sum()), torus.faces.shape[0]
    faces = reverse(torus.faces, which)
    clean = meshcurv.principal_curvatures(torus.vertices, torus.faces)
    for method in ESTIMATORS:
        with pytest.warns(MeshQualityWarning, match=f"orient='outward' reversed {n} of {n_faces} faces") as record:
            r = meshcurv.principal_curvatures(torus.vertices, faces, method=method, orient="outward")
        assert len(record) == 1
        assert r.diagnosis.n_flipped_faces == (np.arange(torus.faces.shape[0]) % 7 == 0).sum()
        assert r.diagnosis.n_inconsistent_edges == 0
        reference = meshcurv.principal_curvatures(torus.vertices, torus.faces, method=method)
        np.testing.assert_array_equal(r.valid, reference.valid)
        np.testing.assert_allclose(
            r.k_max, reference.k_max, rtol=1e-12, atol=1e-12 * np.nanmax(np.abs(reference.k_max))
        )
    with pytest.warns(MeshQualityWarning, match="inconsistently oriented"):
        kept = meshcurv.principal_curvatures(torus.vertices, faces, orient="keep")
    assert not kept.valid.all() and kept.diagnosis.n_flipped_faces == 0
    assert (
        kept.invalid_reason[~kept.valid] == INVALID_REASONS.index("on an edge between inconsistently oriented faces")
    ).all()
    assert clean.valid.all()
    # the default orients: the same numbers as the clean mesh, with one warning that says what was done
    with pytest.warns(MeshQualityWarning, match=f"reversed {n} of {n_faces} faces before the computation: to orient"):
        default = meshcurv.principal_curvatures(torus.vertices, faces)
    np.testing.assert_allclose(default.k_max, clean.k_max, rtol=1e-12, atol=1e-12)


def test_orient_keeps_the_sign_convention_of_an_outward_mesh():
    # flipping every face flips the signs, unless orient='outward' undoes it
    sphere = shapes.icosphere(8, radius=2.0)
    inward = sphere.faces[:, ::-1]
    r = meshcurv.principal_curvatures(sphere.vertices, inward, orient="keep")
    assert np.median(r.mean) == pytest.approx(-0.5, rel=0.01)
    n = sphere.faces.shape[0]
    for orient in ("outward", "auto"):  # 'auto' is 'outward' for every method but matgeom
        with pytest.warns(MeshQualityWarning, match=f"reversed {n} of {n} faces .*: the mesh was wound inward"):
            r = meshcurv.principal_curvatures(sphere.vertices, inward, orient=orient)
        assert np.median(r.mean) == pytest.approx(0.5, rel=0.01)
        assert r.parameters["orient"] == "outward" and r.diagnosis.n_flipped_faces == n
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = meshcurv.principal_curvatures(sphere.vertices, inward, orient="consistent")
    assert r.diagnosis.n_flipped_faces == 0 and np.median(r.mean) == pytest.approx(-0.5, rel=0.01)


def test_moebius_band_is_left_as_given():
    # a non-orientable strip: no orientation is consistent, nothing is reversed
    n = 24
    t = 2 * np.pi * np.arange(n) / n
    inner = np.c_[(1 - 0.2 * np.cos(t / 2)) * np.cos(t), (1 - 0.2 * np.cos(t / 2)) * np.sin(t), -0.2 * np.sin(t / 2)]
    outer = np.c_[(1 + 0.2 * np.cos(t / 2)) * np.cos(t), (1 + 0.2 * np.cos(t / 2)) * np.sin(t), 0.2 * np.sin(t / 2)]
    vertices = np.vstack([inner, outer])
    i = np.arange(n)
    j = (i + 1) % n
    # the last quad joins inner to outer: the half twist
    a, b = i, np.where(j == 0, n + j, j)
    c, d = n + i, np.where(j == 0, j, n + j)
    faces = np.vstack([np.c_[a, b, d], np.c_[a, d, c]])
    top = MeshTopology.from_faces(faces, vertices.shape[0])
    assert top.boundary_edges.sum() == 2 * n  # one boundary loop of length 2n
    fixed, n_flipped = orient_faces(vertices, faces)
    assert n_flipped == 0 and (fixed == faces).all()


def test_repeated_corner_faces_are_never_reversed():
    sphere = shapes.icosphere(2)
    faces = np.vstack([sphere.faces, [[0, 0, 1]]])
    fixed, n_flipped = orient_faces(sphere.vertices, faces)
    assert n_flipped == 0 and (fixed[-1] == [0, 0, 1]).all()


def test_topology_input_and_cyclic_rotation_are_accepted():
    sphere = shapes.icosphere(3)
    faces = reverse(sphere.faces, slice(0, 10))
    top = MeshTopology.from_faces(faces, sphere.vertices.shape[0])
    fixed, n_flipped = orient_faces(sphere.vertices, top)
    assert n_flipped == 10 and same_orientation(fixed, sphere.faces)


def test_inputs_are_not_modified():
    sphere = shapes.icosphere(2)
    faces = reverse(sphere.faces, slice(0, 10))
    before = faces.copy()
    orient_faces(sphere.vertices, faces)
    np.testing.assert_array_equal(faces, before)


def test_bad_orient_values_and_inputs_are_refused():
    sphere = shapes.icosphere(2)
    with pytest.raises(
        InvalidOptionError, match="unknown orient 'inward'; choose one of 'auto', 'outward', 'consistent', 'keep'"
    ):
        meshcurv.principal_curvatures(sphere.vertices, sphere.faces, orient="inward")
    with pytest.raises(InvalidOptionError, match="unknown orient True"):
        meshcurv.principal_curvatures(sphere.vertices, sphere.faces, orient=True)
    # an array is refused by name too (it was compared with 'auto': numpy's "truth value ... ambiguous")
    with pytest.raises(InvalidOptionError, match=r"unknown orient array\(\[1\., 2\.\]\)"):
        meshcurv.principal_curvatures(sphere.vertices, sphere.faces, orient=np.array([1.0, 2.0]))
    top = MeshTopology.from_faces(sphere.faces, sphere.vertices.shape[0] + 1)
    with pytest.raises(InvalidMeshError, match="MeshTopology of 43 vertices but `vertices` has 42 rows"):
        orient_faces(sphere.vertices, top)
    with pytest.raises(InvalidMeshError, match="look 1-based"):
        orient_faces(sphere.vertices, sphere.faces + 1)


@pytest.mark.parametrize("wound", ["as it should be", "every patch outward", "every face inward"])
def test_a_cavity_wall_faces_into_the_cavity(wound):
    # a hollow ball: outward means out of the material, so the inner wall's normals point into the cavity,
    # whose surface then has H = -1/r seen from the material (concave), the outer H = +1/R
    outer = shapes.icosphere(16, radius=2.0)
    inner = shapes.icosphere(8, radius=1.0, center=(0.2, 0.0, 0.0))
    n = outer.vertices.shape[0]
    vertices = np.vstack([outer.vertices, inner.vertices])
    right = np.vstack([outer.faces, inner.faces[:, ::-1] + n])
    faces = {
        "as it should be": right,
        "every patch outward": np.vstack([outer.faces, inner.faces + n]),
        "every face inward": right[:, ::-1],
    }[wound]
    fixed, n_flipped = orient_faces(vertices, faces)
    np.testing.assert_array_equal(np.sort(fixed, axis=1), np.sort(right, axis=1))
    assert (meshcurv.geometry.face_normals(vertices, fixed) * meshcurv.geometry.face_normals(vertices, right)).sum(
        axis=1
    ).min() > 0.99
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshQualityWarning)
        r = meshcurv.principal_curvatures(vertices, faces)
    assert np.median(r.mean[:n]) == pytest.approx(0.5, rel=1e-3)
    assert np.median(r.mean[n:]) == pytest.approx(-1.0, rel=1e-2)


def test_separate_balls_are_each_outward():
    a, b = shapes.icosphere(8, radius=1.0), shapes.icosphere(8, radius=1.0, center=(1.5, 0.0, 0.0))
    vertices = np.vstack([a.vertices, b.vertices])  # their bounding boxes overlap, neither holds the other
    faces = np.vstack([a.faces[:, ::-1], b.faces + a.vertices.shape[0]])
    fixed, n_flipped = orient_faces(vertices, faces)
    assert n_flipped == a.faces.shape[0]
    centres = np.repeat([[0.0, 0.0, 0.0], [1.5, 0.0, 0.0]], [a.faces.shape[0], b.faces.shape[0]], axis=0)
    away = vertices[fixed].mean(axis=1) - centres
    assert (np.einsum("ij,ij->i", meshcurv.geometry.face_normals(vertices, fixed), away) > 0).all()
