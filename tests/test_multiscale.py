"""meshcurv.multiscale_curvatures: one result per radius, each equal to the single call at that radius."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes
from meshcurv.errors import InvalidOptionError, MeshQualityWarning
from meshcurv.estimators import ESTIMATORS

BALL_METHODS = [name for name, estimator in ESTIMATORS.items() if "radius" in estimator.options]


def _meshes():
    hemisphere = shapes.icosphere(8)
    kept = hemisphere.faces[(hemisphere.vertices[hemisphere.faces][:, :, 2] > -0.05).all(axis=1)]
    return {
        "torus": (shapes.torus().vertices, shapes.torus().faces),
        "noisy sphere": (
            shapes.with_normal_noise(shapes.icosphere(8), 0.2, seed=3).vertices,
            shapes.icosphere(8).faces,
        ),
        "open hemisphere": (hemisphere.vertices, kept),
    }


def _single(vertices, faces, method, radius):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshQualityWarning)
        return meshcurv.principal_curvatures(vertices, faces, method=method, radius=radius)


@pytest.mark.parametrize("method", BALL_METHODS)
@pytest.mark.parametrize("name", sorted(_meshes()))
def test_each_scale_equals_the_single_call(name, method):
    vertices, faces = _meshes()[name]
    h = meshcurv.geometry.mean_edge_length(vertices, meshcurv.MeshTopology.from_faces(faces).edges)
    # any order: the results come in the order given (1.5 h: normal_cycle_ball leaves balls below one median
    # edge undefined, and the median edge of these meshes exceeds their mean h)
    radii = [4.0 * h, 1.5 * h, 2.0 * h]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshQualityWarning)
        results = meshcurv.multiscale_curvatures(vertices, faces, radii, method=method)
    assert len(results) == 3
    for radius, result in zip(radii, results):
        single = _single(vertices, faces, method, radius)
        np.testing.assert_array_equal(result.radius, radius)
        np.testing.assert_array_equal(result.valid, single.valid)
        np.testing.assert_array_equal(result.invalid_reason, single.invalid_reason)
        assert result.parameters == single.parameters
        # (quadric at 1.5 h on the noisy sphere: every ball too small for its noise, all NaN on both)
        scale = np.nanmax(np.abs(single.k_max)) if np.isfinite(single.k_max).any() else 1.0
        # the same faces and shares summed in another order (one walk for every radius): round-off
        for field in ("k_min", "k_max", "mean", "gaussian"):
            np.testing.assert_allclose(
                getattr(result, field),
                getattr(single, field),
                rtol=0,
                atol=1e-9 * (scale**2 if field == "gaussian" else scale),
                err_msg=field,
            )
        np.testing.assert_allclose(result.normals, single.normals, rtol=0, atol=1e-12)


# ---------------------------------------------------------------- the normal fits of every radius in one walk


def _jet_options():
    from meshcurv.jets import NORMAL_MIN_SPREAD, SETTLED_SLOPE

    return {"degree": 3, "iterations": 2, "settled": SETTLED_SLOPE, "min_spread": NORMAL_MIN_SPREAD}


@pytest.mark.parametrize("backend", ["numba", "numpy"])
@pytest.mark.parametrize("name", sorted(_meshes()))
def test_nested_fits_equal_the_fits_of_each_radius(name, backend):
    # one walk per vertex for three nested balls (the compiled kernel): the same points in each ball as the
    # walk of that radius alone, so the same normals up to the order of the moments' sums (round-off)
    from meshcurv._backend import use_backend
    from meshcurv.jets import fit_jet_normals
    from meshcurv.jets import nested_jet_normals

    if backend == "numba":
        pytest.importorskip("numba")
    vertices, faces = _meshes()[name]
    topology = meshcurv.MeshTopology.from_faces(faces)
    h = meshcurv.geometry.mean_edge_length(vertices, topology.edges)
    normals = meshcurv.geometry.vertex_normals(vertices, faces)
    allowed = np.ones(vertices.shape[0], dtype=bool)
    allowed[::7] = False  # some vertices kept out of every ball
    radii = [0.9 * h, 3.0 * h, 6.0 * h]  # the smallest holds too few points at some vertices: NaN there
    with use_backend(backend):
        got = nested_jet_normals(
            vertices, normals, radii, adjacency=topology.neighbour_lists, neighbours=allowed, **_jet_options()
        )
        for radius, fitted in zip(radii, got):
            alone = fit_jet_normals(
                vertices, normals, radius, adjacency=topology.neighbour_lists, neighbours=allowed, **_jet_options()
            )
            np.testing.assert_array_equal(np.isnan(fitted), np.isnan(alone))
            np.testing.assert_allclose(fitted, alone, rtol=0, atol=1e-12)
    assert np.isnan(got[0]).sum() > np.isnan(got[2]).sum()  # the smallest balls: too few points at some vertices


def test_nested_fits_keep_the_other_sheet_out_of_the_smaller_balls():
    # a flat ellipsoid: the largest ball reaches the other side round the rim, so its walk reaches vertices
    # of the other side that lie inside the smaller balls; those balls are walked on their own there and
    # still leave the other side out (the fits equal those of each radius alone)
    from meshcurv.jets import fit_jet_normals
    from meshcurv.jets import nested_jet_normals
    from meshcurv.neighborhoods import ball_face_sums

    flat = shapes.ellipsoid((3.0, 3.0, 0.15), subdivisions=10)
    vertices, faces = flat.vertices, flat.faces
    topology = meshcurv.MeshTopology.from_faces(faces)
    h = meshcurv.geometry.mean_edge_length(vertices, topology.edges)
    normals = meshcurv.geometry.vertex_normals(vertices, faces)
    radii = [2.0 * h, 3.0 * h, 9.0 * h]
    ones = np.ones((faces.shape[0], 1))
    other_side = ball_face_sums(vertices, faces, radii[0], ones)[:, 0] > (
        ball_face_sums(vertices, faces, radii[0], ones, connected=True)[:, 0] + 0.5
    )
    reached = np.isclose(
        ball_face_sums(vertices, faces, radii[2], ones, connected=True)[:, 0],
        ball_face_sums(vertices, faces, radii[2], ones)[:, 0],
        rtol=1e-12,
    )
    assert (other_side & reached).sum() > 10  # vertices whose smallest ball is walked on its own
    got = nested_jet_normals(vertices, normals, radii, adjacency=topology.neighbour_lists, **_jet_options())
    for radius, fitted in zip(radii, got):
        alone = fit_jet_normals(vertices, normals, radius, adjacency=topology.neighbour_lists, **_jet_options())
        np.testing.assert_array_equal(np.isnan(fitted), np.isnan(alone))
        np.testing.assert_allclose(fitted, alone, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(
        got[2], fit_jet_normals(vertices, normals, radii[2], adjacency=topology.neighbour_lists, **_jet_options())
    )


@pytest.mark.parametrize("name", ["icosphere", "noisy torus"])
def test_nested_fits_on_numpy_call_the_trusting_core(name, monkeypatch):
    # issue 33: the NumPy path fits each radius with the trusting core (the caller checked the vertices), not
    # the public fit_jet_normals that checks them again per radius; the normals are those of the public call
    from meshcurv import jets
    from meshcurv._backend import use_backend
    from meshcurv.jets import fit_jet_normals
    from meshcurv.jets import nested_jet_normals

    mesh = shapes.icosphere(4) if name == "icosphere" else shapes.with_normal_noise(shapes.torus(), 0.1, seed=5)
    vertices, faces = np.asarray(mesh.vertices, dtype=np.float64), mesh.faces
    topology = meshcurv.MeshTopology.from_faces(faces)
    h = meshcurv.geometry.mean_edge_length(vertices, topology.edges)
    normals = meshcurv.geometry.vertex_normals(vertices, faces)
    radii = [3.0 * h, 5.0 * h]  # balls of about 30 and 80 vertices: a cubic jet (10 terms) fits everywhere
    checked = []
    checked_points = jets.checked_points
    monkeypatch.setattr(jets, "checked_points", lambda points: checked.append(1) or checked_points(points))
    with use_backend("numpy"):
        got = nested_jet_normals(vertices, normals, radii, adjacency=topology.neighbour_lists, **_jet_options())
        assert checked == []  # the public fit_jet_normals would check the vertices once per radius
        for radius, fitted in zip(radii, got):
            alone = fit_jet_normals(vertices, normals, radius, adjacency=topology.neighbour_lists, **_jet_options())
            np.testing.assert_array_equal(fitted, alone)
            assert np.isfinite(fitted).all()


@pytest.mark.parametrize(
    "radii, message",
    [([], "non-empty sequence"), ([1.0, float("inf")], "positive finite"), ([2.0, 1.0], "must not decrease")],
)
def test_nested_fits_refuse_bad_radii(radii, message):
    from meshcurv.jets import nested_jet_normals

    torus = shapes.torus()
    adjacency = meshcurv.MeshTopology.from_faces(torus.faces).neighbour_lists
    with pytest.raises(InvalidOptionError, match=message):
        nested_jet_normals(torus.vertices, torus.vertices, radii, adjacency=adjacency, **_jet_options())


def test_scales_tell_noise_from_shape():
    # a noisy unit sphere: the smallest ball sees the noise, the larger ones the sphere (H = 1)
    noisy = shapes.with_normal_noise(shapes.icosphere(16), 0.3, seed=1)
    h = meshcurv.geometry.mean_edge_length(noisy.vertices, meshcurv.MeshTopology.from_faces(noisy.faces).edges)
    spreads = [np.std(r.mean) for r in meshcurv.multiscale_curvatures(noisy.vertices, noisy.faces, [h, 4 * h])]
    assert spreads[1] < 0.5 * spreads[0]


def test_the_one_warning_names_the_radius_whose_note_differs():
    torus = shapes.torus()
    h = meshcurv.geometry.mean_edge_length(torus.vertices, meshcurv.MeshTopology.from_faces(torus.faces).edges)
    with pytest.warns(MeshQualityWarning, match=r"at radius .*below 0\.6 edge lengths") as record:
        meshcurv.multiscale_curvatures(torus.vertices, torus.faces, [0.3 * h, 2 * h])
    assert len(record) == 1


@pytest.mark.parametrize(
    "radii, message",
    [
        ([], "non-empty sequence"),
        ("1.0", "non-empty sequence"),
        ([[1.0, 2.0]], "non-empty sequence"),
        ([1.0, -2.0], "radii"),
        ([1.0, float("nan")], "radii"),
    ],
)
def test_bad_radii_are_refused(radii, message):
    torus = shapes.torus()
    with pytest.raises(InvalidOptionError, match=message):
        meshcurv.multiscale_curvatures(torus.vertices, torus.faces, radii)


def test_a_method_without_a_ball_is_refused():
    torus = shapes.torus()
    with pytest.raises(InvalidOptionError, match="'normal_cycle' measures no ball.*'icc'"):
        meshcurv.multiscale_curvatures(torus.vertices, torus.faces, [1.0], method="normal_cycle")


# ---------------------------------------------------------------- radius="adaptive": each vertex at its own scale


@pytest.mark.slow
def test_adaptive_scale_averages_the_noise_out_where_one_radius_does_not():
    # normal noise of 0.3 edge lengths on a unit sphere: the default radius (noise rule) leaves about 3% of
    # median H error; each vertex at the stable rung of the ladder gets below 1.5% (measured 0.7%)
    noisy = shapes.with_normal_noise(shapes.icosphere(32), 0.3, seed=1)
    default = _single(noisy.vertices, noisy.faces, "icc", None)
    adaptive = _single(noisy.vertices, noisy.faces, "icc", "adaptive")
    assert adaptive.parameters["scale"] == "adaptive"
    error = np.median(np.abs(adaptive.mean - 1.0))
    assert error < 0.015 and error < 0.5 * np.median(np.abs(default.mean - 1.0))
    # from the default radius upwards, on the ladder's rungs
    rungs = np.asarray(adaptive.parameters["radii"])
    assert rungs[0] == pytest.approx(default.parameters["radius"])
    assert np.isin(adaptive.radius, rungs).all() and adaptive.radius.max() > rungs[0]


def test_adaptive_scale_is_invariant_to_rigid_motion_and_scale():
    noisy = shapes.with_normal_noise(shapes.torus(), 0.2, seed=2)
    rotation, _ = np.linalg.qr(np.random.default_rng(5).standard_normal((3, 3)))
    first = _single(noisy.vertices, noisy.faces, "icc", "adaptive")
    moved = _single(3.0 * noisy.vertices @ rotation.T + 7.0, noisy.faces, "icc", "adaptive")
    np.testing.assert_allclose(moved.radius, 3.0 * first.radius, rtol=1e-9)
    np.testing.assert_allclose(3.0 * moved.mean, first.mean, rtol=0, atol=1e-6 * np.abs(first.mean).max())


def test_adaptive_is_for_icc_only():
    torus = shapes.torus()
    with pytest.raises(InvalidOptionError, match="radius"):
        meshcurv.principal_curvatures(torus.vertices, torus.faces, method="quadric", radius="adaptive")


def test_every_radius_is_fitted_from_one_walk_even_beyond_the_coarse_level(monkeypatch):
    """icc's multi-scale fits on an ordinary mesh: every radius from nested_jet_normals, those beyond the coarse
    level (normal radius > COARSE_EDGES median edges: only a voxel surface at its default is fitted there, issue 29,
    fuzz_api 690/40) too; each equals its single call."""
    from meshcurv.estimators import icc

    vertices, faces = _meshes()["torus"]
    h = meshcurv.geometry.mean_edge_length(vertices, meshcurv.MeshTopology.from_faces(faces).edges)
    radii = [1.5 * h, 2.0 * h, 9.0 * h]  # normal radii 4.5 h, 6 h and 27 h (beyond the coarse level's 16)
    walked = []
    nested = icc.nested_jet_normals

    def recorded(vertices, normals, radii, **options):
        walked.append(list(radii))
        return nested(vertices, normals, radii, **options)

    monkeypatch.setattr(icc, "nested_jet_normals", recorded)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshQualityWarning)
        results = meshcurv.multiscale_curvatures(vertices, faces, radii, method="icc")
    np.testing.assert_allclose(walked, [[icc.NORMAL_RADIUS_RATIO * r for r in radii]], rtol=1e-15)
    for radius, result in zip(radii, results):
        single = _single(vertices, faces, "icc", radius)
        np.testing.assert_array_equal(result.valid, single.valid)
        scale = np.nanmax(np.abs(single.k_max))
        np.testing.assert_allclose(result.mean, single.mean, rtol=0, atol=1e-9 * scale)
        np.testing.assert_allclose(result.normals, single.normals, rtol=0, atol=1e-12)
